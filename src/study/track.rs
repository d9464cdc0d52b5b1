//! Tracking from a measurement file as one use case (spec §4, §6): the file's delays — one per
//! link and step (`steps`), or every link's full list of estimates (`raw_steps`), gated against
//! a calibration (E4) and associated (§4) before each update — run through any tracker (the
//! EKF, the UKF or the particle filter; [`crate::track::Filter`]), started from the file's
//! `initial_state` or from the Levenberg–Marquardt fix of its `initial_snapshot`. The result
//! ([`TrackOutput`]) is the document `scatterloc track` prints. With range rates in the file
//! (`range_rates_mps`, issue 42 §5; docs/doppler.md D1, D5), [`TrackRequest::track_with_rates`]
//! updates every step with delays and range rates ([`Filter::update_doppler`]) and reports the
//! predicted range rates and their innovations ([`TrackDoppler`]).
//!
//! ```
//! use scatterloc::formats::Measurements;
//! use scatterloc::scenario::presets;
//! use scatterloc::study::{track_measurements, TrackRequest};
//! use scatterloc::track::gating::AssociationRule;
//! use scatterloc::track::FilterKind;
//! use scatterloc::Model;
//!
//! let scenario = presets::preset("sensors2019").unwrap();
//! let model = Model::new(&scenario).unwrap();
//! // The delays of a scatterer standing at (10, 10) m, three steps.
//! let truth = scatterloc::Vec2::new(10.0, 10.0);
//! let delays: Vec<Option<f64>> = model.network.delays(truth).into_iter().map(Some).collect();
//! let file = serde_json::json!({
//!     "dt_s": 0.1,
//!     "process_noise": 0.1,
//!     "initial_state": [9.5, 10.5, 0.0, 0.0],
//!     "initial_covariance": [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.1, 0.0], [0.0, 0.0, 0.0, 0.1]],
//!     "steps": [delays.clone(), delays.clone(), delays],
//! });
//! let m = Measurements::from_json(&file.to_string()).unwrap();
//! let out = track_measurements(&TrackRequest {
//!     model: &model,
//!     area: &scenario.area_m,
//!     measurements: &m,
//!     calibration: None,
//!     rule: AssociationRule::Spec,
//!     filter: FilterKind::Ekf,
//!     seed: 1,
//! })
//! .unwrap();
//! assert_eq!(out.t_s.len(), 3);
//! assert!((out.states[2][0] - 10.0).abs() < 0.05 && (out.states[2][1] - 10.0).abs() < 0.05);
//! ```

use alloc::format;
use alloc::string::ToString;
use alloc::vec;
use alloc::vec::Vec;

use serde::Serialize;

use crate::error::{check_every, Cancel, Error, Result};
use crate::formats::{Measurements, RawStep, Start, Steps};
use crate::math::{Mat4, Vec4};
use crate::measure::{rng, Model};
use crate::scenario::Area;
use crate::study::CpiDoc;
use crate::track::gating::{
    start_from_snapshot, AssociationRule, Calibration, Choice, GatedTracker, SegmentConfig,
    SegmentEvent, SegmentSetup, SegmentTracker, START_SPEED_SIGMA_MPS,
};
use crate::track::{step_ns, UpdateSummary};
use crate::track::{ConstantVelocity, Ekf, Filter, FilterKind, MeasurementNoise, Tracker};
use crate::track::{RangeRates, RateNoise};

/// What a track runs on.
#[derive(Debug, Clone, Copy)]
pub struct TrackRequest<'a> {
    /// The measurement model of the scenario.
    pub model: &'a Model,
    /// The scenario's area (the LM fix of `initial_snapshot` searches it).
    pub area: &'a Area,
    /// The measurement file.
    pub measurements: &'a Measurements,
    /// The calibration of the empty area (`raw_steps` only; `None`: nothing is static).
    pub calibration: Option<&'a Calibration>,
    /// How a link's estimates are associated (`raw_steps` only).
    pub rule: AssociationRule,
    /// The tracker.
    pub filter: FilterKind,
    /// The particle filter's seed (it draws its particles from stream 0 of it).
    pub seed: u64,
}

/// A track: one entry per step (after its update).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackOutput {
    /// `t_k = (k + 1) T`, s.
    pub t_s: Vec<f64>,
    /// The estimates `[x, y, vx, vy]`.
    pub states: Vec<[f64; 4]>,
    /// Their covariances.
    pub covariances: Vec<[[f64; 4]; 4]>,
    /// NIS `νᵀS⁻¹ν` of the step; `null` when no link was used.
    pub nis: Vec<Option<f64>>,
    /// Links used per step.
    pub links_used: Vec<usize>,
    /// `raw_steps` only: per step the delay taken per link (`null` = absent), s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delays_used_s: Option<Vec<Vec<Option<f64>>>>,
    /// `raw_steps` only: per step how each link was chosen (absent/single/nearest/strongest).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub choices: Option<Vec<Vec<&'static str>>>,
    /// `raw_steps` only: per step per link the estimates discarded as static (E4).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub static_removed: Option<Vec<Vec<usize>>>,
    /// `initial_snapshot` only: the LM fix that started the filter.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start: Option<TrackStart>,
    /// A file with `range_rates_mps` only: how its range rates were used.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub doppler: Option<TrackDoppler>,
}

/// How a track used its file's range rates (issue 42 §5).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackDoppler {
    /// Whether the updates used them (`false`: ignored, the delay-only track).
    pub used: bool,
    /// Where their σ came from: `fixed` (per link), `cpi` (D5 at the prediction) or `cpi_at`
    /// (D5 at a given position).
    pub sigma: &'static str,
    /// The CPI of a `cpi` σ.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cpi: Option<CpiDoc>,
    /// When used: per step, each link's predicted range rate `ṙ_p(x̂⁻)` after the predict
    /// (D1), m/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted_range_rates_mps: Option<Vec<Vec<f64>>>,
    /// When used: per step, each link's innovation `ṙ_p − ṙ_p(x̂⁻)` (`null` = no rate), m/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_rate_innovations_mps: Option<Vec<Vec<Option<f64>>>>,
}

/// The start of a track from `initial_snapshot`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackStart {
    /// The fix, m.
    pub position_m: [f64; 2],
    /// Its position covariance, m².
    pub covariance_m2: [[f64; 2]; 2],
    /// Why LM stopped.
    pub termination: &'static str,
    /// Links the fix used.
    pub links_used: usize,
    /// The delay taken per link (`null` = none), s.
    pub delays_used_s: Vec<Option<f64>>,
    /// How each link's delay was chosen.
    pub choices: Vec<&'static str>,
}

/// Runs the track of `req`. Errors name the field of the file (`steps[k]`, `raw_steps[k][p]`,
/// `initial_snapshot`, …).
pub fn track_measurements(req: &TrackRequest) -> Result<TrackOutput> {
    track_measurements_in(req, Cancel::NEVER)
}

/// [`track_measurements`] that asks `cancel` every millisecond or so of work
/// ([`check_every`] steps of [`step_ns`]) and stops with [`Error::Cancelled`] (issue 24: a
/// 4096-link UKF step takes seconds, and a file may hold 10⁶ steps).
pub fn track_measurements_in(req: &TrackRequest, cancel: Cancel) -> Result<TrackOutput> {
    run(req, None, cancel)
}

impl TrackRequest<'_> {
    /// [`track_measurements_in`] with range rates: `rates_mps` per step of the file's `steps`,
    /// one per link (`None` = missing; e.g. a file's `range_rates_mps` read by
    /// [`Measurements::from_json_with_rates`]), their σ from `noise`. With `use_rates` each
    /// step predicts, records each link's predicted range rate and innovation, and updates with
    /// delays and range rates ([`Filter::update_doppler`]); without, the track is the
    /// delay-only one. The output's `doppler` says which. Rates with `raw_steps`, or of another
    /// step or link count, are [`Error::InvalidFile`] of `range_rates_mps`.
    pub fn track_with_rates(
        &self,
        rates_mps: &[Vec<Option<f64>>],
        noise: RateNoise,
        use_rates: bool,
        cancel: Cancel,
    ) -> Result<TrackOutput> {
        let n = self.model.link_count();
        let bad = |reason: alloc::string::String| Error::InvalidFile {
            field: "range_rates_mps".into(),
            reason,
        };
        let Some(steps) = &self.measurements.steps else {
            return Err(bad("only with steps (not raw_steps)".into()));
        };
        if rates_mps.len() != steps.len() {
            return Err(bad(format!(
                "expected {} lists (one per step of steps), found {}",
                steps.len(),
                rates_mps.len()
            )));
        }
        if let Some(k) = rates_mps.iter().position(|r| r.len() != n) {
            return Err(Error::InvalidFile {
                field: format!("range_rates_mps[{k}]"),
                reason: format!(
                    "expected {n} range rates (one per link, null = missing), found {}",
                    rates_mps[k].len()
                ),
            });
        }
        let (sigma, cpi) = match noise {
            RateNoise::Fixed(_) => ("fixed", None),
            RateNoise::Cpi(c) => ("cpi", Some(c)),
            RateNoise::CpiAt(c, _) => ("cpi_at", Some(c)),
        };
        let mut doc = TrackDoppler {
            used: use_rates,
            sigma,
            cpi: cpi.as_ref().map(CpiDoc::from),
            predicted_range_rates_mps: None,
            range_rate_innovations_mps: None,
        };
        let mut out = if use_rates {
            let rates = StepRates { rates_mps, noise };
            run(self, Some((&rates, &mut doc)), cancel)?
        } else {
            run(self, None, cancel)?
        };
        out.doppler = Some(doc);
        Ok(out)
    }
}

/// The range rates of a track's steps and their σ.
struct StepRates<'a> {
    rates_mps: &'a [Vec<Option<f64>>],
    noise: RateNoise<'a>,
}

/// The track of `req`, with `rates` (and their document) on the plain form.
fn run(
    req: &TrackRequest,
    rates: Option<(&StepRates, &mut TrackDoppler)>,
    cancel: Cancel,
) -> Result<TrackOutput> {
    let every = check_every(step_ns(req.filter, req.model.link_count()));
    let (model, m) = (req.model, req.measurements);
    let n = model.link_count();
    let motion = m.motion()?;
    let sigmas = m.sigmas(n)?;
    let noise = match &sigmas {
        Some(s) => MeasurementNoise::Fixed(s),
        None => MeasurementNoise::AtPrediction,
    };
    let empty;
    let cal = match req.calibration {
        Some(c) => c,
        None => {
            // No calibration: nothing is static (every estimate is a candidate).
            empty = Calibration {
                links: vec![Default::default(); n],
            };
            &empty
        }
    };
    let (ekf, start) = initial_filter(m, model, cal, req.area)?;
    let steps = m.steps()?;
    let len = steps.len();
    let mut out = TrackOutput {
        t_s: Vec::with_capacity(len),
        states: Vec::with_capacity(len),
        covariances: Vec::with_capacity(len),
        nis: Vec::with_capacity(len),
        links_used: Vec::with_capacity(len),
        delays_used_s: None,
        choices: None,
        static_removed: None,
        start,
        doppler: None,
    };
    let own = rng(req.seed, 0);
    let filter = Tracker::new(req.filter, ekf.state, ekf.covariance, own)?;
    match steps {
        Steps::Plain(steps) => {
            let at = Every { cancel, every };
            match rates {
                None => plain(model, filter, &motion, noise, steps, m.dt_s, at, &mut out)?,
                Some((rates, doc)) => {
                    let run = PlainRun {
                        model,
                        motion: &motion,
                        noise,
                        dt_s: m.dt_s,
                        at,
                    };
                    run.with_rates(filter, steps, rates, doc, &mut out)?
                }
            }
        }
        Steps::Raw(raw) => {
            let tracker = GatedTracker::new(filter, model, cal, motion, noise, req.rule)?;
            let setup = SegmentSetup {
                model,
                calibration: cal,
                area: req.area,
                kind: req.filter,
                process_noise: m.process_noise,
                rule: req.rule,
                estimate_sigmas: true,
                gate_sigma_s: None,
                segments: SegmentConfig::default(),
            };
            let held = SegmentTracker::holding(tracker, setup, 0.0).with_interval(m.dt_s);
            gated(held, n, raw, m.dt_s, Every { cancel, every }, &mut out)?
        }
    }
    Ok(out)
}

/// The filter at `t₀`: from `initial_state` and `initial_covariance`, or (raw steps only) from
/// the LM fix of `initial_snapshot`, reported as `start`.
fn initial_filter(
    m: &Measurements,
    model: &Model,
    cal: &Calibration,
    area: &Area,
) -> Result<(Ekf, Option<TrackStart>)> {
    match m.start()? {
        Start::Given(x0, p0) => Ok((Ekf::new(x0, p0)?, None)),
        Start::Snapshot(snap) => {
            let snap = Measurements::estimates("initial_snapshot", snap, model.link_count())?;
            let f = start_from_snapshot(model, cal, &snap, area, START_SPEED_SIGMA_MPS).map_err(
                |e| Error::InvalidFile {
                    field: "initial_snapshot".into(),
                    reason: e.to_string(),
                },
            )?;
            let c = &f.ekf.covariance;
            let start = TrackStart {
                position_m: [f.report.position.x, f.report.position.y],
                covariance_m2: [[c[(0, 0)], c[(0, 1)]], [c[(1, 0)], c[(1, 1)]]],
                termination: f.report.termination.as_str(),
                links_used: f.report.links_used,
                choices: names(&f.selection.choices),
                delays_used_s: f.selection.delays,
            };
            Ok((f.ekf, Some(start)))
        }
    }
}

/// The names of `choices`.
fn names(choices: &[Choice]) -> Vec<&'static str> {
    choices.iter().map(|c| c.name()).collect()
}

/// A core error of step `field`: `steps[k]: …`, and an invalid delay `delays_s[p]: …` of the
/// core as `steps[k][p]: …`.
fn step_error(field: &str, e: Error) -> Error {
    match e {
        Error::InvalidDelay { link, .. } => {
            let text = e.to_string();
            let reason = text.split_once(": ").map_or(text.as_str(), |(_, r)| r);
            Error::InvalidFile {
                field: format!("{field}[{link}]"),
                reason: reason.to_string(),
            }
        }
        other => Error::InvalidFile {
            field: field.to_string(),
            reason: other.to_string(),
        },
    }
}

/// A [`Cancel`] asked every `every` steps.
#[derive(Debug, Clone, Copy)]
struct Every<'a> {
    cancel: Cancel<'a>,
    every: usize,
}

impl Every<'_> {
    /// [`Error::Cancelled`] at step `k` when it is a checking step and the caller asks.
    fn check(&self, k: usize) -> Result<()> {
        if k.is_multiple_of(self.every.max(1)) {
            self.cancel.check()
        } else {
            Ok(())
        }
    }
}

/// The plain form: one delay (or null) per link and step.
#[allow(clippy::too_many_arguments)]
fn plain(
    model: &Model,
    mut filter: Tracker,
    motion: &ConstantVelocity,
    noise: MeasurementNoise,
    steps: &[Vec<Option<f64>>],
    dt_s: f64,
    at: Every,
    out: &mut TrackOutput,
) -> Result<()> {
    let n = model.link_count();
    for (k, z) in steps.iter().enumerate() {
        at.check(k)?;
        Measurements::check_plain_step(k, z, n)?;
        filter.predict(motion);
        // The step's field is named only when the update fails (formatting it every step was
        // 15-20 % of a long track's time).
        let summary = filter
            .update(model, z, noise)
            .map_err(|e| step_error(&format!("steps[{k}]"), e))?;
        record(out, filter.state(), filter.covariance(), k, dt_s, &summary);
    }
    Ok(())
}

/// What a plain track with range rates runs on.
struct PlainRun<'a> {
    model: &'a Model,
    motion: &'a ConstantVelocity,
    noise: MeasurementNoise<'a>,
    dt_s: f64,
    at: Every<'a>,
}

impl PlainRun<'_> {
    /// The plain form with range rates: per step predict, the predicted range rates (D1) and
    /// the innovations into `doc`, then the update with delays and range rates.
    fn with_rates(
        &self,
        mut filter: Tracker,
        steps: &[Vec<Option<f64>>],
        rates: &StepRates,
        doc: &mut TrackDoppler,
        out: &mut TrackOutput,
    ) -> Result<()> {
        let (model, n) = (self.model, self.model.link_count());
        let rate_noise = rates.noise;
        let (mut predicted, mut innovations) = (
            Vec::with_capacity(steps.len()),
            Vec::with_capacity(steps.len()),
        );
        for (k, (z, r)) in steps.iter().zip(rates.rates_mps).enumerate() {
            self.at.check(k)?;
            Measurements::check_plain_step(k, z, n)?;
            filter.predict(self.motion);
            let field = || format!("steps[{k}]");
            let pred = filter
                .predicted_range_rates(model, rate_noise)
                .map_err(|e| step_error(&field(), e))?;
            innovations.push(
                r.iter()
                    .zip(&pred)
                    .map(|(r, q)| r.map(|r| r - q.range_rate_mps))
                    .collect(),
            );
            predicted.push(pred.iter().map(|q| q.range_rate_mps).collect());
            let step_rates = RangeRates {
                rates_mps: r,
                noise: rate_noise,
            };
            let summary = filter
                .update_doppler(model, z, self.noise, &step_rates)
                .map_err(|e| step_error(&field(), e))?;
            record(
                out,
                filter.state(),
                filter.covariance(),
                k,
                self.dt_s,
                &summary,
            );
        }
        doc.predicted_range_rates_mps = Some(predicted);
        doc.range_rate_innovations_mps = Some(innovations);
        Ok(())
    }
}

/// The raw form: every step (one list per each of `links` links) through the one gated loop
/// of recordings and files, [`SegmentTracker`] (here holding the file's given start, loss
/// detection off), with what it chose.
fn gated(
    mut tracker: SegmentTracker,
    links: usize,
    raw: &[RawStep],
    dt_s: f64,
    at: Every,
    out: &mut TrackOutput,
) -> Result<()> {
    let (mut used, mut choices, mut removed) = (vec![], vec![], vec![]);
    // A held track never restarts, so it never replays.
    let replay = |_: usize| Err(Error::Cancelled);
    for (k, step) in raw.iter().enumerate() {
        at.check(k)?;
        let field = format!("raw_steps[{k}]");
        let estimates = Measurements::estimates(&field, step, links)?;
        let t = (k + 1) as f64 * dt_s;
        let SegmentEvent::Tracked(s) = tracker
            .step(k, t, &estimates, &replay)
            .map_err(|e| step_error(&field, e))?
        else {
            return Err(Error::InvalidFile {
                field,
                reason: "the track was not held".into(),
            });
        };
        record(out, &s.state, &s.covariance, k, dt_s, &s.step.summary);
        choices.push(names(&s.step.selection.choices));
        used.push(s.step.selection.delays);
        removed.push(s.step.selection.static_removed);
    }
    out.delays_used_s = Some(used);
    out.choices = Some(choices);
    out.static_removed = Some(removed);
    Ok(())
}

/// Appends step `k`'s filter state `x` and covariance `p` to the output.
fn record(out: &mut TrackOutput, x: &Vec4, p: &Mat4, k: usize, dt_s: f64, summary: &UpdateSummary) {
    out.t_s.push((k + 1) as f64 * dt_s);
    out.states.push((*x).into());
    out.covariances.push(core::array::from_fn(|i| {
        core::array::from_fn(|j| p[(i, j)])
    }));
    out.nis
        .push((summary.links_used > 0).then_some(summary.nis));
    out.links_used.push(summary.links_used);
}
