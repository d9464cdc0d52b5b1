//! The estimator's per-bin kernels on a flat band (`P[n] = 1`), four bins at a time: the
//! correlation and its first two derivatives in `τ` ([`moments`], C5's Newton step), a rotating
//! path added to the residual ([`add_rotating`]) and both in one pass ([`add_back`]).
//!
//! The phasors `e^{j2π(f_n−f_c)τ}` come by recursion as in the scalar loops they replace, but in
//! four interleaved chains (bins `4m + l` in lane `l`, each chain stepping by `step⁴`): the
//! chains are independent, so the loop runs at the vector units' throughput instead of the
//! latency of one complex product per bin. [`wide::f64x4`] performs each IEEE operation exactly
//! as written (no fused multiply-add, the same order natively and in wasm), so the results are
//! the same bits on every platform; they differ from the one-chain recursion by rounding only
//! (the chains accumulate `N/4` instead of `N` rounding steps). Tested against the direct sums
//! in `tests.rs`.

use wide::f64x4;

use crate::math::{Complex, Real};

/// Four complex values, split into real and imaginary lanes.
#[derive(Clone, Copy)]
struct C4 {
    re: f64x4,
    im: f64x4,
}

impl C4 {
    const ZERO: C4 = C4 {
        re: f64x4::ZERO,
        im: f64x4::ZERO,
    };

    /// `v[0..4]`.
    #[inline(always)]
    fn load(v: &[Complex]) -> C4 {
        C4 {
            re: f64x4::new([v[0].re, v[1].re, v[2].re, v[3].re]),
            im: f64x4::new([v[0].im, v[1].im, v[2].im, v[3].im]),
        }
    }

    /// Writes the four values to `v[0..4]`.
    #[inline(always)]
    fn store(self, v: &mut [Complex]) {
        let (re, im) = (self.re.to_array(), self.im.to_array());
        for (l, x) in v.iter_mut().take(4).enumerate() {
            *x = Complex::new(re[l], im[l]);
        }
    }

    /// Lane `l`.
    #[inline(always)]
    fn lane(self, l: usize) -> Complex {
        Complex::new(self.re.to_array()[l], self.im.to_array()[l])
    }

    /// `self·b`, as `Complex`'s product rounds it.
    #[inline(always)]
    fn mul(self, b: C4) -> C4 {
        C4 {
            re: self.re * b.re - self.im * b.im,
            im: self.re * b.im + self.im * b.re,
        }
    }

    /// `self·conj(b)`.
    #[inline(always)]
    fn mul_conj(self, b: C4) -> C4 {
        C4 {
            re: self.re * b.re + self.im * b.im,
            im: self.im * b.re - self.re * b.im,
        }
    }

    /// The sum of the four lanes, in lane order.
    #[inline(always)]
    fn sum(self) -> Complex {
        let (re, im) = (self.re.to_array(), self.im.to_array());
        Complex::new(
            ((re[0] + re[1]) + re[2]) + re[3],
            ((im[0] + im[1]) + im[2]) + im[3],
        )
    }
}

/// The four chains' first phasors `start·step^l` and their step `step⁴` (splat).
#[inline(always)]
fn chains(start: Complex, step: Complex) -> (C4, C4) {
    let p1 = start * step;
    let p2 = p1 * step;
    let p3 = p2 * step;
    let s2 = step * step;
    let s4 = s2 * s2;
    (
        C4 {
            re: f64x4::new([start.re, p1.re, p2.re, p3.re]),
            im: f64x4::new([start.im, p1.im, p2.im, p3.im]),
        },
        C4 {
            re: f64x4::splat(s4.re),
            im: f64x4::splat(s4.im),
        },
    )
}

/// Adds four bins' terms `x`, `j·w·x` and `−w²·x` (`w` the bins' `2π(f_n − f_c)`) to the
/// moments' partial sums `c0, c1, c2`.
#[inline(always)]
fn accumulate(x: C4, w: &[Real], [c0, c1, c2]: [&mut C4; 3]) {
    let f = f64x4::new([w[0], w[1], w[2], w[3]]);
    c0.re += x.re;
    c0.im += x.im;
    let (xr, xi) = (x.re * f, x.im * f);
    c1.re -= xi;
    c1.im += xr;
    c2.re -= xr * f;
    c2.im -= xi * f;
}

/// [`accumulate`] for one bin (the tail past the last multiple of four).
#[inline(always)]
fn accumulate_one(x: Complex, w: Real, [s0, s1, s2]: [&mut Complex; 3]) {
    *s0 += x;
    let xf = x * w;
    *s1 += Complex::new(-xf.im, xf.re);
    *s2 -= xf * w;
}

/// The moments of the residual `r` at the phasors `ph_n = start·stepⁿ` with angular bin
/// frequencies `tw[n] = 2π(f_n − f_c)`: `c0 = Σ r_n ph_n`, `c1 = Σ j·tw_n·r_n ph_n` and
/// `c2 = −Σ tw_n²·r_n ph_n` (`c(τ)`, `c'(τ)`, `c''(τ)` of C5 up to the sign convention of the
/// caller's phasor).
pub(super) fn moments(
    r: &[Complex],
    tw: &[Real],
    start: Complex,
    step: Complex,
) -> (Complex, Complex, Complex) {
    let n = r.len().min(tw.len());
    let (mut ph, step4) = chains(start, step);
    let (mut c0, mut c1, mut c2) = (C4::ZERO, C4::ZERO, C4::ZERO);
    let full = n / 4 * 4;
    for (rc, wc) in r[..full].chunks_exact(4).zip(tw[..full].chunks_exact(4)) {
        accumulate(C4::load(rc).mul(ph), wc, [&mut c0, &mut c1, &mut c2]);
        ph = ph.mul(step4);
    }
    let (mut s0, mut s1, mut s2) = (c0.sum(), c1.sum(), c2.sum());
    for (l, i) in (full..n).enumerate() {
        accumulate_one(r[i] * ph.lane(l), tw[i], [&mut s0, &mut s1, &mut s2]);
    }
    (s0, s1, s2)
}

/// `r[n] += ph·stepⁿ`.
pub(super) fn add_rotating(r: &mut [Complex], ph: Complex, step: Complex) {
    let n = r.len();
    let (mut p, step4) = chains(ph, step);
    let full = n / 4 * 4;
    for rc in r[..full].chunks_exact_mut(4) {
        let x = C4::load(rc);
        C4 {
            re: x.re + p.re,
            im: x.im + p.im,
        }
        .store(rc);
        p = p.mul(step4);
    }
    for (l, x) in r[full..].iter_mut().enumerate() {
        *x += p.lane(l);
    }
}

/// `r[n] += a·conj(ph_n)` with `ph_n = start·stepⁿ`, then [`moments`] of the new residual at
/// the same phasors, in one pass.
pub(super) fn add_back(
    r: &mut [Complex],
    tw: &[Real],
    a: Complex,
    start: Complex,
    step: Complex,
) -> (Complex, Complex, Complex) {
    let n = r.len().min(tw.len());
    let (mut ph, step4) = chains(start, step);
    let av = C4 {
        re: f64x4::splat(a.re),
        im: f64x4::splat(a.im),
    };
    let (mut c0, mut c1, mut c2) = (C4::ZERO, C4::ZERO, C4::ZERO);
    let full = n / 4 * 4;
    for (rc, wc) in r[..full]
        .chunks_exact_mut(4)
        .zip(tw[..full].chunks_exact(4))
    {
        let pa = av.mul_conj(ph);
        let old = C4::load(rc);
        let v = C4 {
            re: old.re + pa.re,
            im: old.im + pa.im,
        };
        v.store(rc);
        accumulate(v.mul(ph), wc, [&mut c0, &mut c1, &mut c2]);
        ph = ph.mul(step4);
    }
    let (mut s0, mut s1, mut s2) = (c0.sum(), c1.sum(), c2.sum());
    for (l, i) in (full..n).enumerate() {
        let p = ph.lane(l);
        r[i] += a * p.conj();
        accumulate_one(r[i] * p, tw[i], [&mut s0, &mut s1, &mut s2]);
    }
    (s0, s1, s2)
}

/// `Σ r_n·ph_n` with `ph_n = start·stepⁿ` (the correlation `c(τ)` alone).
pub(super) fn correlation(r: &[Complex], start: Complex, step: Complex) -> Complex {
    let n = r.len();
    let (mut ph, step4) = chains(start, step);
    let mut c0 = C4::ZERO;
    let full = n / 4 * 4;
    for rc in r[..full].chunks_exact(4) {
        let x = C4::load(rc).mul(ph);
        c0.re += x.re;
        c0.im += x.im;
        ph = ph.mul(step4);
    }
    let mut s0 = c0.sum();
    for (l, v) in r[full..].iter().enumerate() {
        s0 += v * ph.lane(l);
    }
    s0
}

/// Appends `ph·stepⁿ`, `n < count`, to `out`.
pub(super) fn push_rotating(
    out: &mut alloc::vec::Vec<Complex>,
    count: usize,
    ph: Complex,
    step: Complex,
) {
    let (mut p, step4) = chains(ph, step);
    let full = count / 4 * 4;
    for _ in 0..full / 4 {
        let (re, im) = (p.re.to_array(), p.im.to_array());
        out.extend((0..4).map(|l| Complex::new(re[l], im[l])));
        p = p.mul(step4);
    }
    out.extend((0..count - full).map(|l| p.lane(l)));
}

/// `Σ conj(a_n)·y_n` (four partial sums, added in lane order, then the tail).
pub(super) fn dot_conj(a: &[Complex], y: &[Complex]) -> Complex {
    let n = a.len().min(y.len());
    let full = n / 4 * 4;
    let mut acc = C4::ZERO;
    for (ac, yc) in a[..full].chunks_exact(4).zip(y[..full].chunks_exact(4)) {
        let x = C4::load(yc).mul_conj(C4::load(ac));
        acc.re += x.re;
        acc.im += x.im;
    }
    let mut s = acc.sum();
    for (u, v) in a[full..n].iter().zip(&y[full..n]) {
        s += u.conj() * v;
    }
    s
}

/// `Σ |v_n|²` (four partial sums, added in lane order, then the tail).
pub(super) fn norm_sqr_sum(v: &[Complex]) -> Real {
    let full = v.len() / 4 * 4;
    let mut acc = f64x4::ZERO;
    for c in v[..full].chunks_exact(4) {
        let x = C4::load(c);
        acc += x.re * x.re + x.im * x.im;
    }
    let a = acc.to_array();
    let mut s = ((a[0] + a[1]) + a[2]) + a[3];
    for x in &v[full..] {
        s += x.norm_sqr();
    }
    s
}

/// `Σ Re(conj(r_n)·d_n)` (four partial sums, added in lane order, then the tail).
pub(super) fn re_dot_conj(r: &[Complex], d: &[Complex]) -> Real {
    let n = r.len().min(d.len());
    let full = n / 4 * 4;
    let mut acc = f64x4::ZERO;
    for (rc, dc) in r[..full].chunks_exact(4).zip(d[..full].chunks_exact(4)) {
        let (x, y) = (C4::load(rc), C4::load(dc));
        acc += x.re * y.re + x.im * y.im;
    }
    let a = acc.to_array();
    let mut s = ((a[0] + a[1]) + a[2]) + a[3];
    for (x, y) in r[full..n].iter().zip(&d[full..n]) {
        s += (x.conj() * y).re;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{cos, sin, PI};

    fn cis(x: Real) -> Complex {
        Complex::new(cos(x), sin(x))
    }

    /// Residual, bin frequencies and the phasor of a delay, for `n` bins.
    fn case(n: usize) -> (Vec<Complex>, Vec<Real>, Real, Vec<Real>) {
        let df = 0.5e6;
        let fc: Vec<Real> = (0..n)
            .map(|i| (i as Real - (n as Real - 1.0) / 2.0) * df)
            .collect();
        let r = (0..n)
            .map(|i| Complex::new(sin(0.7 * i as Real) + 0.3, cos(0.11 * (i * i) as Real)))
            .collect();
        let tw = fc.iter().map(|f| 2.0 * PI * f).collect();
        (r, tw, df, fc)
    }

    /// Against the direct sums with `e^{j2π f_n τ}` per bin (no recursion), `N = 1 … 13` and
    /// 241, to `1e-12` of the sums of magnitudes.
    #[test]
    fn kernels_match_direct_sums() {
        for n in (1..=13).chain([241]) {
            let (r, tw, df, fc) = case(n);
            let tau = 37.3e-9;
            let start = cis(2.0 * PI * fc[0] * tau);
            let step = cis(2.0 * PI * df * tau);
            let ph: Vec<Complex> = fc.iter().map(|f| cis(2.0 * PI * f * tau)).collect();
            let scale: Real = r
                .iter()
                .zip(&tw)
                .map(|(v, w)| v.norm() * (1.0 + w * w))
                .sum();
            let close = |a: Complex, b: Complex| (a - b).norm() <= 1e-12 * scale;
            // moments
            let (m0, m1, m2) = moments(&r, &tw, start, step);
            let d0: Complex = r.iter().zip(&ph).map(|(v, p)| v * p).sum();
            let d1: Complex = r
                .iter()
                .zip(&ph)
                .zip(&tw)
                .map(|((v, p), w)| Complex::new(0.0, *w) * v * p)
                .sum();
            let d2: Complex = r
                .iter()
                .zip(&ph)
                .zip(&tw)
                .map(|((v, p), w)| -(v * p) * (w * w))
                .sum();
            assert!(close(m0, d0) && close(m1, d1) && close(m2, d2), "n {n}");
            // add_rotating
            let a = Complex::new(0.4, -1.1);
            let mut x = r.clone();
            add_rotating(&mut x, start.conj() * a, step.conj());
            for i in 0..n {
                let want = r[i] + a * ph[i].conj();
                assert!((x[i] - want).norm() <= 1e-12 * scale, "n {n} bin {i}");
            }
            // add_back = add_rotating then moments
            let mut y = r.clone();
            let (b0, b1, b2) = add_back(&mut y, &tw, a, start, step);
            let (e0, e1, e2) = moments(&x, &tw, start, step);
            for i in 0..n {
                assert!((y[i] - x[i]).norm() <= 1e-12 * scale, "n {n} bin {i}");
            }
            assert!(close(b0, e0) && close(b1, e1) && close(b2, e2), "n {n}");
            // correlation, push_rotating, dot_conj, norm_sqr_sum, re_dot_conj
            assert!(close(correlation(&r, start, step), d0), "n {n}");
            let mut cols = Vec::new();
            push_rotating(&mut cols, n, start.conj(), step.conj());
            assert_eq!(cols.len(), n);
            for i in 0..n {
                assert!((cols[i] - ph[i].conj()).norm() <= 1e-12, "n {n} bin {i}");
            }
            let dc: Complex = cols.iter().zip(&r).map(|(u, v)| u.conj() * v).sum();
            assert!(close(dot_conj(&cols, &r), dc), "n {n}");
            let ns: Real = r.iter().map(|v| v.norm_sqr()).sum();
            assert!((norm_sqr_sum(&r) - ns).abs() <= 1e-12 * ns, "n {n}");
            let rd: Real = r.iter().zip(&x).map(|(u, v)| (u.conj() * v).re).sum();
            assert!(
                (re_dot_conj(&r, &x) - rd).abs() <= 1e-12 * scale * scale,
                "n {n}"
            );
        }
    }
}
