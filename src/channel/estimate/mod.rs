//! The snapshot estimator (C5): greedy ML with cyclic refinement, a CFAR stop and per-path
//! delay standard deviations from the joint Fisher matrix. Every loop has a stated bound
//! ([`limits::MAX_PATHS`], [`limits::ESTIMATOR_SWEEPS`], [`limits::NEWTON_ITERATIONS`]); what a
//! snapshot did against them is in [`SnapshotEstimate::work`].
//!
//! Per snapshot, on the residual `r = H − Ĥ`:
//! 1. the periodogram `|c(τ)|² = |Σ_n P*[n] r[n] e^{j2πf_nτ}|²` on the grid `τ_k = k/(LΔf)`,
//!    `L` the next power of two ≥ `oversample·N`, by one zero-padded FFT (our `PaddedFft`:
//!    deterministic, `no_std`, bit-identical native and wasm; its output stays in slot order);
//! 2. CFAR: stop when `max_k |c_k|²/(σ̂²Σ|P|²) < γ = ln(G/P_fa)`, `G` the grid cells in the
//!    window. Under noise alone each normalised cell is Exp(1), and the grid maximum exceeds γ
//!    with probability ≈ `G_eff·e^{−γ}`, `G_eff ≈ N√(πγ/3)` (Rice's up-crossing rate for the
//!    flat band) — with the default 4× oversampling `G = L ≈ 4N` this is ≈ 0.8–0.9·`P_fa`
//!    (C8 check 2); larger oversampling makes the test conservative;
//! 3. else the new delay: a parabola through the peak cell and its neighbours, then Newton on
//!    `J(τ) = |c(τ)|²` (analytic `J'`, `J''`, the phasors `e^{j2πf_nτ}` by recursion over
//!    `n`); then cyclic refinement (SAGE with one Newton step per path and sweep, as NOMP:
//!    each path re-fitted against the residual of the others) until no delay moves by more
//!    than `SAGE_TOL/B`; paths closer than `MERGE_FRACTION/B` merged (the weaker dropped), and
//!    a joint least-squares fit of all amplitudes (`K×K` Hermitian normal equations) after a
//!    merge and at the end.
//!
//! Each pass of the greedy loop adds a path, or finds the strongest peak left to be a fitted
//! path's misfit (Newton slides onto it, or it merges into it; its cell is left out from then
//! on), or stops: at the CFAR test, at `M_max` paths ([`Stop::PathBudget`] when a peak above γ
//! is left), or after `M_max` misfits ([`Stop::Merged`]) — so it runs at most `2·M_max + 1`
//! passes whatever the data (a merge that kept the count used to re-add the same peak
//! forever).
//!
//! `σ̂²`: the caller's `noise_var` if given; else the median over the periodogram cells at the
//! natural spacing `1/(MΔf)` (`M` the next power of two ≥ N: nearly independent cells) of the
//! current residual, `median |c_k|²/(Σ|P|²·ln 2)` (each cell is `σ²Σ|P|²·Exp(1)` under noise;
//! the median of Exp(1) is ln 2; paths occupy few cells, so the median ignores them — tested
//! unbiased on noise to its standard error). Either is floored at the response's mean bin
//! power `dynamic_range_db` below (default 120 dB): a noise-free (ray-traced) or rounding-level
//! response gets a finite σ̂ and finite paths, never an endless fit. Seeds (C6 predictions) are
//! refined first and kept only if they pass the same CFAR test at their refined delay. Output
//! σ̂_τ: from the inverse of the joint Fisher matrix of C1 for all fitted paths (3 real
//! parameters each), falling back to C4 at the fitted SNR if that matrix is singular.

// `!(x > 0.0)` is meant: a NaN must fail these checks as well.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use alloc::vec;
use alloc::vec::Vec;

use crate::channel::band::{cis, median};
use crate::channel::fft::PaddedFft;
use crate::channel::{Band, DelayEstimate};
use crate::error::{limits, Cancel, Error, Result};
use crate::math::{db_to_linear, ln, round, sincos, sqrt, Complex, Real, PI};

mod kernels;
mod linalg;
pub(crate) use linalg::{inverse_spd_scaled, solve_complex};

/// Paths closer than this fraction of `1/B` are merged (their joint fit is ill-conditioned).
pub const MERGE_FRACTION: Real = 0.25;
/// Convergence of the refinement sweeps, in units of `1/B`.
const SAGE_TOL: Real = 1e-3;
/// Refinement stops once a sweep raises the log-likelihood `‖r‖²/σ²` by less than this.
const LL_TOL: Real = 0.05;
/// Most paths refined jointly (more: cyclic sweeps on).
const MAX_JOINT: usize = 3;
/// Cyclic sweeps before the paths still moving are refined jointly.
const CYCLIC_SWEEPS: usize = 1;
/// Convergence of a new path's Newton iterations, in units of `1/B`.
const NEWTON_TOL: Real = 1e-4;

/// Settings of the snapshot estimator (C5 **[choice]**).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimatorConfig {
    /// Largest number of paths per snapshot `M_max` (1 … [`limits::MAX_PATHS`]).
    pub max_paths: usize,
    /// Design false-alarm probability per snapshot `P_fa` of the CFAR stop, in (0, 1).
    pub p_fa: Real,
    /// Delay-grid oversampling of the periodogram (4 … 64).
    pub oversample: usize,
    /// Search window `[start, end]` of absolute delays, s (`None`: the band's whole
    /// unambiguous span `[o, o + 1/Δf)`, `o` its [`Band::delay_origin_s`]: tap 0 of a CIR, 0
    /// for a CFR); at most `1/Δf` wide.
    pub window_s: Option<(Real, Real)>,
    /// The noise variance is never taken below the response's mean bin power this far down,
    /// dB ([`limits::ESTIMATOR_DYNAMIC_RANGE_DB`]; default 120): the rounding floor of a
    /// noise-free recording (complex64 samples hold about 144 dB).
    pub dynamic_range_db: Real,
}

impl Default for EstimatorConfig {
    /// [S]'s settings: 12 paths, `P_fa = 10⁻³` per snapshot, 4× oversampling, whole span; a
    /// 120 dB floor.
    fn default() -> Self {
        EstimatorConfig {
            max_paths: 12,
            p_fa: 1e-3,
            oversample: 4,
            window_s: None,
            dynamic_range_db: 120.0,
        }
    }
}

impl EstimatorConfig {
    /// Checks the settings: `p_fa` in (0, 1), `oversample` 4 … 64, `max_paths` 1 …
    /// [`limits::MAX_PATHS`], `dynamic_range_db` in [`limits::ESTIMATOR_DYNAMIC_RANGE_DB`]
    /// (the window is checked against the band by [`Estimator::new`]).
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
        limits::ESTIMATOR_DYNAMIC_RANGE_DB.check("dynamic_range_db", cfg.dynamic_range_db)?;
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

/// Why a snapshot's greedy loop stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Stop {
    /// Nothing left above the CFAR threshold (the normal end).
    #[default]
    Threshold,
    /// `M_max` paths and a residual peak still above the threshold: a bound was reached.
    PathBudget,
    /// More than `M_max` of the strongest peaks were fitted paths' misfits (slid onto one, or
    /// merged into one).
    Merged,
}

impl Stop {
    /// Its name: `threshold`, `path_budget`, `merged` (EST.json counts the snapshots that
    /// stopped at a bound in `front_end.bounds`).
    pub fn name(self) -> &'static str {
        match self {
            Stop::Threshold => "threshold",
            Stop::PathBudget => "path_budget",
            Stop::Merged => "merged",
        }
    }
}

/// What one snapshot's estimation did, against the stated bounds of its loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EstimateWork {
    /// Greedy passes (periodograms), at most `2·M_max + 1`.
    pub passes: usize,
    /// The most refinement sweeps after one new path (at most [`limits::ESTIMATOR_SWEEPS`]).
    pub sweeps: usize,
    /// The most Newton iterations of one new path (at most [`limits::NEWTON_ITERATIONS`]).
    pub newton: usize,
    /// Whether some refinement ended at its sweep bound without converging.
    pub sweeps_capped: bool,
    /// Why the greedy loop stopped.
    pub stop: Stop,
}

impl EstimateWork {
    /// Whether a bound ended this snapshot's work (the path budget with a peak left, or the
    /// sweep bound): the snapshot returns what it has and is counted.
    pub fn bounded(&self) -> bool {
        self.stop == Stop::PathBudget || self.sweeps_capped
    }
}

/// One snapshot's result.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotEstimate {
    /// The paths, ascending in delay.
    pub paths: Vec<PathEstimate>,
    /// The noise variance used, W (given, or estimated from the final residual; floored).
    pub noise_var: Real,
    /// What the estimation did against its bounds.
    pub work: EstimateWork,
}

/// The estimator of one band (plans, scratch buffers).
#[derive(Debug, Clone)]
pub struct Estimator {
    band: Band,
    cfg: EstimatorConfig,
    fft: PaddedFft,
    /// Whether `P[n] = 1` for every bin (the products with `P` are skipped).
    flat: bool,
    /// `f_n − f_c` (centred for conditioning), Hz.
    fc: Vec<Real>,
    /// `2π·(f_n − f_c)`, rad/s (the kernels' weights).
    tw: Vec<Real>,
    /// `|P[n]|²`.
    w: Vec<Real>,
    /// `S_a(0)`, `a` = 0, 1, 2 ([`Estimator::kernels`] at a zero delay difference: every
    /// diagonal entry of the Gauss–Newton and Fisher matrices), computed once by the same sums.
    kernels_at_zero: (Complex, Complex, Complex),
    energy: Real,
    df: Real,
    span: Real,
    win_start: Real,
    win_end: Real,
    /// Grid cells in the window: (FFT output slot, delay in the window), in slot order.
    cells: Vec<(u32, Real)>,
    /// Slots of the window's cells at the natural spacing (the median's cells).
    median_slots: Vec<u32>,
    gamma: Real,
    /// Per slot: within the merge separation of a fitted path (not a new path's peak).
    masked: Vec<bool>,
    scratch: Vec<Complex>,
    resid: Vec<Complex>,
    tmp: Vec<Complex>,
    powers: Vec<Real>,
}

/// One pass over the bins at delay `τ`: the phasors `e^{j2π(f_n−f_c)τ}` by recursion.
#[derive(Clone, Copy)]
struct Phasor {
    start: Complex,
    step: Complex,
}

impl Phasor {
    fn at(fc0: Real, df: Real, tau: Real) -> Phasor {
        Phasor {
            start: cis(2.0 * PI * fc0 * tau),
            step: cis(2.0 * PI * df * tau),
        }
    }
}

/// Amplitudes by least squares at fixed delays ([`Estimator::project`]).
struct Projection {
    taus: Vec<Real>,
    alpha: Vec<Complex>,
    resid: Vec<Complex>,
    cost: Real,
    /// The basis columns, column-major (`k` columns of `n`).
    basis: Vec<Complex>,
}

/// `c(τ)` and its first two derivatives `c'`, `c''` in `τ`.
#[derive(Clone, Copy)]
struct Moments {
    c0: Complex,
    c1: Complex,
    c2: Complex,
}

impl Moments {
    /// Newton's step on `J = |c|²` (a quarter-resolution gradient step where `J` is not
    /// concave), clipped to `max_step`.
    fn newton_step(&self, max_step: Real) -> Real {
        let Moments { c0, c1, c2 } = *self;
        let d1 = 2.0 * (c0.conj() * c1).re;
        let d2 = 2.0 * (c1.norm_sqr() + (c0.conj() * c2).re);
        let mut dt = if d2 < 0.0 { -d1 / d2 } else { 0.0 };
        if d2 >= 0.0 || !dt.is_finite() {
            dt = if d1 > 0.0 {
                max_step * 0.25
            } else if d1 < 0.0 {
                -max_step * 0.25
            } else {
                0.0
            };
        }
        dt.clamp(-max_step, max_step)
    }

    /// `c(τ + dt)` by its second-order Taylor series.
    fn at(&self, dt: Real) -> Complex {
        self.c0 + self.c1 * dt + self.c2 * (0.5 * dt * dt)
    }
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
            None => (band.delay_origin_s, band.delay_origin_s + span),
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
        let fft = PaddedFft::new(n, l);
        let cell = span / l as Real;
        let mut cells = Vec::new();
        let mut median_slots = Vec::new();
        let stride = l / n.next_power_of_two().min(l);
        for (slot, &k) in fft.natural().iter().enumerate() {
            let k = k as usize;
            let t = fold(k as Real * cell, ws, span);
            if cfg.window_s.is_none() || t <= we {
                cells.push((slot as u32, t));
                if k.is_multiple_of(stride) {
                    median_slots.push(slot as u32);
                }
            }
        }
        if cells.is_empty() {
            return Err(Error::OutOfRange {
                field: "window_s".into(),
                value: we - ws,
                allowed: "wide enough to hold one periodogram cell",
            });
        }
        if median_slots.is_empty() {
            median_slots = cells.iter().map(|c| c.0).collect();
        }
        let gamma = ln(cells.len() as Real / cfg.p_fa);
        let fcen = 0.5 * (band.freq_hz[0] + band.freq_hz[n - 1]);
        let fc: Vec<Real> = band.freq_hz.iter().map(|f| f - fcen).collect();
        let tw = fc.iter().map(|f| 2.0 * PI * f).collect();
        let w = band.response.iter().map(|p| p.norm_sqr()).collect();
        let energy = band.response_energy();
        let flat = band.response.iter().all(|p| *p == Complex::new(1.0, 0.0));
        let mut est = Estimator {
            fft,
            flat,
            fc,
            tw,
            w,
            energy,
            df,
            span,
            win_start: ws,
            win_end: we,
            cells,
            powers: Vec::with_capacity(median_slots.len()),
            median_slots,
            gamma,
            masked: vec![false; l],
            scratch: vec![Complex::new(0.0, 0.0); l],
            resid: vec![Complex::new(0.0, 0.0); n],
            tmp: vec![Complex::new(0.0, 0.0); n],
            band,
            cfg,
            kernels_at_zero: Default::default(),
        };
        est.kernels_at_zero = (est.kernel(0.0, 0), est.kernel(0.0, 1), est.kernel(0.0, 2));
        Ok(est)
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
    /// `seeds` (predicted delays, s) refined first. The noise variance is floored at `h`'s mean
    /// bin power [`EstimatorConfig::dynamic_range_db`] down. Errors: `h` of the wrong length
    /// ([`Error::LengthMismatch`]) or non-finite, a `noise_var` not finite and > 0, a
    /// non-finite seed. An all-zero `h` gives zero paths.
    pub fn estimate(
        &mut self,
        h: &[Complex],
        noise_var: Option<Real>,
        seeds: &[Real],
    ) -> Result<SnapshotEstimate> {
        let power = h.iter().map(|v| v.norm_sqr()).sum::<Real>() / h.len().max(1) as Real;
        self.estimate_floored(h, noise_var, seeds, power, Cancel::NEVER)
    }

    /// [`Estimator::estimate`] with the floor measured from `reference_power` (W per bin)
    /// instead of `h`'s own: a residual after the background (C9) is floored at the full
    /// response's power, where its rounding and alignment errors come from. `cancel` is asked
    /// before every pass of the greedy loop (a pass is at most one refinement: well under a
    /// second at the largest band and path budget), so a long fit ends with
    /// [`Error::Cancelled`] (issue 37 item 1).
    pub fn estimate_floored(
        &mut self,
        h: &[Complex],
        noise_var: Option<Real>,
        seeds: &[Real],
        reference_power: Real,
        cancel: Cancel,
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
        let peak = h
            .iter()
            .map(|v| v.re.abs().max(v.im.abs()))
            .fold(0.0, Real::max);
        if peak > limits::MAX_SAMPLE_MAGNITUDE {
            return Err(Error::OutOfRange {
                field: "response".into(),
                value: peak,
                allowed: "samples of magnitude at most 1e100 (their powers must stay finite)",
            });
        }
        if let Some(v) = noise_var {
            if !(v > 0.0 && v.is_finite()) {
                return Err(Error::NotPositive {
                    field: "noise_var".into(),
                    value: v,
                });
            }
            if v > limits::MAX_SAMPLE_MAGNITUDE * limits::MAX_SAMPLE_MAGNITUDE {
                return Err(Error::OutOfRange {
                    field: "noise_var".into(),
                    value: v,
                    allowed: "at most 1e200 (the square of the largest sample magnitude)",
                });
            }
        }
        if seeds.iter().any(|s| !s.is_finite()) {
            return Err(Error::NonFinite {
                field: "seeds".into(),
            });
        }
        let floor = if reference_power.is_finite() && reference_power > 0.0 {
            reference_power * db_to_linear(-self.cfg.dynamic_range_db)
        } else {
            0.0
        };
        let mut work = EstimateWork::default();
        let mut paths: Vec<(Real, Complex)> = Vec::new();
        self.resid.clear();
        self.resid.extend_from_slice(h);
        let mut sigma2 = match noise_var {
            Some(v) => v.max(floor),
            None => {
                self.periodogram();
                work.passes += 1;
                self.median_noise().max(floor)
            }
        };
        // Seeds first (C6): Newton from each prediction (at most `max_paths` of them), kept if
        // it passes the CFAR test; then one refinement of the seeded paths together.
        for &seed in seeds.iter().take(self.cfg.max_paths) {
            if paths.len() >= self.cfg.max_paths || !(sigma2 > 0.0) {
                break;
            }
            let (tau, m, it) = self.newton(fold(seed, self.win_start, self.span));
            work.newton = work.newton.max(it);
            let c = m.c0;
            if c.norm_sqr() / (sigma2 * self.energy) >= self.gamma
                && paths.iter().all(|p| (p.0 - tau).abs() >= self.merge_sep())
            {
                let a = c / self.energy;
                self.add_path(tau, -a);
                paths.push((tau, a));
            }
        }
        if !paths.is_empty() {
            cancel.check()?;
            self.refine(h, &mut paths, 0, sigma2, &mut work);
        }
        // The greedy loop. Each pass adds a path, or finds that the strongest peak left is a
        // misfit of a fitted path (Newton slides onto it, or the refinement merges it; its
        // cell is then left out of later passes), or stops: at most `2·max_paths + 1` passes.
        let mut misfits = 0;
        let mut excluded: Vec<Real> = Vec::new();
        let mut dirty = true;
        for _ in 0..=2 * self.cfg.max_paths {
            cancel.check()?;
            if dirty {
                self.periodogram();
                work.passes += 1;
                if noise_var.is_none() {
                    sigma2 = self.median_noise().max(floor);
                }
            }
            if !(sigma2 > 0.0) {
                break;
            }
            // The strongest cell not within the merge separation of a fitted path or an
            // excluded misfit (what is left there is that path's misfit, not a new path).
            self.mask_paths(&paths, &excluded);
            let (mut best, mut slot, mut tk) = (0.0, 0u32, 0.0);
            for &(s, t) in &self.cells {
                if self.masked[s as usize] {
                    continue;
                }
                let v = self.scratch[s as usize].norm_sqr();
                if v > best {
                    best = v;
                    slot = s;
                    tk = t;
                }
            }
            if !(best / (sigma2 * self.energy) >= self.gamma) {
                break;
            }
            if paths.len() >= self.cfg.max_paths {
                work.stop = Stop::PathBudget;
                break;
            }
            let (tau, m, it) = self.newton(tk + self.parabola(slot));
            work.newton = work.newton.max(it);
            let before = paths.len();
            if paths.iter().any(|p| (p.0 - tau).abs() < self.merge_sep()) {
                // Newton slid onto a fitted path: its misfit.
                misfits += 1;
                excluded.push(tk);
                dirty = false;
            } else {
                let a = m.c0 / self.energy;
                self.add_path(tau, -a);
                paths.push((tau, a));
                self.refine(h, &mut paths, before, sigma2, &mut work);
                dirty = true;
                if paths.len() <= before {
                    misfits += 1;
                    excluded.push(tau);
                }
            }
            if misfits > self.cfg.max_paths {
                work.stop = Stop::Merged;
                break;
            }
        }
        self.joint_ls(h, &mut paths);
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
            .collect::<Vec<PathEstimate>>();
        // Every number out finite (issue 37 item 7), or a named error: the input caps above
        // keep the sums finite, so this is a guard, not a path taken.
        let finite = |c: Complex| c.re.is_finite() && c.im.is_finite();
        if !sigma2.is_finite()
            || out.iter().any(|p| {
                !(p.delay_s.is_finite()
                    && finite(p.alpha)
                    && p.sigma_s.is_finite()
                    && p.snr.is_finite())
            })
        {
            return Err(Error::NonFinite {
                field: "estimate (noise variance or a path)".into(),
            });
        }
        Ok(SnapshotEstimate {
            paths: out,
            noise_var: sigma2,
            work,
        })
    }

    fn merge_sep(&self) -> Real {
        MERGE_FRACTION / (self.df * self.band.len() as Real)
    }

    /// `scratch` ← the zero-padded FFT of `P*·r` (slot `s`: `c(k/(LΔf))` up to a phase, `k`
    /// the slot's frequency index).
    fn periodogram(&mut self) {
        if self.flat {
            self.fft.run(&self.resid, &mut self.scratch);
        } else {
            for ((t, r), p) in self
                .tmp
                .iter_mut()
                .zip(&self.resid)
                .zip(&self.band.response)
            {
                *t = p.conj() * r;
            }
            self.fft.run(&self.tmp, &mut self.scratch);
        }
    }

    /// The noise variance per bin of `h` as the estimator would estimate it before fitting a
    /// path: `median |c_k|²/(Σ|P|² ln 2)` of its periodogram (biased up where paths crowd the
    /// delay axis, as every first pass is).
    pub fn noise_of(&mut self, h: &[Complex]) -> Result<Real> {
        if h.len() != self.band.len() {
            return Err(Error::LengthMismatch {
                field: "response",
                expected: self.band.len(),
                found: h.len(),
            });
        }
        self.resid.clear();
        self.resid.extend_from_slice(h);
        self.periodogram();
        Ok(self.median_noise())
    }

    /// `masked[slot]` ← whether the slot's cell lies within the merge separation of a path or
    /// of an excluded delay.
    fn mask_paths(&mut self, paths: &[(Real, Complex)], excluded: &[Real]) {
        for m in self.masked.iter_mut() {
            *m = false;
        }
        let l = self.fft.len();
        let cell = self.span / l as Real;
        let reach = (self.merge_sep() / cell) as i64 + 1;
        for tau in paths.iter().map(|p| p.0).chain(excluded.iter().copied()) {
            let k0 = round(tau / cell) as i64;
            for k in k0 - reach..=k0 + reach {
                let t = k as Real * cell;
                if (t - tau).abs() < self.merge_sep() {
                    let slot = self.fft.slot_of(k.rem_euclid(l as i64) as usize);
                    self.masked[slot as usize] = true;
                }
            }
        }
    }

    /// The sub-cell offset (s) of the peak in `slot` ([`PaddedFft::parabola`]).
    fn parabola(&self, slot: u32) -> Real {
        self.fft.parabola(&self.scratch, slot) * self.span / self.fft.len() as Real
    }

    /// `median |c|² / (Σ|P|² ln 2)` over the window's cells at the natural spacing.
    fn median_noise(&mut self) -> Real {
        self.powers.clear();
        self.powers.extend(
            self.median_slots
                .iter()
                .map(|&s| self.scratch[s as usize].norm_sqr()),
        );
        median(&mut self.powers) / (self.energy * ln(2.0))
    }

    /// `c(τ)`, `c'(τ)`, `c''(τ)` of the residual (`c(τ) = Σ P*[n] r[n] e^{j2π(f_n−f_c)τ}`).
    fn moments(&self, tau: Real) -> Moments {
        let ph0 = Phasor::at(self.fc[0], self.df, tau);
        if self.flat {
            let (c0, c1, c2) = kernels::moments(&self.resid, &self.tw, ph0.start, ph0.step);
            return Moments { c0, c1, c2 };
        }
        let mut ph = ph0.start;
        let (mut c0, mut c1, mut c2) = (
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
        );
        let tp = 2.0 * PI;
        for i in 0..self.resid.len() {
            let r = if self.flat {
                self.resid[i]
            } else {
                self.band.response[i].conj() * self.resid[i]
            };
            let x = r * ph;
            let f = tp * self.fc[i];
            c0 += x;
            let xf = x * f;
            c1 += Complex::new(-xf.im, xf.re);
            c2 -= xf * f;
            ph *= ph0.step;
        }
        Moments { c0, c1, c2 }
    }

    /// `c(τ)` of the residual alone.
    fn correlation(&self, tau: Real) -> Complex {
        let ph0 = Phasor::at(self.fc[0], self.df, tau);
        if self.flat {
            return kernels::correlation(&self.resid, ph0.start, ph0.step);
        }
        let mut ph = ph0.start;
        let mut c0 = Complex::new(0.0, 0.0);
        for i in 0..self.resid.len() {
            let r = if self.flat {
                self.resid[i]
            } else {
                self.band.response[i].conj() * self.resid[i]
            };
            c0 += r * ph;
            ph *= ph0.step;
        }
        c0
    }

    /// `resid += a·P·e^{−j2π(f_n−f_c)τ}`.
    fn add_path(&mut self, tau: Real, a: Complex) {
        let ph0 = Phasor::at(self.fc[0], self.df, tau);
        let mut ph = ph0.start.conj() * a;
        let step = ph0.step.conj();
        if self.flat {
            kernels::add_rotating(&mut self.resid, ph, step);
        } else {
            for (r, p) in self.resid.iter_mut().zip(&self.band.response) {
                *r += p * ph;
                ph *= step;
            }
        }
    }

    /// `resid += a·P·e^{−j2π(f_n−f_c)τ}` and the moments of the new residual at `τ`, in one
    /// pass (a path added back before it is re-fitted).
    fn add_back(&mut self, tau: Real, a: Complex) -> Moments {
        let ph0 = Phasor::at(self.fc[0], self.df, tau);
        if self.flat {
            let (c0, c1, c2) = kernels::add_back(&mut self.resid, &self.tw, a, ph0.start, ph0.step);
            return Moments { c0, c1, c2 };
        }
        let mut ph = ph0.start;
        let (mut c0, mut c1, mut c2) = (
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
        );
        let tp = 2.0 * PI;
        for i in 0..self.resid.len() {
            let pa = if self.flat {
                a
            } else {
                self.band.response[i] * a
            };
            self.resid[i] += pa * ph.conj();
            let r = if self.flat {
                self.resid[i]
            } else {
                self.band.response[i].conj() * self.resid[i]
            };
            let x = r * ph;
            let f = tp * self.fc[i];
            c0 += x;
            let xf = x * f;
            c1 += Complex::new(-xf.im, xf.re);
            c2 -= xf * f;
            ph *= ph0.step;
        }
        Moments { c0, c1, c2 }
    }

    /// Newton on `J(τ) = |c(τ)|²` of the residual from `tau`, steps clipped to a quarter of
    /// `1/B`, at most [`limits::NEWTON_ITERATIONS`]: the delay (folded into the window), the
    /// moments at it and the iterations used.
    fn newton(&self, mut tau: Real) -> (Real, Moments, usize) {
        let n = self.band.len();
        let max_step = 0.25 / (self.df * n as Real);
        let tol = NEWTON_TOL / (self.df * n as Real);
        let mut m = self.moments(tau);
        let mut used = 0;
        for _ in 0..limits::NEWTON_ITERATIONS {
            used += 1;
            let dt = m.newton_step(max_step);
            tau += dt;
            if dt.abs() < tol {
                let c = m.at(dt);
                m = Moments { c0: c, ..m };
                break;
            }
            m = self.moments(tau);
        }
        let folded = fold(tau, self.win_start, self.span).min(self.win_end);
        if folded != tau {
            m = self.moments(folded);
        }
        (folded, m, used)
    }

    /// Refinement after new paths (`paths[new..]`): the new paths and the paths coupled to one
    /// of them — within `2/B`, or so much stronger that their sidelobe there (`|α_j|/(πBΔ)`) is
    /// a tenth of its amplitude (a weak path beside a strong one; other paths are moved by a
    /// new one far below their own error) — cyclic sweeps (one Newton step per path and sweep)
    /// while they converge fast; the paths still moving after [`CYCLIC_SWEEPS`] (strongly
    /// coupled ones: closer than about `1/B`, where a Gauss–Seidel sweep converges slowly) are
    /// refined jointly with their neighbours within `2/B` ([`Estimator::joint_refine`]:
    /// Gauss–Newton with Levenberg damping, amplitudes by least squares, quadratic near the
    /// optimum). At most [`limits::ESTIMATOR_SWEEPS`] sweeps and joint iterations together,
    /// until no delay moves by `SAGE_TOL/B`, a sweep gains less than `LL_TOL` in log-likelihood
    /// (`‖r‖²/σ²`) or two paths come closer than the merge separation;
    /// then the merge of close paths (and a joint LS of the amplitudes); leaves `resid = h − Ĥ`.
    fn refine(
        &mut self,
        h: &[Complex],
        paths: &mut Vec<(Real, Complex)>,
        new: usize,
        sigma2: Real,
        work: &mut EstimateWork,
    ) {
        let n = self.band.len();
        let tol = SAGE_TOL / (self.df * n as Real);
        // A sweep or joint step that lowers ‖r‖² by less than this changes the log-likelihood
        // by less than LL_TOL: converged in what the data can tell, wherever the delays drift
        // (diffuse scattering fitted by a few paths leaves such flat valleys).
        let gain_tol = LL_TOL * sigma2;
        let max_step = 0.25 / (self.df * n as Real);
        let near = 2.0 / (self.df * n as Real);
        let bw = self.df * n as Real;
        // Coupled to a new path: within 2/B, or strong enough that its sidelobe there (the
        // Dirichlet envelope 1/(πBΔ) of its amplitude) is a tenth of the new path's amplitude.
        let coupled = |i: usize, j: usize| {
            let d = (paths[i].0 - paths[j].0).abs();
            d < near
                || sqrt(paths[i].1.norm_sqr()) >= 0.1 * PI * bw * d * sqrt(paths[j].1.norm_sqr())
        };
        let group: Vec<usize> = (0..paths.len())
            .filter(|&i| i >= new || (new..paths.len()).any(|j| coupled(i, j)))
            .collect();
        let mut sweeps = 0;
        let mut converged = group.len() < 2;
        let mut moves: Vec<Real> = vec![0.0; paths.len()];
        while !converged && sweeps < CYCLIC_SWEEPS {
            sweeps += 1;
            let gain = self.sweep(paths, &group, &mut moves, max_step);
            converged = group.iter().all(|&i| moves[i] < tol)
                || gain.abs() < gain_tol
                || self.crowded(paths);
        }
        if !converged {
            // The paths still moving and their neighbours within 2/B: refined jointly when
            // they are few (a resolvable pair or triple, where Gauss–Seidel crawls and
            // Gauss–Newton converges in two or three steps), else by more cyclic sweeps (a dense
            // cluster — diffuse scattering fitted by several paths — where joint steps are
            // ill-conditioned and cost O(k²) kernels each).
            let joint: Vec<usize> = group
                .iter()
                .copied()
                .filter(|&i| {
                    moves[i] >= tol
                        || group
                            .iter()
                            .any(|&j| moves[j] >= tol && (paths[i].0 - paths[j].0).abs() < near)
                })
                .collect();
            let budget = limits::ESTIMATOR_SWEEPS - sweeps;
            if joint.len() <= MAX_JOINT {
                let (iterations, ok) = self.joint_refine(paths, &joint, budget, tol, gain_tol);
                sweeps += iterations;
                converged = ok;
            } else {
                while !converged && sweeps < limits::ESTIMATOR_SWEEPS {
                    sweeps += 1;
                    let gain = self.sweep(paths, &group, &mut moves, max_step);
                    converged = group.iter().all(|&i| moves[i] < tol)
                        || gain.abs() < gain_tol
                        || self.crowded(paths);
                }
            }
        }
        work.sweeps = work.sweeps.max(sweeps);
        work.sweeps_capped |= !converged;
        // merge: keep the stronger of paths closer than MERGE_FRACTION/B
        paths.sort_by(|a, b| a.0.total_cmp(&b.0));
        let sep = self.merge_sep();
        let before = paths.len();
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
        if paths.len() < before {
            self.joint_ls(h, paths);
        }
    }

    /// One cyclic sweep: each path of `group` in turn added back, moved by one Newton step
    /// (clipped to `max_step`) and taken out again with its least-squares amplitude; `moves[i]`
    /// its step. Returns the fall of `‖r‖²`: `(|c(τ')|² − |c(τ)|²)/ΣP²` summed over the moves.
    fn sweep(
        &mut self,
        paths: &mut [(Real, Complex)],
        group: &[usize],
        moves: &mut [Real],
        max_step: Real,
    ) -> Real {
        let mut gain = 0.0;
        for &i in group {
            let (t, a) = paths[i];
            let m = self.add_back(t, a);
            let dt = m.newton_step(max_step);
            let c2 = m.at(dt);
            let a2 = c2 / self.energy;
            let t2 = fold(t + dt, self.win_start, self.span).min(self.win_end);
            self.add_path(t2, -a2);
            paths[i] = (t2, a2);
            moves[i] = dt.abs();
            gain += (c2.norm_sqr() - m.c0.norm_sqr()) / self.energy;
        }
        gain
    }

    /// Whether two paths are closer than the merge separation.
    fn crowded(&self, paths: &[(Real, Complex)]) -> bool {
        let sep = self.merge_sep();
        (0..paths.len())
            .any(|i| (i + 1..paths.len()).any(|j| (paths[i].0 - paths[j].0).abs() < sep))
    }

    /// Gauss–Newton with Levenberg damping on the delays of `paths[group]` (the other paths
    /// fixed), their amplitudes by least squares at every trial (variable projection in
    /// Kaufman's form): at most `budget` trials, until an accepted step moves no delay by
    /// `tol`. Steps are clipped to `1/(4B)`. Returns the trials used and whether it converged;
    /// leaves `resid = h − Ĥ` for the updated paths.
    fn joint_refine(
        &mut self,
        paths: &mut [(Real, Complex)],
        group: &[usize],
        budget: usize,
        tol: Real,
        gain_tol: Real,
    ) -> (usize, bool) {
        let k = group.len();
        if k == 0 {
            return (0, true);
        }
        let n = self.band.len();
        let max_step = 0.25 / (self.df * n as Real);
        // The data the group explains: the residual with the group's paths added back.
        for &g in group {
            let (t, a) = paths[g];
            self.add_path(t, a);
        }
        let y = self.resid.clone();
        let mut taus: Vec<Real> = group.iter().map(|&g| paths[g].0).collect();
        let mut fit = self.project(&y, &taus);
        let mut lambda = 1e-6;
        let (mut used, mut converged) = (0, false);
        while used < budget {
            used += 1;
            let Some((grad, hess)) = self.gauss_newton_terms(&fit) else {
                break;
            };
            let mut sys = hess.clone();
            for i in 0..k {
                sys[i * k + i] *= 1.0 + lambda;
            }
            let Some(inv) = linalg::inverse_sym(sys, k) else {
                lambda *= 10.0;
                continue;
            };
            let mut trial = taus.clone();
            let mut moved: Real = 0.0;
            for i in 0..k {
                let d: Real = -(0..k).map(|j| inv[i * k + j] * grad[j]).sum::<Real>();
                let d = if d.is_finite() {
                    d.clamp(-max_step, max_step)
                } else {
                    0.0
                };
                trial[i] = fold(taus[i] + d, self.win_start, self.span).min(self.win_end);
                moved = moved.max(d.abs());
            }
            let next = self.project(&y, &trial);
            if next.cost <= fit.cost {
                let gain = fit.cost - next.cost;
                taus = trial;
                fit = next;
                lambda = (lambda * 0.1).max(1e-12);
                // Converged, or two paths about to merge (the merge decides; their joint fit is
                // degenerate and would drift on).
                let sep = self.merge_sep();
                let crowded = (0..k).any(|i| (i + 1..k).any(|j| (taus[i] - taus[j]).abs() < sep));
                if moved < tol || gain < gain_tol || crowded {
                    converged = true;
                    break;
                }
            } else {
                lambda *= 10.0;
                if moved < tol {
                    converged = true;
                    break;
                }
            }
        }
        for (i, &g) in group.iter().enumerate() {
            paths[g] = (taus[i], fit.alpha[i]);
        }
        self.resid.clear();
        self.resid.extend_from_slice(&fit.resid);
        (used, converged)
    }

    /// The least-squares amplitudes of paths at `taus` explaining `y`, the residual, its
    /// energy, and the basis columns `a_i` (`P·e^{−j2π(f_n−f_c)τ_i}`).
    fn project(&self, y: &[Complex], taus: &[Real]) -> Projection {
        let (n, k) = (y.len(), taus.len());
        let mut basis = Vec::with_capacity(n * k);
        for &t in taus {
            let ph0 = Phasor::at(self.fc[0], self.df, t);
            let from = basis.len();
            kernels::push_rotating(&mut basis, n, ph0.start.conj(), ph0.step.conj());
            if !self.flat {
                for (v, p) in basis[from..].iter_mut().zip(&self.band.response) {
                    *v *= p;
                }
            }
        }
        let mut g = vec![Complex::new(0.0, 0.0); k * k];
        let mut b = vec![Complex::new(0.0, 0.0); k];
        for i in 0..k {
            let ai = &basis[i * n..(i + 1) * n];
            b[i] = kernels::dot_conj(ai, y);
            g[i * k + i] = Complex::new(self.energy, 0.0);
            for j in i + 1..k {
                let s = self.gram(taus[j] - taus[i]);
                g[i * k + j] = s;
                g[j * k + i] = s.conj();
            }
        }
        let alpha = linalg::solve_complex(&mut g, &mut b, k)
            .unwrap_or_else(|| vec![Complex::new(0.0, 0.0); k]);
        let mut resid = y.to_vec();
        for (i, a) in alpha.iter().enumerate() {
            for (r, v) in resid.iter_mut().zip(&basis[i * n..(i + 1) * n]) {
                *r -= v * a;
            }
        }
        let cost = kernels::norm_sqr_sum(&resid);
        Projection {
            taus: taus.to_vec(),
            alpha,
            resid,
            cost,
            basis,
        }
    }

    /// The gradient and Gauss–Newton Hessian of `‖r‖²` in the delays at `fit` (amplitudes
    /// held): `∂r/∂τ_i = −α_i·(−j2π(f_n−f_c))·a_i`. `None` if not finite.
    fn gauss_newton_terms(&self, fit: &Projection) -> Option<(Vec<Real>, Vec<Real>)> {
        let k = fit.alpha.len();
        let n = fit.resid.len();
        let tp = 2.0 * PI;
        // dr_i[n] = j2π f_n α_i a_i[n]
        let mut dr = Vec::with_capacity(n * k);
        for i in 0..k {
            let a = fit.alpha[i];
            for (v, f) in fit.basis[i * n..(i + 1) * n].iter().zip(&self.fc) {
                let x = v * a * (tp * f);
                dr.push(Complex::new(-x.im, x.re));
            }
        }
        let mut grad = vec![0.0; k];
        let mut hess = vec![0.0; k * k];
        // Kaufman's variable projection: the Jacobian projected off the amplitudes' span,
        // J = (I − A G⁻¹Aᴴ)D, so JᴴJ = DᴴD − Bᴴ G⁻¹ B with G = AᴴA, B = AᴴD; every entry a
        // kernel: (DᴴD)_ij = (2π)² conj(α_i) α_j S_2(τ_j − τ_i), B_ij = j2π α_j S_1(τ_j − τ_i),
        // G_ij = S_0(τ_j − τ_i). Without the projection the steps of strongly coupled paths are
        // far too short (amplitude and delay trade off within 1/B).
        let taus = &fit.taus;
        let mut g = vec![Complex::new(0.0, 0.0); k * k];
        let mut bm = vec![Complex::new(0.0, 0.0); k * k];
        let mut dd = vec![Complex::new(0.0, 0.0); k * k];
        for i in 0..k {
            for j in 0..k {
                let (s0, s1, s2) = self.kernels(taus[j] - taus[i]);
                g[i * k + j] = s0;
                bm[i * k + j] = Complex::new(0.0, tp) * fit.alpha[j] * s1;
                dd[i * k + j] = fit.alpha[i].conj() * fit.alpha[j] * s2 * (tp * tp);
            }
        }
        // X = G⁻¹B, column by column.
        let mut x = vec![Complex::new(0.0, 0.0); k * k];
        for j in 0..k {
            let mut gg = g.clone();
            let mut col: Vec<Complex> = (0..k).map(|i| bm[i * k + j]).collect();
            let sol = linalg::solve_complex(&mut gg, &mut col, k)?;
            for i in 0..k {
                x[i * k + j] = sol[i];
            }
        }
        for i in 0..k {
            let di = &dr[i * n..(i + 1) * n];
            grad[i] = 2.0 * kernels::re_dot_conj(&fit.resid, di);
            for j in i..k {
                // (Bᴴ X)_ij = Σ_m conj(B_mi) X_mj
                let c: Complex = (0..k).map(|m| bm[m * k + i].conj() * x[m * k + j]).sum();
                let h = 2.0 * (dd[i * k + j] - c).re;
                hess[i * k + j] = h;
                hess[j * k + i] = h;
            }
        }
        (grad.iter().all(|v| v.is_finite()) && hess.iter().all(|v| v.is_finite()))
            .then_some((grad, hess))
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
        self.resid.clear();
        self.resid.extend_from_slice(h);
        for i in 0..k {
            b[i] = self.correlation(paths[i].0);
            g[i * k + i] = Complex::new(self.energy, 0.0);
            for j in i + 1..k {
                let s = self.gram(paths[j].0 - paths[i].0);
                g[i * k + j] = s;
                g[j * k + i] = s.conj();
            }
        }
        if let Some(a) = linalg::solve_complex(&mut g, &mut b, k) {
            for (p, v) in paths.iter_mut().zip(a) {
                p.1 = v;
            }
        }
        for &(t, a) in paths.iter() {
            self.add_path(t, -a);
        }
    }

    /// `S_0(d) = Σ |P|² e^{−j2π(f_n−f_c)d}` ([`Estimator::kernels`]).
    fn gram(&self, d: Real) -> Complex {
        self.kernels(d).0
    }

    /// `S_a(d) = Σ |P|² (f_n−f_c)^a e^{−j2π(f_n−f_c)d}` for `a` = 0, 1, 2. For a flat band on
    /// centred bins in closed form, `O(1)`: with `θ = πΔf·d` and the Dirichlet kernel
    /// `D(θ) = sin(Nθ)/sin θ`, `S_0 = D`, `S_1 = j(Δf/2)·D'`, `S_2 = −(Δf²/4)·D''`,
    /// `D' = (N cos Nθ sin θ − sin Nθ cos θ)/sin²θ`, `D'' = (1 − N²)D − 2 cot θ·D'`; the sums
    /// where that cancels (`|Nθ| < 0.1` or `|sin θ| < 10⁻²`; tested against the sums).
    fn kernels(&self, d: Real) -> (Complex, Complex, Complex) {
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
    /// `Re α_i`, `Im α_i`; only its delay diagonal, from the Schur complement of the
    /// amplitudes); C4 at the fitted SNR when it is singular.
    fn fisher_sigmas(&self, paths: &[(Real, Complex)], sigma2: Real) -> Vec<Real> {
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

/// `τ` folded into `[start, start + span)` (`start` itself where rounding would leave it below).
fn fold(tau: Real, start: Real, span: Real) -> Real {
    let q = (tau - start) / span;
    let mut fl = round(q);
    if fl > q {
        fl -= 1.0;
    }
    let t = tau - fl * span;
    let t = if t >= start + span { t - span } else { t };
    // Rounding can leave `t` one step below `start` (a path exactly at the window's start:
    // found by the `cir_windows` fuzz kind, issue 37).
    t.max(start)
}

#[cfg(test)]
mod tests;
