//! Vectors of `f64` lanes for the CRLB map kernel (issue 29): the operations the kernel needs,
//! behind one trait, so that one kernel (`localize::crlb_map_rows_with`) runs on every vector
//! type. The core implements it for [`wide::f64x4`] — four lanes, the scalar reference's exact
//! IEEE operations in its order (bitwise equal to it): two SSE2 registers natively, two simd128
//! registers in the page. The native edge implements it for this CPU's AVX2 and AVX-512
//! registers (runtime dispatch, `crate::native`), in an exact form (bitwise equal too) and a fast
//! one (fused multiply-adds and hardware reciprocal square-root estimates refined by Newton
//! steps: within a bound of the reference, not bitwise).

use core::ops::{Add, BitAnd, Mul, Sub};

use wide::{f64x4, CmpEq, CmpGt, CmpLt};

use super::Real;

/// `LANES` cells' values and the operations of the CRLB map kernel on them.
///
/// The exact implementations (`FUSED == false`) round every operation as the scalar reference
/// does: `mul_add(a, b, c)` is `a·b + c` with two roundings, [`Lanes::inv_distance`] is `1/√d²`,
/// [`Lanes::root_ratio`] `√(tr/det)`. The fast ones may fuse and estimate; their error bound is
/// stated by the implementation.
pub trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + core::fmt::Debug
{
    /// The instruction-set token the vectors need (`()` for `wide`; a zero-sized proof that the
    /// CPU has AVX2 or AVX-512 for the native types): constructors take it.
    type Arch: Copy;
    /// A per-lane mask.
    type Mask: Copy + BitAnd<Output = Self::Mask>;
    /// Lanes per vector.
    const LANES: usize;
    /// Whether `mul_add` is fused (one rounding).
    const FUSED: bool;

    /// The token of this vector.
    fn arch(self) -> Self::Arch;
    /// Every lane `v`.
    fn splat(arch: Self::Arch, v: Real) -> Self;
    /// Lane `i` = `f(i)`.
    fn from_fn(arch: Self::Arch, f: impl FnMut(usize) -> Real) -> Self;
    /// Writes the first `out.len()` (≤ `LANES`) lanes.
    fn write_to(self, out: &mut [Real]);
    /// Lane `i`.
    fn lane(self, i: usize) -> Real;
    /// `a·b + c` (fused or not, see [`Lanes::FUSED`]).
    fn mul_add(a: Self, b: Self, c: Self) -> Self;
    /// `a / b`, correctly rounded.
    fn div(self, b: Self) -> Self;
    /// `self / d` for a constant `d`: exact forms divide, fast ones may multiply by `1/d`.
    fn div_const(self, d: Real) -> Self;
    /// The larger of two lanes (`b` when either is NaN, as x86's `maxpd` and `wide`).
    fn max(self, b: Self) -> Self;
    /// `self < b`.
    fn lt(self, b: Self) -> Self::Mask;
    /// `self > b`.
    fn gt(self, b: Self) -> Self::Mask;
    /// `self == b`.
    fn eq(self, b: Self) -> Self::Mask;
    /// `t` where `m`, else `f`.
    fn select(m: Self::Mask, t: Self, f: Self) -> Self;
    /// `1/d` for `d = √d2`, and `0` where `d < min_m` (a cell on the node, spec §3).
    fn inv_distance(d2: Self, min_m: Real) -> Self;
    /// `√(tr/det)` (the bound S24 from the Fisher matrix's trace and determinant).
    fn root_ratio(tr: Self, det: Self) -> Self;
}

impl Lanes for f64x4 {
    type Arch = ();
    type Mask = f64x4;
    const LANES: usize = 4;
    const FUSED: bool = false;

    #[inline(always)]
    fn arch(self) -> Self::Arch {}

    #[inline(always)]
    fn splat(_: (), v: Real) -> Self {
        f64x4::splat(v)
    }

    #[inline(always)]
    fn from_fn(_: (), f: impl FnMut(usize) -> Real) -> Self {
        f64x4::new(core::array::from_fn(f))
    }

    #[inline(always)]
    fn write_to(self, out: &mut [Real]) {
        let n = out.len();
        out.copy_from_slice(&self.as_array_ref()[..n]);
    }

    #[inline(always)]
    fn lane(self, i: usize) -> Real {
        self.as_array_ref()[i]
    }

    #[inline(always)]
    fn mul_add(a: Self, b: Self, c: Self) -> Self {
        a * b + c
    }

    #[inline(always)]
    fn div(self, b: Self) -> Self {
        self / b
    }

    #[inline(always)]
    fn div_const(self, d: Real) -> Self {
        self / f64x4::splat(d)
    }

    #[inline(always)]
    fn max(self, b: Self) -> Self {
        f64x4::max(self, b)
    }

    #[inline(always)]
    fn lt(self, b: Self) -> Self::Mask {
        self.cmp_lt(b)
    }

    #[inline(always)]
    fn gt(self, b: Self) -> Self::Mask {
        self.cmp_gt(b)
    }

    #[inline(always)]
    fn eq(self, b: Self) -> Self::Mask {
        self.cmp_eq(b)
    }

    #[inline(always)]
    fn select(m: Self::Mask, t: Self, f: Self) -> Self {
        m.blend(t, f)
    }

    #[inline(always)]
    fn inv_distance(d2: Self, min_m: Real) -> Self {
        let d = d2.sqrt();
        d.cmp_lt(f64x4::splat(min_m))
            .blend(f64x4::ZERO, f64x4::ONE / d)
    }

    #[inline(always)]
    fn root_ratio(tr: Self, det: Self) -> Self {
        (tr / det).sqrt()
    }
}
