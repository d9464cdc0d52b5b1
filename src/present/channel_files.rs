//! The files of the channel front end (issue 25) as serde objects, built once here for the CLI
//! (`cir estimate --out EST.json`, `cir track --out TRACK.json`) and the page's channel view,
//! so both write the same JSON for the same input.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use serde::Serialize;

use crate::formats::CalibrationResult;
use crate::math::{log10, Real};
use crate::measure::Model;
use crate::present::ErrorStats;
use crate::scenario::Scenario;
use crate::study::{CirTrackOutput, DelaySigma, FrontEndConfig, RecordingEstimates};
use crate::track::gating::Calibration;

/// One path of `EST.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathDoc {
    /// `τ̂`, s.
    pub delay_s: Real,
    /// `|α̂|` (√W for recordings).
    pub amplitude: Real,
    /// `σ̂_τ`, s.
    pub sigma_s: Real,
    /// The fitted SNR, dB (`null` at SNR ≤ 0).
    pub snr_db: Option<Real>,
    /// The path track's id.
    pub track: u32,
    /// Whether the path track is confirmed.
    pub confirmed: bool,
}

/// `EST.json`: the estimates of a recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EstimatesDoc<'a> {
    /// `scatterloc-estimates`.
    pub format: &'static str,
    /// Snapshot times, s.
    pub t_s: &'a [Real],
    /// Per model link `[transmitter, receiver]`.
    pub links: Vec<[usize; 2]>,
    /// Per model link whether the recording holds it.
    pub recorded: &'a [bool],
    /// `estimates[s][p]`: link `p`'s paths in snapshot `s`.
    pub estimates: Vec<Vec<Vec<PathDoc>>>,
    /// `noise_var[s][p]`, W.
    pub noise_var: &'a [Vec<Real>],
    /// The estimator's `max_paths`.
    pub max_paths: usize,
    /// The estimator's `p_fa`.
    pub p_fa: Real,
}

/// The `EST.json` of `e`, estimated with `cfg` on `model`'s links.
pub fn estimates_doc<'a>(
    model: &Model,
    e: &'a RecordingEstimates,
    cfg: &FrontEndConfig,
) -> EstimatesDoc<'a> {
    EstimatesDoc {
        format: "scatterloc-estimates",
        t_s: &e.t_s,
        links: model.network.links.iter().map(|l| [l.tx, l.rx]).collect(),
        recorded: &e.recorded,
        estimates: e
            .paths
            .iter()
            .map(|s| {
                s.iter()
                    .map(|l| {
                        l.iter()
                            .map(|t| PathDoc {
                                delay_s: t.estimate.delay_s,
                                amplitude: t.estimate.delay_estimate().amplitude,
                                sigma_s: t.estimate.sigma_s,
                                snr_db: (t.estimate.snr > 0.0)
                                    .then(|| 10.0 * log10(t.estimate.snr)),
                                track: t.track_id,
                                confirmed: t.confirmed,
                            })
                            .collect()
                    })
                    .collect()
            })
            .collect(),
        noise_var: &e.noise_var,
        max_paths: cfg.estimator.max_paths,
        p_fa: cfg.estimator.p_fa,
    }
}

/// `TRACK.json`: a recording's track and how it was made.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackDoc<'a> {
    /// The track.
    #[serde(flatten)]
    pub track: &'a CirTrackOutput,
    /// The filter's name (`ekf`, `ukf`, `pf`).
    pub filter: &'static str,
    /// Process-noise intensity, m²/s³.
    pub process_noise: Real,
    /// How each delay was weighted (`estimator`, `budget`).
    pub sigma: &'static str,
    /// The static clusters used.
    pub calibration: CalibrationResult,
    /// With a truth: the position error's statistics over the snapshots with a state (absent
    /// when the track never started).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<ErrorStats>,
}

/// The `TRACK.json` of `track` made by filter `filter` with `process_noise` and `sigma`, from
/// the `calibration` of `calibration_snapshots` snapshots; `error` the statistics against a
/// truth (`None`: no truth, or the track never started).
pub fn track_doc<'a>(
    track: &'a CirTrackOutput,
    filter: &'static str,
    process_noise: Real,
    sigma: DelaySigma,
    calibration: &Calibration,
    calibration_snapshots: usize,
    error: Option<ErrorStats>,
) -> TrackDoc<'a> {
    TrackDoc {
        track,
        filter,
        process_noise,
        sigma: sigma.name(),
        calibration: CalibrationResult {
            gap_s: None,
            min_fraction: None,
            sigma_floor_s: None,
            snapshot_count: Some(calibration_snapshots),
            links: calibration.links.clone(),
        },
        error,
    }
}

/// The names of `model`'s links (`Tx → Rx1`), as the delay figure labels its panels.
pub fn link_names(scenario: &Scenario, model: &Model) -> Vec<String> {
    model
        .network
        .links
        .iter()
        .map(|l| {
            format!(
                "{} → {}",
                scenario.transmitters[l.tx].name, scenario.receivers[l.rx].name
            )
        })
        .collect()
}
