//! Geometry of nodes as seen from points, shared by the EKF's pass 1, the Monte Carlo truth
//! tables and any filter that needs ranges (E1), unit vectors (E3) or the floored distance
//! factor of the SNR (E8).

use crate::math::{sqrt, Real, Vec2};
use crate::measure::{SNR_DISTANCE_FLOOR_M, UNIT_VECTOR_MIN_DISTANCE_M};

/// Geometry of `B` nodes as seen from `B` points (lane `i`: node `i` from point `i`): distance,
/// unit vector node → point
/// (zero closer than [`UNIT_VECTOR_MIN_DISTANCE_M`], as [`crate::measure::unit_from`]) and
/// `1/max(d, 1 m)²` (the floored distance factor of the SNR, E8). One square root and one
/// division per node.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NodeViews<const B: usize> {
    pub(crate) distance: [Real; B],
    pub(crate) ux: [Real; B],
    pub(crate) uy: [Real; B],
    pub(crate) inv_floored_sq: [Real; B],
}

impl<const B: usize> NodeViews<B> {
    /// Nodes `(x[i], y[i])` at vertical offsets `dz[i]` from the target's plane seen from the
    /// points `(px[i], py[i])` of that plane: 3-D distances `√(dx² + (dy² + dz²))` (bitwise the
    /// planar ones when `dz = 0`), the horizontal parts of the 3-D unit vectors.
    #[inline(always)]
    pub(crate) fn new(
        x: &[Real; B],
        y: &[Real; B],
        dz: &[Real; B],
        px: &[Real; B],
        py: &[Real; B],
    ) -> NodeViews<B> {
        let mut v = NodeViews {
            distance: [0.0; B],
            ux: [0.0; B],
            uy: [0.0; B],
            inv_floored_sq: [0.0; B],
        };
        for i in 0..B {
            let (dx, dy) = (px[i] - x[i], py[i] - y[i]);
            let distance = sqrt(dx * dx + (dy * dy + dz[i] * dz[i]));
            let inv = 1.0 / distance;
            let near = distance < UNIT_VECTOR_MIN_DISTANCE_M;
            v.ux[i] = if near { 0.0 } else { dx * inv };
            v.uy[i] = if near { 0.0 } else { dy * inv };
            let inv_floored = if distance >= SNR_DISTANCE_FLOOR_M {
                inv
            } else {
                1.0 / SNR_DISTANCE_FLOOR_M
            };
            v.distance[i] = distance;
            v.inv_floored_sq[i] = inv_floored * inv_floored;
        }
        v
    }
}

/// Geometry of one node as seen from a point `r`: the unit vector node → `r` (zero when they
/// nearly coincide, as [`crate::measure::unit_from`]), the distance and `1/max(d, 1 m)²` (the
/// floored distance factor of the SNR, E8). One division and one square root; lane 0 of
/// [`NodeViews`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct NodeView {
    pub(crate) unit: Vec2,
    pub(crate) distance: Real,
    pub(crate) inv_floored_sq: Real,
}

impl NodeView {
    /// A node at `node` and vertical offset `dz` seen from `r`.
    #[inline(always)]
    pub(crate) fn new(node: Vec2, dz: Real, r: Vec2) -> NodeView {
        let v = NodeViews::<1>::new(&[node.x], &[node.y], &[dz], &[r.x], &[r.y]);
        NodeView {
            unit: Vec2::new(v.ux[0], v.uy[0]),
            distance: v.distance[0],
            inv_floored_sq: v.inv_floored_sq[0],
        }
    }
}
