//! Simulated output of the per-snapshot parameter estimator (spec §4, §9.6): per link a list of
//! (delay, amplitude) estimates made of the static paths (the LoS and one path per static point
//! reflector, each jittering with `σ_static` from snapshot to snapshot), the mobile scatterer's
//! echo (delay noise `σ_p(r)` from E8, amplitude `√SNR_p(r)`) unless it lies within the delay
//! resolution `1/B` of a static path (the blind zone, `cΔτ_p < c/B`: the estimator cannot
//! resolve it, the link drops out), and uniformly drawn false alarms of unit amplitude.
//!
//! This stands in for KEST on measured channel sounder data, which is outside this crate; it is
//! what the gating and association of [`crate::track::gating`] are tested on.

use alloc::vec::Vec;

use rand::Rng as _;
use rand_distr::{Distribution, Poisson};

use crate::error::{Error, Result};
use crate::math::{sqrt, Real, Vec2};
use crate::measure::Model;
use crate::measure::{standard_normal, Rng};
use crate::track::gating::DelayEstimate;

/// Largest mean number of false alarms per link and snapshot accepted.
pub const MAX_FALSE_ALARMS: Real = 100.0;

/// The static channel and the estimator's imperfections.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticChannel {
    /// Static point reflectors (walls, furniture), m: each adds a static path to every link.
    pub reflectors_m: Vec<Vec2>,
    /// Snapshot-to-snapshot standard deviation of a static path's delay estimate, s.
    pub static_sigma_s: Real,
    /// Amplitude of the static paths (the echo's is `√SNR`).
    pub static_amplitude: Real,
    /// Delay resolution `1/B`, s: an echo this close to a static path is not resolved.
    pub resolution_s: Real,
    /// Mean number of false alarms per link and snapshot (Poisson).
    pub false_alarms: Real,
    /// False alarms are uniform in `[τ_LoS, τ_LoS + false_alarm_span_s]`.
    pub false_alarm_span_s: Real,
}

impl StaticChannel {
    /// Checks the settings: finite reflectors, `σ_static`, resolution and span `> 0`, a false
    /// alarm rate in `[0, 100]`.
    pub fn validate(&self) -> Result<()> {
        for (i, r) in self.reflectors_m.iter().enumerate() {
            if !(r.x.is_finite() && r.y.is_finite()) {
                return Err(Error::NonFinite {
                    field: alloc::format!("reflectors_m[{i}]"),
                });
            }
        }
        for (field, v) in [
            ("static_sigma_s", self.static_sigma_s),
            ("static_amplitude", self.static_amplitude),
            ("resolution_s", self.resolution_s),
            ("false_alarm_span_s", self.false_alarm_span_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::NotPositive {
                    field: field.into(),
                    value: v,
                });
            }
        }
        if !(0.0..=MAX_FALSE_ALARMS).contains(&self.false_alarms) {
            return Err(Error::OutOfRange {
                field: "false_alarms".into(),
                value: self.false_alarms,
                allowed: "0 … 100 per link and snapshot",
            });
        }
        Ok(())
    }

    /// The static path delays of link `p`: the LoS first, then one per reflector, s.
    pub fn static_delays(&self, model: &Model, p: usize) -> Vec<Real> {
        let mut d = Vec::with_capacity(1 + self.reflectors_m.len());
        d.push(model.network.los_delay(p));
        d.extend(self.reflectors_m.iter().map(|r| model.network.delay(p, *r)));
        d
    }

    /// Whether an echo at delay `tau` on link `p` is resolved from every static path.
    pub fn resolved(&self, model: &Model, p: usize, tau: Real) -> bool {
        self.resolved_from(&self.static_delays(model, p), tau)
    }

    /// Whether `tau` is at least the resolution away from every delay of `statics`.
    fn resolved_from(&self, statics: &[Real], tau: Real) -> bool {
        statics.iter().all(|s| (tau - s).abs() >= self.resolution_s)
    }

    /// One snapshot's estimates for every link with the scatterer at `target` (`None`: the
    /// empty area, as during calibration). Estimates are sorted by delay within a link.
    pub fn snapshot(
        &self,
        model: &Model,
        target: Option<Vec2>,
        rng: &mut Rng,
    ) -> Vec<Vec<DelayEstimate>> {
        let poisson = Poisson::new(self.false_alarms).ok();
        (0..model.link_count())
            .map(|p| {
                let statics = self.static_delays(model, p);
                let mut list: Vec<DelayEstimate> = statics
                    .iter()
                    .map(|&s| DelayEstimate {
                        delay_s: s + self.static_sigma_s * standard_normal(rng),
                        amplitude: self.static_amplitude,
                        sigma_s: None,
                    })
                    .collect();
                if let Some(r) = target {
                    let tau = model.network.delay(p, r);
                    let noisy = tau + model.sigma_delay(p, r) * standard_normal(rng);
                    if self.resolved_from(&statics, tau) {
                        list.push(DelayEstimate {
                            delay_s: noisy,
                            amplitude: sqrt(model.snr(p, r)),
                            sigma_s: None,
                        });
                    }
                }
                let alarms = poisson.as_ref().map_or(0, |d| d.sample(rng) as usize);
                for _ in 0..alarms {
                    let u: Real = rng.random();
                    list.push(DelayEstimate {
                        delay_s: statics[0] + u * self.false_alarm_span_s,
                        amplitude: 1.0,
                        sigma_s: None,
                    });
                }
                list.sort_by(|a, b| a.delay_s.total_cmp(&b.delay_s));
                list
            })
            .collect()
    }

    /// `count` calibration snapshots of the empty area as delays only (`[k][p]` = link `p`'s
    /// delays in snapshot `k`), as [`crate::track::gating::Calibration::from_snapshots`] takes them.
    pub fn calibration_snapshots(
        &self,
        model: &Model,
        count: usize,
        rng: &mut Rng,
    ) -> Vec<Vec<Vec<Real>>> {
        (0..count)
            .map(|_| {
                self.snapshot(model, None, rng)
                    .iter()
                    .map(|l| l.iter().map(|e| e.delay_s).collect())
                    .collect()
            })
            .collect()
    }
}
