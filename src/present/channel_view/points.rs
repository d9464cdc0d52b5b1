//! The path estimates of the delay figure as points ([`DelayPoint`]): time, path length,
//! amplitude and, when the front end read the scan's CPI, the range rate with its σ (issue 42
//! §5: the figure draws it as the slope `d(c·τ)/dt = ṙ` of a short tick through the point,
//! docs/doppler.md D1).

use alloc::vec::Vec;

use crate::channel::{DelayEstimate, PathEstimate};
use crate::math::{log10, Real, SPEED_OF_LIGHT};

/// One path estimate as drawn: its time, path length, amplitude and range rate.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DelayPoint {
    /// Snapshot time, s.
    pub t_s: Real,
    /// Path length `c·τ̂`, m.
    pub range_m: Real,
    /// `20·log10|α̂|`, dB (re 1 √W for recordings).
    pub amplitude_db: Real,
    /// `[ṙ, σ_ṙ]`, m/s: the path's range rate over the scan's CPI and its σ (D5), the time
    /// derivative of `range_m`; absent without a CPI.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range_rate_mps: Option<[Real; 2]>,
}

/// An estimate [`delay_points`] can draw: its delay entry and, if measured, its range rate.
pub trait DrawnEstimate {
    /// The delay, amplitude (and σ) of the estimate.
    fn delay(&self) -> DelayEstimate;
    /// `[ṙ, σ_ṙ]`, m/s, if the estimate has one.
    fn range_rate(&self) -> Option<[Real; 2]>;
}

impl DrawnEstimate for DelayEstimate {
    fn delay(&self) -> DelayEstimate {
        *self
    }
    fn range_rate(&self) -> Option<[Real; 2]> {
        None
    }
}

impl DrawnEstimate for PathEstimate {
    fn delay(&self) -> DelayEstimate {
        self.delay_estimate()
    }
    fn range_rate(&self) -> Option<[Real; 2]> {
        self.range_rate.map(|r| [r.range_rate_mps, r.sigma_mps])
    }
}

/// The estimates of one link over snapshots as points: `estimates[s]` is snapshot `s`'s list
/// (at `t_s[s]`). Estimates with a non-finite delay or time, or a non-positive or non-finite
/// amplitude, have no place on the figure and are left out; a non-finite range rate or σ is
/// dropped (the point is drawn without it).
pub fn delay_points<E: DrawnEstimate>(t_s: &[Real], estimates: &[Vec<E>]) -> Vec<DelayPoint> {
    t_s.iter()
        .zip(estimates)
        .flat_map(|(&t, list)| {
            list.iter().filter_map(move |x| {
                let e = x.delay();
                let ok = t.is_finite()
                    && e.delay_s.is_finite()
                    && e.amplitude.is_finite()
                    && e.amplitude > 0.0;
                ok.then(|| DelayPoint {
                    t_s: t,
                    range_m: SPEED_OF_LIGHT * e.delay_s,
                    amplitude_db: 20.0 * log10(e.amplitude),
                    range_rate_mps: x
                        .range_rate()
                        .filter(|r| r[0].is_finite() && r[1].is_finite()),
                })
            })
        })
        .collect()
}
