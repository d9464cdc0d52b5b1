//! The `LDLᵀ` factorisation of a symmetric 4 × 4 matrix with its positive-definiteness test,
//! and the NEES quadratic form `eᵀ P⁻¹ e` from it.

use super::positive_finite;
use crate::math::{Mat4, Real, Vec4};

/// `P = L D Lᵀ` of a symmetric positive-definite 4 × 4 `P` (lower triangle read): the
/// strictly lower entries `l_ij` of the unit lower-triangular `L` and the pivots `d_i` (all
/// finite and positive, the Cholesky criterion), with `1/d_0 … 1/d_2`. The Cholesky factor is
/// `L √D`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ldl4 {
    pub(crate) l10: Real,
    pub(crate) l20: Real,
    pub(crate) l30: Real,
    pub(crate) l21: Real,
    pub(crate) l31: Real,
    pub(crate) l32: Real,
    pub(crate) d: [Real; 4],
    inv: [Real; 3],
}

impl Ldl4 {
    /// The factorisation of `p`; `None` unless every pivot is finite and positive (`p` is then
    /// positive definite). Three divisions, no square root.
    #[inline(always)]
    pub(crate) fn new(p: &Mat4) -> Option<Ldl4> {
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
        Some(Ldl4 {
            l10,
            l20,
            l30,
            l21,
            l31,
            l32,
            d: [d0, d1, d2, d3],
            inv: [i0, i1, i2],
        })
    }

    /// `eᵀ P⁻¹ e`: `L y = e`, then `Σ y_i² / d_i`.
    #[inline(always)]
    pub(crate) fn quadratic_form(&self, e: &Vec4) -> Real {
        let [i0, i1, i2] = self.inv;
        let y0 = e[0];
        let y1 = e[1] - self.l10 * y0;
        let y2 = e[2] - self.l20 * y0 - self.l21 * y1;
        let y3 = e[3] - self.l30 * y0 - self.l31 * y1 - self.l32 * y2;
        y0 * y0 * i0 + y1 * y1 * i1 + y2 * y2 * i2 + y3 * y3 / self.d[3]
    }
}

/// `eᵀ P⁻¹ e` for a symmetric positive-definite 4 × 4 `P` via `P = L D Lᵀ` ([`Ldl4`], lower
/// triangle read); `None` unless every pivot `d_i` is finite and positive.
#[inline]
pub(crate) fn spd_quadratic_form(p: &Mat4, e: &Vec4) -> Option<Real> {
    Ldl4::new(p).map(|f| f.quadratic_form(e))
}
