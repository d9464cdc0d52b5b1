//! The §8 experiments ([`crate::mtl::experiment`]) on the ordered driver ([`run_ordered`]):
//! realisations run in parallel and their counts are merged in realisation order, so the result
//! is identical for any thread count (and equal to [`crate::mtl::experiment::run_sequential`]).

use std::sync::atomic::AtomicBool;

use super::driver::run_ordered;
use crate::error::Result;
use crate::mtl::experiment::{evaluate, ExperimentConfig, ExperimentResult, Tally};

/// Runs `cfg` on `threads` worker threads (0 = all cores). `on_progress(done, total)` is called
/// after every wave; when `cancel` becomes true the run stops after the current wave with
/// [`crate::Error::Cancelled`].
pub fn run_experiment_parallel(
    cfg: &ExperimentConfig,
    threads: usize,
    cancel: &AtomicBool,
    mut on_progress: impl FnMut(usize, usize),
) -> Result<ExperimentResult> {
    cfg.validate()?;
    let total = cfg.realisations;
    let mut tally = Tally::new(cfg.curves().len(), cfg.sweep.len());
    run_ordered(
        total,
        threads,
        8,
        cancel,
        |i| evaluate(cfg, i as u64),
        |part| tally.add(&part),
        |done| on_progress(done, total),
    )?;
    Ok(tally.finish(cfg))
}
