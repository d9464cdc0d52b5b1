//! Candidates of Algorithm 1 (§4): a matching `ℳ`, a location `x̂`, the observed blocking vector
//! `ĝ` on the processed TRPs, the vector likelihood (M6), the score `J` (M2) and Gauss–Newton
//! location refinement.

use alloc::vec::Vec;

use crate::math::{sqrt, Mat2, Real, Vec2};
use crate::mtl::algorithm::{Measurements, Refinement};
use crate::mtl::blocking::PartialVector;
use crate::mtl::geometry::MAX_GRADIENT_CONDITION;
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

    /// The matching with `pair` inserted at its place (kept sorted by TRP; `pair`'s TRP must not
    /// be matched yet).
    pub fn with_pair(&self, pair: Pair) -> Vec<Pair> {
        let at = self.matching.partition_point(|p| *p < pair);
        let mut out = Vec::with_capacity(self.matching.len() + 1);
        out.extend_from_slice(&self.matching[..at]);
        out.push(pair);
        out.extend_from_slice(&self.matching[at..]);
        out
    }

    /// A copy with an empty matching (no allocation), for building a child with its own.
    pub fn without_matching(&self) -> Candidate {
        Candidate {
            matching: Vec::new(),
            ..*self
        }
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

    /// `Σ_ℳ (r − d_m(x))²` with the normal equations `GᵀG`, `Gᵀe` of Gauss–Newton at `x`, in one
    /// pass (two distances per pair).
    fn normal_equations(&self, matching: &[Pair], x: &Vec2) -> NormalEquations {
        let mut out = NormalEquations {
            cost: 0.0,
            gtg: Mat2::zeros(),
            gtr: Vec2::zeros(),
        };
        for &p in matching {
            let (d, g) = self
                .map
                .range_and_gradient(p.trp, x, self.input.tx, self.input.rx);
            let e = self.range_of(p) - d;
            out.cost += e * e;
            out.gtg += g * g.transpose();
            out.gtr += g * e;
        }
        out
    }

    /// Gauss–Newton on `Σ_ℳ (r − d_m(x))²` from `x0` (§4, \[P\]): at most `max_iterations`
    /// steps, stopping when `‖Δx‖ < step_tol_m`. A step that would increase the sum is halved
    /// (up to [`MAX_STEP_HALVINGS`] times, then the iteration stops), so the sum never grows and
    /// ill-conditioned ghost matchings cannot diverge; a step already shorter than `step_tol_m`
    /// is taken if it does not increase the sum and ends the iteration either way (halving it
    /// could only move `x` by less than the tolerance). Returns `None` when the iterate stops
    /// being finite or the normal matrix is singular or numerically so: `cond(G)` above
    /// [`MAX_GRADIENT_CONDITION`], the threshold at which §5.2 drops grazing intersections (two
    /// ellipses that do not cross near `x`: their least-squares point is where the gradients are
    /// parallel, and the Gauss–Newton step is meaningless there).
    pub fn refine(&self, matching: &[Pair], x0: Vec2, cfg: &Refinement) -> Option<Vec2> {
        let mut x = x0;
        let mut at = self.normal_equations(matching, &x);
        for _ in 0..cfg.max_iterations {
            if !well_conditioned(&at.gtg) {
                return None;
            }
            let mut dx = at.gtg.try_inverse()? * at.gtr;
            if !(dx.x.is_finite() && dx.y.is_finite()) {
                return None;
            }
            let converged = dx.norm() < cfg.step_tol_m;
            let mut trial = self.normal_equations(matching, &(x + dx));
            let mut halvings = 0;
            while trial.cost > at.cost && !converged && halvings < MAX_STEP_HALVINGS {
                dx *= 0.5;
                halvings += 1;
                trial.cost = self.sum_sq(matching, &(x + dx));
            }
            if trial.cost > at.cost {
                break;
            }
            x += dx;
            if converged || dx.norm() < cfg.step_tol_m {
                break;
            }
            at = if halvings == 0 {
                trial
            } else {
                self.normal_equations(matching, &x)
            };
        }
        Some(x)
    }
}

/// Whether `GᵀG` (symmetric, 2×2) has `cond(G) ≤` [`MAX_GRADIENT_CONDITION`]: with `λ_max` its
/// larger eigenvalue, `cond(G)² = λ_max/λ_min = λ_max²/det`.
fn well_conditioned(gtg: &Mat2) -> bool {
    let (a, b, c) = (gtg[(0, 0)], gtg[(0, 1)], gtg[(1, 1)]);
    let det = a * c - b * b;
    let half = 0.5 * (a + c);
    let lmax = half + sqrt((half * half - det).max(0.0));
    det > 0.0 && lmax * lmax <= MAX_GRADIENT_CONDITION * MAX_GRADIENT_CONDITION * det
}

/// The Gauss–Newton quantities at one point (see [`Geometry::refine`]).
struct NormalEquations {
    /// `Σ e²`, m².
    cost: Real,
    /// `GᵀG`.
    gtg: Mat2,
    /// `Gᵀe`, m.
    gtr: Vec2,
}

/// Largest number of step halvings per Gauss–Newton iteration in [`Geometry::refine`].
pub const MAX_STEP_HALVINGS: usize = 30;
