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

use alloc::string::String;
use alloc::vec::Vec;

use wasm_bindgen::prelude::*;
use web_sys::HtmlCanvasElement;

/// The message of a binding whose body is still missing.
fn not_yet(func: &str) -> JsError {
    JsError::new(&alloc::format!("{func}: not implemented yet"))
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
    let _ = (scenario_json, settings_json);
    Err(not_yet("simulate_channel"))
}

/// A recording's estimation and track in progress (run by `www/js/channel-worker.js`).
#[wasm_bindgen]
pub struct ChannelJob {
    _private: (),
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
    /// (`npz: …`, the array's name, a zip bomb, a size over the cap), a link the scenario does
    /// not have, a bad setting (named by its field), neither or both calibration sources.
    /// Nothing is estimated yet.
    #[wasm_bindgen(constructor)]
    pub fn new(
        scenario_json: &str,
        recording: &[u8],
        calibration: Option<Vec<u8>>,
        truth_json: Option<String>,
        settings_json: &str,
    ) -> Result<ChannelJob, JsError> {
        let _ = (
            scenario_json,
            recording,
            calibration,
            truth_json,
            settings_json,
        );
        Err(not_yet("ChannelJob"))
    }

    /// Runs work for about `budget_ms` ms (at least one unit: one snapshot of one link while
    /// estimating) and returns the progress (as [`ChannelJob::progress`]).
    pub fn step(&mut self, budget_ms: f64) -> Result<JsValue, JsError> {
        let _ = budget_ms;
        Err(not_yet("ChannelJob.step"))
    }

    /// The progress `{phase, done, total, finished}`: `phase` is `"calibration"` (estimating
    /// the calibration recording; `done`/`total` count link-snapshots), `"estimate"` (the
    /// recording; link-snapshots), `"track"` (0 or 1 of 1), `"figure"` (0 or 1 of 1) or
    /// `"done"`; `finished` is true once every result is there.
    pub fn progress(&self) -> Result<JsValue, JsError> {
        Err(not_yet("ChannelJob.progress"))
    }

    /// What was read: `{snapshots, links (recorded), layout ("cfr" | "cir"), samples_per_link,
    /// duration_s, calibration: {source: "file" | "range", snapshots}, truth: bool}`.
    pub fn summary(&self) -> Result<JsValue, JsError> {
        Err(not_yet("ChannelJob.summary"))
    }

    /// Time spent per phase in this job, ms (wall clock in the worker): `{parse_ms (reading the
    /// files), calibration_ms, estimate_ms, track_ms, figure_ms}` (0 for a phase not run yet).
    pub fn timings(&self) -> Result<JsValue, JsError> {
        Err(not_yet("ChannelJob.timings"))
    }

    /// The recording's estimates as JSON text, exactly the file `cir estimate --out` writes
    /// (without its final newline): `{format: "scatterloc-estimates", t_s: [s…], links:
    /// [[transmitter, receiver]…] (every model link), recorded: [bool per link], estimates:
    /// [snapshot][link][{delay_s, amplitude, sigma_s, snr_db (null at SNR ≤ 0), track,
    /// confirmed}], noise_var: [snapshot][link] (W), max_paths, p_fa}`. Throws before the
    /// `"estimate"` phase is done.
    pub fn estimates_json(&self) -> Result<String, JsError> {
        Err(not_yet("ChannelJob.estimates_json"))
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
        Err(not_yet("ChannelJob.track_json"))
    }

    /// The delay figure's data ([S] Fig. 4) as JSON text: `{t_range_s: [t0, t1],
    /// amplitude_db_range: [lo, hi] | null, links: [{name ("Tx → Rx1"), range_m: [lo, hi],
    /// image: {t_s: [s per column], r0_m, dr_m, rows, db: [rows × cols, row-major, row 0 at
    /// r0_m, dB re 1 W], db_range: [lo, hi]} | null, estimates: [{t_s, range_m, amplitude_db}…],
    /// statics: [{mean_m, halfwidth_m}…] (the calibration's clusters, ±3σ), truth: [{kind,
    /// primary, points: [[t_s, range_m]…]}…]}…]}` (one entry per model link). Throws before the
    /// `"figure"` phase is done.
    pub fn figure_json(&self) -> Result<String, JsError> {
        Err(not_yet("ChannelJob.figure_json"))
    }

    /// The track's error view as JSON text (`present::track_errors`, what `cir track --figure`
    /// draws): `{t_s, track_m: [[[x, y]…] per run of snapshots with a state], truth_m: [runs],
    /// error_m: [m | null per snapshot], cdf: [[e, F]…], stats: {count, median_m, p90_m, max_m,
    /// rms_m, fraction_below_1m} | null, track_start: index | null}`. Throws before the
    /// `"track"` phase is done.
    pub fn errors_json(&self) -> Result<String, JsError> {
        Err(not_yet("ChannelJob.errors_json"))
    }
}

/// The channel view's pictures on the page's main thread, from a finished job's texts.
#[wasm_bindgen]
pub struct ChannelFigures {
    _private: (),
}

#[wasm_bindgen]
impl ChannelFigures {
    /// The figures of scenario JSON `scenario_json` from a [`ChannelJob`]'s `figure_json`,
    /// `errors_json` and `track_json` texts. Throws the named parse error on malformed text.
    #[wasm_bindgen(constructor)]
    pub fn new(
        scenario_json: &str,
        figure_json: &str,
        errors_json: &str,
        track_json: &str,
    ) -> Result<ChannelFigures, JsError> {
        let _ = (scenario_json, figure_json, errors_json, track_json);
        Err(not_yet("ChannelFigures"))
    }

    /// Snapshots of the track.
    pub fn snapshot_count(&self) -> usize {
        0
    }

    /// The size `[width, height]` px the CLI gives the delay figure (`chart::delays_size`).
    pub fn delays_size(&self) -> Vec<u32> {
        Vec::new()
    }

    /// The size `[width, height]` px the CLI gives the error chart (`chart::track_errors_size`).
    pub fn errors_size(&self) -> Vec<u32> {
        Vec::new()
    }

    /// Draws the delay figure (`chart::draw_delays`, as `cir track --delays-figure`) on
    /// `canvas` at its pixel size with `title` and `subtitle` (`""`: none).
    pub fn draw_delays(
        &self,
        canvas: HtmlCanvasElement,
        title: &str,
        subtitle: &str,
    ) -> Result<(), JsError> {
        let _ = (canvas, title, subtitle);
        Err(not_yet("ChannelFigures.draw_delays"))
    }

    /// The delay figure as SVG text of `width × height` px (0, 0: the CLI's size).
    pub fn delays_svg(
        &self,
        width: u32,
        height: u32,
        title: &str,
        subtitle: &str,
    ) -> Result<String, JsError> {
        let _ = (width, height, title, subtitle);
        Err(not_yet("ChannelFigures.delays_svg"))
    }

    /// Draws the track figure (`chart::draw_track_errors`, as `cir track --figure`: the track on
    /// the map, the error over time and its CDF) on `canvas` at its pixel size.
    pub fn draw_errors(
        &self,
        canvas: HtmlCanvasElement,
        title: &str,
        subtitle: &str,
    ) -> Result<(), JsError> {
        let _ = (canvas, title, subtitle);
        Err(not_yet("ChannelFigures.draw_errors"))
    }

    /// The track figure as SVG text of `width × height` px (0, 0: the CLI's size).
    pub fn errors_svg(
        &self,
        width: u32,
        height: u32,
        title: &str,
        subtitle: &str,
    ) -> Result<String, JsError> {
        let _ = (width, height, title, subtitle);
        Err(not_yet("ChannelFigures.errors_svg"))
    }

    /// The map overlay of snapshot `k` (0 … snapshot_count − 1): `{index, t_s, track_m: [[x,
    /// y]…] (the estimated positions of snapshots 0 … k that have a state), state: [x, y, vx,
    /// vy] | null, sigma_ellipse: {cx, cy, a, b, angle} | null (the filter's 1σ position
    /// ellipse), error_m: m | null (with a truth), links_used, links: [{link, tx, rx,
    /// delay_s, range_m, sigma_s, choice, ellipse: {cx, cy, a, b, angle} | null}…] (the links
    /// whose delay was used at k, with the iso-delay ellipse of that delay)}`. Throws on `k` out
    /// of range.
    pub fn overlay(&self, k: usize) -> Result<JsValue, JsError> {
        let _ = k;
        Err(not_yet("ChannelFigures.overlay"))
    }
}
