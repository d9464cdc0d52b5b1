//! Long work off the interpreter: a study runs on a worker thread with the GIL released while
//! the calling thread wakes every 50 ms to check Python's signals — Ctrl-C in a terminal or a
//! notebook's interrupt button sets the core's cancel flag, the work stops within milliseconds
//! ([`scatterloc::error::Cancel`]) and the call raises `KeyboardInterrupt` — and to report
//! progress to an optional Python callable `progress(done, total)`.
//!
//! Every call of core work goes through [`guarded`] (by [`run_job`], [`run_sized`] and
//! [`run_quick`]): a panic inside the library — a bug — becomes a `ScatterlocError` of kind
//! `"Panic"` ([`crate::errors::panic_error`]) instead of crossing into Python as
//! `pyo3_runtime.PanicException` (a `BaseException` that `except Exception` does not catch).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use pyo3::prelude::*;

use crate::errors::{arg_error, core_error, panic_error};

/// How often the calling thread checks signals and reports progress.
const POLL: Duration = Duration::from_millis(50);

/// Most worker threads a call may ask for (`threads=`), as the CLI's `--threads` (0 = all
/// cores).
pub const MAX_THREADS: usize = 256;

/// `threads` checked as the CLI checks `--threads`: 0 (all cores) … [`MAX_THREADS`], else a
/// `ScatterlocError` naming `threads` before any work (or any thread) starts.
pub fn check_threads(threads: usize) -> PyResult<()> {
    if threads > MAX_THREADS {
        return Err(arg_error(
            "threads",
            format!("{threads} is outside the allowed range 0..={MAX_THREADS} (0 = all cores)"),
        ));
    }
    Ok(())
}

/// Why core work gave no value.
pub enum Failed {
    /// The library's error.
    Core(scatterloc::Error),
    /// A panic inside the library (a bug), with its message.
    Panic(String),
}

impl From<Failed> for PyErr {
    fn from(f: Failed) -> PyErr {
        match f {
            Failed::Core(e) => core_error(e),
            Failed::Panic(message) => panic_error(&message),
        }
    }
}

/// Runs core `work`, a panic inside it caught as [`Failed::Panic`]: the one place the binding
/// catches panics (module doc). The work's state is dropped with it (nothing is reused after a
/// panic), so the unwind-safety assertion holds.
pub fn guarded<T>(work: impl FnOnce() -> scatterloc::Result<T>) -> Result<T, Failed> {
    match catch_unwind(AssertUnwindSafe(work)) {
        Ok(r) => r.map_err(Failed::Core),
        Err(payload) => {
            let message = if let Some(s) = payload.downcast_ref::<&str>() {
                (*s).to_string()
            } else if let Some(s) = payload.downcast_ref::<String>() {
                s.clone()
            } else {
                "a panic without a message".to_string()
            };
            Err(Failed::Panic(message))
        }
    }
}

/// The flags a running job shares with the calling thread.
pub struct Job {
    /// Set on Ctrl-C (or when the progress callback raised): the work stops.
    pub cancel: AtomicBool,
    /// Units done so far (set by the work).
    pub done: AtomicUsize,
}

impl Job {
    /// Records `n` units done.
    pub fn set_done(&self, n: usize) {
        self.done.store(n, Ordering::Relaxed);
    }

    /// Adds `n` units done.
    pub fn add_done(&self, n: usize) {
        self.done.fetch_add(n, Ordering::Relaxed);
    }

    /// Whether the caller asked the work to stop.
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

/// Runs `work` on a scoped worker thread with the GIL released (see the module doc). `total` is
/// the unit count `progress` is called with. Core errors (and panics, [`guarded`]) become
/// Python exceptions; a cancelled run raises the `KeyboardInterrupt` (or the callback's
/// exception) that stopped it.
pub fn run_job<T: Send>(
    py: Python<'_>,
    total: usize,
    progress: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce(&Job) -> scatterloc::Result<T> + Send,
) -> PyResult<T> {
    let job = Job {
        cancel: AtomicBool::new(false),
        done: AtomicUsize::new(0),
    };
    let (tx, rx) = mpsc::channel();
    std::thread::scope(|scope| {
        let job = &job;
        scope.spawn(move || {
            // The receiver outlives the scope; a send cannot fail before it returns.
            let _ = tx.send(guarded(|| work(job)));
        });
        let mut stopped: Option<PyErr> = None;
        let mut reported = usize::MAX;
        let mut rx = rx;
        loop {
            // The receiver goes into the GIL-free wait and comes back (it is Send, not Sync).
            let (got, back) = py.detach(move || (rx.recv_timeout(POLL), rx));
            rx = back;
            match got {
                Ok(result) => {
                    return match (stopped, result) {
                        (Some(e), _) => Err(e),
                        (None, Ok(v)) => {
                            // The last report: everything done.
                            if let Some(cb) = progress {
                                if reported != total {
                                    cb.call1((total, total))?;
                                }
                            }
                            Ok(v)
                        }
                        (None, Err(e)) => Err(e.into()),
                    };
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if stopped.is_some() {
                        continue;
                    }
                    if let Err(e) = py.check_signals() {
                        job.cancel.store(true, Ordering::SeqCst);
                        stopped = Some(e);
                        continue;
                    }
                    if let Some(cb) = progress {
                        let done = job.done.load(Ordering::Relaxed).min(total);
                        if done != reported {
                            reported = done;
                            if let Err(e) = cb.call1((done, total)) {
                                job.cancel.store(true, Ordering::SeqCst);
                                stopped = Some(e);
                            }
                        }
                    }
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(pyo3::exceptions::PyRuntimeError::new_err(
                        "scatterloc: the worker thread ended without a result",
                    ));
                }
            }
        }
    })
}

/// Work predicted to take less than this runs on the calling thread ([`run_sized`]): starting
/// and joining a worker thread costs ≈ 20 µs, a large part of a short call.
pub const INLINE_S: f64 = 0.05;

/// [`run_job`] for work the core's cost model predicts to take `predicted_s` seconds: below
/// [`INLINE_S`] (and without a progress callback) on the calling thread with the GIL released
/// (a Ctrl-C then waits for it, at most that long), else on a worker as [`run_job`].
pub fn run_sized<T: Send>(
    py: Python<'_>,
    predicted_s: f64,
    total: usize,
    progress: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce(&Job) -> scatterloc::Result<T> + Send,
) -> PyResult<T> {
    if predicted_s < INLINE_S && progress.is_none() {
        let job = Job {
            cancel: AtomicBool::new(false),
            done: AtomicUsize::new(0),
        };
        return py.detach(|| guarded(|| work(&job))).map_err(PyErr::from);
    }
    run_job(py, total, progress, work)
}

/// Runs short `work` with the GIL released on the calling thread (no polling): for calls of
/// bounded, small cost (a map, a fix, a track of a few thousand steps, reading a file).
pub fn run_quick<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> scatterloc::Result<T> + Send,
) -> PyResult<T> {
    py.detach(|| guarded(work)).map_err(PyErr::from)
}
