//! The NEES quadratic form `eᵀ P⁻¹ e` of a 4 × 4 covariance by an `LDLᵀ` factorisation.

use super::positive_finite;
use crate::math::{Mat4, Real, Vec4};

/// `eᵀ P⁻¹ e` for a symmetric positive-definite 4 × 4 `P` via `P = L D Lᵀ` (lower triangle
/// read); `None` unless every pivot `d_i` is finite and positive (the Cholesky criterion).
#[inline]
pub(crate) fn spd_quadratic_form(p: &Mat4, e: &Vec4) -> Option<Real> {
    let pivot_ok = positive_finite;
    let d0 = p[(0, 0)];
    if !pivot_ok(d0) {
        return None;
    }
    let i0 = 1.0 / d0;
    // Column 0 of L times d0 (a_i0 = P_i0), then l_i0 = a_i0 / d0.
    let (a10, a20, a30) = (p[(1, 0)], p[(2, 0)], p[(3, 0)]);
    let (l10, l20, l30) = (a10 * i0, a20 * i0, a30 * i0);
    let d1 = p[(1, 1)] - l10 * a10;
    if !pivot_ok(d1) {
        return None;
    }
    let i1 = 1.0 / d1;
    let a21 = p[(2, 1)] - l20 * a10;
    let a31 = p[(3, 1)] - l30 * a10;
    let (l21, l31) = (a21 * i1, a31 * i1);
    let d2 = p[(2, 2)] - l20 * a20 - l21 * a21;
    if !pivot_ok(d2) {
        return None;
    }
    let i2 = 1.0 / d2;
    let a32 = p[(3, 2)] - l30 * a20 - l31 * a21;
    let l32 = a32 * i2;
    let d3 = p[(3, 3)] - l30 * a30 - l31 * a31 - l32 * a32;
    if !pivot_ok(d3) {
        return None;
    }
    // L y = e, then Σ y_i² / d_i.
    let y0 = e[0];
    let y1 = e[1] - l10 * y0;
    let y2 = e[2] - l20 * y0 - l21 * y1;
    let y3 = e[3] - l30 * y0 - l31 * y1 - l32 * y2;
    Some(y0 * y0 * i0 + y1 * y1 * i1 + y2 * y2 * i2 + y3 * y3 / d3)
}
