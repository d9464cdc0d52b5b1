//! The CRLB map kernel, written once over [`Lanes`] (a vector of `f64` cells): four cells per
//! [`wide::f64x4`] in the core (AVX or two SSE2 registers natively, two simd128 registers in the
//! page's wasm build), and natively also the AVX2 and AVX-512 registers of this CPU
//! (`crate::native`, issue 29).
//!
//! Per vector of cells, every node's unit vector and `1/max(d², 1 m²)` are computed once (one
//! inverse distance per node), the Tx gain once per transmitter, the Fisher sums of all links
//! stay in registers, and the bound is one [`Lanes::root_ratio`]. Terms that are constant along a
//! row (`dy`, `dy²` per node) are hoisted out of it. Cells on a node, inside the SNR floor and
//! unbounded cells are branch-free blends. With an exact [`Lanes`] type the operations and their
//! order are those of the scalar reference [`crlb_map_scalar`](super::crlb_map_scalar), so the
//! two agree bitwise (tested); only a beam pattern without a [`GainPolynomial`] takes the exact
//! formula lane by lane.

use alloc::vec;
use alloc::vec::Vec;

use super::grid::Grid;
use super::{link_weights, SINGULAR_RCOND};
use crate::math::{Lanes, Real, Vec2};
use crate::measure::{Model, TxPattern, SNR_DISTANCE_FLOOR_M, UNIT_VECTOR_MIN_DISTANCE_M};

/// Vectors per block of a row.
const BLOCK: usize = 16;

/// One node seen from a vector of cells: unit vector node → cell and its weight
/// (`1/max(d², 1)`, times the Tx gain for a transmitter).
#[derive(Clone, Copy)]
struct NodeLanes<L> {
    ux: L,
    uy: L,
    weight: L,
}

/// A node's offset from the current row: `dy = y − y_node` and `dy² + dz²` (its vertical offset
/// `dz` from the target's plane; exactly `dy²` when `dz = 0`).
#[derive(Clone, Copy)]
struct RowOffset<L> {
    x: L,
    dy: L,
    dy2: L,
}

/// The per-map constants: link weights and the cell-centre x of every column, padded to whole
/// vectors with the last centre.
pub(super) struct Kernel<'a, L: Lanes> {
    arch: L::Arch,
    model: &'a Model,
    grid: Grid,
    weights: Vec<L>,
    xs: Vec<L>,
}

impl<'a, L: Lanes> Kernel<'a, L> {
    #[inline(always)]
    pub(super) fn new(arch: L::Arch, model: &'a Model, grid: &Grid) -> Kernel<'a, L> {
        let nx = grid.nx;
        let xs = (0..nx.div_ceil(L::LANES))
            .map(|v| L::from_fn(arch, |l| grid.x((v * L::LANES + l).min(nx - 1))))
            .collect();
        Kernel {
            arch,
            model,
            grid: *grid,
            weights: link_weights(model).map(|w| L::splat(arch, w)).collect(),
            xs,
        }
    }
    /// Writes rows `first_row ..` of the map into `out` (whole rows, row-major).
    ///
    /// A row is done in blocks of [`BLOCK`] vectors, one pass per stage, so that the long
    /// dependency chains (square root and division per node, the pattern's Clenshaw recurrence,
    /// the bound's division and square root) of different vectors overlap instead of waiting on
    /// each other; a block's node views stay in L1.
    #[inline(always)]
    pub(super) fn rows(&self, first_row: usize, out: &mut [Real]) {
        let net = &self.model.network;
        let nx = self.grid.nx;
        let (ntx, nrx) = (net.transmitters.len(), net.receivers.len());
        let arch = self.arch;
        let zero = L::splat(arch, 0.0);
        let blank = RowOffset {
            x: zero,
            dy: zero,
            dy2: zero,
        };
        let none = NodeLanes {
            ux: zero,
            uy: zero,
            weight: zero,
        };
        let mut tx_offsets = vec![blank; ntx];
        let mut rx_offsets = vec![blank; nrx];
        let mut tx = vec![none; ntx * BLOCK];
        let mut rx = vec![none; nrx * BLOCK];
        for (r, out_row) in out.chunks_exact_mut(nx).enumerate() {
            let y = self.grid.y(first_row + r);
            let txs = net.transmitters.iter().zip(&net.transmitters_dz);
            for (o, (node, &dz)) in tx_offsets.iter_mut().zip(txs) {
                *o = RowOffset::new(arch, *node, dz, y);
            }
            let rxs = net.receivers.iter().zip(&net.receivers_dz);
            for (o, (node, &dz)) in rx_offsets.iter_mut().zip(rxs) {
                *o = RowOffset::new(arch, *node, dz, y);
            }
            for (b, xs) in self.xs.chunks(BLOCK).enumerate() {
                let n = xs.len();
                for (k, (o, pattern)) in tx_offsets.iter().zip(&self.model.patterns).enumerate() {
                    let lanes = &mut tx[k * BLOCK..k * BLOCK + n];
                    for (l, &x) in lanes.iter_mut().zip(xs) {
                        *l = NodeLanes::new(x, o);
                    }
                    apply_pattern(arch, lanes, pattern);
                }
                for (k, o) in rx_offsets.iter().enumerate() {
                    for (l, &x) in rx[k * BLOCK..k * BLOCK + n].iter_mut().zip(xs) {
                        *l = NodeLanes::new(x, o);
                    }
                }
                for v in 0..n {
                    let rmse = self.cell_bounds(&tx, &rx, v);
                    let first = (b * BLOCK + v) * L::LANES;
                    let m = L::LANES.min(nx - first);
                    rmse.write_to(&mut out_row[first..first + m]);
                }
            }
        }
    }

    /// The RMSE bound of a vector of cells from their node views: `Σ_links w·(gTx/d²)(1/d²)·
    /// (u^Tx+u^Rx)(u^Tx+u^Rx)ᵀ` (E8), then `√(tr F / det F)` or `+∞` where singular.
    #[inline(always)]
    fn cell_bounds(&self, tx: &[NodeLanes<L>], rx: &[NodeLanes<L>], v: usize) -> L {
        let arch = self.arch;
        let zero = L::splat(arch, 0.0);
        let (mut a, mut b, mut c) = (zero, zero, zero);
        for (link, &w) in self.model.network.links.iter().zip(&self.weights) {
            let (t, r) = (&tx[link.tx * BLOCK + v], &rx[link.rx * BLOCK + v]);
            let gx = t.ux + r.ux;
            let gy = t.uy + r.uy;
            let wp = w * t.weight * r.weight;
            let wgx = wp * gx;
            a = L::mul_add(wgx, gx, a);
            b = L::mul_add(wgx, gy, b);
            c = L::mul_add(wp * gy, gy, c);
        }
        let det = a * c - b * b;
        let tr = a + c;
        // `is_regular` without branches: det > k·tr² also rejects NaN.
        let regular = tr.gt(zero)
            & det.gt(tr * L::splat(arch, SINGULAR_RCOND) * tr)
            & det.lt(L::splat(arch, Real::INFINITY));
        L::select(
            regular,
            L::root_ratio(tr, det),
            L::splat(arch, Real::INFINITY),
        )
    }
}

impl<L: Lanes> RowOffset<L> {
    #[inline(always)]
    fn new(arch: L::Arch, node: Vec2, dz: Real, y: Real) -> RowOffset<L> {
        let dy = y - node.y;
        RowOffset {
            x: L::splat(arch, node.x),
            dy: L::splat(arch, dy),
            dy2: L::splat(arch, dy * dy + dz * dz),
        }
    }
}

impl<L: Lanes> NodeLanes<L> {
    /// Unit vectors node → cells (zero on the node, spec §3) and `1/max(d², 1 m²)`.
    #[inline(always)]
    fn new(x: L, o: &RowOffset<L>) -> NodeLanes<L> {
        let floor2 = SNR_DISTANCE_FLOOR_M * SNR_DISTANCE_FLOOR_M;
        let arch = x.arch();
        let dx = x - o.x;
        let d2 = L::mul_add(dx, dx, o.dy2);
        let inv = L::inv_distance(d2, UNIT_VECTOR_MIN_DISTANCE_M);
        NodeLanes {
            ux: dx * inv,
            uy: o.dy * inv,
            weight: L::select(
                d2.lt(L::splat(arch, floor2)),
                L::splat(arch, 1.0 / floor2),
                inv * inv,
            ),
        }
    }
}

/// The cosine of the angle between the boresight `(bx, by)` and the views' unit vectors.
#[inline(always)]
fn cos_to<L: Lanes>(l: &NodeLanes<L>, bx: L, by: L) -> L {
    l.ux * bx + l.uy * by
}

/// The gain `g`, or the peak gain on the Tx itself (a zero unit vector).
#[inline(always)]
fn gain_or_peak<L: Lanes>(l: &NodeLanes<L>, g: L, peak: L, zero: L) -> L {
    L::select(l.ux.eq(zero) & l.uy.eq(zero), peak, g)
}

/// Multiplies the weights of a transmitter's views by its gain toward each cell (peak gain on the
/// Tx itself, as in [`TxPattern::gain_toward`]); the beam's polynomial two vectors at a time.
/// Plain loops and functions, no closures on the hot path: everything must inline into the
/// caller, whose target features the vector operations need (issue 29).
#[inline(always)]
fn apply_pattern<L: Lanes>(arch: L::Arch, lanes: &mut [NodeLanes<L>], pattern: &TxPattern) {
    let peak = L::splat(arch, pattern.peak_gain);
    match (pattern.beam, pattern.polynomial.as_ref()) {
        (None, _) => {
            for l in lanes.iter_mut() {
                l.weight = l.weight * peak;
            }
        }
        (Some(_), Some(p)) => {
            let bx = L::splat(arch, p.boresight.x);
            let by = L::splat(arch, p.boresight.y);
            let zero = L::splat(arch, 0.0);
            let n = lanes.len();
            let mut i = 0;
            while i + 2 <= n {
                let g = p
                    .gains_at_cos_lanes([cos_to(&lanes[i], bx, by), cos_to(&lanes[i + 1], bx, by)]);
                for k in 0..2 {
                    let l = &mut lanes[i + k];
                    l.weight = l.weight * gain_or_peak(l, g[k], peak, zero);
                }
                i += 2;
            }
            if i < n {
                let [g] = p.gains_at_cos_lanes([cos_to(&lanes[i], bx, by)]);
                let l = &mut lanes[i];
                l.weight = l.weight * gain_or_peak(l, g, peak, zero);
            }
        }
        (Some(_), None) => {
            for l in lanes.iter_mut() {
                let (ux, uy) = (l.ux, l.uy);
                l.weight = l.weight
                    * L::from_fn(arch, |i| {
                        pattern.gain_toward(Vec2::new(ux.lane(i), uy.lane(i)))
                    });
            }
        }
    }
}
