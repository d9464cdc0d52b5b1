//! This CPU's wide registers for the CRLB map kernel (issue 29): [`Lanes`] for AVX2 (`__m256d`,
//! four cells) and AVX-512 (`__m512d`, eight cells), each in an exact form — the scalar
//! reference's IEEE operations in its order, bitwise equal to it — and a fast one.
//!
//! Runtime dispatch without `unsafe`: the `pulp` crate's `V3` (AVX2 + FMA) and `V4` (AVX-512
//! F/BW/CD/DQ/VL) are zero-sized proofs that the CPU has the instructions (checked once with
//! `is_x86_feature_detected!` by `try_new`), whose methods are the intrinsics as safe functions,
//! and `vectorize` runs a closure compiled with those target features. The vectors carry the
//! proof (a zero-sized field), so every operation is a plain intrinsic call.
//!
//! The fast forms (`FAST = true`) round each multiply-add once (FMA) and compute `1/d` from
//! `d²` without a square root or division: the hardware estimate (`vrsqrt14pd` on AVX-512,
//! relative error < 2⁻¹⁴; on AVX2 the single-precision `vrsqrtps`, < 1.5·2⁻¹²) refined by Newton
//! steps `y ← y·(3/2 − d²y²/2)` (two on AVX-512, three on AVX2), each of which squares the
//! relative error: after them `1/d` is within 2⁻⁵⁰ (a few units in the last place) of the
//! correctly rounded value. A cell is on its node when `d² < (10⁻⁹ m)²` (the exact forms test
//! `√d² < 10⁻⁹ m`: the two differ only for `d²` within an ulp of 10⁻¹⁸ m²). The bound's
//! `√(tr/det)` stays exact. So each cell's Fisher entries differ from the reference by a few
//! ulps per term and the RMSE bound by `≲ 2⁻⁴⁶·κ` relative, `κ = tr²/det` the matrix's
//! condition (tests/library/map_kernel.rs checks it on random scenarios).

use core::arch::x86_64::{__m256d, __m512d, _CMP_EQ_OQ, _CMP_GT_OQ, _CMP_LT_OQ};
use core::ops::{Add, BitAnd, Mul, Sub};

use pulp::x86::{V3, V4};

use crate::math::{Lanes, Real};

/// Four cells in one AVX2 register; `FAST`: FMA and the estimate of `1/√d²` (module doc).
#[derive(Clone, Copy, Debug)]
pub struct Avx2<const FAST: bool> {
    v: __m256d,
    s: V3,
}

/// Eight cells in one AVX-512 register; `FAST`: FMA and `vrsqrt14pd` (module doc).
#[derive(Clone, Copy, Debug)]
pub struct Avx512<const FAST: bool> {
    v: __m512d,
    s: V4,
}

/// A per-lane mask of [`Avx2`] (all bits of a lane set or clear).
#[derive(Clone, Copy)]
pub struct Mask4 {
    m: __m256d,
    s: V3,
}

/// A per-lane mask of [`Avx512`] (one bit per lane).
#[derive(Clone, Copy)]
pub struct Mask8 {
    m: u8,
}

impl BitAnd for Mask4 {
    type Output = Mask4;
    #[inline(always)]
    fn bitand(self, rhs: Mask4) -> Mask4 {
        Mask4 {
            m: self.s.avx._mm256_and_pd(self.m, rhs.m),
            s: self.s,
        }
    }
}

impl BitAnd for Mask8 {
    type Output = Mask8;
    #[inline(always)]
    fn bitand(self, rhs: Mask8) -> Mask8 {
        Mask8 { m: self.m & rhs.m }
    }
}

macro_rules! binary_ops {
    ($t:ident, $add:ident, $sub:ident, $mul:ident, $unit:ident) => {
        impl<const FAST: bool> Add for $t<FAST> {
            type Output = Self;
            #[inline(always)]
            fn add(self, b: Self) -> Self {
                $t {
                    v: self.s.$unit.$add(self.v, b.v),
                    s: self.s,
                }
            }
        }
        impl<const FAST: bool> Sub for $t<FAST> {
            type Output = Self;
            #[inline(always)]
            fn sub(self, b: Self) -> Self {
                $t {
                    v: self.s.$unit.$sub(self.v, b.v),
                    s: self.s,
                }
            }
        }
        impl<const FAST: bool> Mul for $t<FAST> {
            type Output = Self;
            #[inline(always)]
            fn mul(self, b: Self) -> Self {
                $t {
                    v: self.s.$unit.$mul(self.v, b.v),
                    s: self.s,
                }
            }
        }
    };
}

binary_ops!(Avx2, _mm256_add_pd, _mm256_sub_pd, _mm256_mul_pd, avx);
binary_ops!(Avx512, _mm512_add_pd, _mm512_sub_pd, _mm512_mul_pd, avx512f);

impl<const FAST: bool> Avx2<FAST> {
    #[inline(always)]
    fn with(self, v: __m256d) -> Self {
        Avx2 { v, s: self.s }
    }
}

impl<const FAST: bool> Avx512<FAST> {
    #[inline(always)]
    fn with(self, v: __m512d) -> Self {
        Avx512 { v, s: self.s }
    }
}

impl<const FAST: bool> Lanes for Avx2<FAST> {
    type Arch = V3;
    type Mask = Mask4;
    const LANES: usize = 4;
    const FUSED: bool = FAST;

    #[inline(always)]
    fn arch(self) -> V3 {
        self.s
    }

    #[inline(always)]
    fn splat(s: V3, v: Real) -> Self {
        Avx2 {
            v: s.avx._mm256_set1_pd(v),
            s,
        }
    }

    #[inline(always)]
    fn from_fn(s: V3, f: impl FnMut(usize) -> Real) -> Self {
        let a: [Real; 4] = core::array::from_fn(f);
        Avx2 {
            v: pulp::cast(a),
            s,
        }
    }

    #[inline(always)]
    fn write_to(self, out: &mut [Real]) {
        let a: [Real; 4] = pulp::cast(self.v);
        let n = out.len();
        out.copy_from_slice(&a[..n]);
    }

    #[inline(always)]
    fn lane(self, i: usize) -> Real {
        let a: [Real; 4] = pulp::cast(self.v);
        a[i]
    }

    #[inline(always)]
    fn mul_add(a: Self, b: Self, c: Self) -> Self {
        if FAST {
            a.with(a.s.fma._mm256_fmadd_pd(a.v, b.v, c.v))
        } else {
            a * b + c
        }
    }

    #[inline(always)]
    fn div(self, b: Self) -> Self {
        self.with(self.s.avx._mm256_div_pd(self.v, b.v))
    }

    #[inline(always)]
    fn div_const(self, d: Real) -> Self {
        if FAST {
            self * Self::splat(self.s, 1.0 / d)
        } else {
            self.div(Self::splat(self.s, d))
        }
    }

    #[inline(always)]
    fn max(self, b: Self) -> Self {
        self.with(self.s.avx._mm256_max_pd(self.v, b.v))
    }

    #[inline(always)]
    fn lt(self, b: Self) -> Mask4 {
        Mask4 {
            m: self.s.avx._mm256_cmp_pd::<_CMP_LT_OQ>(self.v, b.v),
            s: self.s,
        }
    }

    #[inline(always)]
    fn gt(self, b: Self) -> Mask4 {
        Mask4 {
            m: self.s.avx._mm256_cmp_pd::<_CMP_GT_OQ>(self.v, b.v),
            s: self.s,
        }
    }

    #[inline(always)]
    fn eq(self, b: Self) -> Mask4 {
        Mask4 {
            m: self.s.avx._mm256_cmp_pd::<_CMP_EQ_OQ>(self.v, b.v),
            s: self.s,
        }
    }

    #[inline(always)]
    fn select(m: Mask4, t: Self, f: Self) -> Self {
        t.with(t.s.avx._mm256_blendv_pd(f.v, t.v, m.m))
    }

    #[inline(always)]
    fn inv_distance(d2: Self, min_m: Real) -> Self {
        let s = d2.s;
        let zero = Self::splat(s, 0.0);
        if FAST {
            // The single-precision estimate (d² < 3.4e38 always: coordinates ≤ 1e7 m), then
            // three Newton steps in double precision.
            let e = s
                .avx
                ._mm256_cvtps_pd(s.sse._mm_rsqrt_ps(s.avx._mm256_cvtpd_ps(d2.v)));
            let y = newton(newton(newton(d2.with(e), d2), d2), d2);
            Self::select(d2.lt(Self::splat(s, min_m * min_m)), zero, y)
        } else {
            let d = d2.with(s.avx._mm256_sqrt_pd(d2.v));
            Self::select(
                d.lt(Self::splat(s, min_m)),
                zero,
                Self::splat(s, 1.0).div(d),
            )
        }
    }

    #[inline(always)]
    fn root_ratio(tr: Self, det: Self) -> Self {
        let q = tr.div(det);
        q.with(q.s.avx._mm256_sqrt_pd(q.v))
    }
}

impl<const FAST: bool> Lanes for Avx512<FAST> {
    type Arch = V4;
    type Mask = Mask8;
    const LANES: usize = 8;
    const FUSED: bool = FAST;

    #[inline(always)]
    fn arch(self) -> V4 {
        self.s
    }

    #[inline(always)]
    fn splat(s: V4, v: Real) -> Self {
        Avx512 {
            v: s.avx512f._mm512_set1_pd(v),
            s,
        }
    }

    #[inline(always)]
    fn from_fn(s: V4, f: impl FnMut(usize) -> Real) -> Self {
        let a: [Real; 8] = core::array::from_fn(f);
        Avx512 {
            v: pulp::cast(a),
            s,
        }
    }

    #[inline(always)]
    fn write_to(self, out: &mut [Real]) {
        let a: [Real; 8] = pulp::cast(self.v);
        let n = out.len();
        out.copy_from_slice(&a[..n]);
    }

    #[inline(always)]
    fn lane(self, i: usize) -> Real {
        let a: [Real; 8] = pulp::cast(self.v);
        a[i]
    }

    #[inline(always)]
    fn mul_add(a: Self, b: Self, c: Self) -> Self {
        if FAST {
            a.with(a.s.avx512f._mm512_fmadd_pd(a.v, b.v, c.v))
        } else {
            a * b + c
        }
    }

    #[inline(always)]
    fn div(self, b: Self) -> Self {
        self.with(self.s.avx512f._mm512_div_pd(self.v, b.v))
    }

    #[inline(always)]
    fn div_const(self, d: Real) -> Self {
        if FAST {
            self * Self::splat(self.s, 1.0 / d)
        } else {
            self.div(Self::splat(self.s, d))
        }
    }

    #[inline(always)]
    fn max(self, b: Self) -> Self {
        self.with(self.s.avx512f._mm512_max_pd(self.v, b.v))
    }

    #[inline(always)]
    fn lt(self, b: Self) -> Mask8 {
        Mask8 {
            m: self.s.avx512f._mm512_cmp_pd_mask::<_CMP_LT_OQ>(self.v, b.v),
        }
    }

    #[inline(always)]
    fn gt(self, b: Self) -> Mask8 {
        Mask8 {
            m: self.s.avx512f._mm512_cmp_pd_mask::<_CMP_GT_OQ>(self.v, b.v),
        }
    }

    #[inline(always)]
    fn eq(self, b: Self) -> Mask8 {
        Mask8 {
            m: self.s.avx512f._mm512_cmp_pd_mask::<_CMP_EQ_OQ>(self.v, b.v),
        }
    }

    #[inline(always)]
    fn select(m: Mask8, t: Self, f: Self) -> Self {
        t.with(t.s.avx512f._mm512_mask_blend_pd(m.m, f.v, t.v))
    }

    #[inline(always)]
    fn inv_distance(d2: Self, min_m: Real) -> Self {
        let s = d2.s;
        let zero = Self::splat(s, 0.0);
        if FAST {
            let e = d2.with(s.avx512f._mm512_rsqrt14_pd(d2.v));
            let y = newton(newton(e, d2), d2);
            Self::select(d2.lt(Self::splat(s, min_m * min_m)), zero, y)
        } else {
            let d = d2.with(s.avx512f._mm512_sqrt_pd(d2.v));
            Self::select(
                d.lt(Self::splat(s, min_m)),
                zero,
                Self::splat(s, 1.0).div(d),
            )
        }
    }

    #[inline(always)]
    fn root_ratio(tr: Self, det: Self) -> Self {
        if FAST {
            // √(tr/det) = tr/√(tr·det), the estimate refined twice (regular cells: tr, det > 0).
            let p = tr * det;
            let e = p.with(p.s.avx512f._mm512_rsqrt14_pd(p.v));
            tr * newton(newton(e, p), p)
        } else {
            let q = tr.div(det);
            q.with(q.s.avx512f._mm512_sqrt_pd(q.v))
        }
    }
}

/// One Newton step of `y ≈ 1/√x`: `y·(3/2 − (x/2)·y²)`, with fused multiply-adds.
#[inline(always)]
fn newton<L: Lanes>(y: L, x: L) -> L {
    let s = y.arch();
    let h = x * L::splat(s, 0.5);
    let r = y * y;
    // 3/2 − h·r, one rounding.
    let e = L::mul_add(L::splat(s, -1.0) * h, r, L::splat(s, 1.5));
    y * e
}
