//! Native parallel driver of the Monte Carlo study ([`crate::montecarlo`]): chunks run on a
//! rayon pool in waves; partial sums are merged in chunk order, so the result is identical for
//! any thread count. Between waves it reports progress and honours a cancel flag (Ctrl-C).

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::math::Real;
use crate::model::Model;
use crate::montecarlo::{
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
/// [`crate::montecarlo::run_pcrlb_sequential`]. Progress counts trajectories.
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

/// Runs `chunk` for every chunk of the study in waves and merges the sums in chunk order.
/// Progress is reported in units of `per_trajectory` runs per trajectory.
fn run_waves(
    model: &Model,
    cfg: &MonteCarloConfig,
    threads: usize,
    cancel: &AtomicBool,
    mut on_progress: impl FnMut(usize, usize),
    chunk: fn(&Model, &MonteCarloConfig, usize) -> Result<PartialSums>,
    per_trajectory: usize,
) -> Result<PartialSums> {
    let pool = thread_pool(threads)?;
    let chunks = cfg.chunk_count();
    let wave = (4 * pool.current_num_threads()).max(1);
    let total = cfg.trajectories * per_trajectory;
    let mut sums = PartialSums::new(cfg.steps);
    let mut start = 0;
    while start < chunks {
        if cancel.load(Ordering::Relaxed) {
            return Err(Error::Cancelled);
        }
        let end = (start + wave).min(chunks);
        let parts: Vec<Result<PartialSums>> = pool.install(|| {
            (start..end)
                .into_par_iter()
                .map(|c| chunk(model, cfg, c))
                .collect()
        });
        for part in parts {
            sums.merge(&part?);
        }
        start = end;
        on_progress(
            (start * CHUNK_TRAJECTORIES * per_trajectory).min(total),
            total,
        );
    }
    Ok(sums)
}

/// A rayon pool of `threads` workers (0 = all cores); [`Error::SizeLimit`] (`threads`) when it
/// cannot be built.
pub fn thread_pool(threads: usize) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|_| Error::SizeLimit {
            field: "threads",
            value: threads,
            min: 0,
            max: 1024,
        })
}
