//! What the estimator returns per snapshot (C5 output): the paths ([`PathEstimate`]), the noise
//! variance, and the work done against the loops' bounds ([`EstimateWork`]) with the reason the
//! greedy loop stopped ([`Stop`]).

use alloc::vec::Vec;

use crate::channel::DelayEstimate;
use crate::math::{sqrt, Complex, Real};

#[cfg(doc)]
use crate::error::limits;

/// One estimated path (C5 output).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathEstimate {
    /// `τ̂`, s (inside the search window).
    pub delay_s: Real,
    /// `α̂`, √W.
    pub alpha: Complex,
    /// `σ̂_τ`, s (joint Fisher matrix of all fitted paths; C4 at the fitted SNR as fallback).
    pub sigma_s: Real,
    /// Fitted integrated SNR `Σ|P|²·|α̂|²/σ̂²` (C3: `N|α̂|²/σ̂²` for `P = 1`), linear.
    pub snr: Real,
    /// Its range rate over the scan's CPI, when the front end read one (issue 42 §2).
    pub range_rate: Option<crate::channel::RateEstimate>,
}

impl PathEstimate {
    /// The entry gating reads.
    pub fn delay_estimate(&self) -> DelayEstimate {
        DelayEstimate {
            delay_s: self.delay_s,
            amplitude: sqrt(self.alpha.norm_sqr()),
            sigma_s: Some(self.sigma_s),
        }
    }
}

/// Why a snapshot's greedy loop stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Stop {
    /// Nothing left above the CFAR threshold (the normal end).
    #[default]
    Threshold,
    /// `M_max` paths and a residual peak still above the threshold: a bound was reached.
    PathBudget,
    /// More than `M_max` of the strongest peaks were fitted paths' misfits (slid onto one, or
    /// merged into one).
    Merged,
}

impl Stop {
    /// Its name: `threshold`, `path_budget`, `merged` (EST.json counts the snapshots that
    /// stopped at a bound in `front_end.bounds`).
    pub fn name(self) -> &'static str {
        match self {
            Stop::Threshold => "threshold",
            Stop::PathBudget => "path_budget",
            Stop::Merged => "merged",
        }
    }
}

/// What one snapshot's estimation did, against the stated bounds of its loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EstimateWork {
    /// Greedy passes (periodograms), at most `2·M_max + 1`.
    pub passes: usize,
    /// The most refinement sweeps after one new path (at most [`limits::ESTIMATOR_SWEEPS`]).
    pub sweeps: usize,
    /// The most Newton iterations of one new path (at most [`limits::NEWTON_ITERATIONS`]).
    pub newton: usize,
    /// Whether some refinement ended at its sweep bound without converging.
    pub sweeps_capped: bool,
    /// Why the greedy loop stopped.
    pub stop: Stop,
}

impl EstimateWork {
    /// Whether a bound ended this snapshot's work (the path budget with a peak left, or the
    /// sweep bound): the snapshot returns what it has and is counted.
    pub fn bounded(&self) -> bool {
        self.stop == Stop::PathBudget || self.sweeps_capped
    }
}

/// One snapshot's result.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotEstimate {
    /// The paths, ascending in delay.
    pub paths: Vec<PathEstimate>,
    /// The noise variance used, W (given, or estimated from the final residual; floored).
    pub noise_var: Real,
    /// What the estimation did against its bounds.
    pub work: EstimateWork,
}
