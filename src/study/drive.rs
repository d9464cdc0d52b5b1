//! The seam between a study and whoever runs its units: [`Driver`] runs independent jobs and
//! hands their results back strictly in job order, so a study's sums never depend on the
//! driver. [`Sequential`] is the core's own (one job after another, as the page's worker runs
//! them); `crate::native::Parallel` runs them on rayon threads. A job gets a [`Cancel`] to ask
//! inside its work (issue 24: a run of 10⁶ particles must stop on Ctrl-C within milliseconds).

use crate::error::{Cancel, Error, Result};

/// Runs `jobs` independent jobs and merges their results in job order.
pub trait Driver {
    /// Runs `job(0..jobs, cancel)` and calls `merge` with each result in job order, and
    /// `progress(done)` from time to time with the number of jobs merged so far. `batch` is a
    /// hint: jobs per worker between two progress reports. The first job error (in job order)
    /// is returned as is; a driver may stop early with [`Error::Cancelled`], and a job that
    /// sees its `cancel` asking returns [`Error::Cancelled`] itself.
    fn run<T: Send>(
        &mut self,
        jobs: usize,
        batch: usize,
        job: &(dyn Fn(usize, Cancel) -> Result<T> + Sync),
        merge: &mut dyn FnMut(T),
        progress: &mut dyn FnMut(usize),
    ) -> Result<()>;
}

/// The core's driver: jobs one after another on the calling thread, progress after each;
/// `keep_going(done, jobs)` returning `false` cancels ([`Error::Cancelled`]) between jobs. Its
/// jobs get [`Cancel::NEVER`]: the page stops a long job by terminating its worker
/// (`www/js/workers.js`).
pub struct Sequential<F: FnMut(usize, usize) -> bool = fn(usize, usize) -> bool> {
    keep_going: F,
}

impl Sequential {
    /// A driver that never cancels.
    pub fn new() -> Sequential {
        Sequential {
            keep_going: |_, _| true,
        }
    }
}

impl Default for Sequential {
    fn default() -> Self {
        Sequential::new()
    }
}

impl<F: FnMut(usize, usize) -> bool> Sequential<F> {
    /// A driver that asks `keep_going(done, jobs)` after each job.
    pub fn cancellable(keep_going: F) -> Sequential<F> {
        Sequential { keep_going }
    }
}

impl<F: FnMut(usize, usize) -> bool> Driver for Sequential<F> {
    fn run<T: Send>(
        &mut self,
        jobs: usize,
        _batch: usize,
        job: &(dyn Fn(usize, Cancel) -> Result<T> + Sync),
        merge: &mut dyn FnMut(T),
        progress: &mut dyn FnMut(usize),
    ) -> Result<()> {
        for i in 0..jobs {
            merge(job(i, Cancel::NEVER)?);
            progress(i + 1);
            if !(self.keep_going)(i + 1, jobs) {
                return Err(Error::Cancelled);
            }
        }
        Ok(())
    }
}
