//! The bound with a free height (issue 40 §2, "in 3-D where the user asks"): the unknowns are
//! `[x, y, δz]`, the target's horizontal position and its height offset `δz` from the stated
//! target height (the plane the network's `dz` are measured from). A node at offset `dz_n`
//! is at vertical distance `h_n = dz_n − δz` from the target, the 3-D unit vector from the node
//! to the target is `(r − r_n, −h_n)/d_n` with `d_n = √(‖r − r_n‖² + h_n²)`, and E8 becomes
//! `F = Σ_p w_p g_p g_pᵀ` with `g_p = u^Tx + u^Rx` in 3-D (the same link budget `w_p` as
//! [`fisher`](super::fisher), which is this matrix's upper 2×2 block at `δz = 0`, bitwise).
//!
//! The bound on `(x, y)` with the height unknown is never below the bound with the height known
//! (the Schur complement of a positive semidefinite block): the price of not knowing how tall
//! the target is. A network whose nodes all sit in the target's plane has `g_z = 0` at
//! `δz = 0`: the height is unobservable there and the bound is unbounded (`None`), not NaN.

use nalgebra::SymmetricEigen;

use super::{link_weights, SINGULAR_RCOND};
use crate::math::{sqrt, Mat3, Real, Vec2, Vec3};
use crate::measure::{unit_from_dz, vertical_unit, Model, SNR_DISTANCE_FLOOR_M};

/// The bound on `[x, y, z]` when the Fisher matrix is invertible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound3 {
    /// `σx = √[F⁻¹]₁₁`, m.
    pub sigma_x_m: Real,
    /// `σy = √[F⁻¹]₂₂`, m.
    pub sigma_y_m: Real,
    /// `σz = √[F⁻¹]₃₃`, m.
    pub sigma_z_m: Real,
    /// The horizontal RMSE bound `√(σx² + σy²)` with the height unknown, m (S24's quantity).
    pub rmse_m: Real,
    /// `√(σx² + σy² + σz²)`, m.
    pub rmse_3d_m: Real,
    /// `F⁻¹`, m².
    pub covariance_m2: Mat3,
}

/// The 3-D bound at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrlbFreeZ {
    /// Where it was evaluated: `[x, y, δz]`, m (`δz` from the stated target height).
    pub position: Vec3,
    /// `F`, 1/m².
    pub fisher_per_m2: Mat3,
    /// `None` when `F` is singular (the height or a direction unobservable).
    pub bound: Option<Bound3>,
}

/// `F(r, δz)`, 1/m²: E8 over the unknowns `[x, y, δz]`.
pub fn fisher_free_z(model: &Model, r: Vec2, dz: Real) -> Mat3 {
    let mut f = Mat3::zeros();
    for (p, w) in link_weights(model).enumerate() {
        let l = model.network.links[p];
        let (h_tx, h_rx) = (
            model.network.transmitters_dz[l.tx] - dz,
            model.network.receivers_dz[l.rx] - dz,
        );
        let (u_tx, d_tx) = unit_from_dz(model.network.transmitters[l.tx], h_tx, r);
        let (u_rx, d_rx) = unit_from_dz(model.network.receivers[l.rx], h_rx, r);
        let gz = vertical_unit(h_tx, d_tx) + vertical_unit(h_rx, d_rx);
        let (d_tx, d_rx) = (
            d_tx.max(SNR_DISTANCE_FLOOR_M),
            d_rx.max(SNR_DISTANCE_FLOOR_M),
        );
        let gh = u_tx + u_rx;
        let g = Vec3::new(gh.x, gh.y, gz);
        let wp = w * model.patterns[l.tx].gain_toward(u_tx) / (d_tx * d_tx * d_rx * d_rx);
        f += wp * g * g.transpose();
    }
    f
}

/// The bound from a symmetric 3×3 Fisher matrix; `None` when it is singular to working
/// precision: an eigenvalue not finite, or `λ_min/λ_max` below [`SINGULAR_RCOND`] (the planar
/// bound's test, here on the eigenvalues themselves).
pub fn bound3_from_fisher(f: &Mat3) -> Option<Bound3> {
    if !f.iter().all(|v| v.is_finite()) {
        return None;
    }
    let e = SymmetricEigen::new(*f);
    let (lo, hi) = (e.eigenvalues.min(), e.eigenvalues.max());
    if !(hi > 0.0 && lo > SINGULAR_RCOND * hi) {
        return None;
    }
    let mut inv = Mat3::zeros();
    for i in 0..3 {
        let v = e.eigenvectors.column(i);
        inv += (v * v.transpose()) / e.eigenvalues[i];
    }
    let (vx, vy, vz) = (inv[(0, 0)], inv[(1, 1)], inv[(2, 2)]);
    if !(vx > 0.0 && vy > 0.0 && vz > 0.0 && inv.iter().all(|v| v.is_finite())) {
        return None;
    }
    Some(Bound3 {
        sigma_x_m: sqrt(vx),
        sigma_y_m: sqrt(vy),
        sigma_z_m: sqrt(vz),
        rmse_m: sqrt(vx + vy),
        rmse_3d_m: sqrt(vx + vy + vz),
        covariance_m2: inv,
    })
}

/// The bound with a free height at `r` and height offset `dz` (m) from the stated target height.
pub fn crlb_free_z(model: &Model, r: Vec2, dz: Real) -> CrlbFreeZ {
    let f = fisher_free_z(model, r, dz);
    CrlbFreeZ {
        position: Vec3::new(r.x, r.y, dz),
        fisher_per_m2: f,
        bound: bound3_from_fisher(&f),
    }
}
