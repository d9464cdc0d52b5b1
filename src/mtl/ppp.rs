//! The PPP disc blocking model (spec multi-target.md §6.2, Appendix A of \[A\]): scatterers are
//! discs of diameter `D` whose centres form a homogeneous Poisson point process of intensity `λ`.
//! A segment of length `d` is LoS iff no centre lies in the `d × D` rectangle around it, so
//! `p_LoS(d) = e^{−λ d D}` (M9). For a node pattern `(a, b)` at `x` the rectangles `A_n` of the
//! unblocked nodes form the LoS polygon `A_L`, and each blocked node's NLoS polygon
//! `A'_n = A_n \ A_L` must hold a centre: the lower bound (M10) and the exact Poisson
//! inclusion–exclusion value (M11).
//!
//! Node order: TX `j` is node `j`, RX `j` is node `N_t + j`. Pattern bits: bit `j` of `a` is
//! `γ^T_j` and bit `j` of `b` is `γ^R_j`, 1 = LoS (unblocked), 0 = blocked (§3).

use alloc::format;
use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::{exp, Real, Vec2};
use crate::mtl::blocking::NodePatternModel;
use crate::mtl::polygon::{
    rectangle_in_region, segment_rectangle, subset_intersection_areas_clipped, Rect,
};

/// Largest `N_t + N_r` the PPP model accepts (its area tables have `2^(N_t+N_r)` entries).
pub const MAX_PPP_NODES: usize = 20;

/// LoS probability of a segment of length `distance_m` (M9): `e^{−λ d D}`.
#[inline]
pub fn p_los(lambda: Real, distance_m: Real, diameter_m: Real) -> Real {
    exp(-lambda * distance_m * diameter_m)
}

/// The PPP disc blocking model (§6.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PppBlocking {
    /// Intensity `λ` of the disc centres, m⁻² (≥ 0).
    pub lambda: Real,
    /// Disc diameter `D`, m (> 0): the width of each rectangle `A_n`.
    pub diameter: Real,
    /// Region `R` holding the centres; when given, every `A_n` is clipped to it (\[P\]).
    pub region: Option<Rect>,
    /// `true`: exact inclusion–exclusion (M11); `false`: the lower bound (M10) of \[A\].
    pub exact: bool,
}

fn check_point(field: impl FnOnce() -> alloc::string::String, p: Vec2) -> Result<()> {
    if p.x.is_finite() && p.y.is_finite() {
        Ok(())
    } else {
        Err(Error::NonFinite { field: field() })
    }
}

impl PppBlocking {
    /// A validated model: [`Error::NonFinite`] / [`Error::OutOfRange`] for `λ` not finite or
    /// negative (`lambda`), [`Error::NotPositive`] for `D ≤ 0` or not finite (`diameter`).
    pub fn new(
        lambda: Real,
        diameter: Real,
        region: Option<Rect>,
        exact: bool,
    ) -> Result<PppBlocking> {
        let m = PppBlocking {
            lambda,
            diameter,
            region,
            exact,
        };
        m.validate()?;
        Ok(m)
    }

    /// Checks the parameters (see [`PppBlocking::new`]; a given region must have `min < max`).
    pub fn validate(&self) -> Result<()> {
        if !self.lambda.is_finite() {
            return Err(Error::NonFinite {
                field: "lambda".into(),
            });
        }
        if self.lambda < 0.0 {
            return Err(Error::OutOfRange {
                field: "lambda".into(),
                value: self.lambda,
                allowed: "λ ≥ 0 m⁻²",
            });
        }
        if !(self.diameter.is_finite() && self.diameter > 0.0) {
            return Err(Error::NotPositive {
                field: "diameter".into(),
                value: self.diameter,
            });
        }
        if let Some(r) = self.region {
            Rect::new(r.min, r.max)?;
        }
        Ok(())
    }

    /// `p_LoS(d) = e^{−λ d D}` (M9).
    #[inline]
    pub fn p_los(&self, distance_m: Real) -> Real {
        p_los(self.lambda, distance_m, self.diameter)
    }

    /// The rectangles `A_n` at `x` (TXs then RXs, clipped to the region when one is set) and the
    /// areas of all their intersections. Compute once per `x`, then evaluate any number of node
    /// patterns with [`NodeAreas::probability`]. [`Error::NonFinite`] names a non-finite point
    /// (`x`, `tx[j]`, `rx[j]`); [`Error::SizeLimit`] when `N_t + N_r >` [`MAX_PPP_NODES`].
    pub fn node_areas(&self, x: Vec2, tx: &[Vec2], rx: &[Vec2]) -> Result<NodeAreas> {
        self.validate()?;
        check_point(|| "x".into(), x)?;
        for (j, p) in tx.iter().enumerate() {
            check_point(|| format!("tx[{j}]"), *p)?;
        }
        for (j, p) in rx.iter().enumerate() {
            check_point(|| format!("rx[{j}]"), *p)?;
        }
        let n = tx.len() + rx.len();
        if n > MAX_PPP_NODES {
            return Err(Error::SizeLimit {
                field: "nodes",
                value: n,
                min: 0,
                max: MAX_PPP_NODES,
            });
        }
        let full: Vec<[Vec2; 4]> = tx
            .iter()
            .chain(rx.iter())
            .map(|node| segment_rectangle(x, *node, self.diameter))
            .collect();
        let rects: Vec<Vec<Vec2>> = full
            .iter()
            .map(|a| rectangle_in_region(a, self.region.as_ref()))
            .collect();
        let intersections = subset_intersection_areas_clipped(&rects, &full)?;
        // Union areas of every node set: zeta transform of (−1)^{|T|+1} |∩_T A_n|.
        let mut union = intersections.clone();
        for (t, u) in union.iter_mut().enumerate() {
            if t.count_ones() % 2 == 0 {
                *u = -*u;
            }
        }
        for i in 0..n {
            for s in 0..union.len() {
                if s & (1 << i) != 0 {
                    union[s] += union[s ^ (1 << i)];
                }
            }
        }
        Ok(NodeAreas {
            n_tx: tx.len(),
            n_rx: rx.len(),
            rectangles: rects,
            intersections,
            union,
        })
    }

    /// `P_node(γ^T = a, γ^R = b | x)` (M11 when `exact`, else the bound M10). Bits at or above
    /// `N_t` in `a` (`N_r` in `b`) are ignored. Errors as [`PppBlocking::node_areas`].
    pub fn node_pattern_probability(
        &self,
        x: Vec2,
        tx: &[Vec2],
        rx: &[Vec2],
        a_bits: u64,
        b_bits: u64,
    ) -> Result<Real> {
        let areas = self.node_areas(x, tx, rx)?;
        Ok(areas.probability(self.lambda, self.exact, a_bits, b_bits))
    }
}

/// The rectangles `A_n` at one point and the areas of their intersections and unions (§6.2).
#[derive(Debug, Clone, PartialEq)]
pub struct NodeAreas {
    /// `N_t`.
    pub n_tx: usize,
    /// `N_r`.
    pub n_rx: usize,
    /// `A_n` (TXs then RXs), possibly clipped; empty when of zero area.
    pub rectangles: Vec<Vec<Vec2>>,
    /// `|∩_{n∈T} A_n|` indexed by the bit mask of `T` (0 for `T = ∅`).
    intersections: Vec<Real>,
    /// `|∪_{n∈S} A_n|` indexed by the bit mask of `S`.
    union: Vec<Real>,
}

impl NodeAreas {
    /// Number of nodes `N_t + N_r`.
    pub fn node_count(&self) -> usize {
        self.n_tx + self.n_rx
    }

    /// `|A_n|`, m².
    pub fn area(&self, n: usize) -> Real {
        self.intersections[1 << n]
    }

    /// `|∩_{n∈T} A_n|` for the node mask `T`, m².
    pub fn intersection_area(&self, mask: usize) -> Real {
        self.intersections[mask]
    }

    /// `|∪_{n∈S} A_n|` for the node mask `S` (inclusion–exclusion), m².
    pub fn union_area(&self, mask: usize) -> Real {
        self.union[mask]
    }

    /// Node mask of the unblocked set `U` of pattern `(a, b)`.
    pub fn unblocked_mask(&self, a_bits: u64, b_bits: u64) -> usize {
        let a = (a_bits as usize) & ((1usize << self.n_tx) - 1);
        let b = (b_bits as usize) & ((1usize << self.n_rx) - 1);
        a | (b << self.n_tx)
    }

    /// The lower bound (M10): `e^{−λ|A_L|} Π_{n∈B} (1 − e^{−λ|A'_n|})`, with
    /// `|A'_n| = |A_L ∪ A_n| − |A_L|`.
    pub fn bound(&self, lambda: Real, unblocked: usize) -> Real {
        let full = (1usize << self.node_count()) - 1;
        let blocked = full & !unblocked;
        let al = self.union[unblocked];
        let mut p = exp(-lambda * al);
        for n in 0..self.node_count() {
            if blocked & (1 << n) != 0 {
                let an = (self.union[unblocked | (1 << n)] - al).max(0.0);
                p *= 1.0 - exp(-lambda * an);
            }
        }
        p
    }

    /// The exact value (M11): `e^{−λ|A_L|} Σ_{T⊆B} (−1)^{|T|} e^{−λ|∪_{n∈T} A'_n|}`, with
    /// `|∪_{n∈T} A'_n| = |A_L ∪ ∪_{n∈T} A_n| − |A_L|`.
    pub fn exact(&self, lambda: Real, unblocked: usize) -> Real {
        let full = (1usize << self.node_count()) - 1;
        let blocked = full & !unblocked;
        let al = self.union[unblocked];
        let mut sum = 0.0;
        let mut t = blocked;
        loop {
            let extra = (self.union[unblocked | t] - al).max(0.0);
            let term = exp(-lambda * extra);
            if t.count_ones().is_multiple_of(2) {
                sum += term;
            } else {
                sum -= term;
            }
            if t == 0 {
                break;
            }
            t = (t - 1) & blocked;
        }
        exp(-lambda * al) * sum
    }

    /// (M11) when `exact`, else (M10), for every node pattern, indexed by the unblocked mask
    /// `a | b << N_t`. With `E[S] = e^{−λ|∪_{n∈S} A_n|}` tabulated once (`2^N` exponentials):
    /// (M11) is `Σ_{T⊆B} (−1)^{|T|} E[U ∪ T]`, a signed superset sum over the blocked set,
    /// evaluated for all patterns by one `O(N 2^N)` transform; (M10) is
    /// `E[U] Π_{n∈B} (1 − E[U ∪ {n}]/E[U])`. Equal to [`NodeAreas::probability`] per pattern up
    /// to rounding.
    pub fn all_patterns(&self, lambda: Real, exact: bool) -> Vec<Real> {
        let n = self.node_count();
        let e: Vec<Real> = self.union.iter().map(|&u| exp(-lambda * u)).collect();
        if exact {
            // f[S] = Σ_{T ⊆ ~S} (−1)^{|T|} e[S ∪ T]: for each node, f[S] -= f[S | bit] when the
            // bit is not in S (in-place superset transform with signs).
            let mut f = e;
            for i in 0..n {
                let bit = 1usize << i;
                for s in 0..f.len() {
                    if s & bit == 0 {
                        f[s] -= f[s | bit];
                    }
                }
            }
            // Rounding can leave tiny negatives for near-impossible patterns.
            f.iter_mut().for_each(|v| *v = v.max(0.0));
            f
        } else {
            let full = (1usize << n) - 1;
            (0..=full)
                .map(|u| {
                    let eu = e[u];
                    if eu == 0.0 {
                        return 0.0;
                    }
                    let mut p = eu;
                    for k in 0..n {
                        let bit = 1usize << k;
                        if u & bit == 0 {
                            p *= (1.0 - e[u | bit] / eu).max(0.0);
                        }
                    }
                    p
                })
                .collect()
        }
    }

    /// `P_node(γ^T = a, γ^R = b | x)`: (M11) when `exact`, else (M10).
    pub fn probability(&self, lambda: Real, exact: bool, a_bits: u64, b_bits: u64) -> Real {
        let u = self.unblocked_mask(a_bits, b_bits);
        if exact {
            self.exact(lambda, u)
        } else {
            self.bound(lambda, u)
        }
    }
}

/// A [`PppBlocking`] model bound to one network's node positions: the
/// [`NodePatternModel`] the Bayesian blocking likelihood (M4–M5) consumes.
#[derive(Debug, Clone, PartialEq)]
pub struct PppNodeModel {
    /// The PPP parameters.
    pub model: PppBlocking,
    /// TX positions `u_j`, m.
    pub tx: Vec<Vec2>,
    /// RX positions `v_j`, m.
    pub rx: Vec<Vec2>,
}

impl PppNodeModel {
    /// Validates the model and the node positions (errors as [`PppBlocking::node_areas`]).
    pub fn new(model: PppBlocking, tx: Vec<Vec2>, rx: Vec<Vec2>) -> Result<PppNodeModel> {
        let centre = tx
            .first()
            .or(rx.first())
            .copied()
            .unwrap_or_else(Vec2::zeros);
        model.node_areas(centre, &tx, &rx)?;
        Ok(PppNodeModel { model, tx, rx })
    }

    /// The areas at `x` (see [`PppBlocking::node_areas`]).
    pub fn node_areas(&self, x: Vec2) -> Result<NodeAreas> {
        self.model.node_areas(x, &self.tx, &self.rx)
    }

    /// `P_node(a, b | x)` of every node pattern at `x`, indexed `a | b << N_t` (the order of
    /// [`crate::mtl::blocking::NodeTable`]), from one area computation ([`NodeAreas::all_patterns`]).
    pub fn pattern_probabilities(&self, x: Vec2) -> Result<Vec<Real>> {
        let areas = self.node_areas(x)?;
        Ok(areas.all_patterns(self.model.lambda, self.model.exact))
    }
}

impl NodePatternModel for PppNodeModel {
    /// (M11) or (M10) at `x`; 0 when `x` is not finite (so `L_b = ∞`, never NaN).
    fn node_pattern_probability(&self, x: &Vec2, a: u64, b: u64) -> Real {
        match self.node_areas(*x) {
            Ok(areas) => areas.probability(self.model.lambda, self.model.exact, a, b),
            Err(_) => 0.0,
        }
    }

    /// All patterns from one area computation ([`PppNodeModel::pattern_probabilities`]); all
    /// zeros when `x` is not finite.
    fn pattern_probabilities_at(&self, x: &Vec2, n_tx: usize, n_rx: usize) -> Vec<Real> {
        self.pattern_probabilities(*x)
            .unwrap_or_else(|_| alloc::vec![0.0; 1 << (n_tx + n_rx)])
    }
}

#[cfg(test)]
mod tests;
