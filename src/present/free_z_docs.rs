//! The documents of the single-snapshot use cases with a free height (issue 40 §2, "in 3-D
//! where the user asks"): the bound over `[x, y, z]` ([`CrlbFreeZDoc`], `scatterloc crlb
//! --free-z`) and the LM fix over `[x, y, z]` ([`FixFreeZDoc`], `scatterloc locate --free-z`).
//! Heights here are absolute (the scenario's frame: the floor at 0), the core's height offset
//! `δz` plus the scenario's target height.

use serde::Serialize;

use crate::localize::{bound_from_fisher, crlb_free_z, FreeZReport};
use crate::math::{Mat3, Real, Vec2};
use crate::measure::Model;
use crate::scenario::Scenario;

/// A symmetric 3×3 matrix as nested rows, from its upper triangle (as [`sym2`](super::sym2)).
pub fn sym3(m: &Mat3) -> [[Real; 3]; 3] {
    core::array::from_fn(|i| core::array::from_fn(|j| m[(i.min(j), i.max(j))]))
}

/// The bound on `[x, y, z]` at one point (`scatterloc crlb --free-z`). Unbounded (a singular
/// Fisher matrix, e.g. every node at the target's height): `bounded` false and the sigmas and
/// covariance `None`, never NaN.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrlbFreeZDoc {
    /// The point `[x, y, z]`, m (z absolute).
    pub position_m: [Real; 3],
    /// Whether the 3×3 Fisher matrix is invertible.
    pub bounded: bool,
    /// `σx`, m.
    pub sigma_x_m: Option<Real>,
    /// `σy`, m.
    pub sigma_y_m: Option<Real>,
    /// `σz`, m.
    pub sigma_z_m: Option<Real>,
    /// The horizontal RMSE bound `√(σx² + σy²)` with the height unknown, m.
    pub rmse_bound_m: Option<Real>,
    /// `√(σx² + σy² + σz²)`, m.
    pub rmse_3d_bound_m: Option<Real>,
    /// The horizontal RMSE bound with the height known (the inverse of `F`'s upper 2×2 block:
    /// `scatterloc crlb` at this height), m; never above `rmse_bound_m`.
    pub height_known_rmse_bound_m: Option<Real>,
    /// `F`, 1/m², over `[x, y, z]`.
    pub fim_per_m2: [[Real; 3]; 3],
    /// `F⁻¹`, m².
    pub covariance_m2: Option<[[Real; 3]; 3]>,
}

impl CrlbFreeZDoc {
    /// The bound of `model` (compiled from `scenario`) at horizontal `at` and absolute height
    /// `height_m`.
    pub fn at(scenario: &Scenario, model: &Model, at: [Real; 2], height_m: Real) -> CrlbFreeZDoc {
        let r = Vec2::new(at[0], at[1]);
        let dz = height_m - scenario.target.height_m;
        let pt = crlb_free_z(model, r, dz);
        let b = pt.bound;
        let f = &pt.fisher_per_m2;
        let known = bound_from_fisher(f[(0, 0)], f[(0, 1)], f[(1, 1)]).map(|b| b.rmse_m);
        CrlbFreeZDoc {
            position_m: [at[0], at[1], height_m],
            bounded: b.is_some(),
            sigma_x_m: b.map(|b| b.sigma_x_m),
            sigma_y_m: b.map(|b| b.sigma_y_m),
            sigma_z_m: b.map(|b| b.sigma_z_m),
            rmse_bound_m: b.map(|b| b.rmse_m),
            rmse_3d_bound_m: b.map(|b| b.rmse_3d_m),
            height_known_rmse_bound_m: known,
            fim_per_m2: sym3(&pt.fisher_per_m2),
            covariance_m2: b.map(|b| sym3(&b.covariance_m2)),
        }
    }
}

/// A weighted LM fix over `[x, y, z]` (`scatterloc locate --free-z`; the keys of
/// [`FixDoc`](super::FixDoc) with 3-vectors).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FixFreeZDoc {
    /// `[x̂, ŷ, ẑ]`, m (z absolute).
    pub position_m: [Real; 3],
    /// `(JᵀR⁻¹J)⁻¹` at the fix, m² (`None` when singular: the height unobservable).
    pub covariance_m2: Option<[[Real; 3]; 3]>,
    /// `𝓛` at the fix (E5).
    pub cost: Real,
    /// Iterations (Jacobian evaluations).
    pub iterations: usize,
    /// Why it stopped ([`crate::localize::Termination::as_str`]).
    pub termination: &'static str,
    /// Whether the termination means a converged fix.
    pub converged: bool,
    /// Links that carried a measurement.
    pub links_used: usize,
    /// Where the kept iteration started, m (z absolute).
    pub start_m: [Real; 3],
}

impl FixFreeZDoc {
    /// The document of `rep` for a scenario whose target height is `target_height_m`.
    pub fn new(rep: &FreeZReport, target_height_m: Real) -> FixFreeZDoc {
        let (p, s) = (rep.position, rep.start);
        FixFreeZDoc {
            position_m: [p.x, p.y, p.z + target_height_m],
            covariance_m2: rep.covariance_m2.as_ref().map(sym3),
            cost: rep.cost,
            iterations: rep.iterations,
            termination: rep.termination.as_str(),
            converged: rep.termination.converged(),
            links_used: rep.links_used,
            start_m: [s.x, s.y, s.z + target_height_m],
        }
    }
}
