//! Native parallel driver of the §8 experiments ([`crate::mtl::experiment`]): realisations run
//! on a rayon pool in waves and their counts are merged in realisation order, so the result is
//! identical for any thread count (and equal to [`crate::mtl::experiment::run_sequential`]).
//! Between waves it reports progress and honours a cancel flag (Ctrl-C).

use std::sync::atomic::{AtomicBool, Ordering};
use std::vec::Vec;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::mtl::experiment::{evaluate, ExperimentConfig, ExperimentResult, Tally};
use crate::parallel::thread_pool;

/// Runs `cfg` on `threads` worker threads (0 = all cores). `on_progress(done, total)` is called
/// after every wave; when `cancel` becomes true the run stops after the current wave with
/// [`Error::Cancelled`].
pub fn run_parallel(
    cfg: &ExperimentConfig,
    threads: usize,
    cancel: &AtomicBool,
    mut on_progress: impl FnMut(usize, usize),
) -> Result<ExperimentResult> {
    cfg.validate()?;
    let pool = thread_pool(threads)?;
    let wave = (8 * pool.current_num_threads()).max(1);
    let total = cfg.realisations;
    let mut tally = Tally::new(cfg.curves().len(), cfg.sweep.len());
    let mut start = 0;
    while start < total {
        if cancel.load(Ordering::Relaxed) {
            return Err(Error::Cancelled);
        }
        let end = (start + wave).min(total);
        let parts: Vec<Result<_>> = pool.install(|| {
            (start..end)
                .into_par_iter()
                .map(|i| evaluate(cfg, i as u64))
                .collect()
        });
        for part in parts {
            tally.add(&part?);
        }
        start = end;
        on_progress(start, total);
    }
    Ok(tally.finish(cfg))
}
