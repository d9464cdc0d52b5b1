//! The files of the channel front end (issue 25) as serde objects, built once here for the CLI
//! (`cir estimate --out EST.json`, `cir track --out TRACK.json`) and the page's channel view,
//! so both write the same JSON for the same input.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use serde::Serialize;

use crate::channel::Alignment;
use crate::formats::CalibrationResult;
use crate::math::{log10, Real};
use crate::measure::Model;
use crate::present::ErrorStats;
use crate::scenario::Scenario;
use crate::study::{
    BoundCounts, ChannelRequest, ChannelStatics, CirTrackOutput, FrontEndConfig, LinkStaticsInfo,
    RecordingEstimates,
};

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
    /// The range rate over the scan's CPI and its σ, m/s (issue 42 §2; absent without a CPI).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_rate_mps: Option<[Real; 2]>,
}

/// A snapshot's alignment to the background in `EST.json` (C9 step 2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AlignmentDoc {
    /// `δ̂`, s.
    pub delay_s: Real,
    /// `ĝ` as `[re, im]`.
    pub gain: [Real; 2],
}

impl AlignmentDoc {
    fn of(a: &Alignment) -> AlignmentDoc {
        AlignmentDoc {
            delay_s: a.delay_s,
            gain: [a.gain.re, a.gain.im],
        }
    }
}

/// How the estimates were made, in `EST.json` and `TRACK.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrontEndDoc {
    /// The estimator's `max_paths`.
    pub max_paths: usize,
    /// The estimator's `p_fa`.
    pub p_fa: Real,
    /// `background` or `clusters`.
    pub statics: &'static str,
    /// `absolute` or `los`.
    pub delay_reference: &'static str,
    /// The recursive background's time constant, s (used without an empty-area recording).
    pub background_time_s: Real,
    /// Per model link what its statics were made of (`null`: not recorded).
    pub links: Vec<Option<LinkStaticsInfo>>,
    /// The link-snapshots that ended at a bound of the estimator.
    pub bounds: BoundCounts,
}

impl FrontEndDoc {
    /// The front end `cfg` with the `statics` and `est` it made.
    pub fn of(cfg: &FrontEndConfig, statics: &ChannelStatics, est: &RecordingEstimates) -> Self {
        FrontEndDoc {
            max_paths: cfg.estimator.max_paths,
            p_fa: cfg.estimator.p_fa,
            statics: cfg.statics.name(),
            delay_reference: cfg.delay_reference.name(),
            background_time_s: cfg.background_time_s,
            links: statics.links.clone(),
            bounds: est.bounds(),
        }
    }
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
    /// `alignment[s][p]`: the snapshot's alignment to the background (`null`: none made).
    pub alignment: Vec<Vec<Option<AlignmentDoc>>>,
    /// The estimator's `max_paths`.
    pub max_paths: usize,
    /// The estimator's `p_fa`.
    pub p_fa: Real,
    /// How the estimates were made.
    pub front_end: FrontEndDoc,
    /// The static clusters the tracker gates with (E4), per model link.
    pub calibration: CalibrationResult,
}

/// The `EST.json` of `e`, estimated with `cfg` and `statics` on `model`'s links.
pub fn estimates_doc<'a>(
    model: &Model,
    e: &'a RecordingEstimates,
    cfg: &FrontEndConfig,
    statics: &ChannelStatics,
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
                                range_rate_mps: t
                                    .estimate
                                    .range_rate
                                    .map(|r| [r.range_rate_mps, r.sigma_mps]),
                            })
                            .collect()
                    })
                    .collect()
            })
            .collect(),
        noise_var: &e.noise_var,
        alignment: e
            .alignment
            .iter()
            .map(|row| {
                row.iter()
                    .map(|a| a.as_ref().map(AlignmentDoc::of))
                    .collect()
            })
            .collect(),
        max_paths: cfg.estimator.max_paths,
        p_fa: cfg.estimator.p_fa,
        front_end: FrontEndDoc::of(cfg, statics, e),
        calibration: calibration_doc(statics),
    }
}

/// The static clusters of `statics` as a calibration file (`snapshot_count`: the most
/// empty-area snapshots a link used).
fn calibration_doc(statics: &ChannelStatics) -> CalibrationResult {
    CalibrationResult {
        gap_s: None,
        min_fraction: None,
        sigma_floor_s: None,
        snapshot_count: statics
            .links
            .iter()
            .flatten()
            .map(|l| l.empty_snapshots)
            .max(),
        links: statics.calibration.links.clone(),
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
    /// The association rule (`gated`, `spec`).
    pub association: &'static str,
    /// The scatterer's extent added to each σ̂, m.
    pub extent_sigma_m: Real,
    /// How the estimates were made.
    pub front_end: FrontEndDoc,
    /// The static clusters used.
    pub calibration: CalibrationResult,
    /// With a truth: the position error's statistics over the snapshots with a state (absent
    /// when the track never started).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<ErrorStats>,
}

/// The `TRACK.json` of `track` made with `req` from the estimates `est` (front end `cfg`,
/// statics `statics`); `error` the statistics against a truth (`None`: no truth, or the track
/// never started). Errors: the request's filter ([`ChannelRequest::filter_kind`]).
pub fn track_doc<'a>(
    track: &'a CirTrackOutput,
    req: &ChannelRequest,
    cfg: &FrontEndConfig,
    statics: &ChannelStatics,
    est: &RecordingEstimates,
    error: Option<ErrorStats>,
) -> crate::error::Result<TrackDoc<'a>> {
    Ok(TrackDoc {
        track,
        filter: req.filter_kind()?.name(),
        process_noise: req.process_noise,
        sigma: req.sigma.name(),
        association: req.association.name(),
        extent_sigma_m: req.extent_sigma_m,
        front_end: FrontEndDoc::of(cfg, statics, est),
        calibration: calibration_doc(statics),
        error,
    })
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
