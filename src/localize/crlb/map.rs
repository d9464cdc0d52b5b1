//! The CRLB map: the kernel [`crlb_map`] that writes the RMSE bound of every cell of a
//! [`Grid`] row by row in structure-of-arrays form (spec §7, S24).

use alloc::vec;
use alloc::vec::Vec;

use super::grid::Grid;
use super::simd::Kernel;
use super::{is_regular, link_weights};
use crate::error::{check_len, Error, Result};
use crate::math::{sqrt, Lanes, Real, Vec2};
use crate::measure::TxPattern;
use crate::measure::UNIT_VECTOR_MIN_DISTANCE_M;
use crate::measure::{Model, SNR_DISTANCE_FLOOR_M};

/// Writes the RMSE bound of every grid cell into `out` (row-major, row `j` = `y_j`, ascending y),
/// m; unbounded cells get `+∞`. `out.len()` must equal `grid.len()`.
///
/// The same quantity as [`crlb_at`](super::crlb_at) per cell (E8, S24), computed by the SIMD
/// kernel: four cells per vector, node terms once per cell, row constants hoisted, branch-free
/// handling of unbounded cells. It agrees bitwise with the scalar reference [`crlb_map_scalar`].
/// The Tx pattern goes through [`GainPolynomial`](crate::measure::GainPolynomial) (≤ 1e-12
/// relative from the exact §9.3 formula) when it can be fitted, else the exact formula. One
/// thread; `crate::native::crlb_map_parallel` splits the rows over threads.
pub fn crlb_map(model: &Model, grid: &Grid, out: &mut [Real]) -> Result<()> {
    check_len("map buffer", grid.len(), out.len())?;
    crlb_map_rows(model, grid, 0, out)
}

/// [`crlb_map`] for the whole rows `first_row ..` of the grid that `out` holds (`out.len()` a
/// multiple of `grid.nx`, rows inside the grid): the unit of work of a parallel map.
pub fn crlb_map_rows(model: &Model, grid: &Grid, first_row: usize, out: &mut [Real]) -> Result<()> {
    crlb_map_rows_with::<wide::f64x4>((), model, grid, first_row, out)
}

/// [`crlb_map_rows`] on the vector type `L` ([`Lanes`], whose instruction-set token is `arch`): the one kernel that every build runs —
/// [`wide::f64x4`] in the core, this CPU's AVX2 or AVX-512 registers in `crate::native` (issue
/// 29). An exact `L` gives the scalar reference's bits; a fast one a result within its stated
/// bound. `#[inline(always)]`, so a caller compiled for wider instructions gets them.
#[inline(always)]
pub fn crlb_map_rows_with<L: Lanes>(
    arch: L::Arch,
    model: &Model,
    grid: &Grid,
    first_row: usize,
    out: &mut [Real],
) -> Result<()> {
    let rows = out.len() / grid.nx;
    check_len("map buffer", rows * grid.nx, out.len())?;
    if first_row + rows > grid.ny {
        return Err(Error::SizeLimit {
            field: "map rows",
            value: first_row + rows,
            min: 0,
            max: grid.ny,
        });
    }
    Kernel::<L>::new(arch, model, grid).rows(first_row, out);
    Ok(())
}

/// The scalar reference of [`crlb_map`]: the same result, computed row by row in
/// structure-of-arrays form with plain loops (kept for tests and benchmarks).
pub fn crlb_map_scalar(model: &Model, grid: &Grid, out: &mut [Real]) -> Result<()> {
    check_len("map buffer", grid.len(), out.len())?;
    let net = &model.network;
    let nx = grid.nx;
    let weights: Vec<Real> = link_weights(model).collect();
    let xs: Vec<Real> = (0..nx).map(|i| grid.x(i)).collect();
    // Per node and row: unit vector (ux, uy) and gain/d² (Tx) or 1/d² (Rx).
    let mut tx_rows = vec![NodeRow::new(nx); net.transmitters.len()];
    let mut rx_rows = vec![NodeRow::new(nx); net.receivers.len()];
    let mut fisher = FisherRow::new(nx);
    for (j, out_row) in out.chunks_exact_mut(nx).enumerate() {
        let y = grid.y(j);
        for (k, row) in tx_rows.iter_mut().enumerate() {
            row.fill(net.transmitters[k], net.transmitters_dz[k], y, &xs);
            row.apply_pattern(&model.patterns[k]);
        }
        for (l, row) in rx_rows.iter_mut().enumerate() {
            row.fill(net.receivers[l], net.receivers_dz[l], y, &xs);
        }
        fisher.clear();
        for (link, &w) in net.links.iter().zip(&weights) {
            fisher.accumulate(&tx_rows[link.tx], &rx_rows[link.rx], w);
        }
        fisher.rmse_into(out_row);
    }
    Ok(())
}

/// One grid row seen from one node.
#[derive(Clone)]
struct NodeRow {
    ux: Vec<Real>,
    uy: Vec<Real>,
    /// `1/max(d², 1 m²)`, times the Tx gain for transmitters.
    weight: Vec<Real>,
}

impl NodeRow {
    fn new(n: usize) -> NodeRow {
        NodeRow {
            ux: vec![0.0; n],
            uy: vec![0.0; n],
            weight: vec![0.0; n],
        }
    }

    /// Unit vectors node → cell (horizontal parts of the 3-D ones for a node at vertical offset
    /// `dz`; zero on the node, spec §3) and `1/max(d², 1)` with the 3-D `d² = dx² + (dy² + dz²)`.
    fn fill(&mut self, node: Vec2, dz: Real, y: Real, xs: &[Real]) {
        let dy = y - node.y;
        let dy2 = dy * dy + dz * dz;
        let floor2 = SNR_DISTANCE_FLOOR_M * SNR_DISTANCE_FLOOR_M;
        let n = xs.len();
        let (ux, uy, w) = (&mut self.ux[..n], &mut self.uy[..n], &mut self.weight[..n]);
        for i in 0..n {
            let dx = xs[i] - node.x;
            let d2 = dx * dx + dy2;
            let d = sqrt(d2);
            let inv = if d < UNIT_VECTOR_MIN_DISTANCE_M {
                0.0
            } else {
                1.0 / d
            };
            ux[i] = dx * inv;
            uy[i] = dy * inv;
            // 1/max(d², 1 m²) without a second division.
            w[i] = if d2 < floor2 { 1.0 / floor2 } else { inv * inv };
        }
    }

    /// Multiplies the weights by the Tx gain toward each cell.
    fn apply_pattern(&mut self, pattern: &TxPattern) {
        let n = self.weight.len();
        match (pattern.beam, pattern.polynomial.as_ref()) {
            (None, _) => self.weight.iter_mut().for_each(|w| *w *= pattern.peak_gain),
            (Some(_), Some(p)) => {
                // LANES cells at a time, so the Clenshaw recurrence lives in vector registers.
                const LANES: usize = 4;
                let mut i0 = 0;
                while i0 < n {
                    let m = LANES.min(n - i0);
                    let mut c = [1.0; LANES];
                    for (l, c) in c.iter_mut().enumerate().take(m) {
                        *c = self.ux[i0 + l] * p.boresight.x + self.uy[i0 + l] * p.boresight.y;
                    }
                    let gains = p.gains_at_cos(c);
                    for (l, g) in gains.iter().enumerate().take(m) {
                        let i = i0 + l;
                        // A cell on the Tx gets the peak gain, as in `TxPattern::gain_toward`.
                        let on_node = self.ux[i] == 0.0 && self.uy[i] == 0.0;
                        self.weight[i] *= if on_node { pattern.peak_gain } else { *g };
                    }
                    i0 += m;
                }
            }
            (Some(_), None) => {
                for i in 0..n {
                    self.weight[i] *= pattern.gain_toward(Vec2::new(self.ux[i], self.uy[i]));
                }
            }
        }
    }
}

/// Fisher entries `[[a, b], [b, c]]` of one grid row.
struct FisherRow {
    a: Vec<Real>,
    b: Vec<Real>,
    c: Vec<Real>,
}

impl FisherRow {
    fn new(n: usize) -> FisherRow {
        FisherRow {
            a: vec![0.0; n],
            b: vec![0.0; n],
            c: vec![0.0; n],
        }
    }

    fn clear(&mut self) {
        self.a.fill(0.0);
        self.b.fill(0.0);
        self.c.fill(0.0);
    }

    /// Adds one link's `w·(gTx/d²)(1/d²)·(u^Tx+u^Rx)(u^Tx+u^Rx)ᵀ`.
    fn accumulate(&mut self, tx: &NodeRow, rx: &NodeRow, w: Real) {
        let n = self.a.len();
        let (a, b, c) = (&mut self.a[..n], &mut self.b[..n], &mut self.c[..n]);
        let (tux, tuy, tw) = (&tx.ux[..n], &tx.uy[..n], &tx.weight[..n]);
        let (rux, ruy, rw) = (&rx.ux[..n], &rx.uy[..n], &rx.weight[..n]);
        for i in 0..n {
            let gx = tux[i] + rux[i];
            let gy = tuy[i] + ruy[i];
            let wp = w * tw[i] * rw[i];
            a[i] += wp * gx * gx;
            b[i] += wp * gx * gy;
            c[i] += wp * gy * gy;
        }
    }

    /// `√(σx² + σy²)` per cell, `+∞` where singular (same rule as
    /// [`bound_from_fisher`](super::bound_from_fisher)).
    fn rmse_into(&self, out: &mut [Real]) {
        let n = out.len();
        let (a, b, c) = (&self.a[..n], &self.b[..n], &self.c[..n]);
        for i in 0..n {
            let det = a[i] * c[i] - b[i] * b[i];
            let tr = a[i] + c[i];
            out[i] = if is_regular(det, tr) {
                sqrt(tr / det)
            } else {
                Real::INFINITY
            };
        }
    }
}
