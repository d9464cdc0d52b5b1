//! The page's channel view (issue 26 §1): a channel recording (`.npz`, docs/recording.md) to
//! the delay figure and a track, through the same core entry points as the CLI's `cir simulate`,
//! `cir estimate` and `cir track` (`channel::simulate_recording`, `npz::read_recording`,
//! `study::{estimate_recording, calibrate_estimates, cir_track}`, `present::{delay_figure,
//! track_errors}`), so the page's files equal the CLI's for the same input.
//!
//! - [`simulate_channel`] → [`SimulatedChannel`]: the files `cir simulate` writes.
//! - [`ChannelJob`] (run in a Web Worker, `www/js/channel-worker.js`): reads the files, then
//!   estimates, calibrates, tracks and assembles the figures in slices (`step(budget_ms)`), so
//!   the worker reports progress and drops the job on Stop between two slices. Its results are
//!   JSON text: `estimates_json` (= `cir estimate --out`), `track_json` (= `cir track --out`),
//!   `figure_json` (the delay figure's data), `errors_json` (the error over time).
//! - [`ChannelFigures`] (on the page's main thread, from the worker's texts): the delay figure
//!   and the error chart on a `<canvas>` (plotters-canvas) or as SVG text (plotters' SVG
//!   backend), both by the CLI's chart code (`chart::channel`), and the map overlay of one
//!   snapshot (`overlay(k)`).
//!
//! Every error is an exception carrying the core's one-line message (naming the field or the
//! array); sizes are capped before parsing ([`crate::error::limits::MAX_PAGE_RECORDING_BYTES`]);
//! non-finite numbers reach JavaScript as `null`.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters_canvas::CanvasBackend;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;
use web_sys::HtmlCanvasElement;

/// The charts with a time cursor (the page's channel view).
mod cursor;

use super::base::err;
use super::json::{to_js, to_json};
use super::tracking::page_filter;
use super::MAX_FIGURE_PX;
use crate::channel::{simulate_recording, Band, ChannelScene, Recording};
use crate::chart::{
    delays_size, draw_delays, draw_track_errors, scenario_nodes, track_errors_size,
    ChannelChartOptions,
};
use crate::error::limits::{MAX_PAGE_RECORDING_BYTES, MAX_PAGE_TEXT_BYTES};
use crate::error::{Cancel, Error};
use crate::formats::Truth;
use crate::math::{Mat4, Vec4};
use crate::present::{
    delay_figure, estimates_doc, link_names, position_ellipse, track_doc, track_errors,
    DelayFigure, EllipseView, TrackErrorView,
};
use crate::study::{
    calibrate_estimates, cir_track, CirTrackOutput, CirTrackRequest, DelaySigma, EstimationRun,
    FrontEndConfig, RecordingEstimates, EXTENT_SIGMA_M,
};
use crate::track::gating::{AmplitudeClusterConfig, AssociationRule, Calibration};
use crate::track::{ConstantVelocity, FilterKind};
use crate::{npz, Model, Scenario};

/// Default process-noise intensity of the channel view's tracker, m²/s³ (`cir track`'s).
pub const DEFAULT_CHANNEL_PROCESS_NOISE: f64 = 1.0;

/// Default particles of the channel view's particle filter (`cir track --particles`).
const DEFAULT_PARTICLES: usize = 1000;

/// Most particle-steps (`snapshots × particles`) of a channel-view track: the track runs in
/// one call of the worker (a few seconds at most).
pub const MAX_CHANNEL_PARTICLE_STEPS: usize = 20_000_000;

/// A core error as a JavaScript exception, its message prefixed by `what` (`recording`,
/// `calibration`, `truth`, …).
fn named(what: &str) -> impl Fn(Error) -> JsError + '_ {
    move |e| JsError::new(&format!("{what}: {e}"))
}

/// `Ok` when a dropped file of `len` bytes is within `max`, else [`Error::SizeLimit`] of
/// `field` (checked before the file is parsed).
fn check_size(field: &'static str, len: usize, max: u64) -> Result<(), Error> {
    if len as u64 > max {
        return Err(Error::SizeLimit {
            field,
            value: len,
            min: 0,
            max: max as usize,
        });
    }
    Ok(())
}

/// A settings object from JSON text (`""`: all defaults); unknown fields are refused.
fn parse_settings<T: serde::de::DeserializeOwned + Default>(
    what: &str,
    json: &str,
) -> Result<T, JsError> {
    if json.trim().is_empty() {
        return Ok(T::default());
    }
    check_size("settings", json.len(), MAX_PAGE_TEXT_BYTES as u64).map_err(err)?;
    serde_json::from_str(json).map_err(|e| {
        named(what)(Error::Parse {
            message: e.to_string(),
        })
    })
}

/// The scenario of the channel view and its model.
fn scenario_and_model(json: &str) -> Result<(Scenario, Model), JsError> {
    check_size("scenario", json.len(), MAX_PAGE_TEXT_BYTES as u64).map_err(err)?;
    let s = Scenario::from_json(json).map_err(named("scenario"))?;
    let m = Model::new(&s).map_err(named("scenario"))?;
    Ok((s, m))
}

/// Milliseconds from the worker's (or page's) `performance.now()` (`Date.now()` without one).
fn now_ms() -> f64 {
    let g = js_sys::global();
    js_sys::Reflect::get(&g, &JsValue::from_str("performance"))
        .ok()
        .and_then(|p| {
            let f: js_sys::Function = js_sys::Reflect::get(&p, &JsValue::from_str("now"))
                .ok()?
                .dyn_into()
                .ok()?;
            f.call0(&p).ok()?.as_f64()
        })
        .unwrap_or_else(js_sys::Date::now)
}

/// The files of `cir simulate` for one scenario and simulator settings.
#[wasm_bindgen]
pub struct SimulatedChannel {
    recording: Vec<u8>,
    calibration: Vec<u8>,
    truth_json: String,
    scene_json: String,
    summary: String,
}

#[wasm_bindgen]
impl SimulatedChannel {
    /// `recording.npz` (the walk, with the person), bytes.
    pub fn recording(&self) -> Vec<u8> {
        self.recording.clone()
    }

    /// `calibration.npz` (the empty area, its own noise stream), bytes.
    pub fn calibration(&self) -> Vec<u8> {
        self.calibration.clone()
    }

    /// `truth.json` as text: `{t_s: [s…], states: [[x, y, vx, vy]…], resolved: [[bool per
    /// link]…]}` (one state per snapshot of the recording).
    pub fn truth_json(&self) -> String {
        self.truth_json.clone()
    }

    /// `scene.json` as text: the scene simulated (the hangar or the one given, with the
    /// settings' overrides applied).
    pub fn scene_json(&self) -> String {
        self.scene_json.clone()
    }

    /// The summary `cir simulate` prints, as JSON text: `{snapshots, calibration_snapshots,
    /// links, subcarriers}`.
    pub fn summary_json(&self) -> String {
        self.summary.clone()
    }
}

/// Simulates the recordings of `cir simulate` on scenario JSON `scenario_json` (schema v1):
/// `settings_json` is `""` or `{scene?: <scene JSON object, default the hangar>, walk?: [[x,
/// y], …] (m, ≥ 2 points; the CLI's --walk), speed_mps?: m/s (--speed), duration_s?: s
/// (--duration), dt_s?: s (--dt), calibration_duration_s?: s (--calibration-duration, default
/// 1), seed?: integer (--seed, default 1)}`; unknown fields are refused. Throws the core's
/// named error (`walk.waypoints`, `duration_s`, the sample cap, …).
#[wasm_bindgen]
pub fn simulate_channel(
    scenario_json: &str,
    settings_json: &str,
) -> Result<SimulatedChannel, JsError> {
    let (scenario, model) = scenario_and_model(scenario_json)?;
    let set: SimulateSettings = parse_settings("settings", settings_json)?;
    let mut scene = set.scene.unwrap_or_else(ChannelScene::hangar);
    if let Some(w) = set.walk {
        scene.walk.waypoints_m = w;
    }
    if let Some(v) = set.speed_mps {
        scene.walk.speed_mps = v;
    }
    if let Some(d) = set.duration_s {
        scene.duration_s = Some(d);
    }
    if let Some(dt) = set.dt_s {
        scene.dt_s = dt;
    }
    scene.validate().map_err(named("scene"))?;
    let mut empty = scene.clone();
    empty.duration_s = Some(set.calibration_duration_s.unwrap_or(1.0));
    empty.validate().map_err(named("calibration_duration_s"))?;
    check_simulated_size("duration_s", &scene, model.link_count())?;
    check_simulated_size("calibration_duration_s", &empty, model.link_count())?;
    let seed = set.seed.unwrap_or(1);
    let (rec, truth) =
        simulate_recording(&scenario, &model, &scene, true, seed).map_err(named("scene"))?;
    let (cal, _) = simulate_recording(&scenario, &model, &empty, false, seed)
        .map_err(named("calibration_duration_s"))?;
    let enc = |r: &Recording| npz::write_recording(r).map_err(named("recording"));
    Ok(SimulatedChannel {
        recording: enc(&rec)?,
        calibration: enc(&cal)?,
        truth_json: to_json(&truth)?,
        scene_json: to_json(&scene)?,
        summary: to_json(&serde_json::json!({
            "snapshots": rec.t_s.len(),
            "calibration_snapshots": cal.t_s.len(),
            "links": model.link_count(),
            "subcarriers": scene.subcarriers,
        }))?,
    })
}

/// The settings of [`simulate_channel`] (the flags of `cir simulate`).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct SimulateSettings {
    #[serde(default)]
    scene: Option<ChannelScene>,
    #[serde(default)]
    walk: Option<Vec<[f64; 2]>>,
    #[serde(default)]
    speed_mps: Option<f64>,
    #[serde(default)]
    duration_s: Option<f64>,
    #[serde(default)]
    dt_s: Option<f64>,
    #[serde(default)]
    calibration_duration_s: Option<f64>,
    #[serde(default)]
    seed: Option<u64>,
}

/// [`Error::SizeLimit`] of `field` when a (validated) `scene` on `links` links would make a
/// recording of more than [`MAX_PAGE_RECORDING_BYTES`] of complex128 samples (checked before
/// anything is simulated: the simulator's own cap is for the CLI's memory).
fn check_simulated_size(
    field: &'static str,
    scene: &ChannelScene,
    links: usize,
) -> Result<(), JsError> {
    let duration = match scene.duration_s {
        Some(d) => d,
        None => scene.walk.duration_s().map_err(named("scene"))?,
    };
    let per_snapshot = (links * scene.subcarriers * 16).max(1) as f64;
    let max = MAX_PAGE_RECORDING_BYTES as f64 / per_snapshot;
    let snapshots = duration / scene.dt_s + 1.0;
    if snapshots.is_nan() || snapshots > max {
        return Err(err(Error::SizeLimit {
            field,
            value: snapshots.min(usize::MAX as f64) as usize,
            min: 1,
            max: max as usize,
        }));
    }
    Ok(())
}

/// The settings of a [`ChannelJob`] (the flags of `cir estimate` and `cir track`).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct JobSettings {
    #[serde(default)]
    max_paths: Option<usize>,
    #[serde(default)]
    pfa: Option<f64>,
    #[serde(default)]
    filter: Option<String>,
    #[serde(default)]
    particles: Option<usize>,
    #[serde(default)]
    seed: Option<u64>,
    #[serde(default)]
    process_noise: Option<f64>,
    #[serde(default)]
    sigma: Option<String>,
    #[serde(default)]
    extent_sigma_m: Option<f64>,
    #[serde(default)]
    association: Option<String>,
    #[serde(default)]
    calibration_range_s: Option<[f64; 2]>,
}

/// How a job tracks (from its settings, checked).
struct TrackSettings {
    kind: FilterKind,
    q: f64,
    rule: AssociationRule,
    sigma: DelaySigma,
    extent_sigma_m: f64,
    seed: u64,
}

/// The tracker settings (as `cir track --filter --particles --seed --process-noise --sigma
/// --extent-sigma-m --association`, with its defaults).
fn track_settings(set: &JobSettings, snapshots: usize) -> Result<TrackSettings, Error> {
    let name = set.filter.as_deref().unwrap_or("ekf");
    let only_pf = |field: &str| Error::InvalidFile {
        field: field.into(),
        reason: "only for the pf filter (filter is not pf)".into(),
    };
    if name != "pf" {
        if set.particles.is_some() {
            return Err(only_pf("particles"));
        }
        if set.seed.is_some() {
            return Err(only_pf("seed"));
        }
    }
    let particles = set.particles.unwrap_or(DEFAULT_PARTICLES);
    let kind = page_filter("filter", name, particles)?;
    if name == "pf" && particles.saturating_mul(snapshots) > MAX_CHANNEL_PARTICLE_STEPS {
        return Err(Error::SizeLimit {
            field: "particles",
            value: particles,
            min: 1,
            max: MAX_CHANNEL_PARTICLE_STEPS / snapshots.max(1),
        });
    }
    let q = set.process_noise.unwrap_or(DEFAULT_CHANNEL_PROCESS_NOISE);
    ConstantVelocity::validated(1.0, q).map_err(|e| Error::InvalidFile {
        field: "process_noise".into(),
        reason: e.to_string(),
    })?;
    let bad = |field: &str, v: &str, allowed: &str| Error::InvalidFile {
        field: field.into(),
        reason: format!("\"{v}\" is not one of {allowed}"),
    };
    let sigma = match set.sigma.as_deref() {
        None | Some("estimator") => DelaySigma::Estimator,
        Some("budget") => DelaySigma::LinkBudget,
        Some(v) => return Err(bad("sigma", v, "estimator, budget")),
    };
    let rule = match set.association.as_deref() {
        None | Some("gated") => AssociationRule::Gated,
        Some("spec") => AssociationRule::Spec,
        Some(v) => return Err(bad("association", v, "gated, spec")),
    };
    Ok(TrackSettings {
        kind,
        q,
        rule,
        sigma,
        extent_sigma_m: set.extent_sigma_m.unwrap_or(EXTENT_SIGMA_M),
        seed: set.seed.unwrap_or(1),
    })
}

/// Reads a dropped `.npz` recording named `what` (`recording`, `calibration`): its size is
/// checked before parsing ([`MAX_PAGE_RECORDING_BYTES`]), the reader's caps while parsing, and
/// its links against `model`.
fn read_page_recording(
    what: &'static str,
    bytes: &js_sys::Uint8Array,
    model: &Model,
) -> Result<Recording, JsError> {
    // Before the bytes are copied into the module's memory.
    check_size(what, bytes.length() as usize, MAX_PAGE_RECORDING_BYTES).map_err(err)?;
    let bytes = bytes.to_vec();
    let rec = npz::read_recording_within(&bytes, MAX_PAGE_RECORDING_BYTES).map_err(named(what))?;
    rec.link_map(model).map_err(named(what))?;
    Ok(rec)
}

/// Where a job is.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Phase {
    Calibration,
    Estimate,
    Track,
    Figure,
    Done,
}

impl Phase {
    fn name(self) -> &'static str {
        match self {
            Phase::Calibration => "calibration",
            Phase::Estimate => "estimate",
            Phase::Track => "track",
            Phase::Figure => "figure",
            Phase::Done => "done",
        }
    }
}

/// `ChannelJob.progress()`.
#[derive(Serialize)]
struct ProgressJs {
    phase: &'static str,
    done: usize,
    total: usize,
    finished: bool,
}

/// `ChannelJob.timings()`, ms.
#[derive(Serialize, Default, Clone, Copy)]
struct TimingsJs {
    parse_ms: f64,
    calibration_ms: f64,
    estimate_ms: f64,
    track_ms: f64,
    figure_ms: f64,
}

/// `ChannelJob.summary()`.
#[derive(Serialize)]
struct SummaryJs {
    snapshots: usize,
    links: usize,
    layout: &'static str,
    samples_per_link: usize,
    duration_s: f64,
    calibration: CalibrationSummaryJs,
    truth: bool,
}

/// The calibration part of `ChannelJob.summary()`.
#[derive(Serialize)]
struct CalibrationSummaryJs {
    source: &'static str,
    snapshots: usize,
}

/// A recording's estimation and track in progress (run by `www/js/channel-worker.js`).
#[wasm_bindgen]
pub struct ChannelJob {
    scenario: Scenario,
    model: Model,
    rec: Recording,
    cal: Recording,
    cal_source: &'static str,
    truth: Option<Truth>,
    cfg: FrontEndConfig,
    tracking: TrackSettings,
    phase: Phase,
    run: Option<EstimationRun>,
    empty: Option<RecordingEstimates>,
    calibration: Option<Calibration>,
    est: Option<RecordingEstimates>,
    track: Option<CirTrackOutput>,
    view: Option<TrackErrorView>,
    figure: Option<DelayFigure>,
    timings: TimingsJs,
}

#[wasm_bindgen]
impl ChannelJob {
    /// A job on scenario JSON `scenario_json` (schema v1), the bytes of the recording
    /// `recording` (`.npz`), the calibration recording's bytes `calibration` (`undefined`: use
    /// the settings' `calibration_range_s` of the same recording), the truth file's text
    /// `truth_json` (`undefined`: none; its times must equal the recording's), and
    /// `settings_json` (`""` or an object; every field optional, the CLI's defaults):
    ///
    /// `{max_paths: integer (--max-paths, the estimator's default), pfa: number (--pfa),
    /// filter: "ekf" | "ukf" | "pf" (--filter, default "ekf"), particles: integer (--particles,
    /// pf only, default 1000), seed: integer (--seed, pf only, default 1), process_noise:
    /// m²/s³ (--process-noise, default 1), sigma: "estimator" | "budget" (--sigma, default
    /// "estimator"), extent_sigma_m: m (--extent-sigma-m, default 0.2), association: "gated" |
    /// "spec" (--association, default "gated"), calibration_range_s: [t0, t1] (s: the
    /// snapshots of the recording with t0 ≤ t ≤ t1 are the empty area; only without a
    /// calibration file)}`.
    ///
    /// Reads the files here (sizes capped before parsing): throws the reader's named error
    /// prefixed by the file (`recording: npz: …`, `calibration: cfr: wrong shape …`, a zip bomb,
    /// `recording: 300000000 is …` over the cap), a link the scenario does not have, a bad
    /// setting (named by its field), neither or both calibration sources. Nothing is estimated
    /// yet.
    #[wasm_bindgen(constructor)]
    pub fn new(
        scenario_json: &str,
        recording: &js_sys::Uint8Array,
        calibration: Option<js_sys::Uint8Array>,
        truth_json: Option<String>,
        settings_json: &str,
    ) -> Result<ChannelJob, JsError> {
        let t0 = now_ms();
        let (scenario, model) = scenario_and_model(scenario_json)?;
        let set: JobSettings = parse_settings("settings", settings_json)?;
        let cfg = FrontEndConfig::with_overrides(set.max_paths, set.pfa).map_err(err)?;
        let rec = read_page_recording("recording", recording, &model)?;
        let tracking = track_settings(&set, rec.t_s.len()).map_err(err)?;
        let (cal, cal_source) = match (calibration, set.calibration_range_s) {
            (Some(bytes), None) => (read_page_recording("calibration", &bytes, &model)?, "file"),
            (None, Some([a, b])) => (
                rec.between("calibration_range_s", a, b).map_err(err)?,
                "range",
            ),
            (Some(_), Some(_)) => {
                return Err(JsError::new(
                    "calibration_range_s: give a calibration recording or a time range of the \
                     recording, not both",
                ))
            }
            (None, None) => {
                return Err(JsError::new(
                    "calibration: missing (give a calibration recording of the empty area, or a \
                     time range of the recording in which the area is empty)",
                ))
            }
        };
        let truth = match truth_json {
            Some(text) => {
                check_size("truth", text.len(), MAX_PAGE_TEXT_BYTES as u64).map_err(err)?;
                let t = Truth::from_json(&text).map_err(named("truth"))?;
                t.check_times(&rec.t_s).map_err(named("truth"))?;
                Some(t)
            }
            None => None,
        };
        let bw = scenario.radio.bandwidth_hz;
        let run = EstimationRun::new(&model, bw, &cal, &cfg).map_err(named("calibration"))?;
        // The recording's own checks now too (they do not depend on the calibration).
        EstimationRun::new(&model, bw, &rec, &cfg).map_err(named("recording"))?;
        let timings = TimingsJs {
            parse_ms: now_ms() - t0,
            ..TimingsJs::default()
        };
        Ok(ChannelJob {
            scenario,
            model,
            rec,
            cal,
            cal_source,
            truth,
            cfg,
            tracking,
            phase: Phase::Calibration,
            run: Some(run),
            empty: None,
            calibration: None,
            est: None,
            track: None,
            view: None,
            figure: None,
            timings,
        })
    }

    /// Runs work for about `budget_ms` ms (at least one unit: one snapshot of one link while
    /// estimating; the track and the figure are one unit each) and returns the progress (as
    /// [`ChannelJob::progress`]). Throws the core's named error of the phase (prefixed by
    /// `calibration`, `recording`, `track` or `figure`); after an error the job is spent.
    pub fn step(&mut self, budget_ms: f64) -> Result<JsValue, JsError> {
        let start = now_ms();
        loop {
            let (t, phase) = (now_ms(), self.phase);
            self.unit()?;
            let spent = now_ms() - t;
            match phase {
                Phase::Calibration => self.timings.calibration_ms += spent,
                Phase::Estimate => self.timings.estimate_ms += spent,
                _ => {}
            }
            if self.phase == Phase::Done || now_ms() - start >= budget_ms {
                break;
            }
        }
        self.progress()
    }

    /// The progress `{phase, done, total, finished}`: `phase` is `"calibration"` (estimating
    /// the calibration recording; `done`/`total` count link-snapshots), `"estimate"` (the
    /// recording; link-snapshots), `"track"` (0 of 1), `"figure"` (0 of 1) or `"done"` (1 of
    /// 1); `finished` is true once every result is there.
    pub fn progress(&self) -> Result<JsValue, JsError> {
        let (done, total) = match (&self.run, self.phase) {
            (Some(r), _) => (r.done(), r.total()),
            (None, Phase::Done) => (1, 1),
            (None, _) => (0, 1),
        };
        to_js(&ProgressJs {
            phase: self.phase.name(),
            done,
            total,
            finished: self.phase == Phase::Done,
        })
    }

    /// What was read: `{snapshots, links (recorded), layout ("cfr" | "cir"), samples_per_link,
    /// duration_s, calibration: {source: "file" | "range", snapshots}, truth: bool}`.
    pub fn summary(&self) -> Result<JsValue, JsError> {
        let r = &self.rec;
        to_js(&SummaryJs {
            snapshots: r.snapshot_count(),
            links: r.link_count(),
            layout: r.layout.array(),
            samples_per_link: r.samples_per_link(),
            duration_s: r.t_s[r.t_s.len() - 1] - r.t_s[0],
            calibration: CalibrationSummaryJs {
                source: self.cal_source,
                snapshots: self.cal.snapshot_count(),
            },
            truth: self.truth.is_some(),
        })
    }

    /// Time spent per phase in this job, ms (wall clock in the worker, `performance.now()`):
    /// `{parse_ms (reading and checking the files), calibration_ms, estimate_ms, track_ms,
    /// figure_ms}` (0 for a phase not run yet).
    pub fn timings(&self) -> Result<JsValue, JsError> {
        to_js(&self.timings)
    }

    /// The recording's estimates as JSON text, exactly the file `cir estimate --out` writes
    /// (without its final newline): `{format: "scatterloc-estimates", t_s: [s…], links:
    /// [[transmitter, receiver]…] (every model link), recorded: [bool per link], estimates:
    /// [snapshot][link][{delay_s, amplitude, sigma_s, snr_db (null at SNR ≤ 0), track,
    /// confirmed}], noise_var: [snapshot][link] (W), max_paths, p_fa}`. Throws before the
    /// `"estimate"` phase is done.
    pub fn estimates_json(&self) -> Result<String, JsError> {
        let est = self.est.as_ref().ok_or_else(|| pending("estimates_json"))?;
        to_json(&estimates_doc(&self.model, est, &self.cfg))
    }

    /// The track as JSON text, exactly the file `cir track --out` writes (without its final
    /// newline): `{t_s, states: [[x, y, vx, vy] | null…], covariances: [4×4 | null…],
    /// links_used: [n…], delays_used_s: [snapshot][link] (s | null), sigmas_used_s:
    /// [snapshot][link] (s | null), choices: [snapshot][link] ("absent" | "single" | "nearest" |
    /// "strongest"), static_removed: [snapshot][link], start: {snapshot, t_s, position_m,
    /// covariance_m2, termination, links_used, choices, delays_used_s} | null, filter,
    /// process_noise, sigma ("estimator" | "budget"), calibration: {snapshot_count, links:
    /// [{clusters: [{mean_s, sigma_s, …}]}…]}, error?: {count, median_m, p90_m, max_m, rms_m,
    /// fraction_below_1m} (with a truth and a started track)}`. Throws before the `"track"`
    /// phase is done.
    pub fn track_json(&self) -> Result<String, JsError> {
        let (track, view, cal, empty) =
            match (&self.track, &self.view, &self.calibration, &self.empty) {
                (Some(t), Some(v), Some(c), Some(e)) => (t, v, c, e),
                _ => return Err(pending("track_json")),
            };
        let error = self.truth.as_ref().and(view.stats);
        to_json(&track_doc(
            track,
            self.tracking.kind.name(),
            self.tracking.q,
            self.tracking.sigma,
            cal,
            empty.len(),
            error,
        ))
    }

    /// The delay figure's data ([S] Fig. 4) as JSON text: `{t_range_s: [t0, t1],
    /// amplitude_db_range: [lo, hi] | null, links: [{name ("Tx → Rx1"), range_m: [lo, hi],
    /// image: {t_s: [s per column], r0_m, dr_m, rows, db: [rows × cols, row-major, row 0 at
    /// r0_m, dB re 1 W], db_range: [lo, hi]} | null, estimates: [{t_s, range_m, amplitude_db}…],
    /// statics: [{mean_m, halfwidth_m}…] (the calibration's clusters, ±3σ), truth: [{kind,
    /// primary, points: [[t_s, range_m]…]}…]}…]}` (one entry per model link). Throws before the
    /// `"figure"` phase is done.
    pub fn figure_json(&self) -> Result<String, JsError> {
        to_json(self.figure.as_ref().ok_or_else(|| pending("figure_json"))?)
    }

    /// The track's error view as JSON text (`present::track_errors`, what `cir track --figure`
    /// draws): `{t_s, track_m: [[[x, y]…] per run of snapshots with a state], truth_m: [runs],
    /// error_m: [m | null per snapshot], cdf: [[e, F]…], stats: {count, median_m, p90_m, max_m,
    /// rms_m, fraction_below_1m} | null, track_start: index | null}`. Throws before the
    /// `"track"` phase is done.
    pub fn errors_json(&self) -> Result<String, JsError> {
        to_json(self.view.as_ref().ok_or_else(|| pending("errors_json"))?)
    }
}

/// The exception of a result asked for before its phase is done.
fn pending(func: &str) -> JsError {
    JsError::new(&format!(
        "ChannelJob.{func}: not computed yet (step the job until it is finished)"
    ))
}

impl ChannelJob {
    /// One unit of work of the current phase.
    fn unit(&mut self) -> Result<(), JsError> {
        let bw = self.scenario.radio.bandwidth_hz;
        match self.phase {
            Phase::Calibration | Phase::Estimate => {
                let (rec, what) = if self.phase == Phase::Calibration {
                    (&self.cal, "calibration")
                } else {
                    (&self.rec, "recording")
                };
                let run = self
                    .run
                    .as_mut()
                    .ok_or_else(|| JsError::new("ChannelJob: the job failed earlier"))?;
                // A few link-snapshots per clock reading (each is 0.1–2 ms).
                if !run.run(rec, 4).map_err(named(what))? {
                    return Ok(());
                }
                let run = self.run.take().ok_or_else(|| pending("step"))?;
                let est = run.finish(&self.model, rec).map_err(named(what))?;
                if self.phase == Phase::Calibration {
                    let ccfg =
                        AmplitudeClusterConfig::for_bandwidth(bw).map_err(named("scenario"))?;
                    self.calibration = Some(
                        calibrate_estimates(&self.model, &est, &ccfg)
                            .map_err(named("calibration"))?,
                    );
                    self.empty = Some(est);
                    self.run = Some(
                        EstimationRun::new(&self.model, bw, &self.rec, &self.cfg)
                            .map_err(named("recording"))?,
                    );
                    self.phase = Phase::Estimate;
                } else {
                    self.est = Some(est);
                    self.phase = Phase::Track;
                }
            }
            Phase::Track => {
                let t = now_ms();
                let (cal, est) = match (&self.calibration, &self.est) {
                    (Some(c), Some(e)) => (c, e),
                    _ => return Err(pending("step")),
                };
                let s = &self.tracking;
                let req = CirTrackRequest {
                    model: &self.model,
                    area: &self.scenario.area_m,
                    calibration: cal,
                    estimates: est,
                    filter: s.kind,
                    process_noise: s.q,
                    rule: s.rule,
                    sigma: s.sigma,
                    extent_sigma_m: s.extent_sigma_m,
                    seed: s.seed,
                };
                let track = cir_track(&req, Cancel::NEVER).map_err(named("track"))?;
                let truth_states: Vec<Option<[f64; 4]>> = self
                    .truth
                    .as_ref()
                    .map(|t| t.states.iter().map(|s| Some(*s)).collect())
                    .unwrap_or_default();
                let view = track_errors(&track.t_s, &track.states, &truth_states)
                    .map_err(named("truth"))?;
                self.track = Some(track);
                self.view = Some(view);
                self.timings.track_ms += now_ms() - t;
                self.phase = Phase::Figure;
            }
            Phase::Figure => {
                let t = now_ms();
                let (cal, est) = match (&self.calibration, &self.est) {
                    (Some(c), Some(e)) => (c, e),
                    _ => return Err(pending("step")),
                };
                let band = Band::of_recording(&self.rec, bw).map_err(named("figure"))?;
                let fig = delay_figure(
                    &self.model,
                    &self.rec,
                    &band,
                    est,
                    Some(cal),
                    self.truth.as_ref().map(|t| t.states.as_slice()),
                    &link_names(&self.scenario, &self.model),
                )
                .map_err(named("figure"))?;
                self.figure = Some(fig);
                self.timings.figure_ms += now_ms() - t;
                self.phase = Phase::Done;
            }
            Phase::Done => {}
        }
        Ok(())
    }
}

/// The parts of `TRACK.json` the map overlay reads (other keys are ignored).
#[derive(Deserialize)]
struct TrackParts {
    t_s: Vec<f64>,
    states: Vec<Option<[f64; 4]>>,
    covariances: Vec<Option<[[f64; 4]; 4]>>,
    links_used: Vec<usize>,
    delays_used_s: Vec<Vec<Option<f64>>>,
    sigmas_used_s: Vec<Vec<Option<f64>>>,
    choices: Vec<Vec<String>>,
}

/// One used link of `ChannelFigures.overlay(k)`.
#[derive(Serialize)]
struct OverlayLinkJs {
    link: usize,
    tx: usize,
    rx: usize,
    delay_s: f64,
    range_m: f64,
    sigma_s: Option<f64>,
    choice: String,
    ellipse: Option<EllipseView>,
}

/// `ChannelFigures.overlay(k)`.
#[derive(Serialize)]
struct OverlayJs {
    index: usize,
    t_s: f64,
    track_m: Vec<[f64; 2]>,
    state: Option<[f64; 4]>,
    sigma_ellipse: Option<EllipseView>,
    error_m: Option<f64>,
    links_used: usize,
    links: Vec<OverlayLinkJs>,
}

/// The channel view's pictures on the page's main thread, from a finished job's texts.
#[wasm_bindgen]
pub struct ChannelFigures {
    scenario: Scenario,
    model: Model,
    figure: DelayFigure,
    view: TrackErrorView,
    track: TrackParts,
}

/// A figure's size: `(0, 0)` the CLI's `default`, else both within 200 … [`MAX_FIGURE_PX`].
fn chart_size(default: (u32, u32), width: u32, height: u32) -> Result<(u32, u32), Error> {
    if width == 0 && height == 0 {
        return Ok(default);
    }
    for (field, v) in [("width", width), ("height", height)] {
        if !(200..=MAX_FIGURE_PX).contains(&v) {
            return Err(Error::SizeLimit {
                field,
                value: v as usize,
                min: 200,
                max: MAX_FIGURE_PX as usize,
            });
        }
    }
    Ok((width, height))
}

fn chart_options(title: &str, subtitle: &str) -> ChannelChartOptions {
    ChannelChartOptions {
        title: title.to_string(),
        subtitle: (!subtitle.is_empty()).then(|| subtitle.to_string()),
    }
}

/// Draws with `draw` on a canvas' drawing area and presents it.
fn on_canvas(
    func: &str,
    canvas: HtmlCanvasElement,
    draw: impl FnOnce(&DrawingArea<CanvasBackend, Shift>) -> Result<(), crate::chart::ChartError>,
) -> Result<(), JsError> {
    let root = CanvasBackend::with_canvas_object(canvas)
        .ok_or_else(|| JsError::new(&format!("{func}: the canvas has no 2-D context")))?
        .into_drawing_area();
    draw(&root).map_err(|e| JsError::new(&format!("{func}: {e}")))?;
    root.present()
        .map_err(|e| JsError::new(&format!("{func}: {e}")))
}

/// The SVG text of `size` px drawn by `draw`.
fn to_svg(
    func: &str,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), crate::chart::ChartError>,
) -> Result<String, JsError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(&root).map_err(|e| JsError::new(&format!("{func}: {e}")))?;
        root.present()
            .map_err(|e| JsError::new(&format!("{func}: {e}")))?;
    }
    Ok(svg)
}

#[wasm_bindgen]
impl ChannelFigures {
    /// The figures of scenario JSON `scenario_json` from a [`ChannelJob`]'s `figure_json`,
    /// `errors_json` and `track_json` texts. Throws the named parse error on malformed text or
    /// texts of different lengths.
    #[wasm_bindgen(constructor)]
    pub fn new(
        scenario_json: &str,
        figure_json: &str,
        errors_json: &str,
        track_json: &str,
    ) -> Result<ChannelFigures, JsError> {
        let (scenario, model) = scenario_and_model(scenario_json)?;
        let parse = |what: &'static str, e: serde_json::Error| {
            named(what)(Error::Parse {
                message: e.to_string(),
            })
        };
        let figure: DelayFigure =
            serde_json::from_str(figure_json).map_err(|e| parse("figure", e))?;
        let view: TrackErrorView =
            serde_json::from_str(errors_json).map_err(|e| parse("errors", e))?;
        let track: TrackParts = serde_json::from_str(track_json).map_err(|e| parse("track", e))?;
        let n = track.t_s.len();
        for (field, len) in [
            ("track.states", track.states.len()),
            ("track.covariances", track.covariances.len()),
            ("track.links_used", track.links_used.len()),
            ("track.delays_used_s", track.delays_used_s.len()),
            ("track.sigmas_used_s", track.sigmas_used_s.len()),
            ("track.choices", track.choices.len()),
            ("errors.error_m", view.error_m.len()),
        ] {
            crate::error::check_len(field, n, len).map_err(err)?;
        }
        Ok(ChannelFigures {
            scenario,
            model,
            figure,
            view,
            track,
        })
    }

    /// Snapshots of the track.
    pub fn snapshot_count(&self) -> usize {
        self.track.t_s.len()
    }

    /// The size `[width, height]` px the CLI gives the delay figure (`chart::delays_size`).
    pub fn delays_size(&self) -> Vec<u32> {
        let (w, h) = delays_size(self.figure.links.len());
        vec![w, h]
    }

    /// The size `[width, height]` px the CLI gives the track figure (`chart::track_errors_size`).
    pub fn errors_size(&self) -> Vec<u32> {
        let (w, h) = track_errors_size();
        vec![w, h]
    }

    /// Draws the delay figure (`chart::draw_delays`, as `cir track --delays-figure`) on
    /// `canvas` at its pixel size with `title` and `subtitle` (`""`: none). Throws
    /// `draw_delays: …`.
    pub fn draw_delays(
        &self,
        canvas: HtmlCanvasElement,
        title: &str,
        subtitle: &str,
    ) -> Result<(), JsError> {
        let opts = chart_options(title, subtitle);
        on_canvas("draw_delays", canvas, |root| {
            draw_delays(root, &self.figure, &opts)
        })
    }

    /// The delay figure as SVG text of `width × height` px (0, 0: the CLI's size; else each
    /// 200 … 8000). Throws `delays_svg: …`.
    pub fn delays_svg(
        &self,
        width: u32,
        height: u32,
        title: &str,
        subtitle: &str,
    ) -> Result<String, JsError> {
        let size = chart_size(delays_size(self.figure.links.len()), width, height)
            .map_err(named("delays_svg"))?;
        let opts = chart_options(title, subtitle);
        to_svg("delays_svg", size, |root| {
            draw_delays(root, &self.figure, &opts)
        })
    }

    /// Draws the track figure (`chart::draw_track_errors`, as `cir track --figure`: the track on
    /// the map, the error over time and its CDF) on `canvas` at its pixel size. Throws
    /// `draw_errors: …`.
    pub fn draw_errors(
        &self,
        canvas: HtmlCanvasElement,
        title: &str,
        subtitle: &str,
    ) -> Result<(), JsError> {
        let opts = chart_options(title, subtitle);
        let nodes = scenario_nodes(&self.scenario);
        on_canvas("draw_errors", canvas, |root| {
            draw_track_errors(root, &self.view, &nodes, &self.scenario.area_m, &opts)
        })
    }

    /// The track figure as SVG text of `width × height` px (0, 0: the CLI's size; else each
    /// 200 … 8000). Throws `errors_svg: …`.
    pub fn errors_svg(
        &self,
        width: u32,
        height: u32,
        title: &str,
        subtitle: &str,
    ) -> Result<String, JsError> {
        let size = chart_size(track_errors_size(), width, height).map_err(named("errors_svg"))?;
        let opts = chart_options(title, subtitle);
        let nodes = scenario_nodes(&self.scenario);
        to_svg("errors_svg", size, |root| {
            draw_track_errors(root, &self.view, &nodes, &self.scenario.area_m, &opts)
        })
    }

    /// The map overlay of snapshot `k` (0 … snapshot_count − 1): `{index, t_s, track_m: [[x,
    /// y]…] (the estimated positions of snapshots 0 … k that have a state), state: [x, y, vx,
    /// vy] | null, sigma_ellipse: {cx, cy, a, b, angle} | null (the filter's 1σ position
    /// ellipse), error_m: m | null (with a truth), links_used, links: [{link, tx, rx, delay_s,
    /// range_m, sigma_s (s | null), choice, ellipse: {cx, cy, a, b, angle} | null}…] (the
    /// links whose delay was used at k, with the iso-delay ellipse of that delay)}`. Throws on
    /// `k` out of range.
    pub fn overlay(&self, k: usize) -> Result<JsValue, JsError> {
        let t = &self.track;
        if k >= t.t_s.len() {
            return Err(err(Error::SizeLimit {
                field: "snapshot",
                value: k,
                min: 0,
                max: t.t_s.len().saturating_sub(1),
            }));
        }
        let track_m = t.states[..=k]
            .iter()
            .flatten()
            .map(|x| [x[0], x[1]])
            .collect();
        let sigma_ellipse = match (t.states[k], t.covariances[k]) {
            (Some(x), Some(c)) => position_ellipse(
                &Vec4::new(x[0], x[1], x[2], x[3]),
                &Mat4::from_fn(|i, j| c[i][j]),
                1.0,
            )
            .map(EllipseView::from),
            _ => None,
        };
        let net = &self.model.network;
        let links = t.delays_used_s[k]
            .iter()
            .enumerate()
            .filter_map(|(p, d)| {
                let (d, l) = ((*d)?, net.links.get(p)?);
                Some(OverlayLinkJs {
                    link: p,
                    tx: l.tx,
                    rx: l.rx,
                    delay_s: d,
                    range_m: crate::math::SPEED_OF_LIGHT * d,
                    sigma_s: t.sigmas_used_s[k].get(p).copied().flatten(),
                    choice: t.choices[k].get(p).cloned().unwrap_or_default(),
                    ellipse: net.iso_delay_ellipse(p, d).map(EllipseView::from),
                })
            })
            .collect();
        to_js(&OverlayJs {
            index: k,
            t_s: t.t_s[k],
            track_m,
            state: t.states[k],
            sigma_ellipse,
            error_m: self.view.error_m[k],
            links_used: t.links_used[k],
            links,
        })
    }
}
