//! A small radix-2 FFT for the channel front end (C2 map, C5 periodogram).
//!
//! Why our own: the core is `no_std` and its results must be bit-identical natively and in wasm.
//! `rustfft` needs `std` and picks AVX/SSE kernels at run time (different rounding per CPU);
//! this one is plain iterative Cooley–Tukey on `f64` with twiddles from
//! [`crate::math`]'s `sin`/`cos` (the `libm` crate on every platform; the platform's own
//! differ in the last bits), no FMA, so every platform gets the same bits. Sizes are powers of two (the periodogram zero-pads to one).

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

#[cfg(test)]
mod tests {
    use super::*;

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
