//! A small radix-2 FFT for the channel front end (C2 map, C5 periodogram).
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

    /// In-place radix-2 decimation in frequency of size `M`, output in bit-reversed order.
    fn dif(&self, x: &mut [Complex]) {
        let mut span = self.m;
        let mut tw = 0;
        while span >= 2 {
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
