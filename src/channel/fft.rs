//! A small radix-2 FFT for the channel front end (C2 map, C5 periodogram) and the chirp-z
//! transform of the delay figure's profile ([`ChirpZ`]).
//!
//! Why our own: the core is `no_std` and its results must be bit-identical natively and in wasm.
//! `rustfft` needs `std` and picks AVX/SSE kernels at run time (different rounding per CPU);
//! this one is plain iterative Cooley–Tukey on `f64` with twiddles from
//! [`crate::math`]'s `sin`/`cos` (the `libm` crate on every platform; the platform's own
//! differ in the last bits), no FMA, so every platform gets the same bits. Sizes are powers of two (the periodogram zero-pads to one).

use alloc::vec;
use alloc::vec::Vec;

use crate::math::{cos, sin, Complex, Real, PI};

/// A plan for transforms of one power-of-two size `n`: twiddles and the bit-reversal table.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Fft {
    n: usize,
    /// `e^{-j2πk/n}`, `k = 0 … n/2−1`.
    twiddles: Vec<Complex>,
    bitrev: Vec<u32>,
}

impl Fft {
    /// A plan for size `n` (a power of two ≥ 1; callers guarantee it).
    pub(crate) fn new(n: usize) -> Fft {
        debug_assert!(n.is_power_of_two());
        let half = n / 2;
        let twiddles = (0..half)
            .map(|k| {
                let a = -2.0 * PI * (k as Real) / (n as Real);
                Complex::new(cos(a), sin(a))
            })
            .collect();
        let bits = n.trailing_zeros();
        let bitrev = (0..n as u32)
            .map(|i| {
                if bits == 0 {
                    0
                } else {
                    i.reverse_bits() >> (32 - bits)
                }
            })
            .collect();
        Fft {
            n,
            twiddles,
            bitrev,
        }
    }

    /// In place, `X[k] = Σ_m x[m] e^{-j2πkm/n}` (`inverse`: `e^{+j…}`, unscaled).
    /// `x.len()` must be `n`.
    pub(crate) fn run(&self, x: &mut [Complex], inverse: bool) {
        let n = self.n;
        debug_assert_eq!(x.len(), n);
        for i in 0..n {
            let j = self.bitrev[i] as usize;
            if j > i {
                x.swap(i, j);
            }
        }
        let mut len = 2;
        while len <= n {
            let half = len / 2;
            let stride = n / len;
            for start in (0..n).step_by(len) {
                for k in 0..half {
                    let t = self.twiddles[k * stride];
                    let w = if inverse { t.conj() } else { t };
                    let a = x[start + k];
                    let b = x[start + k + half];
                    let bw = Complex::new(b.re * w.re - b.im * w.im, b.re * w.im + b.im * w.re);
                    x[start + k] = Complex::new(a.re + bw.re, a.im + bw.im);
                    x[start + k + half] = Complex::new(a.re - bw.re, a.im - bw.im);
                }
            }
            len *= 2;
        }
    }
}

/// The transform of a zero-padded input, `X[k] = Σ_{m<n} x[m] e^{+j2πkm/L}` for `k < L`
/// (`L` a power of two ≥ `n`), the periodogram of C5. Faster than [`Fft`] on the padded
/// vector: with `M` the next power of two ≥ `n` and `R = L/M`,
/// `X[Rq + r] = Σ_m (x[m] e^{+j2πrm/L}) e^{+j2πqm/M}` — `R` transforms of size `M` of
/// pre-rotated copies (the stages that would only move zeros are skipped), each a
/// decimation-in-frequency radix-2 pass with per-stage contiguous twiddles and no bit-reversal:
/// the output stays in *slot* order and [`PaddedFft::natural`] maps a slot to its `k`. Plain
/// `f64` arithmetic, no FMA: the same bits on every platform.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PaddedFft {
    n: usize,
    m: usize,
    r: usize,
    /// `e^{+j2πrm/L}`, `r = 1 … R−1`, `m < n` (row `r−1`).
    rotate: Vec<Complex>,
    /// Per stage (span `M, M/2, …, 2`) the twiddles `e^{+j2πk/span}`, `k < span/2`, back to back.
    twiddles: Vec<Complex>,
    /// `natural[slot] = k`.
    natural: Vec<u32>,
    /// `slot_of[k] = slot`.
    slot_of: Vec<u32>,
}

impl PaddedFft {
    /// A plan for inputs of length `n ≥ 1` padded to `l` (a power of two ≥ `n`; callers
    /// guarantee both).
    pub(crate) fn new(n: usize, l: usize) -> PaddedFft {
        debug_assert!(l.is_power_of_two() && l >= n && n >= 1);
        let m = n.next_power_of_two().min(l);
        let r = l / m;
        let mut rotate = Vec::with_capacity((r - 1) * n);
        for rr in 1..r {
            for k in 0..n {
                let a = 2.0 * PI * ((rr * k) % l) as Real / l as Real;
                rotate.push(Complex::new(cos(a), sin(a)));
            }
        }
        let mut twiddles = Vec::with_capacity(m);
        let mut span = m;
        while span >= 2 {
            for k in 0..span / 2 {
                let a = 2.0 * PI * k as Real / span as Real;
                twiddles.push(Complex::new(cos(a), sin(a)));
            }
            span /= 2;
        }
        let bits = m.trailing_zeros();
        let rev = |i: usize| {
            if bits == 0 {
                0
            } else {
                (i as u32).reverse_bits() >> (32 - bits)
            }
        };
        let natural: Vec<u32> = (0..l)
            .map(|slot| (r * rev(slot % m) as usize + slot / m) as u32)
            .collect();
        let mut slot_of = vec![0u32; l];
        for (slot, &k) in natural.iter().enumerate() {
            slot_of[k as usize] = slot as u32;
        }
        PaddedFft {
            n,
            m,
            r,
            rotate,
            twiddles,
            natural,
            slot_of,
        }
    }

    /// The transform size `L`.
    pub(crate) fn len(&self) -> usize {
        self.m * self.r
    }

    /// The output slot holding frequency index `k` (`k < L`).
    pub(crate) fn slot_of(&self, k: usize) -> u32 {
        self.slot_of[k]
    }

    /// `natural[slot]`: the frequency index `k` held by output slot `slot`.
    pub(crate) fn natural(&self) -> &[u32] {
        &self.natural
    }

    /// The vertex of the parabola through the magnitudes of `out`'s frequency index
    /// `natural[slot]` and its two neighbours (cyclic), as a fraction of a cell in
    /// `[−0.5, 0.5]` (0 where the three are not concave): a peak's sub-cell offset.
    pub(crate) fn parabola(&self, out: &[Complex], slot: u32) -> Real {
        let l = self.natural.len();
        let k = self.natural[slot as usize] as usize;
        let mag = |k: usize| crate::math::sqrt(out[self.slot_of[k % l] as usize].norm_sqr());
        let (y0, y1, y2) = (mag(k + l - 1), mag(k), mag(k + 1));
        let den = y0 - 2.0 * y1 + y2;
        if den < 0.0 {
            (0.5 * (y0 - y2) / den).clamp(-0.5, 0.5)
        } else {
            0.0
        }
    }

    /// `out[slot] = X[natural[slot]]` of `x` (`x.len() = n`, `out.len() = L`).
    pub(crate) fn run(&self, x: &[Complex], out: &mut [Complex]) {
        let (n, m) = (self.n, self.m);
        debug_assert!(x.len() == n && out.len() == m * self.r);
        for (rr, block) in out.chunks_exact_mut(m).enumerate() {
            if rr == 0 {
                block[..n].copy_from_slice(x);
            } else {
                let rot = &self.rotate[(rr - 1) * n..rr * n];
                for ((o, v), w) in block.iter_mut().zip(x).zip(rot) {
                    *o = Complex::new(v.re * w.re - v.im * w.im, v.re * w.im + v.im * w.re);
                }
            }
            for o in &mut block[n..] {
                *o = Complex::new(0.0, 0.0);
            }
            self.dif(block);
        }
    }

    /// In-place radix-2 decimation in frequency of size `M`, output in bit-reversed order. The
    /// last two stages, whose twiddles are `1` and `j`, are done without multiplications.
    fn dif(&self, x: &mut [Complex]) {
        let mut span = self.m;
        let mut tw = 0;
        while span >= 8 {
            let half = span / 2;
            let w = &self.twiddles[tw..tw + half];
            for block in x.chunks_exact_mut(span) {
                let (lo, hi) = block.split_at_mut(half);
                for ((a, b), t) in lo.iter_mut().zip(hi.iter_mut()).zip(w) {
                    let (s, d) = (
                        Complex::new(a.re + b.re, a.im + b.im),
                        Complex::new(a.re - b.re, a.im - b.im),
                    );
                    *a = s;
                    *b = Complex::new(d.re * t.re - d.im * t.im, d.re * t.im + d.im * t.re);
                }
            }
            tw += half;
            span = half;
        }
        let add = |a: Complex, b: Complex| Complex::new(a.re + b.re, a.im + b.im);
        let sub = |a: Complex, b: Complex| Complex::new(a.re - b.re, a.im - b.im);
        if span == 4 {
            // Twiddles 1 and e^{+jπ/2} = j.
            for q in x.chunks_exact_mut(4) {
                let (a0, a1, b0, b1) = (q[0], q[1], q[2], q[3]);
                let (d0, d1) = (sub(a0, b0), sub(a1, b1));
                q[0] = add(a0, b0);
                q[1] = add(a1, b1);
                q[2] = d0;
                q[3] = Complex::new(-d1.im, d1.re);
            }
            span = 2;
        }
        if span == 2 {
            for q in x.chunks_exact_mut(2) {
                let (a, b) = (q[0], q[1]);
                q[0] = add(a, b);
                q[1] = sub(a, b);
            }
        }
    }
}

/// The delay profile of C1 on a uniform delay grid by the chirp-z transform (Bluestein):
/// `X_j = Σ_{n<N} x[n]·e^{+j2πnΔf·τ_j}` at `τ_j = τ_0 + j·δτ`, `j < J`, for samples `x[n]` at
/// frequencies `f_0 + nΔf` (`|e^{j2πf_0τ}| = 1`: `|X_j|` is the profile's magnitude). With
/// `w = e^{j2πΔf·δτ}` and `nj = (n² + j² − (j−n)²)/2`,
/// `X_j = w^{j²/2}·Σ_n (x[n]·e^{j2πnΔfτ_0}·w^{n²/2})·w^{−(j−n)²/2}`: a convolution with the chirp
/// `w^{−m²/2}`, `−N < m < J`, done as a circular one of size `L` (the power of two ≥ `N + J − 1`,
/// so nothing wraps onto the rows), and `|w^{j²/2}| = 1`. The convolution is a forward
/// decimation-in-frequency pass (natural order in, bit-reversed out; the stages' butterflies
/// whose lower input is padding are skipped), the product with the chirp's transform (held in
/// the same bit-reversed order) and an inverse decimation-in-time pass (bit-reversed in, natural
/// out; its last stage computes the `J` rows only): no bit-reversal permutation. Exact up to
/// rounding (against the direct sum: within `1e-12·(Σ|x|)²` in power), `O(L log L)` per profile
/// instead of `N·J`. Plain `f64` arithmetic, no FMA, phases from [`crate::math`]: the same bits
/// on every platform.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ChirpZ {
    n: usize,
    rows: usize,
    /// `e^{j2πnΔfτ_0}·w^{n²/2}`, `n < N`.
    pre: Vec<Complex>,
    /// Per stage (span `L, L/2, …, 2`) the twiddles `e^{−j2πk/span}`, `k < span/2`, back to back
    /// (the stage of span `s` from index `L − s`).
    twiddles: Vec<Complex>,
    /// The transform of the chirp `w^{−m²/2}` (at index `m mod L`) in bit-reversed order, over
    /// `L` (the inverse transform's scale).
    kernel: Vec<Complex>,
}

/// `a·b`.
#[inline]
fn mul(a: Complex, b: Complex) -> Complex {
    Complex::new(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re)
}

/// `a·conj(b)`.
#[inline]
fn mul_conj(a: Complex, b: Complex) -> Complex {
    Complex::new(a.re * b.re + a.im * b.im, a.im * b.re - a.re * b.im)
}

impl ChirpZ {
    /// A plan for `n ≥ 1` samples of spacing `df_hz` and `rows ≥ 1` delays `tau0_s + j·dtau_s`
    /// (all finite; callers guarantee it).
    pub(crate) fn new(n: usize, rows: usize, df_hz: Real, tau0_s: Real, dtau_s: Real) -> ChirpZ {
        debug_assert!(n >= 1 && rows >= 1);
        let l = (n + rows - 1).next_power_of_two();
        // Cycles: Δf·τ_0 per sample, a/2 per n² with a = Δf·δτ.
        let (c0, a) = (df_hz * tau0_s, df_hz * dtau_s);
        let phasor = |cycles: Real| {
            let ph = 2.0 * PI * cycles;
            Complex::new(cos(ph), sin(ph))
        };
        let half_sq = |m: usize| 0.5 * a * (m as Real * m as Real);
        let pre = (0..n)
            .map(|k| phasor(c0 * k as Real + half_sq(k)))
            .collect();
        let mut twiddles = Vec::with_capacity(l);
        let mut span = l;
        while span >= 2 {
            for k in 0..span / 2 {
                let a = -2.0 * PI * k as Real / span as Real;
                twiddles.push(Complex::new(cos(a), sin(a)));
            }
            span /= 2;
        }
        let mut plan = ChirpZ {
            n,
            rows,
            pre,
            twiddles,
            kernel: Vec::new(),
        };
        let mut kernel = vec![Complex::new(0.0, 0.0); l];
        for (m, k) in kernel.iter_mut().enumerate().take(rows) {
            *k = phasor(-half_sq(m));
        }
        for m in 1..n {
            kernel[l - m] = phasor(-half_sq(m));
        }
        plan.forward(&mut kernel, l);
        let scale = 1.0 / l as Real; // a power of two: exact
        for v in &mut kernel {
            *v = Complex::new(v.re * scale, v.im * scale);
        }
        plan.kernel = kernel;
        plan
    }

    /// The transform size `L`.
    pub(crate) fn len(&self) -> usize {
        self.twiddles.len() + 1
    }

    /// `power[j] = |X_j|²` of `x` (`x.len() = N`, `power.len() = J`); `work` is scratch (resized
    /// to `L`).
    pub(crate) fn power(&self, x: &[Complex], work: &mut Vec<Complex>, power: &mut [Real]) {
        debug_assert!(x.len() == self.n && power.len() == self.rows);
        work.clear();
        work.extend(x.iter().zip(&self.pre).map(|(v, w)| mul(*v, *w)));
        work.resize(self.len(), Complex::new(0.0, 0.0));
        self.forward(work, self.n);
        for (v, k) in work.iter_mut().zip(&self.kernel) {
            *v = mul(*v, *k);
        }
        self.inverse(work);
        for (p, v) in power.iter_mut().zip(work.iter()) {
            *p = v.re * v.re + v.im * v.im;
        }
    }

    /// In place, the forward transform `Σ_m x[m] e^{−j2πkm/L}` in bit-reversed order of `x`
    /// whose entries from `nz` on are zero (decimation in frequency).
    fn forward(&self, x: &mut [Complex], mut nz: usize) {
        let l = x.len();
        let mut span = l;
        while span >= 2 {
            let half = span / 2;
            let w = &self.twiddles[l - span..l - span + half];
            for block in x.chunks_exact_mut(span) {
                let (lo, hi) = block.split_at_mut(half);
                if nz <= half {
                    // The upper half is zero: a stays, b = a·w (zero from nz on).
                    for ((a, b), t) in lo[..nz].iter().zip(&mut hi[..nz]).zip(w) {
                        *b = mul(*a, *t);
                    }
                } else {
                    for ((a, b), t) in lo.iter_mut().zip(hi.iter_mut()).zip(w) {
                        let (s, d) = (
                            Complex::new(a.re + b.re, a.im + b.im),
                            Complex::new(a.re - b.re, a.im - b.im),
                        );
                        *a = s;
                        *b = mul(d, *t);
                    }
                }
            }
            nz = nz.min(half);
            span = half;
        }
    }

    /// In place, the unscaled inverse transform `Σ_k X[k] e^{+j2πkm/L}` of `X` in bit-reversed
    /// order, in natural order; only `m < J` is computed in full (decimation in time).
    fn inverse(&self, x: &mut [Complex]) {
        let l = x.len();
        let mut span = 2;
        while span <= l {
            let half = span / 2;
            let w = &self.twiddles[l - span..l - span + half];
            // The last stage writes outputs m and m + L/2: only those below J are wanted.
            let (keep_lo, keep_hi) = if span == l {
                (self.rows.min(half), self.rows.saturating_sub(half))
            } else {
                (half, half)
            };
            for block in x.chunks_exact_mut(span) {
                let (lo, hi) = block.split_at_mut(half);
                for (k, ((a, b), t)) in lo.iter_mut().zip(hi.iter_mut()).zip(w).enumerate() {
                    if k >= keep_lo && k >= keep_hi {
                        break;
                    }
                    let bw = mul_conj(*b, *t);
                    let (s, d) = (
                        Complex::new(a.re + bw.re, a.im + bw.im),
                        Complex::new(a.re - bw.re, a.im - bw.im),
                    );
                    *a = s;
                    *b = d;
                }
            }
            span *= 2;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;

    fn direct(x: &[Complex], inverse: bool) -> Vec<Complex> {
        let n = x.len();
        let s = if inverse { 1.0 } else { -1.0 };
        (0..n)
            .map(|k| {
                let mut acc = Complex::new(0.0, 0.0);
                for (m, v) in x.iter().enumerate() {
                    let a = s * 2.0 * PI * ((k * m) % n) as Real / n as Real;
                    acc += v * Complex::new(cos(a), sin(a));
                }
                acc
            })
            .collect()
    }

    /// The padded transform equals the direct sum `Σ x[m] e^{+j2πkm/L}` in every slot, for
    /// input lengths 1 … 300 and paddings up to 16×.
    #[test]
    fn padded_matches_direct_sum() {
        for n in [1usize, 2, 3, 7, 16, 33, 241, 256, 300] {
            let x: Vec<Complex> = (0..n)
                .map(|i| {
                    let t = i as Real;
                    Complex::new(sin(0.37 * t + 0.1) + 0.5, cos(1.3 * t * t))
                })
                .collect();
            let mut l = n.next_power_of_two();
            while l <= 16 * n.next_power_of_two() {
                let plan = PaddedFft::new(n, l);
                assert_eq!(plan.len(), l);
                let mut out = vec![Complex::new(0.0, 0.0); l];
                plan.run(&x, &mut out);
                let mut seen = vec![false; l];
                for (slot, &k) in plan.natural().iter().enumerate() {
                    let k = k as usize;
                    assert!(!seen[k], "n {n} l {l}: k {k} twice");
                    seen[k] = true;
                    let mut acc = Complex::new(0.0, 0.0);
                    for (mm, v) in x.iter().enumerate() {
                        let a = 2.0 * PI * ((k * mm) % l) as Real / l as Real;
                        acc += v * Complex::new(cos(a), sin(a));
                    }
                    let d = crate::math::sqrt((out[slot] - acc).norm_sqr());
                    assert!(
                        d <= 1e-12 * n as Real,
                        "n {n} l {l} k {k}: {} vs {acc}",
                        out[slot]
                    );
                }
                l *= 2;
            }
        }
    }

    /// The chirp-z profile equals the direct sum `Σ x[n] e^{+j2πnΔfτ_j}` (its power, to 1e-12
    /// of `(Σ|x|)²`) for sample counts 1 … 241, 1 … 300 rows and grids inside, across and beyond
    /// the unambiguous range `1/Δf`.
    #[test]
    fn chirp_z_matches_direct_sum() {
        let df = 0.5e6;
        for (n, rows, tau0, dtau) in [
            (1usize, 1usize, 0.0, 1e-9),
            (2, 7, -3e-8, 2.5e-9),
            (16, 10, 0.0, 3.3e-7),
            (64, 60, 1e-8, 1.7e-9),
            (241, 300, 5.0 / 3e8, 0.13 / 3e8),
            (241, 300, 1.9e-6, 4e-9),
            (241, 3, -7e-6, 1e-6),
            (200, 300, 0.0, 1e-8),
        ] {
            let x: Vec<Complex> = (0..n)
                .map(|i| {
                    let t = i as Real;
                    Complex::new(sin(0.37 * t + 0.1) + 0.5, cos(1.3 * t * t))
                })
                .collect();
            let plan = ChirpZ::new(n, rows, df, tau0, dtau);
            assert!(plan.len() >= n + rows - 1 && plan.len().is_power_of_two());
            let mut work = Vec::new();
            let mut p = vec![0.0; rows];
            plan.power(&x, &mut work, &mut p);
            let total: Real = x.iter().map(|v| crate::math::sqrt(v.norm_sqr())).sum();
            for (j, pj) in p.iter().enumerate() {
                let tau = tau0 + j as Real * dtau;
                let mut acc = Complex::new(0.0, 0.0);
                for (k, v) in x.iter().enumerate() {
                    let a = 2.0 * PI * df * k as Real * tau;
                    acc += v * Complex::new(cos(a), sin(a));
                }
                let d = (pj - acc.norm_sqr()).abs();
                assert!(
                    d <= 1e-12 * total * total,
                    "n {n} rows {rows} j {j}: {pj} vs {}",
                    acc.norm_sqr()
                );
            }
        }
    }

    /// Against the direct DFT to 1e-12 (relative to the input's size), both directions, sizes 1 … 1024.
    #[test]
    fn matches_direct_dft() {
        for bits in 0..=10 {
            let n = 1usize << bits;
            let x: Vec<Complex> = (0..n)
                .map(|i| {
                    let t = i as Real;
                    Complex::new(sin(0.37 * t + 0.1) + 0.5, cos(1.3 * t * t))
                })
                .collect();
            for inverse in [false, true] {
                let mut y = x.clone();
                Fft::new(n).run(&mut y, inverse);
                let d = direct(&x, inverse);
                let scale = n as Real;
                for (a, b) in y.iter().zip(&d) {
                    assert!(
                        crate::math::sqrt((a - b).norm_sqr()) <= 1e-12 * scale,
                        "n {n}: {a} vs {b}"
                    );
                }
            }
        }
    }
}
