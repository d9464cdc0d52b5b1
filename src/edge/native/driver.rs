//! The one ordered parallel driver: `jobs` independent jobs run on a rayon pool in waves, and
//! their results are merged strictly in job order, so a result depends on the jobs alone, never
//! on the thread count. Between waves it reports progress and honours a cancel flag (Ctrl-C).

use std::sync::atomic::{AtomicBool, Ordering};
use std::vec::Vec;

use rayon::prelude::*;

use crate::error::{Cancel, Error, Result};
use crate::study::Driver;

/// Runs `job(0..jobs)` on `threads` workers (0 = all cores), `per_thread` jobs per worker and
/// wave, and calls `merge` with each result in job order. After each wave `on_progress(done)`
/// gets the number of jobs merged so far. When `cancel` becomes true the run stops before the
/// next wave with [`Error::Cancelled`]; the first job error (in job order) is returned as is.
pub fn run_ordered<T: Send>(
    jobs: usize,
    threads: usize,
    per_thread: usize,
    cancel: &AtomicBool,
    job: impl Fn(usize) -> Result<T> + Sync,
    mut merge: impl FnMut(T),
    mut on_progress: impl FnMut(usize),
) -> Result<()> {
    let pool = thread_pool(threads)?;
    let wave = (per_thread * pool.current_num_threads()).max(1);
    let mut start = 0;
    while start < jobs {
        if cancel.load(Ordering::Relaxed) {
            return Err(Error::Cancelled);
        }
        let end = (start + wave).min(jobs);
        let parts: Vec<Result<T>> =
            pool.install(|| (start..end).into_par_iter().map(&job).collect());
        for part in parts {
            merge(part?);
        }
        start = end;
        on_progress(start);
    }
    Ok(())
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

/// The study [`Driver`] on threads: [`run_ordered`] on `threads` workers (0 = all cores), with
/// `cancel` (Ctrl-C) checked between waves and, through the jobs' [`Cancel`], inside them. Results equal [`crate::study::Sequential`]'s for
/// any thread count.
pub struct Parallel<'a> {
    threads: usize,
    cancel: &'a AtomicBool,
}

impl<'a> Parallel<'a> {
    /// A driver on `threads` workers (0 = all cores) that stops when `cancel` becomes true.
    pub fn new(threads: usize, cancel: &'a AtomicBool) -> Parallel<'a> {
        Parallel { threads, cancel }
    }
}

impl Driver for Parallel<'_> {
    fn run<T: Send>(
        &mut self,
        jobs: usize,
        batch: usize,
        job: &(dyn Fn(usize, Cancel) -> Result<T> + Sync),
        merge: &mut dyn FnMut(T),
        progress: &mut dyn FnMut(usize),
    ) -> Result<()> {
        let flag = self.cancel;
        let stop = move || flag.load(Ordering::Relaxed);
        let cancel = Cancel::when(&stop);
        run_ordered(
            jobs,
            self.threads,
            batch,
            flag,
            |i| job(i, cancel),
            merge,
            progress,
        )
    }
}
