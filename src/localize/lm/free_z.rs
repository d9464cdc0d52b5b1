//! The fix with a free height (issue 40 §2, "in 3-D where the user asks"): LM over
//! `[x, y, δz]`, the horizontal position and the height offset from the stated target height
//! (the plane the network's `dz` are measured from), with the planar fix's problem rows, config
//! and iteration ([`iterate`]).
//!
//! Start: the caller's `[x, y, δz]`, or **\[choice\]** a multi-start over the height: for each
//! `δz` of [`FREE_Z_START_OFFSETS_M`] the planar fix (grid start, E5–E6) of the network seen
//! from that height, lifted to that `δz`, then LM over the three unknowns; the lowest cost is
//! kept (the first on a tie). The planar fix at the wrong height is biased (docs/rooms-3d.md),
//! and from a start 0.7 m off in height LM can stop in a local minimum next to a receiver: the
//! tests met one with the stated height alone. When every node sits at one height `H`, the
//! cost is symmetric about `δz = H − z_t` (a target below the ceiling and its mirror image above
//! it fit equally): the fix is the branch of the starts, below the nodes when they are more than
//! 1 m above the stated height.

use super::iterate::{iterate, LmProblem, Run};
use super::problem::Problem;
use super::{chi_square_upper_tail, locate, DelayMeasurements, LmConfig, Termination};
use crate::error::{limits, Error, Result};
use crate::localize::bound3_from_fisher;
use crate::math::{Mat3, Real, Vec3};
use crate::measure::{unit_from_dz, vertical_unit, Network};
use crate::scenario::Area;
use alloc::vec::Vec;

/// The height offsets from the stated target height the default start tries, m, in order.
pub const FREE_Z_START_OFFSETS_M: [Real; 5] = [0.0, -0.5, 0.5, -1.0, 1.0];

/// Result of a fix with a free height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeZReport {
    /// `[x̂, ŷ, δẑ]`, m (`δẑ` from the stated target height).
    pub position: Vec3,
    /// `(JᵀR⁻¹J)⁻¹` at the fix, m²; `None` when singular (e.g. every node in the target's
    /// plane: the height is unobservable there).
    pub covariance_m2: Option<Mat3>,
    /// `𝓛` at the fix (E5).
    pub cost: Real,
    /// Iterations (Jacobian evaluations) of the kept run.
    pub iterations: usize,
    /// Why it stopped.
    pub termination: Termination,
    /// Links that carried a measurement.
    pub links_used: usize,
    /// Where the kept run started, `[x, y, δz]`, m.
    pub start: Vec3,
    /// True when the caller's start ended implausibly (the χ² test of
    /// [`LmConfig::restart_tail_probability`], `m − 3` degrees of freedom) and the kept fix comes
    /// from the default multi-start.
    pub restarted: bool,
}

/// The planar problem's rows over `[x, y, δz]`.
struct FreeZ<'a>(&'a Problem);

impl LmProblem<3> for FreeZ<'_> {
    fn cost(&self, x: &Vec3) -> Real {
        let r = x.xy();
        self.0
            .rows
            .iter()
            .map(|row| {
                let d = crate::measure::node_distance(row.tx, row.dz_tx - x.z, r)
                    + crate::measure::node_distance(row.rx, row.dz_rx - x.z, r);
                let e = row.range - d;
                row.weight * e * e
            })
            .sum()
    }

    fn linearize(&self, x: &Vec3) -> (Real, Mat3, Vec3) {
        let r = x.xy();
        let (mut cost, mut n, mut g) = (0.0, Mat3::zeros(), Vec3::zeros());
        for row in &self.0.rows {
            let (h_tx, h_rx) = (row.dz_tx - x.z, row.dz_rx - x.z);
            let (u_tx, d_tx) = unit_from_dz(row.tx, h_tx, r);
            let (u_rx, d_rx) = unit_from_dz(row.rx, h_rx, r);
            let gh = u_tx + u_rx;
            let j = Vec3::new(
                gh.x,
                gh.y,
                vertical_unit(h_tx, d_tx) + vertical_unit(h_rx, d_rx),
            );
            let e = row.range - (d_tx + d_rx);
            cost += row.weight * e * e;
            n += row.weight * j * j.transpose();
            g += (row.weight * e) * j;
        }
        (cost, n, g)
    }
}

fn report(p: &Problem, cfg: &LmConfig, start: Vec3) -> FreeZReport {
    let Run {
        x,
        normal,
        cost,
        iterations,
        termination,
    } = iterate(&FreeZ(p), cfg, start);
    FreeZReport {
        position: x,
        covariance_m2: bound3_from_fisher(&normal).map(|b| b.covariance_m2),
        cost,
        iterations,
        termination,
        links_used: p.rows.len(),
        start,
        restarted: false,
    }
}

/// The default start's runs (module doc): per offset of [`FREE_Z_START_OFFSETS_M`] the planar
/// fix of the network seen from that height, then LM over `[x, y, δz]`; the lowest cost.
fn multi_start(
    net: &Network,
    p: &Problem,
    m: &DelayMeasurements,
    config: &LmConfig,
    area: &Area,
) -> Result<FreeZReport> {
    let mut best: Option<FreeZReport> = None;
    for dz in FREE_Z_START_OFFSETS_M {
        let shift = |v: &[Real]| v.iter().map(|h| h - dz).collect::<Vec<Real>>();
        let seen = Network {
            transmitters_dz: shift(&net.transmitters_dz),
            receivers_dz: shift(&net.receivers_dz),
            ..net.clone()
        };
        let planar = locate(&seen, m, config, None, area)?;
        let run = report(
            p,
            config,
            Vec3::new(planar.position.x, planar.position.y, dz),
        );
        if best.as_ref().is_none_or(|b| run.cost < b.cost) {
            best = Some(run);
        }
    }
    // The offsets are not empty, so a run was kept.
    best.ok_or(Error::TooFewLinks {
        available: 0,
        required: super::MIN_LINKS,
    })
}

/// Weighted LM fix over `[x, y, δz]` (E5–E6 with 3-D distances and a free height). Starts at
/// `initial` or, when `None`, at the multi-start of the module doc.
pub fn locate_free_z(
    net: &Network,
    m: &DelayMeasurements,
    config: &LmConfig,
    initial: Option<Vec3>,
    area: &Area,
) -> Result<FreeZReport> {
    let problem = Problem::new(net, m)?;
    let Some(start) = initial else {
        return multi_start(net, &problem, m, config, area);
    };
    if !start.iter().all(|v| v.is_finite()) {
        return Err(Error::NonFinite {
            field: "initial_m".into(),
        });
    }
    for v in start.iter() {
        limits::COORDINATE_M.check("initial_m", *v)?;
    }
    let fix = report(&problem, config, start);
    let dof = problem.rows.len().saturating_sub(3);
    let implausible = config.restart_tail_probability.is_some_and(|p| {
        dof > 0 && fix.cost > dof as Real && chi_square_upper_tail(dof, fix.cost) < p
    });
    if implausible && area.validate().is_ok() {
        let retry = multi_start(net, &problem, m, config, area)?;
        if retry.cost < fix.cost {
            return Ok(FreeZReport {
                restarted: true,
                ..retry
            });
        }
    }
    Ok(fix)
}
