//! [`ChannelJob`]: a recording's statics, estimates, track and delay figure in slices (run in a
//! Web Worker, `www/js/channel-worker.js`), through the core's channel chain: the settings are
//! the core's [`ChannelRequest`] (its JSON, field for field), the estimation one
//! [`EstimationRun`] (statics and estimates in the same run, as `cir estimate`), the track
//! [`cir_track`], the files [`estimates_doc`] and [`track_doc`] (as the CLI writes them); with
//! several people on ([`ChannelJob::set_targets`]) also the labelled tracks of `cir track
//! --targets auto` (`people.rs`).

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use serde::Serialize;
use wasm_bindgen::prelude::*;

use super::people::{parse_targets, people_doc, truth_others, PeopleDoc};
use super::{check_size, named, now_ms, scenario_and_model, MAX_CHANNEL_PARTICLE_STEPS};
use crate::channel::ResponseMap;
use crate::channel::{Band, Recording};
use crate::edge::wasm::base::err;
use crate::edge::wasm::json::{to_js, to_json};
use crate::error::limits::{MAX_PAGE_RECORDING_BYTES, MAX_PAGE_TEXT_BYTES};
use crate::error::{Cancel, Error};
use crate::formats::Truth;
use crate::present::{
    delay_figure_link, estimates_doc, link_names, track_doc, track_errors, DelayFigure, LinkDelays,
    TrackErrorView,
};
use crate::study::{
    cir_track, prepare, ChannelRequest, ChannelStatics, CirTrackOutput, EstimationRun,
    FrontEndConfig, RecordingEstimates,
};
use crate::track::FilterKind;
use crate::{Model, Scenario};

/// Link-snapshots estimated per clock reading (each is 0.1–2 ms).
const UNITS_PER_READING: usize = 4;

/// Reads a dropped recording (`.npz` or CSI) named `what` (`recording`, `calibration`): its size is
/// checked before parsing ([`MAX_PAGE_RECORDING_BYTES`]), the reader's caps while parsing, and
/// its links against `model`.
pub(super) fn read_page_recording(
    what: &'static str,
    bytes: &js_sys::Uint8Array,
    model: &Model,
) -> Result<Recording, JsError> {
    // Before the bytes are copied into the module's memory.
    check_size(what, bytes.length() as usize, MAX_PAGE_RECORDING_BYTES).map_err(err)?;
    let bytes = bytes.to_vec();
    let rec = super::open::page_recording(&bytes).map_err(named(what))?;
    rec.link_map(model).map_err(named(what))?;
    Ok(rec)
}

/// An error of the estimation of the recording with its empty area: the core names the empty
/// area's problems `calibration…` (statics `clusters` without an empty area, links or bands
/// that differ, no direct path in the background), which stay as they are; anything else is
/// the recording's.
pub(super) fn estimation_error(e: Error) -> JsError {
    if e.field().is_some_and(|f| f.starts_with("calibration")) {
        err(e)
    } else {
        named("recording")(e)
    }
}

/// The page's cap on a particle filter's work: particles × snapshots within
/// [`MAX_CHANNEL_PARTICLE_STEPS`] (the track runs in one call of the worker).
pub(super) fn check_particle_steps(req: &ChannelRequest, snapshots: usize) -> Result<(), Error> {
    if let FilterKind::Pf(pf) = req.filter_kind()? {
        if pf.particles.saturating_mul(snapshots) > MAX_CHANNEL_PARTICLE_STEPS {
            return Err(Error::SizeLimit {
                field: "particles",
                value: pf.particles,
                min: 1,
                max: MAX_CHANNEL_PARTICLE_STEPS / snapshots.max(1),
            });
        }
    }
    Ok(())
}

/// Where a job is.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Phase {
    Estimate,
    Track,
    Figure,
    Done,
}

impl Phase {
    fn name(self) -> &'static str {
        match self {
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
    synchronized: Option<bool>,
    calibration: CalibrationSummaryJs,
    statics: &'static str,
    delay_reference: &'static str,
    truth: bool,
    targets: &'static str,
}

/// The empty area of `ChannelJob.summary()`.
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
    empty: Option<Recording>,
    empty_source: &'static str,
    truth: Option<Truth>,
    /// The truth file's further walkers (`others`), or the error reading them (raised only
    /// when several people are tracked).
    others: Result<Vec<Vec<[f64; 4]>>, Error>,
    /// Whether the labelled tracks of several people are made too (`set_targets("auto")`).
    several: bool,
    people: Option<PeopleDoc>,
    req: ChannelRequest,
    cfg: FrontEndConfig,
    phase: Phase,
    run: Option<EstimationRun>,
    statics: Option<ChannelStatics>,
    est: Option<RecordingEstimates>,
    track: Option<CirTrackOutput>,
    view: Option<TrackErrorView>,
    figure: Option<DelayFigure>,
    /// The delay figure's panels made so far (one per unit of the `"figure"` phase) and the
    /// recording's band they are made from.
    panels: Vec<LinkDelays>,
    band: Option<(Band, ResponseMap)>,
    timings: TimingsJs,
}

#[wasm_bindgen]
impl ChannelJob {
    /// A job on scenario JSON `scenario_json` (schema v1), the bytes of the recording
    /// `recording` (`.npz`), the bytes of the empty area's recording `calibration`
    /// (`undefined`: the settings' `calibration_range_s` of the same recording, or, without
    /// one, a background learnt recursively from the recording itself), the truth file's text
    /// `truth_json` (`undefined`: none; its times must equal the recording's), and
    /// `settings_json`: `""` or the core's `ChannelRequest` as JSON, every field optional with
    /// the CLI's defaults, unknown fields refused:
    ///
    /// `{max_paths (--max-paths, 12), pfa (--pfa, 1e-3), statics: "background" | "clusters"
    /// (--statics, "background"; "clusters" needs an empty area), delay_reference: "absolute" |
    /// "los" (--delay-reference; absent: the recording's own `synchronized` flag, absolute
    /// without one), background_time_s (--background-time, 10 s), calibration_range_s: [t0,
    /// t1] (--calibration-range: the snapshots with t0 ≤ t ≤ t1 are the empty area), filter:
    /// "ekf" | "ukf" | "pf" (--filter), ukf_alpha, ukf_beta, ukf_kappa (ukf only), particles,
    /// roughening, bootstrap, seed (pf only), process_noise (m²/s³, 1), association: "gated" |
    /// "spec", sigma: "estimator" | "budget", extent_sigma_m (m, 0.2)}`; a particle filter's
    /// particles × snapshots at most [`MAX_CHANNEL_PARTICLE_STEPS`].
    ///
    /// Reads the files here (sizes capped before parsing): throws the reader's named error
    /// prefixed by the file (`recording: npz: …`, `calibration: cfr: wrong shape …`, a zip bomb,
    /// `recording: 300000000 is …` over the cap), a link the scenario does not have, a bad
    /// setting (named by its field; `settings: invalid JSON: …` for an unknown field), both a
    /// calibration recording and a time range. Nothing is estimated yet.
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
        check_size("settings", settings_json.len(), MAX_PAGE_TEXT_BYTES as u64).map_err(err)?;
        let req = ChannelRequest::from_json(settings_json).map_err(|e| match e {
            Error::Parse { .. } => named("settings")(e),
            e => err(e),
        })?;
        let rec = read_page_recording("recording", recording, &model)?;
        check_particle_steps(&req, rec.t_s.len()).map_err(err)?;
        let file = match calibration {
            Some(bytes) => Some(read_page_recording("calibration", &bytes, &model)?),
            None => None,
        };
        // The core's rule: the file, or the range of the recording, or neither.
        let empty_source = match (&file, req.calibration_range_s) {
            (Some(_), _) => "file",
            (None, Some(_)) => "range",
            (None, None) => "none",
        };
        let empty = req
            .empty_area(file.as_ref(), &rec)
            .map_err(err)?
            .map(alloc::borrow::Cow::into_owned);
        let (truth, others) = match truth_json {
            Some(text) => {
                check_size("truth", text.len(), MAX_PAGE_TEXT_BYTES as u64).map_err(err)?;
                let t = Truth::from_json(&text).map_err(named("truth"))?;
                t.check_times(&rec.t_s).map_err(named("truth"))?;
                (Some(t), truth_others(&text))
            }
            None => (None, Ok(Vec::new())),
        };
        let bw = scenario.radio.bandwidth_hz;
        // The empty area's own checks first, so its problems are named as its.
        if let Some(e) = &empty {
            prepare(&model, bw, e, None, &FrontEndConfig::default())
                .map_err(named("calibration"))?;
        }
        let cfg = req.front_end(rec.synchronized);
        let run =
            EstimationRun::new(&model, bw, &rec, empty.as_ref(), &cfg).map_err(estimation_error)?;
        let timings = TimingsJs {
            parse_ms: now_ms() - t0,
            ..TimingsJs::default()
        };
        Ok(ChannelJob {
            scenario,
            model,
            rec,
            empty,
            empty_source,
            truth,
            others,
            several: false,
            people: None,
            req,
            cfg,
            phase: Phase::Estimate,
            run: Some(run),
            statics: None,
            est: None,
            track: None,
            view: None,
            figure: None,
            panels: Vec::new(),
            band: None,
            timings,
        })
    }

    /// How many people the run tracks: `"one"` (the default: the single-target track of `cir
    /// track`) or `"auto"` (several people: after the single-target track, also the labelled
    /// tracks `cir track --targets auto` makes with its defaults, [`ChannelJob::people_json`]).
    /// Throws `targets: "…" is not one of one, auto`, or once the track has been made.
    pub fn set_targets(&mut self, targets: &str) -> Result<(), JsError> {
        let several = parse_targets(targets).map_err(err)?;
        if self.phase != Phase::Estimate {
            return Err(JsError::new(
                "ChannelJob.set_targets: the track is made already (set it before stepping)",
            ));
        }
        self.several = several;
        Ok(())
    }

    /// Runs work for about `budget_ms` ms (at least one unit: a few snapshots of one link while
    /// estimating, a link's statics with its first snapshot; the track is one unit, the figure
    /// one unit per link), returning early when a phase ends (so the next phase's progress is
    /// reported before its first unit runs, issue 38 item 9), and returns the progress (as
    /// [`ChannelJob::progress`]). Throws the core's
    /// named error of the phase (prefixed by `recording`, `track` or `figure`; the empty
    /// area's as `calibration…`); after an error the job is spent.
    pub fn step(&mut self, budget_ms: f64) -> Result<JsValue, JsError> {
        let start = now_ms();
        loop {
            let (t, phase) = (now_ms(), self.phase);
            self.unit()?;
            let spent = now_ms() - t;
            match phase {
                Phase::Estimate => self.timings.estimate_ms += spent,
                Phase::Track => self.timings.track_ms += spent,
                Phase::Figure => self.timings.figure_ms += spent,
                Phase::Done => {}
            }
            if self.phase != phase || now_ms() - start >= budget_ms {
                break;
            }
        }
        self.progress()
    }

    /// The progress `{phase, done, total, finished}`: `phase` is `"estimate"` (the statics and
    /// paths of every link; `done`/`total` count link-snapshots), `"track"` (0 of 1),
    /// `"figure"` (`done` of `total` links' panels) or `"done"` (1 of 1); `finished` is true
    /// once every result is there.
    pub fn progress(&self) -> Result<JsValue, JsError> {
        let (done, total) = match (&self.run, self.phase) {
            (Some(r), _) => (r.done(), r.total()),
            (None, Phase::Done) => (1, 1),
            (None, Phase::Figure) => (self.panels.len(), self.model.link_count().max(1)),
            (None, _) => (0, 1),
        };
        to_js(&ProgressJs {
            phase: self.phase.name(),
            done,
            total,
            finished: self.phase == Phase::Done,
        })
    }

    /// What was read and how it will be estimated: `{snapshots, links (recorded), layout
    /// ("cfr" | "cir"), samples_per_link, duration_s, synchronized (the recording's flag, or
    /// null), calibration: {source: "file" | "range" | "none" (a background learnt from the
    /// recording itself), snapshots (of the empty area; 0 for "none")}, statics ("background"
    /// | "clusters"), delay_reference ("absolute" | "los", resolved), truth: bool, targets:
    /// "one" | "auto"}`.
    pub fn summary(&self) -> Result<JsValue, JsError> {
        let r = &self.rec;
        to_js(&SummaryJs {
            snapshots: r.snapshot_count(),
            links: r.link_count(),
            layout: r.layout.array(),
            samples_per_link: r.samples_per_link(),
            duration_s: r.t_s[r.t_s.len() - 1] - r.t_s[0],
            synchronized: r.synchronized,
            calibration: CalibrationSummaryJs {
                source: self.empty_source,
                snapshots: self.empty.as_ref().map_or(0, Recording::snapshot_count),
            },
            statics: self.cfg.statics.name(),
            delay_reference: self.cfg.delay_reference.name(),
            truth: self.truth.is_some(),
            targets: if self.several { "auto" } else { "one" },
        })
    }

    /// Time spent per phase in this job, ms (wall clock in the worker, `performance.now()`):
    /// `{parse_ms (reading and checking the files), estimate_ms (statics and paths), track_ms
    /// (with several people, their labelled tracks too), figure_ms}` (0 for a phase not run
    /// yet).
    pub fn timings(&self) -> Result<JsValue, JsError> {
        to_js(&self.timings)
    }

    /// The recording's estimates as JSON text, exactly the file `cir estimate --out` writes
    /// (without its final newline; `present::estimates_doc`): `{format:
    /// "scatterloc-estimates", t_s, links, recorded, estimates: [snapshot][link][{delay_s,
    /// amplitude, sigma_s, snr_db, track, confirmed}], noise_var, alignment, max_paths, p_fa,
    /// front_end: {max_paths, p_fa, statics, delay_reference, background_time_s, links,
    /// bounds}, calibration}`. Throws before the `"estimate"` phase is done.
    pub fn estimates_json(&self) -> Result<String, JsError> {
        match (&self.est, &self.statics) {
            (Some(est), Some(st)) => to_json(&estimates_doc(&self.model, est, &self.cfg, st)),
            _ => Err(pending("estimates_json")),
        }
    }

    /// The track as JSON text, exactly the file `cir track --out` writes (without its final
    /// newline; `present::track_doc`): `{t_s, states: [[x, y, vx, vy] | null…] (null outside
    /// the segments), covariances, links_used, delays_used_s, sigmas_used_s, choices,
    /// static_removed, start: {…} | null, segments: [{first, last, t_first_s, t_last_s, end:
    /// "innovation" | "misses" | "outside_area" | "filter" | "end", confirmed_at, hits, start}…], filter,
    /// process_noise, sigma, association, extent_sigma_m, front_end, calibration, error?:
    /// {count, median_m, p90_m, max_m, rms_m, fraction_below_1m} (with a truth and a started
    /// track)}`. Throws before the `"track"` phase is done.
    pub fn track_json(&self) -> Result<String, JsError> {
        let (track, view, st, est) = match (&self.track, &self.view, &self.statics, &self.est) {
            (Some(t), Some(v), Some(s), Some(e)) => (t, v, s, e),
            _ => return Err(pending("track_json")),
        };
        let error = self.truth.as_ref().and(view.stats);
        let doc = track_doc(track, &self.req, &self.cfg, st, est, error).map_err(err)?;
        to_json(&doc)
    }

    /// The people of a run with several people (`set_targets("auto")`) as JSON text: `{track
    /// (the document `cir track --targets auto --out` writes without its additions: {method,
    /// settings, t_s, targets: [scan][{label, state, covariance, …}], tracks: [{label,
    /// first_scan, last_scan, …}], static_removed}), extent_sigma_m, statics, delay_reference
    /// (its additions), ellipses: [scan][the 1σ ellipse {cx, cy, a, b, angle} | null per
    /// reported target], truth: {t_s, targets} | null (label 0 the truth file's walker, i + 1
    /// its `others[i]`), score: {c_m, gospa_m, mean_gospa_m, switches, …} | null (with a truth,
    /// GOSPA c = 1 m)}`. Throws with one person, or before the `"track"` phase is done.
    pub fn people_json(&self) -> Result<String, JsError> {
        if !self.several {
            return Err(JsError::new(
                "ChannelJob.people_json: one person is tracked (set_targets(\"auto\") for several)",
            ));
        }
        to_json(self.people.as_ref().ok_or_else(|| pending("people_json"))?)
    }

    /// The delay figure's data ([S] Fig. 4) as JSON text: `{t_range_s: [t0, t1],
    /// amplitude_db_range: [lo, hi] | null, links: [{name ("Tx → Rx1"), range_m: [lo, hi],
    /// image: {t_s: [s per column], r0_m, dr_m, rows, db: [rows × cols, row-major, row 0 at
    /// r0_m, dB re 1 W], db_range: [lo, hi]} | null, estimates: [{t_s, range_m, amplitude_db}…],
    /// statics: [{mean_m, halfwidth_m}…] (the static clusters, ±3σ), truth: [{kind, primary,
    /// points: [[t_s, range_m]…]}…]}…]}` (one entry per model link). Throws before the
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
        match self.phase {
            Phase::Estimate => {
                let run = self
                    .run
                    .as_mut()
                    .ok_or_else(|| JsError::new("ChannelJob: the job failed earlier"))?;
                if !run
                    .run(&self.rec, self.empty.as_ref(), UNITS_PER_READING)
                    .map_err(estimation_error)?
                {
                    return Ok(());
                }
                let run = self.run.take().ok_or_else(|| pending("step"))?;
                let (statics, est) = run
                    .finish(&self.model, &self.rec)
                    .map_err(estimation_error)?;
                self.statics = Some(statics);
                self.est = Some(est);
                self.phase = Phase::Track;
            }
            Phase::Track => {
                let (st, est) = match (&self.statics, &self.est) {
                    (Some(s), Some(e)) => (s, e),
                    _ => return Err(pending("step")),
                };
                let track = cir_track(
                    &self.req,
                    &self.model,
                    &self.scenario.area_m,
                    &st.calibration,
                    est,
                    Cancel::NEVER,
                )
                .map_err(named("track"))?;
                let truth_states: Vec<Option<[f64; 4]>> = self
                    .truth
                    .as_ref()
                    .map(|t| t.states.iter().map(|s| Some(*s)).collect())
                    .unwrap_or_default();
                let view = track_errors(&track.t_s, &track.states, &truth_states)
                    .map_err(named("truth"))?;
                if self.several {
                    let others = self.others.clone().map_err(named("truth"))?;
                    let doc = people_doc(
                        &self.model,
                        &self.scenario.area_m,
                        st,
                        est,
                        &self.req,
                        &self.cfg,
                        self.truth.as_ref().map(|t| (t, others.as_slice())),
                    )
                    .map_err(|(what, e)| named(what)(e))?;
                    self.people = Some(doc);
                }
                self.track = Some(track);
                self.view = Some(view);
                self.phase = Phase::Figure;
            }
            Phase::Figure => {
                let (st, est) = match (&self.statics, &self.est) {
                    (Some(s), Some(e)) => (s, e),
                    _ => return Err(pending("step")),
                };
                if self.band.is_none() {
                    let bw = self.scenario.radio.bandwidth_hz;
                    self.band = Some(Band::of_recording(&self.rec, bw).map_err(named("figure"))?);
                }
                let band = self.band.as_ref().ok_or_else(|| pending("step"))?;
                let p = self.panels.len();
                if p < self.model.link_count() {
                    let panel = delay_figure_link(
                        &self.model,
                        &self.rec,
                        band,
                        est,
                        Some(&st.calibration),
                        self.truth.as_ref().map(|t| t.states.as_slice()),
                        &link_names(&self.scenario, &self.model),
                        p,
                    )
                    .map_err(named("figure"))?;
                    self.panels.push(panel);
                }
                if self.panels.len() >= self.model.link_count() {
                    let panels = core::mem::take(&mut self.panels);
                    self.figure = Some(DelayFigure::new(&self.rec.t_s, panels));
                    self.band = None;
                    self.phase = Phase::Done;
                }
            }
            Phase::Done => {}
        }
        Ok(())
    }
}
