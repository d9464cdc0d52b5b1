//! The snapshot estimator (C5): greedy ML with cyclic (SAGE) refinement, a CFAR stop and
//! per-path delay standard deviations from the joint Fisher matrix.
//!
//! Per snapshot, on the residual `r = H − Ĥ`:
//! 1. the periodogram `|c(τ)|² = |Σ_n P*[n] r[n] e^{j2πf_nτ}|²` on the grid `τ_k = k/(LΔf)`,
//!    `L` the next power of two ≥ `oversample·N`, by one zero-padded FFT (our radix-2
//!    [`fft`](crate::channel) module: deterministic, `no_std`, bit-identical native and wasm);
//! 2. CFAR: stop when `max_k |c_k|²/(σ̂²Σ|P|²) < γ = ln(G/P_fa)`, `G` the grid cells in the
//!    window. Under noise alone each normalised cell is Exp(1), and the grid maximum exceeds γ
//!    with probability ≈ `G_eff·e^{−γ}`, `G_eff ≈ N√(πγ/3)` (Rice's up-crossing rate for the
//!    flat band) — with the default 4× oversampling `G = L ≈ 4N` this is ≈ 0.8–0.9·`P_fa`
//!    (C8 check 2); larger oversampling makes the test conservative;
//! 3. else Newton on `J(τ) = |c(τ)|²` from the grid maximum (analytic `J'`, `J''`, the
//!    phasors `e^{j2πf_nτ}` by recursion over `n`), then SAGE sweeps (each path re-fitted by
//!    Newton against the residual of the others), paths closer than `MERGE_FRACTION/B` merged
//!    (the weaker dropped), and a joint least-squares fit of all amplitudes (`K×K` Hermitian
//!    normal equations).
//!
//! `σ̂²`: the caller's `noise_var` if given; else the median over the periodogram grid of the
//! current residual, `median_k |c_k|²/(Σ|P|²·ln 2)` (each cell is `σ²Σ|P|²·Exp(1)` under noise;
//! the median of Exp(1) is ln 2; paths occupy few cells, so the median ignores them — tested
//! unbiased on noise to its standard error). Seeds (C6 predictions) are refined first and kept
//! only if they pass the same CFAR test at their refined delay. Output σ̂_τ: from the inverse of
//! the joint Fisher matrix of C1 for all fitted paths (3 real parameters each), falling back to
//! C4 at the fitted SNR if that matrix is singular.

// `!(x > 0.0)` is meant: a NaN must fail these checks as well.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use alloc::vec;
use alloc::vec::Vec;

use crate::channel::band::{cis, median};
use crate::channel::fft::Fft;
use crate::channel::{Band, DelayEstimate};
use crate::error::{limits, Error, Result};
use crate::math::{ln, round, sqrt, Complex, Real, PI};

mod linalg;

/// Paths closer than this fraction of `1/B` are merged (their joint fit is ill-conditioned).
pub const MERGE_FRACTION: Real = 0.25;
/// Most SAGE sweeps over all paths after each new path (they stop earlier once no delay moves
/// by more than `SAGE_TOL/B`).
const SAGE_SWEEPS: usize = 30;
/// Convergence of the SAGE sweeps, in units of `1/B`.
const SAGE_TOL: Real = 1e-4;
/// Newton iterations per refinement.
const NEWTON_ITERS: usize = 8;

/// Settings of the snapshot estimator (C5 **[choice]**).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimatorConfig {
    /// Largest number of paths per snapshot `M_max` (1 … [`limits::MAX_PATHS`]).
    pub max_paths: usize,
    /// Design false-alarm probability per snapshot `P_fa` of the CFAR stop, in (0, 1).
    pub p_fa: Real,
    /// Delay-grid oversampling of the periodogram (4 … 64).
    pub oversample: usize,
    /// Search window `[start, end]` of absolute delays, s (`None`: the whole unambiguous span
    /// `[0, 1/Δf)`); at most `1/Δf` wide.
    pub window_s: Option<(Real, Real)>,
}

impl Default for EstimatorConfig {
    /// [S]'s settings: 12 paths, `P_fa = 10⁻³` per snapshot, 4× oversampling, whole span.
    fn default() -> Self {
        EstimatorConfig {
            max_paths: 12,
            p_fa: 1e-3,
            oversample: 4,
            window_s: None,
        }
    }
}

impl EstimatorConfig {
    /// Checks the settings: `p_fa` in (0, 1), `oversample` 4 … 64, `max_paths` 1 …
    /// [`limits::MAX_PATHS`] (the window is checked against the band by [`Estimator::new`]).
    pub fn validate(&self) -> Result<()> {
        let cfg = self;
        if !(cfg.p_fa > 0.0 && cfg.p_fa < 1.0) {
            return Err(Error::OutOfRange {
                field: "p_fa".into(),
                value: cfg.p_fa,
                allowed: "0 < p_fa < 1",
            });
        }
        if !(4..=64).contains(&cfg.oversample) {
            return Err(Error::SizeLimit {
                field: "oversample",
                value: cfg.oversample,
                min: 4,
                max: 64,
            });
        }
        if !(1..=limits::MAX_PATHS).contains(&cfg.max_paths) {
            return Err(Error::SizeLimit {
                field: "max_paths",
                value: cfg.max_paths,
                min: 1,
                max: limits::MAX_PATHS,
            });
        }
        Ok(())
    }
}

/// One estimated path (C5 output).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathEstimate {
    /// `τ̂`, s (inside the search window).
    pub delay_s: Real,
    /// `α̂`, √W.
    pub alpha: Complex,
    /// `σ̂_τ`, s (joint Fisher matrix of all fitted paths; C4 at the fitted SNR as fallback).
    pub sigma_s: Real,
    /// Fitted integrated SNR `Σ|P|²·|α̂|²/σ̂²` (C3: `N|α̂|²/σ̂²` for `P = 1`), linear.
    pub snr: Real,
}

impl PathEstimate {
    /// The entry gating reads.
    pub fn delay_estimate(&self) -> DelayEstimate {
        DelayEstimate {
            delay_s: self.delay_s,
            amplitude: sqrt(self.alpha.norm_sqr()),
            sigma_s: Some(self.sigma_s),
        }
    }
}

/// One snapshot's result.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotEstimate {
    /// The paths, ascending in delay.
    pub paths: Vec<PathEstimate>,
    /// The noise variance used, W (given, or estimated from the final residual).
    pub noise_var: Real,
}

/// The estimator of one band (plans, scratch buffers).
#[derive(Debug, Clone)]
pub struct Estimator {
    band: Band,
    cfg: EstimatorConfig,
    fft: Fft,
    /// `f_n − f_c` (centred for conditioning), Hz.
    fc: Vec<Real>,
    /// `|P[n]|²`.
    w: Vec<Real>,
    energy: Real,
    df: Real,
    span: Real,
    win_start: Real,
    win_end: Real,
    /// Grid cells in the window (indices into the FFT output) and their delays in the window.
    cells: Vec<(usize, Real)>,
    gamma: Real,
    scratch: Vec<Complex>,
    resid: Vec<Complex>,
}

impl Estimator {
    /// An estimator for `band` with `cfg` (validated: `p_fa` in (0, 1), `oversample` 4 … 64,
    /// `max_paths` 1 … [`limits::MAX_PATHS`], a finite window `start < end ≤ start + 1/Δf`).
    pub fn new(band: Band, cfg: EstimatorConfig) -> Result<Estimator> {
        cfg.validate()?;
        let n = band.len();
        let l = (cfg.oversample * n).next_power_of_two();
        if l > limits::MAX_PERIODOGRAM {
            return Err(Error::SizeLimit {
                field: "oversample",
                value: cfg.oversample,
                min: 4,
                max: (limits::MAX_PERIODOGRAM / n).max(4),
            });
        }
        let df = band.spacing_hz();
        let span = 1.0 / df;
        let (ws, we) = match cfg.window_s {
            None => (0.0, span),
            Some((a, b)) => {
                if !(a.is_finite() && b.is_finite()) {
                    return Err(Error::NonFinite {
                        field: "window_s".into(),
                    });
                }
                if !(b > a && b - a <= span * (1.0 + 1e-12)) {
                    return Err(Error::OutOfRange {
                        field: "window_s".into(),
                        value: b - a,
                        allowed: "end > start and end − start ≤ 1/Δf (the unambiguous span)",
                    });
                }
                (a, b)
            }
        };
        let cell = span / l as Real;
        let mut cells = Vec::new();
        for k in 0..l {
            let t = fold(k as Real * cell, ws, span);
            if cfg.window_s.is_none() || t <= we {
                cells.push((k, t));
            }
        }
        if cells.is_empty() {
            return Err(Error::OutOfRange {
                field: "window_s".into(),
                value: we - ws,
                allowed: "wide enough to hold one periodogram cell",
            });
        }
        let gamma = ln(cells.len() as Real / cfg.p_fa);
        let fcen = 0.5 * (band.freq_hz[0] + band.freq_hz[n - 1]);
        let fc = band.freq_hz.iter().map(|f| f - fcen).collect();
        let w = band.response.iter().map(|p| p.norm_sqr()).collect();
        let energy = band.response_energy();
        Ok(Estimator {
            fft: Fft::new(l),
            fc,
            w,
            energy,
            df,
            span,
            win_start: ws,
            win_end: we,
            cells,
            gamma,
            scratch: vec![Complex::new(0.0, 0.0); l],
            resid: vec![Complex::new(0.0, 0.0); n],
            band,
            cfg,
        })
    }

    /// The band.
    pub fn band(&self) -> &Band {
        &self.band
    }

    /// The configuration.
    pub fn config(&self) -> &EstimatorConfig {
        &self.cfg
    }

    /// The CFAR threshold `γ = ln(G/P_fa)` on the normalised periodogram.
    pub fn threshold(&self) -> Real {
        self.gamma
    }

    /// `G`, the periodogram cells in the search window.
    pub fn grid_cells(&self) -> usize {
        self.cells.len()
    }

    /// Estimates the paths of one response `h` (`None` noise: estimated from the data), with
    /// `seeds` (predicted delays, s) refined first. Errors: `h` of the wrong length
    /// ([`Error::LengthMismatch`]) or non-finite, a `noise_var` not finite and > 0, a
    /// non-finite seed. An all-zero `h` gives zero paths.
    pub fn estimate(
        &mut self,
        h: &[Complex],
        noise_var: Option<Real>,
        seeds: &[Real],
    ) -> Result<SnapshotEstimate> {
        let n = self.band.len();
        if h.len() != n {
            return Err(Error::LengthMismatch {
                field: "response",
                expected: n,
                found: h.len(),
            });
        }
        if h.iter().any(|v| !(v.re.is_finite() && v.im.is_finite())) {
            return Err(Error::NonFinite {
                field: "response".into(),
            });
        }
        if let Some(v) = noise_var {
            if !(v > 0.0 && v.is_finite()) {
                return Err(Error::NotPositive {
                    field: "noise_var".into(),
                    value: v,
                });
            }
        }
        if seeds.iter().any(|s| !s.is_finite()) {
            return Err(Error::NonFinite {
                field: "seeds".into(),
            });
        }
        let mut paths: Vec<(Real, Complex)> = Vec::new();
        self.resid.clear();
        self.resid.extend_from_slice(h);
        let mut sigma2 = match noise_var {
            Some(v) => v,
            None => {
                self.periodogram();
                self.median_noise()
            }
        };
        // Seeds first (C6): Newton from each prediction, kept if it passes the CFAR test.
        for &seed in seeds {
            if paths.len() >= self.cfg.max_paths || !(sigma2 > 0.0) {
                break;
            }
            let tau = self.newton(fold(seed, self.win_start, self.span));
            let c = self.corr(&self.resid, tau);
            if c.norm_sqr() / (sigma2 * self.energy) >= self.gamma
                && paths.iter().all(|p| (p.0 - tau).abs() >= self.merge_sep())
            {
                let a = c / self.energy;
                self.sub_path(tau, a, -1.0);
                paths.push((tau, a));
                self.refine(h, &mut paths);
            }
        }
        loop {
            self.periodogram();
            if noise_var.is_none() {
                sigma2 = self.median_noise();
            }
            if paths.len() >= self.cfg.max_paths || !(sigma2 > 0.0) {
                break;
            }
            let (mut best, mut tk) = (0.0, 0.0);
            for &(k, t) in &self.cells {
                let v = self.scratch[k].norm_sqr();
                if v > best {
                    best = v;
                    tk = t;
                }
            }
            if !(best / (sigma2 * self.energy) >= self.gamma) {
                break;
            }
            let tau = self.newton(tk);
            if paths.iter().any(|p| (p.0 - tau).abs() < self.merge_sep()) {
                break; // the strongest residual peak is an existing path's misfit
            }
            let a = self.corr(&self.resid, tau) / self.energy;
            self.sub_path(tau, a, -1.0);
            paths.push((tau, a));
            self.refine(h, &mut paths);
        }
        if !(sigma2 > 0.0) {
            sigma2 = 0.0;
        }
        paths.sort_by(|a, b| a.0.total_cmp(&b.0));
        let sig = if sigma2 > 0.0 {
            self.fisher_sigmas(&paths, sigma2)
        } else {
            vec![0.0; paths.len()]
        };
        let out = paths
            .iter()
            .zip(&sig)
            .map(|(&(tau, a), &s)| {
                let snr = if sigma2 > 0.0 {
                    self.energy * a.norm_sqr() / sigma2
                } else {
                    0.0
                };
                PathEstimate {
                    delay_s: tau,
                    alpha: a,
                    sigma_s: s,
                    snr,
                }
            })
            .collect();
        Ok(SnapshotEstimate {
            paths: out,
            noise_var: sigma2,
        })
    }

    fn merge_sep(&self) -> Real {
        MERGE_FRACTION / (self.df * self.band.len() as Real)
    }

    /// `scratch` ← the zero-padded FFT of `P*·r` (cell `k`: `c(k/(LΔf))` up to a phase).
    fn periodogram(&mut self) {
        for v in self.scratch.iter_mut() {
            *v = Complex::new(0.0, 0.0);
        }
        for ((s, r), p) in self
            .scratch
            .iter_mut()
            .zip(&self.resid)
            .zip(&self.band.response)
        {
            *s = p.conj() * r;
        }
        self.fft.run(&mut self.scratch, true);
    }

    /// `median_k |c_k|² / (Σ|P|² ln 2)` over the window's cells.
    fn median_noise(&self) -> Real {
        let mut v: Vec<Real> = self
            .cells
            .iter()
            .map(|&(k, _)| self.scratch[k].norm_sqr())
            .collect();
        median(&mut v) / (self.energy * ln(2.0))
    }

    /// `c(τ) = Σ P*[n] x[n] e^{j2π(f_n−f_c)τ}`.
    fn corr(&self, x: &[Complex], tau: Real) -> Complex {
        let mut ph = cis(2.0 * PI * self.fc[0] * tau);
        let step = cis(2.0 * PI * self.df * tau);
        let mut acc = Complex::new(0.0, 0.0);
        for (v, p) in x.iter().zip(&self.band.response) {
            acc += p.conj() * v * ph;
            ph *= step;
        }
        acc
    }

    /// `resid += sign·α·P·e^{−j2π(f_n−f_c)τ}`.
    fn sub_path(&mut self, tau: Real, a: Complex, sign: Real) {
        let mut ph = cis(-2.0 * PI * self.fc[0] * tau);
        let step = cis(-2.0 * PI * self.df * tau);
        let a = a * sign;
        for (r, p) in self.resid.iter_mut().zip(&self.band.response) {
            *r += p * ph * a;
            ph *= step;
        }
    }

    /// Newton on `J(τ) = |c(τ)|²` of the residual from `tau`, steps clipped to a quarter of
    /// `1/B`; the result folded into the window.
    fn newton(&self, mut tau: Real) -> Real {
        let n = self.band.len();
        let max_step = 0.25 / (self.df * n as Real);
        for _ in 0..NEWTON_ITERS {
            let mut ph = cis(2.0 * PI * self.fc[0] * tau);
            let step = cis(2.0 * PI * self.df * tau);
            let (mut c0, mut c1, mut c2) = (
                Complex::new(0.0, 0.0),
                Complex::new(0.0, 0.0),
                Complex::new(0.0, 0.0),
            );
            for i in 0..n {
                let x = self.band.response[i].conj() * self.resid[i] * ph;
                let f = 2.0 * PI * self.fc[i];
                c0 += x;
                c1 += x * Complex::new(0.0, f);
                c2 += x * (-f * f);
                ph *= step;
            }
            let d1 = 2.0 * (c0.conj() * c1).re;
            let d2 = 2.0 * (c1.norm_sqr() + (c0.conj() * c2).re);
            let mut dt = if d2 < 0.0 { -d1 / d2 } else { 0.0 };
            if d2 >= 0.0 || !dt.is_finite() {
                // not concave here: a small gradient step towards the rise
                dt = if d1 > 0.0 {
                    max_step * 0.25
                } else if d1 < 0.0 {
                    -max_step * 0.25
                } else {
                    0.0
                };
            }
            let dt = dt.clamp(-max_step, max_step);
            tau += dt;
            if dt.abs() < 1e-7 * max_step {
                break;
            }
        }
        fold(tau, self.win_start, self.span).min(self.win_end)
    }

    /// SAGE sweeps over all paths, merge of close paths, joint LS of the amplitudes; leaves
    /// `resid = h − Ĥ`.
    fn refine(&mut self, h: &[Complex], paths: &mut Vec<(Real, Complex)>) {
        let tol = SAGE_TOL / (self.df * self.band.len() as Real);
        for sweep in 0..SAGE_SWEEPS {
            let mut moved: Real = 0.0;
            for path in paths.iter_mut() {
                let (t, a) = *path;
                self.sub_path(t, a, 1.0);
                let t2 = self.newton(t);
                let a2 = self.corr(&self.resid, t2) / self.energy;
                self.sub_path(t2, a2, -1.0);
                *path = (t2, a2);
                moved = moved.max((t2 - t).abs());
            }
            if paths.len() < 2 || (sweep > 0 && moved < tol) {
                break;
            }
        }
        // merge: keep the stronger of paths closer than MERGE_FRACTION/B
        paths.sort_by(|a, b| a.0.total_cmp(&b.0));
        let sep = self.merge_sep();
        let mut i = 1;
        while i < paths.len() {
            if paths[i].0 - paths[i - 1].0 < sep {
                if paths[i].1.norm_sqr() > paths[i - 1].1.norm_sqr() {
                    paths.remove(i - 1);
                } else {
                    paths.remove(i);
                }
            } else {
                i += 1;
            }
        }
        self.joint_ls(h, paths);
    }

    /// Joint least squares of all amplitudes at fixed delays; `resid` ← `h − Ĥ`.
    fn joint_ls(&mut self, h: &[Complex], paths: &mut [(Real, Complex)]) {
        let k = paths.len();
        if k == 0 {
            self.resid.clear();
            self.resid.extend_from_slice(h);
            return;
        }
        let mut g = vec![Complex::new(0.0, 0.0); k * k];
        let mut b = vec![Complex::new(0.0, 0.0); k];
        for i in 0..k {
            b[i] = self.corr(h, paths[i].0);
            g[i * k + i] = Complex::new(self.energy, 0.0);
            for j in i + 1..k {
                let s = self.kernel(paths[j].0 - paths[i].0, 0);
                g[i * k + j] = s;
                g[j * k + i] = s.conj();
            }
        }
        if let Some(a) = linalg::solve_complex(&mut g, &mut b, k) {
            for (p, v) in paths.iter_mut().zip(a) {
                p.1 = v;
            }
        }
        self.resid.clear();
        self.resid.extend_from_slice(h);
        for &(t, a) in paths.iter() {
            self.sub_path(t, a, -1.0);
        }
    }

    /// `S_a(d) = Σ |P|² (f_n−f_c)^a e^{−j2π(f_n−f_c)d}` (`a` = 0, 1, 2).
    fn kernel(&self, d: Real, a: u32) -> Complex {
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
    /// `Re α_i`, `Im α_i`); C4 at the fitted SNR when it is singular.
    fn fisher_sigmas(&self, paths: &[(Real, Complex)], sigma2: Real) -> Vec<Real> {
        let fim = fisher_matrix(&self.fc, &self.w, self.df, paths, sigma2);
        let k = paths.len();
        match linalg::inverse_sym(fim, 3 * k) {
            Some(inv) => (0..k)
                .map(|i| {
                    let v = inv[(3 * i) * 3 * k + 3 * i];
                    if v > 0.0 && v.is_finite() {
                        sqrt(v)
                    } else {
                        self.band
                            .delay_bound_s(self.energy * paths[i].1.norm_sqr() / sigma2)
                    }
                })
                .collect(),
            None => paths
                .iter()
                .map(|p| {
                    self.band
                        .delay_bound_s(self.energy * p.1.norm_sqr() / sigma2)
                })
                .collect(),
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
    let k = paths.len();
    let m = 3 * k;
    let mut out = vec![0.0; m * m];
    let j = Complex::new(0.0, 1.0);
    let tp = 2.0 * PI;
    for i in 0..k {
        for l in 0..k {
            let d = paths[l].0 - paths[i].0;
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

/// `τ` folded into `[start, start + span)`.
fn fold(tau: Real, start: Real, span: Real) -> Real {
    let q = (tau - start) / span;
    let mut fl = round(q);
    if fl > q {
        fl -= 1.0;
    }
    let t = tau - fl * span;
    if t >= start + span {
        t - span
    } else {
        t
    }
}

#[cfg(test)]
mod tests;
