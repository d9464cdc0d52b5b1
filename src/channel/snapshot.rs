//! What the front end hands to gating (spec §4, E4): per snapshot and link the list of path
//! estimates.

use alloc::vec::Vec;

use crate::math::Real;

/// One entry of a parameter estimator's per-snapshot list: a delay, its amplitude and, when the
/// estimator gives one, its standard deviation (C5: from C4 at the fitted SNR).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DelayEstimate {
    /// `τ̂`, s.
    pub delay_s: Real,
    /// Amplitude `|α̂|` (√W for recordings; any linear unit otherwise; only compared within a
    /// link).
    pub amplitude: Real,
    /// `σ̂_τ` of this estimate, s, when the estimator gives one (`None`: the tracker uses the
    /// link budget, E8).
    pub sigma_s: Option<Real>,
}

/// One snapshot of every link: `snapshot[p]` = link `p`'s estimates (scenario link order). The
/// one type through which estimates reach gating ([`crate::track::gating::select`]).
pub type Snapshot = Vec<Vec<DelayEstimate>>;
