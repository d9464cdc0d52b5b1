//! Monte Carlo evaluation of the tracker against its bound ([S] §5.2, spec §8, §9.5):
//! `N_traj` truth trajectories from the prior, each with `N_noise` measurement-noise sequences;
//! `ε_EKF(t_n) = √(mean ‖r̂ − r‖²)`, `ε_PCRLB(t_n)` from (E9) with `E[F̃]` the mean over the same
//! truth trajectories, and the average NEES.
//!
//! Work is split into fixed chunks of trajectories whose partial sums are combined in chunk
//! order, and every trajectory and noise run draws from its own stream `rng(seed, index)`, so
//! the result depends on the seed only — not on how many threads run the chunks. This module
//! is `no_std`: the browser worker runs chunks one after another; `crate::parallel` runs them on
//! threads.

use alloc::vec;
use alloc::vec::Vec;

use crate::crlb::fisher;
use crate::ekf::{Ekf, MeasurementNoise};
use crate::error::{Error, Result};
use crate::math::{sqrt, Mat2, Mat4, Real, Vec2, Vec4};
use crate::model::Model;
use crate::motion::ConstantVelocity;
use crate::pcrlb::pcrlb_rmse;
use crate::simulate::{rng, standard_normal};
use crate::trajectory::{step_count, TruthSampler};

/// Trajectories per chunk (the unit of parallel work and of deterministic reduction).
pub const CHUNK_TRAJECTORIES: usize = 16;
/// Largest number of EKF runs (`trajectories × noise_runs`) accepted.
pub const MAX_RUNS: usize = 10_000_000;
/// Largest number of steps per run accepted.
pub const MAX_STEPS: usize = 1_000_000;

/// A Monte Carlo study.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MonteCarloConfig {
    /// Motion model (step `T`, intensity `q̃`).
    pub motion: ConstantVelocity,
    /// Number of steps after `t₀`.
    pub steps: usize,
    /// Prior mean `x̄₀` (truth mean and filter start).
    pub mean_state: Vec4,
    /// Prior covariance `P(t₀)` (truth spread and filter start).
    pub initial_covariance: Mat4,
    /// Truth trajectories `N_traj`.
    pub trajectories: usize,
    /// Noise sequences per trajectory `N_noise`.
    pub noise_runs: usize,
    /// Seed of every random stream.
    pub seed: u64,
    /// `true`: the EKF's `R` uses the link budget at the truth ("oracle"); default `false`: at
    /// the predicted position (spec §6).
    pub oracle_noise: bool,
}

impl MonteCarloConfig {
    /// The study for `steps` of `motion` covering `duration_s`.
    pub fn steps_for(motion: &ConstantVelocity, duration_s: Real) -> usize {
        step_count(duration_s, motion.dt_s)
    }

    /// Checks counts against the caps and the covariance.
    pub fn validate(&self) -> Result<()> {
        ConstantVelocity::validated(self.motion.dt_s, self.motion.intensity)?;
        let cap = |field: &'static str, value: usize, max: usize| {
            if value == 0 || value > max {
                Err(Error::SizeLimit {
                    field,
                    value,
                    min: 1,
                    max,
                })
            } else {
                Ok(())
            }
        };
        cap("runs", self.trajectories, MAX_RUNS)?;
        cap("noise_runs", self.noise_runs, MAX_RUNS)?;
        cap(
            "runs*noise_runs",
            self.trajectories.saturating_mul(self.noise_runs),
            MAX_RUNS,
        )?;
        cap("steps", self.steps, MAX_STEPS)?;
        if self.mean_state.iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                field: "initial_state".into(),
            });
        }
        crate::ekf::check_covariance("initial_covariance", &self.initial_covariance)
    }

    /// Number of chunks.
    pub fn chunk_count(&self) -> usize {
        self.trajectories.div_ceil(CHUNK_TRAJECTORIES)
    }

    /// Total EKF runs.
    pub fn runs(&self) -> usize {
        self.trajectories * self.noise_runs
    }
}

/// Per-step sums of a set of runs (combined in a fixed order).
#[derive(Debug, Clone, PartialEq)]
pub struct PartialSums {
    /// Σ ‖r̂ − r‖² over runs, per step `0 … steps`.
    pub squared_error: Vec<Real>,
    /// Σ NEES over runs, per step.
    pub nees: Vec<Real>,
    /// Σ F(r_true) over trajectories, per step (index 0 unused: no measurement at t₀).
    pub fisher: Vec<Mat2>,
    /// Runs counted (those that did not fail).
    pub runs: usize,
    /// Runs whose filter reported a numerical failure (excluded from the sums).
    pub failed_runs: usize,
    /// Trajectories counted.
    pub trajectories: usize,
}

impl PartialSums {
    /// Zero sums for `steps` steps.
    pub fn new(steps: usize) -> PartialSums {
        PartialSums {
            squared_error: vec![0.0; steps + 1],
            nees: vec![0.0; steps + 1],
            fisher: vec![Mat2::zeros(); steps + 1],
            runs: 0,
            failed_runs: 0,
            trajectories: 0,
        }
    }

    /// Adds `other` (call in chunk order for a thread-count-independent result).
    pub fn merge(&mut self, other: &PartialSums) {
        for (a, b) in self.squared_error.iter_mut().zip(&other.squared_error) {
            *a += b;
        }
        for (a, b) in self.nees.iter_mut().zip(&other.nees) {
            *a += b;
        }
        for (a, b) in self.fisher.iter_mut().zip(&other.fisher) {
            *a += b;
        }
        self.runs += other.runs;
        self.failed_runs += other.failed_runs;
        self.trajectories += other.trajectories;
    }
}

/// The curves of a study.
#[derive(Debug, Clone, PartialEq)]
pub struct MonteCarloResult {
    /// `t_n = n T`, s, `n = 0 … steps`.
    pub t_s: Vec<Real>,
    /// `ε_EKF(t_n)`, m.
    pub rmse_ekf_m: Vec<Real>,
    /// `ε_PCRLB(t_n)`, m (`None` if the information became singular).
    pub rmse_pcrlb_m: Vec<Option<Real>>,
    /// Average NEES per step (4 degrees of freedom for a consistent filter).
    pub nees: Vec<Real>,
    /// EKF runs counted.
    pub runs: usize,
    /// EKF runs that failed numerically (excluded).
    pub failed_runs: usize,
    /// The seed.
    pub seed: u64,
}

/// Scratch buffers reused across trajectories of a chunk.
struct Scratch {
    truth: Vec<Vec4>,
    delays: Vec<Real>,
    sigmas: Vec<Real>,
    measurement: Vec<Option<Real>>,
    squared_error: Vec<Real>,
    nees: Vec<Real>,
}

/// Runs chunk `chunk` (trajectories `chunk·16 …`) of the study and returns its sums.
/// Trajectory `i` uses stream `rng(seed, 2i)`; its noise run `j` uses `rng(seed, 2(i·N_noise + j) + 1)`.
pub fn run_chunk(model: &Model, cfg: &MonteCarloConfig, chunk: usize) -> Result<PartialSums> {
    let links = model.link_count();
    let steps = cfg.steps;
    let sampler = TruthSampler::new(cfg.motion, cfg.mean_state, &cfg.initial_covariance)?;
    let mut sums = PartialSums::new(steps);
    let mut s = Scratch {
        truth: Vec::with_capacity(steps + 1),
        delays: vec![0.0; links * (steps + 1)],
        sigmas: vec![0.0; links * (steps + 1)],
        measurement: vec![None; links],
        squared_error: vec![0.0; steps + 1],
        nees: vec![0.0; steps + 1],
    };
    let first = chunk * CHUNK_TRAJECTORIES;
    let last = (first + CHUNK_TRAJECTORIES).min(cfg.trajectories);
    for traj in first..last {
        sampler.sample(steps, &mut rng(cfg.seed, 2 * traj as u64), &mut s.truth);
        // Per step: true delays, σ_p at the truth (E8), and F(r_true) for E[F̃].
        for (n, x) in s.truth.iter().enumerate().skip(1) {
            let r = Vec2::new(x[0], x[1]);
            for p in 0..links {
                s.delays[n * links + p] = model.network.delay(p, r);
                s.sigmas[n * links + p] = model.sigma_delay(p, r);
            }
            sums.fisher[n] += fisher(model, r);
        }
        sums.trajectories += 1;
        for run in 0..cfg.noise_runs {
            let stream = 2 * (traj as u64 * cfg.noise_runs as u64 + run as u64) + 1;
            if run_filter(model, cfg, &mut s, &mut rng(cfg.seed, stream)) {
                for n in 0..=steps {
                    sums.squared_error[n] += s.squared_error[n];
                    sums.nees[n] += s.nees[n];
                }
                sums.runs += 1;
            } else {
                sums.failed_runs += 1;
            }
        }
    }
    Ok(sums)
}

/// One EKF run over the prepared truth; fills `s.squared_error` and `s.nees`. False if the
/// filter failed numerically.
fn run_filter(
    model: &Model,
    cfg: &MonteCarloConfig,
    s: &mut Scratch,
    rng: &mut crate::simulate::Rng,
) -> bool {
    let links = model.link_count();
    let Ok(mut ekf) = Ekf::new(cfg.mean_state, cfg.initial_covariance) else {
        return false;
    };
    for (n, x) in s.truth.iter().enumerate() {
        if n > 0 {
            ekf.predict(&cfg.motion);
            for p in 0..links {
                let k = n * links + p;
                s.measurement[p] = Some(s.delays[k] + s.sigmas[k] * standard_normal(rng));
            }
            let noise = if cfg.oracle_noise {
                MeasurementNoise::At(Vec2::new(x[0], x[1]))
            } else {
                MeasurementNoise::AtPrediction
            };
            if ekf.update(model, &s.measurement, noise, None).is_err() {
                return false;
            }
        }
        let e = ekf.position() - Vec2::new(x[0], x[1]);
        s.squared_error[n] = e.norm_squared();
        match ekf.nees(x) {
            Some(v) => s.nees[n] = v,
            None => return false,
        }
    }
    true
}

/// Turns the combined sums into the curves (E9 with the Monte Carlo mean Fisher matrices).
pub fn finish(cfg: &MonteCarloConfig, sums: &PartialSums) -> Result<MonteCarloResult> {
    if sums.runs == 0 {
        return Err(Error::SizeLimit {
            field: "runs (successful)",
            value: 0,
            min: 1,
            max: MAX_RUNS,
        });
    }
    let runs = sums.runs as Real;
    let trajectories = sums.trajectories.max(1) as Real;
    let mean_fishers: Vec<Mat2> = sums.fisher[1..].iter().map(|f| f / trajectories).collect();
    Ok(MonteCarloResult {
        t_s: (0..=cfg.steps)
            .map(|n| n as Real * cfg.motion.dt_s)
            .collect(),
        rmse_ekf_m: sums.squared_error.iter().map(|v| sqrt(v / runs)).collect(),
        rmse_pcrlb_m: pcrlb_rmse(&cfg.motion, &cfg.initial_covariance, &mean_fishers)?,
        nees: sums.nees.iter().map(|v| v / runs).collect(),
        runs: sums.runs,
        failed_runs: sums.failed_runs,
        seed: cfg.seed,
    })
}

/// Runs the whole study on the calling thread, chunk by chunk. `on_chunk(done, total)` is called
/// after each chunk and may return `false` to cancel (then `Err(Error::Cancelled)`).
pub fn run_sequential(
    model: &Model,
    cfg: &MonteCarloConfig,
    mut on_chunk: impl FnMut(usize, usize) -> bool,
) -> Result<MonteCarloResult> {
    cfg.validate()?;
    let total = cfg.chunk_count();
    let mut sums = PartialSums::new(cfg.steps);
    for chunk in 0..total {
        sums.merge(&run_chunk(model, cfg, chunk)?);
        if !on_chunk(chunk + 1, total) {
            return Err(Error::Cancelled);
        }
    }
    finish(cfg, &sums)
}
