//! The §8 experiments ([`crate::mtl::experiment`]) on the ordered driver ([`run_ordered`]):
//! realisations run in parallel and their counts are added exactly ([`Tally`]), so the result is
//! identical for any thread count (and equal to [`crate::mtl::experiment::run_sequential`]), and
//! the tallies of shards ([`run_experiment_range`]) merge into exactly the whole run's.

use std::ops::Range;
use std::sync::atomic::AtomicBool;

use super::driver::Parallel;
use crate::error::Result;
use crate::mtl::experiment::{ExperimentConfig, ExperimentResult, Tally};
use crate::study::RocStudy;

/// Runs `cfg` on `threads` worker threads (0 = all cores). `on_progress(done, total)` is called
/// after every wave; when `cancel` becomes true the run stops after the current wave with
/// [`crate::Error::Cancelled`].
pub fn run_experiment_parallel(
    cfg: &ExperimentConfig,
    threads: usize,
    cancel: &AtomicBool,
    on_progress: impl FnMut(usize, usize),
) -> Result<ExperimentResult> {
    let tally = run_experiment_range(cfg, 0..cfg.realisations, threads, cancel, on_progress)?;
    Ok(tally.finish(cfg))
}

/// The tally of the realisations `realisations` of `cfg` (a shard: [`crate::math::Shard::range`]
/// of `cfg.realisations`) on `threads` worker threads; progress (counting these realisations)
/// and cancel as in [`run_experiment_parallel`]. Tallies of disjoint ranges merged with
/// [`Tally::merge`] equal the tally of their union exactly; an empty range gives an empty
/// tally. [`crate::Error::IndexOutOfRange`] (`realisations`) past the last realisation.
pub fn run_experiment_range(
    cfg: &ExperimentConfig,
    realisations: Range<usize>,
    threads: usize,
    cancel: &AtomicBool,
    mut on_progress: impl FnMut(usize, usize),
) -> Result<Tally> {
    RocStudy::run_range(
        cfg,
        realisations,
        &mut Parallel::new(threads, cancel),
        &mut on_progress,
    )
}
