//! The kernels `S_a(d) = Σ |P|² (f_n−f_c)^a e^{−j2π(f_n−f_c)d}` (closed form on a flat band) and
//! the output `σ̂_τ`: the delay diagonal of the inverse joint Fisher matrix of C1
//! ([`fisher_matrix`]), C4 at the fitted SNR where that matrix is singular.

use alloc::vec;
use alloc::vec::Vec;

use super::linalg;
use crate::channel::band::cis;
use crate::channel::Estimator;
use crate::math::{sincos, sqrt, Complex, Real, PI};

impl Estimator {
    /// `S_0(d) = Σ |P|² e^{−j2π(f_n−f_c)d}` ([`Estimator::kernels`]).
    pub(super) fn gram(&self, d: Real) -> Complex {
        self.kernels(d).0
    }

    /// `S_a(d) = Σ |P|² (f_n−f_c)^a e^{−j2π(f_n−f_c)d}` for `a` = 0, 1, 2. For a flat band on
    /// centred bins in closed form, `O(1)`: with `θ = πΔf·d` and the Dirichlet kernel
    /// `D(θ) = sin(Nθ)/sin θ`, `S_0 = D`, `S_1 = j(Δf/2)·D'`, `S_2 = −(Δf²/4)·D''`,
    /// `D' = (N cos Nθ sin θ − sin Nθ cos θ)/sin²θ`, `D'' = (1 − N²)D − 2 cot θ·D'`; the sums
    /// where that cancels (`|Nθ| < 0.1` or `|sin θ| < 10⁻²`; tested against the sums).
    pub(super) fn kernels(&self, d: Real) -> (Complex, Complex, Complex) {
        if d == 0.0 {
            return self.kernels_at_zero;
        }
        let n = self.band.len() as Real;
        let th = PI * self.df * d;
        let (st, ct) = sincos(th);
        if self.flat && (n * th).abs() >= 0.1 && st.abs() >= 1e-2 {
            let (sn, cn) = sincos(n * th);
            let dk = sn / st;
            let d1 = (n * cn * st - sn * ct) / (st * st);
            let d2 = (1.0 - n * n) * dk - 2.0 * (ct / st) * d1;
            let df = self.df;
            return (
                Complex::new(dk, 0.0),
                Complex::new(0.0, 0.5 * df * d1),
                Complex::new(-0.25 * df * df * d2, 0.0),
            );
        }
        (self.kernel(d, 0), self.kernel(d, 1), self.kernel(d, 2))
    }

    /// `S_a(d) = Σ |P|² (f_n−f_c)^a e^{−j2π(f_n−f_c)d}` (`a` = 0, 1, 2).
    pub(super) fn kernel(&self, d: Real, a: u32) -> Complex {
        let mut ph = cis(-2.0 * PI * self.fc[0] * d);
        let step = cis(-2.0 * PI * self.df * d);
        let mut acc = Complex::new(0.0, 0.0);
        for (w, f) in self.w.iter().zip(&self.fc) {
            let m = match a {
                0 => *w,
                1 => w * f,
                _ => w * f * f,
            };
            acc += ph * m;
            ph *= step;
        }
        acc
    }

    /// `σ_τ` per path from the inverse of the joint Fisher matrix of C1 (parameters `τ_i`,
    /// `Re α_i`, `Im α_i`; only its delay diagonal, from the Schur complement of the
    /// amplitudes); C4 at the fitted SNR when it is singular.
    pub(super) fn fisher_sigmas(&self, paths: &[(Real, Complex)], sigma2: Real) -> Vec<Real> {
        let fim = fisher_with(paths, sigma2, |d| self.kernels(d));
        let k = paths.len();
        let delays: Vec<usize> = (0..k).map(|i| 3 * i).collect();
        let c4 = |p: &(Real, Complex)| {
            self.band
                .delay_bound_s(self.energy * p.1.norm_sqr() / sigma2)
        };
        match linalg::inverse_diagonal_spd(&fim, 3 * k, &delays) {
            Some(var) => var
                .iter()
                .zip(paths)
                .map(|(&v, p)| {
                    if v > 0.0 && v.is_finite() {
                        sqrt(v)
                    } else {
                        c4(p)
                    }
                })
                .collect(),
            None => paths.iter().map(c4).collect(),
        }
    }
}

/// The joint Fisher matrix of C1 (row-major `3K × 3K`, parameter order `τ_i, Re α_i, Im α_i`)
/// for paths `(τ_i, α_i)` on bins `fc` (any origin; the τ block does not depend on it) with
/// weights `w = |P|²` and spacing `df`, noise variance `sigma2`: `(2/σ²)·Re(DᴴD)`.
pub fn fisher_matrix(
    fc: &[Real],
    w: &[Real],
    df: Real,
    paths: &[(Real, Complex)],
    sigma2: Real,
) -> Vec<Real> {
    let tp = 2.0 * PI;
    fisher_with(paths, sigma2, |d| {
        let mut ph = cis(-tp * fc[0] * d);
        let step = cis(-tp * df * d);
        let (mut s0, mut s1, mut s2) = (
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
        );
        for (wn, f) in w.iter().zip(fc) {
            s0 += ph * *wn;
            s1 += ph * (wn * f);
            s2 += ph * (wn * f * f);
            ph *= step;
        }
        (s0, s1, s2)
    })
}

/// The Fisher matrix of [`fisher_matrix`] from the kernels `S_a(τ_l − τ_i)`, `a` = 0, 1, 2.
fn fisher_with(
    paths: &[(Real, Complex)],
    sigma2: Real,
    kernels: impl Fn(Real) -> (Complex, Complex, Complex),
) -> Vec<Real> {
    let k = paths.len();
    let m = 3 * k;
    let mut out = vec![0.0; m * m];
    let j = Complex::new(0.0, 1.0);
    let tp = 2.0 * PI;
    for i in 0..k {
        for l in 0..k {
            let d = paths[l].0 - paths[i].0;
            let (s0, s1, s2) = kernels(d);
            let (ai, al) = (paths[i].1, paths[l].1);
            // columns: d_τ = −j2πα f e, e, j e
            let dt_i = Complex::new(0.0, -tp) * ai; // times f
            let dt_l = Complex::new(0.0, -tp) * al;
            let blocks = [
                [
                    dt_i.conj() * dt_l * s2,
                    dt_i.conj() * s1,
                    dt_i.conj() * j * s1,
                ],
                [dt_l * s1, s0, j * s0],
                [(-j) * dt_l * s1, (-j) * s0, s0],
            ];
            for (r, row) in blocks.iter().enumerate() {
                for (c, v) in row.iter().enumerate() {
                    out[(3 * i + r) * m + 3 * l + c] = 2.0 / sigma2 * v.re;
                }
            }
        }
    }
    out
}
