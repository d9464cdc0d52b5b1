//! Monte Carlo evaluation of the tracker against its bound ([S] §5.2, spec §8, §9.5):
//! `N_traj` truth trajectories from the prior, each with `N_noise` measurement-noise sequences;
//! `ε_EKF(t_n) = √(mean ‖r̂ − r‖²)`, `ε_PCRLB(t_n)` from (E9) with `E[F̃]` the mean over the same
//! truth trajectories, and the average NEES.
//!
//! Work is split into fixed chunks of trajectories; every trajectory and noise run draws from
//! its own stream `rng(seed, index)`, and the chunks' sums are combined exactly
//! ([`StudySums`], [`ExactSum`](crate::math::ExactSum)), so the result depends on the seed
//! only — not on how many threads run the chunks, nor on how the chunks are split into shards
//! ([`MonteCarloConfig::shard_chunks`]) run by separate processes and merged later. This
//! module is `no_std`: the browser worker runs chunks one after another; `crate::native` runs
//! them on threads.

use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::{sqrt, Mat2, Mat4, Real, Shard, Vec4};
use crate::measure::Model;
use crate::track::pcrlb_rmse;
use crate::track::step_count;
use crate::track::ConstantVelocity;

mod chunk;
mod sums;

pub use chunk::{run_chunk, run_chunk_in, run_filter_chunk, run_filter_chunk_in, run_truth_chunk};
pub use sums::{PartialSums, StudySums};

/// Trajectories per chunk (the unit of parallel work, of the fixed-order sums inside a chunk and
/// of shards).
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
        crate::track::check_covariance("initial_covariance", &self.initial_covariance)
    }

    /// Number of chunks.
    pub fn chunk_count(&self) -> usize {
        self.trajectories.div_ceil(CHUNK_TRAJECTORIES)
    }

    /// The chunks of `shard`: [`Shard::range`] of the [`chunk_count`](Self::chunk_count).
    pub fn shard_chunks(&self, shard: Shard) -> core::ops::Range<usize> {
        shard.range(self.chunk_count())
    }

    /// Trajectories in `chunks` (a range of chunk indices).
    pub fn trajectories_in(&self, chunks: &core::ops::Range<usize>) -> usize {
        let at = |c: usize| c.saturating_mul(CHUNK_TRAJECTORIES).min(self.trajectories);
        at(chunks.end).saturating_sub(at(chunks.start))
    }

    /// Total EKF runs.
    pub fn runs(&self) -> usize {
        self.trajectories * self.noise_runs
    }
}

/// The curves of a study.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MonteCarloResult {
    /// `t_n = n T`, s, `n = 0 … steps`.
    pub t_s: Vec<Real>,
    /// The filter's RMSE `ε(t_n)`, m (any filter's; the JSON key keeps the name of the EKF's
    /// curve, `rmse_ekf_m`, of \[S\] Fig. 3).
    #[serde(rename = "rmse_ekf_m")]
    pub rmse_m: Vec<Real>,
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

/// Turns the combined sums into the curves (E9 with the Monte Carlo mean Fisher matrices): each
/// sum is rounded once ([`ExactSum::value`](crate::math::ExactSum::value)), then divided by the
/// count. [`Error::SizeLimit`] (`runs (successful)`) when no run was counted.
pub fn finish(cfg: &MonteCarloConfig, sums: &StudySums) -> Result<MonteCarloResult> {
    if sums.runs == 0 {
        return Err(Error::SizeLimit {
            field: "runs (successful)",
            value: 0,
            min: 1,
            max: MAX_RUNS,
        });
    }
    let runs = sums.runs as Real;
    Ok(MonteCarloResult {
        t_s: (0..=cfg.steps)
            .map(|n| n as Real * cfg.motion.dt_s)
            .collect(),
        rmse_m: sums
            .squared_error
            .iter()
            .map(|v| sqrt(v.value() / runs))
            .collect(),
        rmse_pcrlb_m: pcrlb_from_sums(cfg, sums)?,
        nees: sums.nees.iter().map(|v| v.value() / runs).collect(),
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
    let mut sums = StudySums::new(cfg.steps);
    for chunk in 0..total {
        sums.add(&run_chunk(model, cfg, chunk)?);
        if !on_chunk(chunk + 1, total) {
            return Err(Error::Cancelled);
        }
    }
    finish(cfg, &sums)
}

/// The Monte Carlo PCRLB alone (spec §8, check 10): `ε_PCRLB(t_n)` from (E9) with `E[F̃]` the
/// mean over the study's truth trajectories — the same trajectories (streams `rng(seed, 2i)`)
/// and chunks as [`run_sequential`], so the curve equals its `rmse_pcrlb_m`, but
/// without the EKF runs (`noise_runs` is ignored). `on_chunk` as in [`run_sequential`].
pub fn run_pcrlb_sequential(
    model: &Model,
    cfg: &MonteCarloConfig,
    mut on_chunk: impl FnMut(usize, usize) -> bool,
) -> Result<Vec<Option<Real>>> {
    MonteCarloConfig {
        noise_runs: 1,
        ..*cfg
    }
    .validate()?;
    let total = cfg.chunk_count();
    let mut sums = StudySums::new(cfg.steps);
    for chunk in 0..total {
        sums.add(&run_truth_chunk(model, cfg, chunk)?);
        if !on_chunk(chunk + 1, total) {
            return Err(Error::Cancelled);
        }
    }
    pcrlb_from_sums(cfg, &sums)
}

/// `ε_PCRLB(t_n)` (E9) with `E[F̃]` the mean of the summed truth Fisher matrices.
pub fn pcrlb_from_sums(cfg: &MonteCarloConfig, sums: &StudySums) -> Result<Vec<Option<Real>>> {
    let trajectories = sums.trajectories.max(1) as Real;
    let mean_fishers: Vec<Mat2> = (1..sums.fisher.len())
        .map(|n| sums.fisher_at(n) / trajectories)
        .collect();
    pcrlb_rmse(&cfg.motion, &cfg.initial_covariance, &mean_fishers)
}
