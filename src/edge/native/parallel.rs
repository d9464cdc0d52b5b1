//! The Monte Carlo study ([`crate::track`]) on the ordered driver: the tracker's study is the
//! core's [`FilterStudy`] on the [`Parallel`] driver; the PCRLB alone runs truth chunks on
//! [`run_ordered`]. Chunks of trajectories run in parallel and their sums are combined exactly ([`StudySums`]), so the
//! result is identical for any thread count, and a shard's sums ([`run_chunks_parallel`])
//! merge into exactly the sums of the whole study.

use std::ops::Range;
use std::sync::atomic::AtomicBool;

use super::driver::{run_ordered, Parallel};
use crate::error::Result;
use crate::math::Real;
use crate::measure::Model;
use crate::study::FilterStudy;
use crate::track::{
    finish, pcrlb_from_sums, run_truth_chunk, FilterKind, MonteCarloConfig, MonteCarloResult,
    PartialSums, StudySums,
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
    let sums = run_chunks_parallel(
        model,
        cfg,
        0..cfg.chunk_count(),
        threads,
        cancel,
        on_progress,
    )?;
    finish(cfg, &sums)
}

/// The sums of the chunks `chunks` of the study (a shard: see
/// [`MonteCarloConfig::shard_chunks`]) on `threads` worker threads (0 = all cores); progress
/// and cancel as in [`run_parallel`], counting the runs of these chunks. Sums of disjoint
/// ranges merged with [`StudySums::merge`] equal those of their union exactly. An empty range
/// gives zero sums. [`crate::Error::IndexOutOfRange`] (`chunks`) past the last chunk.
pub fn run_chunks_parallel(
    model: &Model,
    cfg: &MonteCarloConfig,
    chunks: Range<usize>,
    threads: usize,
    cancel: &AtomicBool,
    on_progress: impl FnMut(usize, usize),
) -> Result<StudySums> {
    run_filter_chunks_parallel(
        model,
        cfg,
        FilterKind::Ekf,
        chunks,
        threads,
        cancel,
        on_progress,
    )
}

/// [`run_chunks_parallel`] with any tracker (issue 15): the sums of the chunks `chunks` of the
/// study run by `filter` ([`crate::track::run_filter_chunk`]: the EKF study's truth and measurements), on
/// `threads` worker threads (0 = all cores), with progress and cancel as in [`run_parallel`].
/// [`FilterKind::Ekf`] gives exactly [`run_chunks_parallel`]'s sums. The filter's settings are
/// validated first (errors name `ukf_alpha`, `ukf_beta`, `ukf_kappa`, `particles`,
/// `roughening`).
pub fn run_filter_chunks_parallel(
    model: &Model,
    cfg: &MonteCarloConfig,
    filter: FilterKind,
    chunks: Range<usize>,
    threads: usize,
    cancel: &AtomicBool,
    mut on_progress: impl FnMut(usize, usize),
) -> Result<StudySums> {
    filter.validate()?;
    let mut study = FilterStudy::new(*cfg, &[filter])?;
    study.run_range(
        model,
        chunks,
        &mut Parallel::new(threads, cancel),
        &mut on_progress,
    )?;
    Ok(study.sums().swap_remove(0))
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
    let all = 0..cfg.chunk_count();
    let sums = run_waves(
        model,
        cfg,
        all,
        threads,
        cancel,
        on_progress,
        run_truth_chunk,
        1,
    )?;
    pcrlb_from_sums(cfg, &sums)
}

/// Runs `chunk` for every chunk of `chunks` through [`run_ordered`] and adds the sums exactly.
/// Progress is reported in runs: `per_trajectory` per trajectory of the range.
#[allow(clippy::too_many_arguments)]
fn run_waves(
    model: &Model,
    cfg: &MonteCarloConfig,
    chunks: Range<usize>,
    threads: usize,
    cancel: &AtomicBool,
    mut on_progress: impl FnMut(usize, usize),
    chunk: impl Fn(&Model, &MonteCarloConfig, usize) -> Result<PartialSums> + Sync,
    per_trajectory: usize,
) -> Result<StudySums> {
    let first = chunks.start;
    let total = cfg.trajectories_in(&chunks) * per_trajectory;
    let mut sums = StudySums::new(cfg.steps);
    run_ordered(
        chunks.len(),
        threads,
        4,
        cancel,
        |c| chunk(model, cfg, first + c),
        |part| sums.add(&part),
        |done| {
            let runs = cfg.trajectories_in(&(first..first + done)) * per_trajectory;
            on_progress(runs, total)
        },
    )?;
    Ok(sums)
}
