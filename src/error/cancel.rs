//! In-run cancellation (issue 24, "Long work"): long work asks a [`Cancel`] every few
//! milliseconds of work whether to stop, inside a Monte Carlo run or a track, not only between
//! units, so Ctrl-C (the CLI) or Stop (the page) ends a run of 10⁶ particles at once. The core
//! stays `no_std`: the question is a callback the front end supplies (the CLI reads the flag its
//! Ctrl-C handler sets).

use core::fmt;

use crate::error::{Error, Result};

/// Whether the caller wants the work to stop: a callback asked from inside a run.
#[derive(Clone, Copy)]
pub struct Cancel<'a> {
    stop: Option<&'a (dyn Fn() -> bool + Sync)>,
}

/// Work between two checks of a [`Cancel`] inside a run: about one millisecond (see
/// [`check_every`]).
pub const CHECK_NS: f64 = 1e6;

impl Cancel<'static> {
    /// Never stops (the library's plain entry points).
    pub const NEVER: Cancel<'static> = Cancel { stop: None };
}

impl<'a> Cancel<'a> {
    /// Stops once `stop()` returns `true`.
    pub fn when(stop: &'a (dyn Fn() -> bool + Sync)) -> Cancel<'a> {
        Cancel { stop: Some(stop) }
    }

    /// Whether the caller asked to stop.
    pub fn requested(&self) -> bool {
        self.stop.is_some_and(|f| f())
    }

    /// [`Error::Cancelled`] once the caller asked to stop.
    pub fn check(&self) -> Result<()> {
        if self.requested() {
            Err(Error::Cancelled)
        } else {
            Ok(())
        }
    }
}

impl fmt::Debug for Cancel<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.stop.is_some() {
            "Cancel(callback)"
        } else {
            "Cancel::NEVER"
        })
    }
}

/// Steps of `step_ns` predicted nanoseconds each (`crate::track::step_ns`) between two checks
/// of a [`Cancel`]: about [`CHECK_NS`] of work, at least 1 (a step longer than that is checked
/// after every step), at most 4096.
pub fn check_every(step_ns: f64) -> usize {
    if !(step_ns.is_finite() && step_ns > 0.0) {
        return 1;
    }
    (CHECK_NS / step_ns).clamp(1.0, 4096.0) as usize
}
