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

use alloc::vec;
use alloc::vec::Vec;

use super::estimator::fold;
use crate::channel::{EstimateWork, Estimator, PathEstimate, SnapshotEstimate, Stop};
use crate::error::{limits, Cancel, Error, Result};
use crate::math::{db_to_linear, Complex, Real};

impl Estimator {
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
                    range_rate: None,
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
}
