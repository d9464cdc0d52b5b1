//! Snapshot Cramér–Rao bound (spec §7): Fisher matrix `F(r) = Jᵀ F_τ J` (E8), the bounds
//! σx, σy, the RMSE bound `√(σx² + σy²)` (S24) and the 1σ error ellipse, plus a fast map kernel
//! over a grid that writes into a caller-provided buffer.

use crate::math::{sqrt, Mat2, Real, Vec2, PI, SPEED_OF_LIGHT};
use crate::measure::Ellipse;
use crate::measure::{Model, SNR_DISTANCE_FLOOR_M};

mod doppler_map;
mod free_z;
mod grid;
mod map;
mod simd;

pub use doppler_map::{doppler_map, MapQuantity};
pub use free_z::{bound3_from_fisher, crlb_free_z, fisher_free_z, Bound3, CrlbFreeZ};
pub use grid::{Grid, MAX_GRID_CELLS, MAX_GRID_SIDE};
pub use map::{crlb_map, crlb_map_rows, crlb_map_rows_with, crlb_map_scalar};

pub use crate::math::SINGULAR_RCOND;

/// The bound at one point when the Fisher matrix is invertible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// `σx = √[F⁻¹]₁₁`, m (S18).
    pub sigma_x_m: Real,
    /// `σy = √[F⁻¹]₂₂`, m (S19).
    pub sigma_y_m: Real,
    /// `√(σx² + σy²)`, m (S24).
    pub rmse_m: Real,
    /// `F⁻¹`, m².
    pub covariance_m2: Mat2,
}

/// CRLB evaluation at a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrlbPoint {
    /// Where it was evaluated, m.
    pub position: Vec2,
    /// `F(r)`, 1/m² (E8).
    pub fisher_per_m2: Mat2,
    /// `None` when `F` is singular (unbounded).
    pub bound: Option<Bound>,
}

impl CrlbPoint {
    /// The 1σ error ellipse of the bound, if bounded.
    pub fn ellipse(&self) -> Option<Ellipse> {
        self.bound
            .and_then(|b| Ellipse::from_covariance(self.position, &b.covariance_m2, 1.0))
    }

    /// The RMSE bound, m; `+∞` when unbounded.
    pub fn rmse_m(&self) -> Real {
        self.bound.map_or(Real::INFINITY, |b| b.rmse_m)
    }
}

/// Per-link weight turning `(u^Tx+u^Rx)(u^Tx+u^Rx)ᵀ` into Fisher information, 1/m², at unit
/// distances and unit Tx gain: `8π²β²·snr_scale/c²`.
fn link_weights(model: &Model) -> impl Iterator<Item = Real> + '_ {
    let k = 8.0 * PI * PI * model.beta2 / (SPEED_OF_LIGHT * SPEED_OF_LIGHT);
    model.snr_scale.iter().map(move |s| k * s)
}

/// `F(r) = Jᵀ F_τ J`, 1/m² (E8 with E3; 3-D distances when nodes are off the target's plane).
pub fn fisher(model: &Model, r: Vec2) -> Mat2 {
    let mut f = Mat2::zeros();
    for (p, w) in link_weights(model).enumerate() {
        let l = model.network.links[p];
        let (u_tx, d_tx) = model.network.tx_unit(l.tx, r);
        let (u_rx, d_rx) = model.network.rx_unit(l.rx, r);
        let (d_tx, d_rx) = (
            d_tx.max(SNR_DISTANCE_FLOOR_M),
            d_rx.max(SNR_DISTANCE_FLOOR_M),
        );
        let g = u_tx + u_rx;
        let wp = w * model.patterns[l.tx].gain_toward(u_tx) / (d_tx * d_tx * d_rx * d_rx);
        f += wp * g * g.transpose();
    }
    f
}

/// Whether a 2×2 Fisher matrix with determinant `det` and trace `tr` is invertible to working
/// precision: `det/tr² ≈ λ_min/λ_max` for an ill-conditioned matrix must exceed [`SINGULAR_RCOND`].
#[inline(always)]
fn is_regular(det: Real, tr: Real) -> bool {
    tr > 0.0 && det > SINGULAR_RCOND * tr * tr && det.is_finite()
}

/// The bound from a symmetric Fisher matrix `[[a, b], [b, c]]`; `None` when singular.
#[inline(always)]
pub fn bound_from_fisher(a: Real, b: Real, c: Real) -> Option<Bound> {
    let det = a * c - b * b;
    if !is_regular(det, a + c) {
        return None;
    }
    let (vx, vy) = (c / det, a / det);
    Some(Bound {
        sigma_x_m: sqrt(vx),
        sigma_y_m: sqrt(vy),
        rmse_m: sqrt(vx + vy),
        covariance_m2: Mat2::new(vx, -b / det, -b / det, vy),
    })
}

/// The CRLB at `r`.
pub fn crlb_at(model: &Model, r: Vec2) -> CrlbPoint {
    let f = fisher(model, r);
    CrlbPoint {
        position: r,
        fisher_per_m2: f,
        bound: bound_from_fisher(f[(0, 0)], f[(0, 1)], f[(1, 1)]),
    }
}
