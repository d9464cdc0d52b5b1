//! The generalised optimal sub-pattern assignment metric (GOSPA; Rahmathullah,
//! García-Fernández and Svensson, FUSION 2017) with `α = 2`, the score of a multi-target
//! estimate against the truth (issue 41 §1): for true positions `X` (`|X| = n`) and estimates
//! `Y` (`|Y| = m`),
//!
//! ```text
//! d_p^(c,2)(X, Y) = ( min_γ Σ_{(i,j)∈γ} d(x_i, y_j)^p  +  c^p/2 · (n + m − 2|γ|) )^(1/p)
//! ```
//!
//! over partial assignments `γ` whose pairs are closer than `c`. With `α = 2` it splits into a
//! localisation part (`Σ d^p` over `γ`), a missed part (`c^p/2` per unassigned truth) and a
//! false part (`c^p/2` per unassigned estimate), all reported as `p`-th powers as Stone Soup's
//! `GOSPAMetric` does. It is computed as one optimal assignment ([`assign`]) of the
//! `min(n, m)` pairs with the cost `min(d, c)^p`: a pair at `d ≥ c` costs `c^p`, exactly the
//! price of leaving both unassigned, so such pairs are reported as one missed and one false.

use alloc::vec::Vec;

use serde::Serialize;

use crate::error::{Error, Result};
use crate::math::{assign, pow, Real, Vec2};

/// Most points on either side ([`gospa`] is `O(n²·m)`): 4096 (≈ 0.1 s at the cap).
pub const MAX_GOSPA_POINTS: usize = 4096;

/// GOSPA settings (`α = 2` fixed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GospaConfig {
    /// Cut-off distance `c`, m (> 0).
    pub c: Real,
    /// Order `p` (≥ 1).
    pub p: Real,
}

/// The GOSPA distance and its parts (the parts are `p`-th powers; their sum is `distance^p`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gospa {
    /// `d_p^(c,2)(X, Y)`, m.
    pub distance: Real,
    /// `Σ d(x_i, y_j)^p` over the assigned pairs, m^p.
    pub localisation: Real,
    /// `c^p/2 ·` the unassigned truths, m^p.
    pub missed: Real,
    /// `c^p/2 ·` the unassigned estimates, m^p (JSON key `false`).
    #[serde(rename = "false")]
    pub false_: Real,
    /// The assigned pairs `(truth, estimate)`, closer than `c`, in truth order.
    pub pairs: Vec<(usize, usize)>,
    /// Unassigned truths.
    pub missed_count: usize,
    /// Unassigned estimates.
    pub false_count: usize,
}

fn check_points(field: &'static str, pts: &[Vec2]) -> Result<()> {
    if pts.len() > MAX_GOSPA_POINTS {
        return Err(Error::SizeLimit {
            field,
            value: pts.len(),
            min: 0,
            max: MAX_GOSPA_POINTS,
        });
    }
    if let Some(i) = pts
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        return Err(Error::NonFinite {
            field: alloc::format!("{field}[{i}]"),
        });
    }
    Ok(())
}

/// GOSPA (`α = 2`) between the true positions `truth` and the estimates `estimates`.
/// Errors: `c` not positive and finite, `p` below 1 or not finite, a coordinate not finite,
/// more than [`MAX_GOSPA_POINTS`] on a side.
pub fn gospa(truth: &[Vec2], estimates: &[Vec2], config: &GospaConfig) -> Result<Gospa> {
    let GospaConfig { c, p } = *config;
    if !(c.is_finite() && c > 0.0) {
        return Err(Error::NotPositive {
            field: "gospa.c".into(),
            value: c,
        });
    }
    if !(p.is_finite() && p >= 1.0) {
        return Err(Error::OutOfRange {
            field: "gospa.p".into(),
            value: p,
            allowed: "1 ≤ p < ∞",
        });
    }
    check_points("truth", truth)?;
    check_points("estimates", estimates)?;
    let (n, m) = (truth.len(), estimates.len());
    let cp = pow(c, p);
    let mut cost = Vec::with_capacity(n * m);
    for x in truth {
        for y in estimates {
            let d = (x - y).norm();
            cost.push(if d < c { pow(d, p) } else { cp });
        }
    }
    let a = assign(&cost, n, m);
    let mut pairs = Vec::new();
    let mut localisation = 0.0;
    for (i, j) in a.rows.iter().enumerate() {
        if let Some(j) = *j {
            let d = (truth[i] - estimates[j]).norm();
            if d < c {
                pairs.push((i, j));
                localisation += cost[i * m + j];
            }
        }
    }
    let (missed_count, false_count) = (n - pairs.len(), m - pairs.len());
    let missed = 0.5 * cp * missed_count as Real;
    let false_ = 0.5 * cp * false_count as Real;
    let total = localisation + missed + false_;
    Ok(Gospa {
        distance: pow(total, 1.0 / p),
        localisation,
        missed,
        false_,
        pairs,
        missed_count,
        false_count,
    })
}
