//! The calibration files (spec §4, E4): the snapshots of the empty area that `calibrate`
//! clusters, and the static clusters per link it writes (`track --calibration` reads them).

use alloc::format;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use super::one_list_per_link;
use crate::error::{Error, Result};
use crate::scenario::parse_json;
use crate::track::gating::{
    Calibration, ClusterConfig, LinkCalibration, MAX_CALIBRATION_SNAPSHOTS,
};

/// The calibration snapshots (`calibrate --snapshots`; `simulate-walk` writes
/// `calibration_snapshots.json`): per snapshot, per link, the delay estimates, s.
///
/// # Example
///
/// ```
/// use scatterloc::formats::CalibrationSnapshots;
/// use scatterloc::track::gating::ClusterConfig;
///
/// let text = r#"{"snapshots": [[[4.0e-8]], [[4.0e-8, 9.0e-8]], [[4.0e-8]]]}"#;
/// let s = CalibrationSnapshots::from_json(text).unwrap();
/// s.check(1).unwrap();
/// let cal = s.calibrate(1, &ClusterConfig::for_bandwidth(100e6).unwrap()).unwrap();
/// // 9e-8 s is in one snapshot of three, below the 50 % rule: not a static path.
/// assert_eq!(cal.links[0].clusters.len(), 1);
/// // Two links expected, one given: named.
/// assert!(s.check(2).unwrap_err().to_string().starts_with("snapshots[0]: expected 2 lists"));
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationSnapshots {
    /// `snapshots[k][p]` = link `p`'s delays in snapshot `k`.
    pub snapshots: Vec<Vec<Vec<f64>>>,
}

impl CalibrationSnapshots {
    /// Parses a snapshots file (errors name the field: [`Error::Parse`]).
    pub fn from_json(text: &str) -> Result<CalibrationSnapshots> {
        parse_json(text)
    }

    /// Checks 1 … [`MAX_CALIBRATION_SNAPSHOTS`] snapshots, each with one list per each of
    /// `links` links ([`Error::InvalidFile`] naming `snapshots` or `snapshots[k]`).
    pub fn check(&self, links: usize) -> Result<()> {
        let n = self.snapshots.len();
        if n == 0 || n > MAX_CALIBRATION_SNAPSHOTS {
            return Err(Error::InvalidFile {
                field: "snapshots".into(),
                reason: format!("{n} given, 1 … {MAX_CALIBRATION_SNAPSHOTS} are allowed"),
            });
        }
        for (k, snap) in self.snapshots.iter().enumerate() {
            one_list_per_link(&format!("snapshots[{k}]"), snap.len(), links)?;
        }
        Ok(())
    }

    /// [`CalibrationSnapshots::check`], then the static clusters per link (spec §4
    /// **\[choice\]**, [`Calibration::from_snapshots`]).
    pub fn calibrate(&self, links: usize, cfg: &ClusterConfig) -> Result<Calibration> {
        self.check(links)?;
        Calibration::from_snapshots(&self.snapshots, links, cfg)
    }
}

/// The calibration result (`calibrate`'s output, `track --calibration`'s input): the
/// clusterer's settings (informative on input) and per link its static clusters.
///
/// # Example
///
/// ```
/// use scatterloc::formats::CalibrationResult;
///
/// let text = r#"{"links": [{"clusters": [{"mean_s": 4e-8, "sigma_s": 1e-10,
///                                          "count": 10, "snapshots": 10}]}]}"#;
/// let cal = CalibrationResult::from_json(text).unwrap().into_calibration(1).unwrap();
/// assert!(cal.links[0].is_static(4.0e-8));
/// // A calibration for one link does not fit a model with two.
/// assert!(CalibrationResult::from_json(text).unwrap().into_calibration(2).is_err());
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub struct CalibrationResult {
    /// Clusterer gap `g`, s (informative on input).
    #[serde(default)]
    pub gap_s: Option<f64>,
    /// The 50 % rule's fraction (informative on input).
    #[serde(default)]
    pub min_fraction: Option<f64>,
    /// `σ_min`, s (informative on input).
    #[serde(default)]
    pub sigma_floor_s: Option<f64>,
    /// Calibration snapshots used (informative on input).
    #[serde(default)]
    pub snapshot_count: Option<usize>,
    /// Per link in scenario link order: `{"clusters": [{"mean_s", "sigma_s", ..}]}`.
    pub links: Vec<LinkCalibration>,
}

impl CalibrationResult {
    /// Parses a calibration file (errors name the field: [`Error::Parse`]).
    pub fn from_json(text: &str) -> Result<CalibrationResult> {
        parse_json(text)
    }

    /// The file of a calibration made with `cfg` from `snapshot_count` snapshots.
    pub fn of(cal: Calibration, cfg: &ClusterConfig, snapshot_count: usize) -> CalibrationResult {
        CalibrationResult {
            gap_s: Some(cfg.gap_s),
            min_fraction: Some(cfg.min_fraction),
            sigma_floor_s: Some(cfg.sigma_floor_s),
            snapshot_count: Some(snapshot_count),
            links: cal.links,
        }
    }

    /// The validated calibration for a model with `links` links (each link's clusters as
    /// [`LinkCalibration::from_clusters`]; a wrong link count is `LengthMismatch`).
    pub fn into_calibration(self, links: usize) -> Result<Calibration> {
        let cal = Calibration {
            links: self
                .links
                .into_iter()
                .enumerate()
                .map(|(p, l)| LinkCalibration::from_clusters(p, l.clusters))
                .collect::<Result<Vec<_>>>()?,
        };
        cal.check_links(links)?;
        Ok(cal)
    }
}
