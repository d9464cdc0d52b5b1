//! The CRLB map kernel in explicit SIMD: [`wide::f64x4`] (AVX, or two SSE2 registers natively;
//! two simd128 registers in the page's wasm build), four cells of a row per vector.
//!
//! Per vector of cells, every node's unit vector and `1/max(d², 1 m²)` are computed once (one
//! square root and one division per node), the Tx gain once per transmitter, the Fisher sums of
//! all links stay in registers, and the bound is one division and one square root. Terms that
//! are constant along a row (`dy`, `dy²` per node) are hoisted out of it. Cells on a node, inside
//! the SNR floor and unbounded cells are branch-free blends. The operations and their order are
//! those of the scalar reference [`crlb_map_scalar`](super::crlb_map_scalar), so the two agree
//! bitwise (tested); only a beam pattern without a [`GainPolynomial`] takes the exact formula
//! lane by lane.

use alloc::vec;
use alloc::vec::Vec;

use wide::{f64x4, CmpEq, CmpGt, CmpLt};

use super::grid::Grid;
use super::{link_weights, SINGULAR_RCOND};
use crate::math::{Real, Vec2};
use crate::measure::{Model, TxPattern, SNR_DISTANCE_FLOOR_M, UNIT_VECTOR_MIN_DISTANCE_M};

/// Cells per vector.
const LANES: usize = 4;
/// Vectors per block of a row (64 cells).
const BLOCK: usize = 16;

/// One node seen from four cells: unit vector node → cell and its weight (`1/max(d², 1)`, times
/// the Tx gain for a transmitter).
#[derive(Clone, Copy, Default)]
struct NodeLanes {
    ux: f64x4,
    uy: f64x4,
    weight: f64x4,
}

/// A node's offset from the current row: `dy = y − y_node` and `dy²`.
#[derive(Clone, Copy, Default)]
struct RowOffset {
    x: Real,
    dy: f64x4,
    dy2: f64x4,
}

/// The per-map constants: link weights and the cell-centre x of every column, padded to whole
/// vectors with the last centre.
pub(super) struct Kernel<'a> {
    model: &'a Model,
    grid: Grid,
    weights: Vec<f64x4>,
    xs: Vec<f64x4>,
}

impl<'a> Kernel<'a> {
    pub(super) fn new(model: &'a Model, grid: &Grid) -> Kernel<'a> {
        let nx = grid.nx;
        let xs = (0..nx.div_ceil(LANES))
            .map(|v| {
                f64x4::new(core::array::from_fn(|l| {
                    grid.x((v * LANES + l).min(nx - 1))
                }))
            })
            .collect();
        Kernel {
            model,
            grid: *grid,
            weights: link_weights(model).map(f64x4::splat).collect(),
            xs,
        }
    }

    /// Writes rows `first_row ..` of the map into `out` (whole rows, row-major).
    ///
    /// A row is done in blocks of [`BLOCK`] vectors, one pass per stage, so that the long
    /// dependency chains (square root and division per node, the pattern's Clenshaw recurrence,
    /// the bound's division and square root) of different vectors overlap instead of waiting on
    /// each other; a block's node views stay in L1.
    pub(super) fn rows(&self, first_row: usize, out: &mut [Real]) {
        let net = &self.model.network;
        let nx = self.grid.nx;
        let (ntx, nrx) = (net.transmitters.len(), net.receivers.len());
        let mut tx_offsets = vec![RowOffset::default(); ntx];
        let mut rx_offsets = vec![RowOffset::default(); nrx];
        let mut tx = vec![NodeLanes::default(); ntx * BLOCK];
        let mut rx = vec![NodeLanes::default(); nrx * BLOCK];
        for (r, out_row) in out.chunks_exact_mut(nx).enumerate() {
            let y = self.grid.y(first_row + r);
            for (o, node) in tx_offsets.iter_mut().zip(&net.transmitters) {
                *o = RowOffset::new(*node, y);
            }
            for (o, node) in rx_offsets.iter_mut().zip(&net.receivers) {
                *o = RowOffset::new(*node, y);
            }
            for (b, xs) in self.xs.chunks(BLOCK).enumerate() {
                let n = xs.len();
                for (k, (o, pattern)) in tx_offsets.iter().zip(&self.model.patterns).enumerate() {
                    let lanes = &mut tx[k * BLOCK..k * BLOCK + n];
                    for (l, &x) in lanes.iter_mut().zip(xs) {
                        *l = NodeLanes::new(x, o);
                    }
                    apply_pattern(lanes, pattern);
                }
                for (k, o) in rx_offsets.iter().enumerate() {
                    for (l, &x) in rx[k * BLOCK..k * BLOCK + n].iter_mut().zip(xs) {
                        *l = NodeLanes::new(x, o);
                    }
                }
                for v in 0..n {
                    let rmse = self.cell_bounds(&tx, &rx, v);
                    let first = (b * BLOCK + v) * LANES;
                    let m = LANES.min(nx - first);
                    out_row[first..first + m].copy_from_slice(&rmse.as_array_ref()[..m]);
                }
            }
        }
    }

    /// The RMSE bound of four cells from their node views: `Σ_links w·(gTx/d²)(1/d²)·(u^Tx+u^Rx)
    /// (u^Tx+u^Rx)ᵀ` (E8), then `√(tr F / det F)` or `+∞` where singular.
    #[inline(always)]
    fn cell_bounds(&self, tx: &[NodeLanes], rx: &[NodeLanes], v: usize) -> f64x4 {
        let (mut a, mut b, mut c) = (f64x4::ZERO, f64x4::ZERO, f64x4::ZERO);
        for (link, &w) in self.model.network.links.iter().zip(&self.weights) {
            let (t, r) = (&tx[link.tx * BLOCK + v], &rx[link.rx * BLOCK + v]);
            let gx = t.ux + r.ux;
            let gy = t.uy + r.uy;
            let wp = w * t.weight * r.weight;
            a += wp * gx * gx;
            b += wp * gx * gy;
            c += wp * gy * gy;
        }
        let det = a * c - b * b;
        let tr = a + c;
        // `is_regular` without branches: det > k·tr² also rejects NaN.
        let regular = tr.cmp_gt(f64x4::ZERO)
            & det.cmp_gt(tr * SINGULAR_RCOND * tr)
            & det.cmp_lt(f64x4::splat(Real::INFINITY));
        regular.blend((tr / det).sqrt(), f64x4::splat(Real::INFINITY))
    }
}

impl RowOffset {
    #[inline(always)]
    fn new(node: Vec2, y: Real) -> RowOffset {
        let dy = y - node.y;
        RowOffset {
            x: node.x,
            dy: f64x4::splat(dy),
            dy2: f64x4::splat(dy * dy),
        }
    }
}

impl NodeLanes {
    /// Unit vectors node → cells (zero on the node, spec §3) and `1/max(d², 1 m²)`.
    #[inline(always)]
    fn new(x: f64x4, o: &RowOffset) -> NodeLanes {
        let floor2 = SNR_DISTANCE_FLOOR_M * SNR_DISTANCE_FLOOR_M;
        let dx = x - o.x;
        let d2 = dx * dx + o.dy2;
        let d = d2.sqrt();
        let inv = d
            .cmp_lt(f64x4::splat(UNIT_VECTOR_MIN_DISTANCE_M))
            .blend(f64x4::ZERO, f64x4::ONE / d);
        NodeLanes {
            ux: dx * inv,
            uy: o.dy * inv,
            weight: d2
                .cmp_lt(f64x4::splat(floor2))
                .blend(f64x4::splat(1.0 / floor2), inv * inv),
        }
    }
}

/// Multiplies the weights of a transmitter's views by its gain toward each cell (peak gain on the
/// Tx itself, as in [`TxPattern::gain_toward`]); the beam's polynomial two vectors at a time.
#[inline(always)]
fn apply_pattern(lanes: &mut [NodeLanes], pattern: &TxPattern) {
    match (pattern.beam, pattern.polynomial.as_ref()) {
        (None, _) => {
            for l in lanes.iter_mut() {
                l.weight = l.weight * pattern.peak_gain;
            }
        }
        (Some(_), Some(p)) => {
            let peak = f64x4::splat(pattern.peak_gain);
            let cos = |l: &NodeLanes| l.ux * p.boresight.x + l.uy * p.boresight.y;
            let gain = |l: &NodeLanes, g: f64x4| {
                let on_node = l.ux.cmp_eq(f64x4::ZERO) & l.uy.cmp_eq(f64x4::ZERO);
                on_node.blend(peak, g)
            };
            let mut pairs = lanes.chunks_exact_mut(2);
            for pair in &mut pairs {
                let g = p.gains_at_cos_x4([cos(&pair[0]), cos(&pair[1])]);
                for (l, g) in pair.iter_mut().zip(g) {
                    l.weight *= gain(l, g);
                }
            }
            for l in pairs.into_remainder() {
                let [g] = p.gains_at_cos_x4([cos(l)]);
                l.weight *= gain(l, g);
            }
        }
        (Some(_), None) => {
            for l in lanes.iter_mut() {
                let (ux, uy) = (l.ux.to_array(), l.uy.to_array());
                l.weight *= f64x4::new(core::array::from_fn(|i| {
                    pattern.gain_toward(Vec2::new(ux[i], uy[i]))
                }));
            }
        }
    }
}
