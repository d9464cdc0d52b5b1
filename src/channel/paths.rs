//! Path tracking over snapshots (C6) — SKELETON: the estimator helper fills this in.

use alloc::vec::Vec;

use crate::channel::{Estimator, PathEstimate};
use crate::error::Result;
use crate::math::{Complex, Real};

/// Settings of the per-link path tracker (C6 **[choice]**).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathTrackerConfig {
    /// Confirm after `m` hits in the last `n` snapshots.
    pub confirm_m: usize,
    /// See `confirm_m`.
    pub confirm_n: usize,
    /// End a track after this many consecutive misses.
    pub end_misses: usize,
}

/// One path of a snapshot with its track.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackedPath {
    /// The snapshot estimate.
    pub estimate: PathEstimate,
    /// The path track's id (unique per link).
    pub track_id: u32,
    /// Whether the track is confirmed.
    pub confirmed: bool,
}

/// The path tracker of one link.
#[derive(Debug, Clone)]
pub struct PathTracker {
    _estimator: Estimator,
    _cfg: PathTrackerConfig,
}

impl PathTracker {
    /// A tracker estimating with `estimator`.
    pub fn new(estimator: Estimator, cfg: PathTrackerConfig) -> Result<PathTracker> {
        Ok(PathTracker {
            _estimator: estimator,
            _cfg: cfg,
        })
    }

    /// One snapshot at `t_s`: predict the tracks, estimate seeded by them, associate.
    pub fn step(
        &mut self,
        _t_s: Real,
        _h: &[Complex],
        _noise_var: Option<Real>,
    ) -> Result<Vec<TrackedPath>> {
        todo!("estimator helper")
    }
}
