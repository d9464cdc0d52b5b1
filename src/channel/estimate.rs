//! The snapshot estimator (C5) — SKELETON: the estimator helper fills this in.

use alloc::vec::Vec;

use crate::channel::{Band, DelayEstimate};
use crate::error::Result;
use crate::math::{sqrt, Complex, Real};

/// Settings of the snapshot estimator (C5 **[choice]**).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimatorConfig {
    /// Largest number of paths per snapshot `M_max`.
    pub max_paths: usize,
    /// Design false-alarm probability per snapshot `P_fa` of the CFAR stop.
    pub p_fa: Real,
    /// Delay-grid oversampling of the periodogram (≥ 4).
    pub oversample: usize,
    /// Search window `[start, end]` of absolute delays, s (`None`: the whole unambiguous span).
    pub window_s: Option<(Real, Real)>,
}

/// One estimated path (C5 output).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathEstimate {
    /// `τ̂`, s.
    pub delay_s: Real,
    /// `α̂`, √W.
    pub alpha: Complex,
    /// `σ̂_τ`, s (C4 at the fitted SNR, or from the joint Fisher matrix).
    pub sigma_s: Real,
    /// Fitted integrated SNR `N|α̂|²/σ̂²`, linear.
    pub snr: Real,
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

/// One snapshot's result.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotEstimate {
    /// The paths, ascending in delay.
    pub paths: Vec<PathEstimate>,
    /// The noise variance used, W.
    pub noise_var: Real,
}

/// The estimator of one band (plans, scratch buffers).
#[derive(Debug, Clone)]
pub struct Estimator {
    _band: Band,
    _cfg: EstimatorConfig,
}

impl Estimator {
    /// An estimator for `band` with `cfg` (validated).
    pub fn new(band: Band, cfg: EstimatorConfig) -> Result<Estimator> {
        Ok(Estimator {
            _band: band,
            _cfg: cfg,
        })
    }

    /// Estimates the paths of one response `h` (`None` noise: estimated from the data), with
    /// `seeds` (predicted delays, s) refined first.
    pub fn estimate(
        &mut self,
        _h: &[Complex],
        _noise_var: Option<Real>,
        _seeds: &[Real],
    ) -> Result<SnapshotEstimate> {
        todo!("estimator helper")
    }
}
