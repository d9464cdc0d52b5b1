//! Calibration by delay and amplitude (C7, \[S\] §3.1, \[I\] §III).
//!
//! The papers cluster each link's calibration estimates in (delay, amplitude in dB) with X-means.
//! This is the documented deterministic alternative C7 allows: per link,
//! 1. sort all estimates of all calibration snapshots by delay and split where consecutive
//!    delays differ by more than `gap_s` (`1/B`: the delay-only clusterer's rule, spec §4);
//! 2. within each delay group, sort by amplitude `20·log10|α̂|` and split where consecutive
//!    amplitudes differ by more than `amplitude_gap_db` (default 10 dB): estimator false alarms
//!    near the CFAR threshold fall apart from a static path well above it even when they share
//!    its delay group;
//! 3. keep a cluster seen in at least `min_fraction` of the snapshots (a snapshot counts once);
//! 4. per kept cluster: the mean and sample σ of the delay (σ floored at `sigma_floor_s`) and
//!    the mean and sample σ of the amplitude in dB.
//!
//! The steps run on the skeleton the delay-only clusterer shares (`clustering.rs`: sizes, sort,
//! gap splits, the snapshot fraction, the statistics). The kept clusters are the static
//! clusters of E4 (ascending in mean delay), so [`LinkCalibration::is_static`] gates with them
//! exactly as with the delay-only ones. An estimate with amplitude `0` (no dB value) is
//! skipped; a non-finite or negative amplitude is an error.

use alloc::format;
use alloc::vec::Vec;

use crate::channel::DelayEstimate;
use crate::error::{limits, Error, Result};
use crate::math::{log10, Real};
use crate::track::gating::clustering::{cluster_link, cluster_network, Entry};
use crate::track::gating::{Calibration, ClusterConfig, LinkCalibration};

/// Settings of the delay-and-amplitude clusterer (C7 **\[choice\]**, module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AmplitudeClusterConfig {
    /// Split between sorted consecutive delays further apart than this, s (default `1/B`).
    pub gap_s: Real,
    /// Split between sorted consecutive amplitudes further apart than this, dB (default 10).
    pub amplitude_gap_db: Real,
    /// Keep a cluster only if it holds at least this fraction of the snapshots (default 0.5).
    pub min_fraction: Real,
    /// Floor of a cluster's delay standard deviation, s (default `0.01/B`).
    pub sigma_floor_s: Real,
}

impl AmplitudeClusterConfig {
    /// The defaults for a receiver bandwidth `B` (Hz): `1/B`, 10 dB, 50 %, `0.01/B`.
    pub fn for_bandwidth(bandwidth_hz: Real) -> Result<AmplitudeClusterConfig> {
        let d = ClusterConfig::for_bandwidth(bandwidth_hz)?;
        Ok(AmplitudeClusterConfig {
            gap_s: d.gap_s,
            amplitude_gap_db: 10.0,
            min_fraction: d.min_fraction,
            sigma_floor_s: d.sigma_floor_s,
        })
    }

    /// The delay part of the settings.
    pub fn delay_config(&self) -> ClusterConfig {
        ClusterConfig {
            gap_s: self.gap_s,
            min_fraction: self.min_fraction,
            sigma_floor_s: self.sigma_floor_s,
        }
    }

    /// Checks the settings: those of [`ClusterConfig::validate`] and a finite amplitude gap
    /// `> 0` (field `calibration.amplitude_gap_db`).
    pub fn validate(&self) -> Result<()> {
        self.delay_config().validate()?;
        if !(self.amplitude_gap_db.is_finite() && self.amplitude_gap_db > 0.0) {
            return Err(Error::NotPositive {
                field: "calibration.amplitude_gap_db".into(),
                value: self.amplitude_gap_db,
            });
        }
        Ok(())
    }
}

impl LinkCalibration {
    /// Clusters link `link`'s calibration estimates (`snapshots[k]` = its list in snapshot `k`)
    /// by delay and amplitude (module docs). Errors: no snapshots or too many (`SizeLimit`), a
    /// delay outside [`limits::DELAY_S`] or a non-finite or negative amplitude (naming
    /// `calibration[k][link][i]`), invalid settings.
    pub fn from_estimates(
        link: usize,
        snapshots: &[Vec<DelayEstimate>],
        cfg: &AmplitudeClusterConfig,
    ) -> Result<LinkCalibration> {
        Self::from_estimate_lists(link, snapshots.iter().map(Vec::as_slice), cfg)
    }

    fn from_estimate_lists<'s>(
        link: usize,
        lists: impl ExactSizeIterator<Item = &'s [DelayEstimate]> + Clone,
        cfg: &AmplitudeClusterConfig,
    ) -> Result<LinkCalibration> {
        cfg.validate()?;
        let delay = cfg.delay_config();
        cluster_link(lists, &delay, Some(cfg.amplitude_gap_db), |k, i, e| {
            limits::DELAY_S.check(&format!("calibration[{k}][{link}][{i}].delay_s"), e.delay_s)?;
            if !(e.amplitude.is_finite() && e.amplitude >= 0.0) {
                return Err(Error::OutOfRange {
                    field: format!("calibration[{k}][{link}][{i}].amplitude"),
                    value: e.amplitude,
                    allowed: "finite and ≥ 0",
                });
            }
            Ok((e.amplitude > 0.0).then(|| Entry {
                delay_s: e.delay_s,
                snapshot: k,
                amplitude_db: Some(20.0 * log10(e.amplitude)),
            }))
        })
    }
}

impl Calibration {
    /// Clusters the calibration estimates of a network of `links` links (`snapshots[k][p]` =
    /// link `p`'s estimates in snapshot `k`, e.g. [`crate::channel::Snapshot`]s) by delay and
    /// amplitude (C7; [`LinkCalibration::from_estimates`]). Errors: a snapshot without one list
    /// per link (`LengthMismatch`), and those of [`LinkCalibration::from_estimates`].
    pub fn from_estimates(
        snapshots: &[Vec<Vec<DelayEstimate>>],
        links: usize,
        cfg: &AmplitudeClusterConfig,
    ) -> Result<Calibration> {
        cluster_network(snapshots, links, |p| {
            LinkCalibration::from_estimate_lists(p, snapshots.iter().map(|s| s[p].as_slice()), cfg)
        })
    }
}

#[cfg(test)]
mod tests;
