//! Snapshot Cramér–Rao bound (spec §7): Fisher matrix `F(r) = Jᵀ F_τ J` (E8), the bounds
//! σx, σy, the RMSE bound `√(σx² + σy²)` (S24) and the 1σ error ellipse, plus a fast map kernel
//! over a grid that writes into a caller-provided buffer.

use alloc::vec;

use crate::ellipse::Ellipse;
use crate::error::{Error, Result};
use crate::geometry::unit_from;
use crate::math::{sqrt, Mat2, Real, Vec2, PI, SPEED_OF_LIGHT};
use crate::model::{Model, SNR_DISTANCE_FLOOR_M};
use crate::scenario::Area;

/// A Fisher matrix whose reciprocal condition number `λ_min/λ_max` is below this is treated as
/// singular: the position is unbounded along some direction (collinear or too few informative
/// links, a point on a baseline with too few other links).
pub const SINGULAR_RCOND: Real = 1e-12;

/// Largest grid side accepted by the map kernel.
pub const MAX_GRID_SIDE: usize = 4096;
/// Largest number of grid cells accepted by the map kernel (2048²).
pub const MAX_GRID_CELLS: usize = 2048 * 2048;

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
}

/// Per-link weight turning `(u^Tx+u^Rx)(u^Tx+u^Rx)ᵀ` into Fisher information, 1/m², at unit
/// distances and unit Tx gain: `8π²β²·snr_scale/c²`.
fn link_weights(model: &Model) -> impl Iterator<Item = Real> + '_ {
    let k = 8.0 * PI * PI * model.beta2 / (SPEED_OF_LIGHT * SPEED_OF_LIGHT);
    model.snr_scale.iter().map(move |s| k * s)
}

/// `F(r) = Jᵀ F_τ J`, 1/m² (E8 with E3).
pub fn fisher(model: &Model, r: Vec2) -> Mat2 {
    let mut f = Mat2::zeros();
    for (p, w) in link_weights(model).enumerate() {
        let l = model.network.links[p];
        let (u_tx, d_tx) = unit_from(model.network.transmitters[l.tx], r);
        let (u_rx, d_rx) = unit_from(model.network.receivers[l.rx], r);
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

/// The bound from a symmetric Fisher matrix `[[a, b], [b, c]]`; `None` when singular.
#[inline(always)]
pub fn bound_from_fisher(a: Real, b: Real, c: Real) -> Option<Bound> {
    let det = a * c - b * b;
    let tr = a + c;
    // 4·det/tr² = 4 λ1 λ2 / (λ1+λ2)² ≈ 4 λ_min/λ_max for an ill-conditioned matrix.
    if !(tr > 0.0) || !(det > SINGULAR_RCOND * tr * tr) || !det.is_finite() {
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

/// A regular grid of cell centres over a rectangle: `x_i = x_min + (i + ½)·(x_max − x_min)/nx`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Extent, m.
    pub area: Area,
    /// Number of columns (x).
    pub nx: usize,
    /// Number of rows (y).
    pub ny: usize,
}

impl Grid {
    /// A validated grid: finite, non-inverted area; `2 ≤ nx, ny ≤ 4096`; at most 2048² cells.
    pub fn new(area: Area, nx: usize, ny: usize) -> Result<Grid> {
        area.validate()?;
        for (field, v) in [("nx", nx), ("ny", ny)] {
            if !(2..=MAX_GRID_SIDE).contains(&v) {
                return Err(Error::SizeLimit {
                    field,
                    value: v,
                    min: 2,
                    max: MAX_GRID_SIDE,
                });
            }
        }
        if nx * ny > MAX_GRID_CELLS {
            return Err(Error::SizeLimit {
                field: "nx*ny",
                value: nx * ny,
                min: 4,
                max: MAX_GRID_CELLS,
            });
        }
        Ok(Grid { area, nx, ny })
    }

    /// x of column `i` (cell centre), m.
    #[inline]
    pub fn x(&self, i: usize) -> Real {
        self.area.x[0] + (i as Real + 0.5) * (self.area.x[1] - self.area.x[0]) / self.nx as Real
    }

    /// y of row `j` (cell centre), m.
    #[inline]
    pub fn y(&self, j: usize) -> Real {
        self.area.y[0] + (j as Real + 0.5) * (self.area.y[1] - self.area.y[0]) / self.ny as Real
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// Always false for a validated grid.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Writes the RMSE bound of every grid cell into `out` (row-major, row `j` = `y_j`, ascending y),
/// m; unbounded cells get `+∞`. `out.len()` must equal `grid.len()`.
pub fn crlb_map(model: &Model, grid: &Grid, out: &mut [Real]) -> Result<()> {
    if out.len() != grid.len() {
        return Err(Error::LengthMismatch {
            field: "map buffer",
            expected: grid.len(),
            found: out.len(),
        });
    }
    let net = &model.network;
    let weights: alloc::vec::Vec<Real> = link_weights(model).collect();
    // Per-cell scratch, reused: transmitter (unit vector, gain/d²), receiver (unit vector, 1/d²).
    let mut tx_state = vec![(Vec2::zeros(), 0.0); net.transmitters.len()];
    let mut rx_state = vec![(Vec2::zeros(), 0.0); net.receivers.len()];
    let floor2 = SNR_DISTANCE_FLOOR_M * SNR_DISTANCE_FLOOR_M;
    for j in 0..grid.ny {
        let y = grid.y(j);
        let row = &mut out[j * grid.nx..(j + 1) * grid.nx];
        for (i, cell) in row.iter_mut().enumerate() {
            let r = Vec2::new(grid.x(i), y);
            for (k, st) in tx_state.iter_mut().enumerate() {
                let (u, d) = unit_from(net.transmitters[k], r);
                *st = (u, model.patterns[k].gain_toward(u) / (d * d).max(floor2));
            }
            for (l, st) in rx_state.iter_mut().enumerate() {
                let (u, d) = unit_from(net.receivers[l], r);
                *st = (u, 1.0 / (d * d).max(floor2));
            }
            let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
            for (link, w) in net.links.iter().zip(&weights) {
                let (ut, gt) = tx_state[link.tx];
                let (ur, gr) = rx_state[link.rx];
                let (gx, gy) = (ut.x + ur.x, ut.y + ur.y);
                let wp = w * gt * gr;
                a += wp * gx * gx;
                b += wp * gx * gy;
                c += wp * gy * gy;
            }
            *cell = match bound_from_fisher(a, b, c) {
                Some(bd) => bd.rmse_m,
                None => Real::INFINITY,
            };
        }
    }
    Ok(())
}
