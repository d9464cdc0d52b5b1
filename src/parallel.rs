//! Native parallel driver of the Monte Carlo study ([`crate::montecarlo`]): chunks run on a
//! rayon pool in waves; partial sums are merged in chunk order, so the result is identical for
//! any thread count. Between waves it reports progress and honours a cancel flag (Ctrl-C).

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::model::Model;
use crate::montecarlo::{finish, run_chunk, MonteCarloConfig, MonteCarloResult, PartialSums};

/// Runs the study on `threads` worker threads (0 = all cores). `on_progress(runs_done,
/// runs_total)` is called after every wave; when `cancel` becomes true the study stops after
/// the current wave with `Err(Error::Cancelled)`.
pub fn run_parallel(
    model: &Model,
    cfg: &MonteCarloConfig,
    threads: usize,
    cancel: &AtomicBool,
    mut on_progress: impl FnMut(usize, usize),
) -> Result<MonteCarloResult> {
    cfg.validate()?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|_| Error::SizeLimit {
            field: "threads",
            value: threads,
            min: 0,
            max: 1024,
        })?;
    let chunks = cfg.chunk_count();
    let wave = (4 * pool.current_num_threads()).max(1);
    let mut sums = PartialSums::new(cfg.steps);
    let runs_per_chunk = crate::montecarlo::CHUNK_TRAJECTORIES * cfg.noise_runs;
    let mut start = 0;
    while start < chunks {
        if cancel.load(Ordering::Relaxed) {
            return Err(Error::Cancelled);
        }
        let end = (start + wave).min(chunks);
        let parts: Vec<Result<PartialSums>> = pool.install(|| {
            (start..end)
                .into_par_iter()
                .map(|c| run_chunk(model, cfg, c))
                .collect()
        });
        for part in parts {
            sums.merge(&part?);
        }
        start = end;
        on_progress((start * runs_per_chunk).min(cfg.runs()), cfg.runs());
    }
    finish(cfg, &sums)
}
