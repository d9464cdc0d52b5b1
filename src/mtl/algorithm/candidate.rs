//! Candidates of Algorithm 1 (§4): a matching `ℳ`, a location `x̂`, the observed blocking vector
//! `ĝ` on the processed TRPs, the vector likelihood (M6), the score `J` (M2) and Gauss–Newton
//! location refinement.

use alloc::vec::Vec;

use crate::math::{sqrt, Mat2, Real, Vec2};
use crate::mtl::algorithm::{Measurements, Refinement};
use crate::mtl::blocking::PartialVector;
use crate::mtl::trp::TrpMap;

/// One (TRP, MPC) pair `(m, i)`: range `r_{m,i}` of TRP `m` (both 0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Pair {
    /// TRP `m`.
    pub trp: usize,
    /// MPC index `i` within `r_m`.
    pub mpc: usize,
}

/// A hypothesis `(ℳ, x̂, ĝ)` of one target (§4).
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// The matching `ℳ` (≤ 1 pair per TRP), sorted by TRP.
    pub matching: Vec<Pair>,
    /// Location estimate `x̂`, m.
    pub x: Vec2,
    /// Observed vector `ĝ` on the processed TRPs `S` (`ĝ_m = 1` iff `m` is matched).
    pub g: PartialVector,
    /// Family (seed) id.
    pub family: usize,
    /// Blocking likelihood `L_b = −ln P(γ̂_S(x̂) = ĝ)`, nats.
    pub l_b: Real,
    /// Score `J` (M2): range term plus `L_b`.
    pub j: Real,
}

impl Candidate {
    /// The matching with the pair of TRP `trp` removed (unchanged if absent).
    pub fn without(&self, trp: usize) -> Vec<Pair> {
        self.matching
            .iter()
            .copied()
            .filter(|p| p.trp != trp)
            .collect()
    }

    /// Number of (TRP, MPC) pairs two matchings share.
    pub fn shared_pairs(a: &[Pair], b: &[Pair]) -> usize {
        a.iter().filter(|p| b.contains(p)).count()
    }
}

/// The geometry of one run: TRP map, node positions, ranges and `cσ`.
#[derive(Debug, Clone, Copy)]
pub struct Geometry<'a> {
    /// TRP map.
    pub map: TrpMap,
    /// Measured input.
    pub input: Measurements<'a>,
}

impl Geometry<'_> {
    /// Range `r_{m,i}` of `p`.
    pub fn range_of(&self, p: Pair) -> Real {
        self.input.ranges[p.trp][p.mpc]
    }

    /// `d_m(x)` (M1).
    pub fn d(&self, m: usize, x: &Vec2) -> Real {
        self.map.range(m, x, self.input.tx, self.input.rx)
    }

    /// `∇d_m(x)`.
    pub fn grad(&self, m: usize, x: &Vec2) -> Vec2 {
        self.map.range_gradient(m, x, self.input.tx, self.input.rx)
    }

    /// `Σ_ℳ (r − d_m(x))²`, m².
    pub fn sum_sq(&self, matching: &[Pair], x: &Vec2) -> Real {
        matching
            .iter()
            .map(|&p| {
                let e = self.range_of(p) - self.d(p.trp, x);
                e * e
            })
            .sum()
    }

    /// The range term of (M2): `Σ_ℳ (r − d_m(x))² / (2c²σ²)`.
    pub fn range_term(&self, matching: &[Pair], x: &Vec2) -> Real {
        let s = self.input.c_sigma_m;
        self.sum_sq(matching, x) / (2.0 * s * s)
    }

    /// `(GᵀG)⁻¹` of the gradient rows of `matching` at `x`; `None` when singular or not finite.
    pub fn information_inverse(&self, matching: &[Pair], x: &Vec2) -> Option<Mat2> {
        let mut gtg = Mat2::zeros();
        for p in matching {
            let g = self.grad(p.trp, x);
            gtg += g * g.transpose();
        }
        let inv = gtg.try_inverse()?;
        inv.iter().all(|v| v.is_finite()).then_some(inv)
    }

    /// The ellipse test of (M6): `|e|/σ_e` for range `r` of TRP `m` against a candidate with
    /// matching `matching` at `x`, `e = r − d_m(x)`, `σ_e² = c²σ²(1 + η_mᵀ(GᵀG)⁻¹η_m)`.
    /// `None` when `GᵀG` is singular (the candidate has no location).
    pub fn normalized_error(&self, matching: &[Pair], x: &Vec2, m: usize, r: Real) -> Option<Real> {
        let inv = self.information_inverse(matching, x)?;
        Some(self.normalized_error_with(&inv, x, m, r))
    }

    /// [`Geometry::normalized_error`] with `(GᵀG)⁻¹` already computed (one inverse per
    /// candidate and TRP).
    pub fn normalized_error_with(&self, inv: &Mat2, x: &Vec2, m: usize, r: Real) -> Real {
        let eta = self.grad(m, x);
        let s2 = 1.0 + eta.dot(&(inv * eta));
        let sigma = self.input.c_sigma_m * sqrt(s2.max(1.0));
        (r - self.d(m, x)).abs() / sigma
    }

    /// Gauss–Newton on `Σ_ℳ (r − d_m(x))²` from `x0` (§4, \[P\]): at most `max_iterations`
    /// steps, stopping when `‖Δx‖ < step_tol_m`. A step that would increase the sum is halved
    /// (up to [`MAX_STEP_HALVINGS`] times, then the iteration stops), so the sum never grows and
    /// ill-conditioned ghost matchings cannot diverge. Returns `None` when the normal matrix is
    /// singular or the iterate stops being finite.
    pub fn refine(&self, matching: &[Pair], x0: Vec2, cfg: &Refinement) -> Option<Vec2> {
        let mut x = x0;
        let mut cost = self.sum_sq(matching, &x);
        for _ in 0..cfg.max_iterations {
            let mut gtg = Mat2::zeros();
            let mut gtr = Vec2::zeros();
            for &p in matching {
                let g = self.grad(p.trp, &x);
                let e = self.range_of(p) - self.d(p.trp, &x);
                gtg += g * g.transpose();
                gtr += g * e;
            }
            let mut dx = gtg.try_inverse()? * gtr;
            if !(dx.x.is_finite() && dx.y.is_finite()) {
                return None;
            }
            let mut halvings = 0;
            let mut next = self.sum_sq(matching, &(x + dx));
            while next > cost && halvings < MAX_STEP_HALVINGS {
                dx *= 0.5;
                halvings += 1;
                next = self.sum_sq(matching, &(x + dx));
            }
            if next > cost {
                break;
            }
            x += dx;
            cost = next;
            if dx.norm() < cfg.step_tol_m {
                break;
            }
        }
        Some(x)
    }
}

/// Largest number of step halvings per Gauss–Newton iteration in [`Geometry::refine`].
pub const MAX_STEP_HALVINGS: usize = 30;
