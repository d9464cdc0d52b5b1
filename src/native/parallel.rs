//! The Monte Carlo study ([`crate::track`]) on the ordered driver ([`run_ordered`]): chunks of
//! trajectories run in parallel and their partial sums are merged in chunk order, so the result
//! is identical for any thread count.

use std::sync::atomic::AtomicBool;

use super::driver::run_ordered;
use crate::error::Result;
use crate::math::Real;
use crate::measure::Model;
use crate::track::{
    finish, pcrlb_from_sums, run_chunk, run_truth_chunk, MonteCarloConfig, MonteCarloResult,
    PartialSums, CHUNK_TRAJECTORIES,
};

/// Runs the study on `threads` worker threads (0 = all cores). `on_progress(runs_done,
/// runs_total)` is called after every wave; when `cancel` becomes true the study stops after
/// the current wave with `Err(Error::Cancelled)`.
pub fn run_parallel(
    model: &Model,
    cfg: &MonteCarloConfig,
    threads: usize,
    cancel: &AtomicBool,
    on_progress: impl FnMut(usize, usize),
) -> Result<MonteCarloResult> {
    cfg.validate()?;
    let sums = run_waves(
        model,
        cfg,
        threads,
        cancel,
        on_progress,
        run_chunk,
        cfg.noise_runs,
    )?;
    finish(cfg, &sums)
}

/// The Monte Carlo PCRLB alone (spec §8, check 10) in parallel: truth trajectories and
/// `E[F̃]` only, no EKF runs — the same curve as [`run_parallel`]'s `rmse_pcrlb_m` and as
/// [`crate::track::run_pcrlb_sequential`]. Progress counts trajectories.
pub fn run_pcrlb_parallel(
    model: &Model,
    cfg: &MonteCarloConfig,
    threads: usize,
    cancel: &AtomicBool,
    on_progress: impl FnMut(usize, usize),
) -> Result<Vec<Option<Real>>> {
    MonteCarloConfig {
        noise_runs: 1,
        ..*cfg
    }
    .validate()?;
    let sums = run_waves(model, cfg, threads, cancel, on_progress, run_truth_chunk, 1)?;
    pcrlb_from_sums(cfg, &sums)
}

/// Runs `chunk` for every chunk of the study through [`run_ordered`] and merges the sums in
/// chunk order. Progress is reported in units of `per_trajectory` runs per trajectory.
fn run_waves(
    model: &Model,
    cfg: &MonteCarloConfig,
    threads: usize,
    cancel: &AtomicBool,
    mut on_progress: impl FnMut(usize, usize),
    chunk: fn(&Model, &MonteCarloConfig, usize) -> Result<PartialSums>,
    per_trajectory: usize,
) -> Result<PartialSums> {
    let total = cfg.trajectories * per_trajectory;
    let mut sums = PartialSums::new(cfg.steps);
    run_ordered(
        cfg.chunk_count(),
        threads,
        4,
        cancel,
        |c| chunk(model, cfg, c),
        |part| sums.merge(&part),
        |done| {
            on_progress(
                (done * CHUNK_TRAJECTORIES * per_trajectory).min(total),
                total,
            )
        },
    )?;
    Ok(sums)
}
