//! Calibration stage and 3σ gating (spec §4, \[S\] §3.1–3.2, \[I\] §III-A/B).
//!
//! With no mobile object in the area (`Q = 0`) every link records `⌊T_cal/T_g⌋` snapshots, each a
//! list of estimated delays `τ̂` (from a parameter estimator such as KEST, which is outside this
//! crate). The delays of one link are clustered into its static paths `r = 0 … R_kl` (the LoS is
//! the earliest, index 0), each stored as a mean `τ̄_kl,r` and a standard deviation `σ̄_kl,r`.
//! In the estimation stage a delay is *static* and discarded when it lies within `3σ̄` of a
//! cluster mean (E4); the rest are the candidates of the mobile scatterer.
//!
//! The default clusterer is the spec's **\[choice\]** (delay only): sort all calibration delays of
//! the link, split where consecutive values differ by more than the gap `g = 1/B`, drop clusters
//! holding fewer than 50 % of the snapshots (counted as the snapshots with a delay in the
//! cluster, so one snapshot's repeated estimates count once), and floor `σ̄` at `σ_min = 0.01/B`.
//! Estimator false alarms recorded during calibration are a known weakness of this delay-only
//! rule: when they are denser than one per `g` they chain into one wide cluster that holds
//! most snapshots and then gates the echo as well; calibrate with a detection threshold that
//! keeps them sparse, or cluster by amplitude too: the papers use X-means on (amplitude, delay);
//! [`crate::track::gating::AmplitudeClusterConfig`] with [`Calibration::from_estimates`] is the
//! deterministic alternative (C7) behind the same [`LinkCalibration`]; both run on the skeleton
//! of `clustering.rs`.

use alloc::format;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::error::{check_len, limits, Error, Result};
use crate::math::Real;
use crate::track::gating::clustering::{cluster_link, cluster_network, Entry};

/// The gate's half-width in cluster standard deviations (E4).
pub const GATE_SIGMAS: Real = 3.0;

/// Largest number of calibration snapshots accepted per link.
pub const MAX_CALIBRATION_SNAPSHOTS: usize = 1_000_000;

/// Largest number of delays accepted in one link's calibration (all snapshots together).
pub const MAX_CALIBRATION_DELAYS: usize = 10_000_000;

/// Settings of the default delay-only clusterer (spec §4 **\[choice\]**).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClusterConfig {
    /// Split between sorted consecutive delays further apart than this, s (`g`, default `1/B`).
    pub gap_s: Real,
    /// Keep a cluster only if it holds at least this fraction of the snapshots (default 0.5).
    pub min_fraction: Real,
    /// Floor of a cluster's standard deviation, s (`σ_min`, default `0.01/B`).
    pub sigma_floor_s: Real,
}

impl ClusterConfig {
    /// The spec's defaults for a receiver bandwidth `B` (Hz): `g = 1/B`, 50 %, `σ_min = 0.01/B`.
    pub fn for_bandwidth(bandwidth_hz: Real) -> Result<ClusterConfig> {
        if !(bandwidth_hz.is_finite() && bandwidth_hz > 0.0) {
            return Err(Error::NotPositive {
                field: "radio.bandwidth_hz".into(),
                value: bandwidth_hz,
            });
        }
        Ok(ClusterConfig {
            gap_s: 1.0 / bandwidth_hz,
            min_fraction: 0.5,
            sigma_floor_s: 0.01 / bandwidth_hz,
        })
    }

    /// Checks the settings: a finite gap and floor `> 0`, a fraction in `[0, 1]`.
    pub fn validate(&self) -> Result<()> {
        for (field, v) in [
            ("calibration.gap_s", self.gap_s),
            ("calibration.sigma_floor_s", self.sigma_floor_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::NotPositive {
                    field: field.into(),
                    value: v,
                });
            }
        }
        if !(0.0..=1.0).contains(&self.min_fraction) {
            return Err(Error::OutOfRange {
                field: "calibration.min_fraction".into(),
                value: self.min_fraction,
                allowed: "0 … 1",
            });
        }
        Ok(())
    }
}

/// One static path of a link: `τ̄_kl,r` and `σ̄_kl,r` (JSON: `{"mean_s", "sigma_s", "count",
/// "snapshots", "amplitude_db_mean", "amplitude_db_sigma"}`, all but the first two optional).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StaticCluster {
    /// Cluster mean `τ̄`, s.
    pub mean_s: Real,
    /// Cluster standard deviation `σ̄` (sample, floored at `σ_min`), s.
    pub sigma_s: Real,
    /// Calibration delays in the cluster.
    #[serde(default)]
    pub count: usize,
    /// Calibration snapshots with at least one delay in the cluster (the 50 % rule counts these).
    #[serde(default)]
    pub snapshots: usize,
    /// Mean amplitude of the cluster's estimates, dB (`20·log10|α̂|`), when clustered by
    /// amplitude too (C7, [`crate::track::gating::AmplitudeClusterConfig`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude_db_mean: Option<Real>,
    /// Sample standard deviation of those amplitudes, dB.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude_db_sigma: Option<Real>,
}

impl StaticCluster {
    /// `|τ − τ̄| ≤ 3σ̄` (E4).
    #[inline]
    pub fn contains(&self, delay_s: Real) -> bool {
        (delay_s - self.mean_s).abs() <= GATE_SIGMAS * self.sigma_s
    }
}

/// The static paths of one link, ascending in delay (index 0 is the LoS when it was seen).
/// Deserialised values are unchecked: pass them through [`LinkCalibration::from_clusters`].
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkCalibration {
    /// The kept clusters, ascending in mean delay.
    pub clusters: Vec<StaticCluster>,
}

impl LinkCalibration {
    /// Clusters the calibration snapshots of link `link` (each a list of delay estimates, s)
    /// with the default clusterer. Errors: no snapshots or too many (`SizeLimit`), a non-finite
    /// delay (`NonFinite`, naming the snapshot), invalid settings.
    pub fn from_snapshots(
        link: usize,
        snapshots: &[Vec<Real>],
        cfg: &ClusterConfig,
    ) -> Result<LinkCalibration> {
        Self::from_lists(link, snapshots.iter().map(Vec::as_slice), cfg)
    }

    /// [`LinkCalibration::from_snapshots`] over link `link`'s list of each snapshot.
    fn from_lists<'s>(
        link: usize,
        lists: impl ExactSizeIterator<Item = &'s [Real]> + Clone,
        cfg: &ClusterConfig,
    ) -> Result<LinkCalibration> {
        cfg.validate()?;
        cluster_link(lists, cfg, None, |k, i, &d| {
            limits::DELAY_S.check(&format!("calibration[{k}][{link}][{i}]"), d)?;
            Ok(Some(Entry {
                delay_s: d,
                snapshot: k,
                amplitude_db: None,
            }))
        })
    }

    /// A link calibration from given clusters (e.g. read back from JSON): every mean finite and
    /// every `σ̄` finite and `> 0`; sorted by mean.
    pub fn from_clusters(link: usize, mut clusters: Vec<StaticCluster>) -> Result<LinkCalibration> {
        for (r, c) in clusters.iter().enumerate() {
            limits::DELAY_S.check(
                &format!("calibration.links[{link}].clusters[{r}].mean_s"),
                c.mean_s,
            )?;
            if !(c.sigma_s.is_finite() && c.sigma_s > 0.0) {
                return Err(Error::NotPositive {
                    field: format!("calibration.links[{link}].clusters[{r}].sigma_s"),
                    value: c.sigma_s,
                });
            }
        }
        clusters.sort_by(|a, b| a.mean_s.total_cmp(&b.mean_s));
        Ok(LinkCalibration { clusters })
    }

    /// E4: `τ̂` is static iff some cluster has `|τ̂ − τ̄_r| ≤ 3σ̄_r`.
    pub fn is_static(&self, delay_s: Real) -> bool {
        self.clusters.iter().any(|c| c.contains(delay_s))
    }
}

/// The calibration of every link of a scenario, in scenario link order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Calibration {
    /// Per link, its static clusters.
    pub links: Vec<LinkCalibration>,
}

impl Calibration {
    /// Clusters the calibration snapshots of a network of `links` links (`snapshots[k][p]` =
    /// link `p`'s delays in snapshot `k`, as recorded). Errors: a snapshot without one list per
    /// link (`LengthMismatch`), and those of [`LinkCalibration::from_snapshots`].
    pub fn from_snapshots(
        snapshots: &[Vec<Vec<Real>>],
        links: usize,
        cfg: &ClusterConfig,
    ) -> Result<Calibration> {
        cluster_network(snapshots, links, |p| {
            LinkCalibration::from_lists(p, snapshots.iter().map(|s| s[p].as_slice()), cfg)
        })
    }

    /// Number of links calibrated.
    pub fn link_count(&self) -> usize {
        self.links.len()
    }

    /// Checks that there is one entry per link of a model with `links` links.
    pub fn check_links(&self, links: usize) -> Result<()> {
        check_len("calibration.links", links, self.links.len())?;
        Ok(())
    }
}

#[cfg(test)]
mod tests;
