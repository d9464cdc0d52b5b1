//! Core results as JavaScript values: one serde struct per object the page reads, serialised by
//! [`to_js`] (or [`to_json`] for text). Field names, nesting and `null`s are the page's API (the
//! key sets are pinned by this file's tests); labels are the core's [`format_length_m`] with 3
//! significant digits. Ellipses have the page's shape `{cx, cy, a, b, angle}`
//! ([`EllipseView`], shared with the multi-target view); points are `[x, y]`.

use serde::{Serialize, Serializer};
use wasm_bindgen::prelude::*;

use crate::localize::CrlbPoint;
use crate::math::{Real, Vec4};
use crate::measure::Ellipse;
use crate::present::EllipseView;
use crate::present::MtlView;
use crate::present::Session;
use crate::present::{format_length_m, Tick};
use crate::present::{LinkSim, SnapshotFix, SnapshotSimulation};
use crate::present::{TrackEstimate, TrackFrame};
use crate::track::{FilterKind, MonteCarloConfig, MonteCarloResult, TrackRun};
use crate::{Model, Scenario, Vec2};

/// `v` as JSON text. serde_json writes non-finite numbers as `null`, so no NaN reaches
/// JavaScript.
pub(super) fn to_json<T: Serialize + ?Sized>(v: &T) -> Result<String, JsError> {
    serde_json::to_string(v).map_err(|e| JsError::new(&format!("internal error: {e}")))
}

/// `v` as a JavaScript value (its JSON text, parsed).
pub(super) fn to_js<T: Serialize + ?Sized>(v: &T) -> Result<JsValue, JsError> {
    js_sys::JSON::parse(&to_json(v)?).map_err(|_| JsError::new("internal error: bad JSON"))
}

fn label(m: Real) -> String {
    format_length_m(m, 3)
}

/// `{cx, cy, a, b, angle}` or `None` (null).
fn ellipse(e: Option<Ellipse>) -> Option<EllipseView> {
    e.map(EllipseView::from)
}

/// Serialises points as `[[x, y], …]`.
fn xy_points<S: Serializer>(p: &[Vec2], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(p.iter().map(|q| [q.x, q.y]))
}

/// Serialises states as their positions, `[[x, y], …]`.
fn state_positions<S: Serializer>(x: &[Vec4], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(x.iter().map(|x| [x[0], x[1]]))
}

/// Serialises states as `[[x, y, vx, vy], …]`.
fn states<S: Serializer>(x: &[Vec4], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(x.iter().map(|x| [x[0], x[1], x[2], x[3]]))
}

/// A position `{x, y}`, m.
#[derive(Serialize)]
pub(super) struct Position {
    x: Real,
    y: Real,
}

/// A position and velocity `{x, y, vx, vy}`, m and m/s.
#[derive(Serialize)]
pub(super) struct PositionVelocity {
    x: Real,
    y: Real,
    vx: Real,
    vy: Real,
}

/// `{x, y, bounded, sigma_x_m, sigma_y_m, rmse_m, rmse_label, sigma_x_label, sigma_y_label,
/// ellipse}`; unbounded: `bounded: false`, numbers and ellipse null, labels `unbounded` / `∞`.
#[derive(Serialize)]
pub(super) struct CrlbJs {
    x: Real,
    y: Real,
    bounded: bool,
    sigma_x_m: Option<Real>,
    sigma_y_m: Option<Real>,
    rmse_m: Option<Real>,
    rmse_label: String,
    sigma_x_label: String,
    sigma_y_label: String,
    ellipse: Option<EllipseView>,
}

impl CrlbJs {
    pub(super) fn new(c: &CrlbPoint) -> CrlbJs {
        let (x, y) = (c.position.x, c.position.y);
        match c.bound {
            Some(b) => CrlbJs {
                x,
                y,
                bounded: true,
                sigma_x_m: Some(b.sigma_x_m),
                sigma_y_m: Some(b.sigma_y_m),
                rmse_m: Some(b.rmse_m),
                rmse_label: label(b.rmse_m),
                sigma_x_label: label(b.sigma_x_m),
                sigma_y_label: label(b.sigma_y_m),
                ellipse: ellipse(c.ellipse()),
            },
            None => CrlbJs {
                x,
                y,
                bounded: false,
                sigma_x_m: None,
                sigma_y_m: None,
                rmse_m: None,
                rmse_label: "unbounded".into(),
                sigma_x_label: "\u{221e}".into(),
                sigma_y_label: "\u{221e}".into(),
                ellipse: None,
            },
        }
    }
}

/// A transmitter `{name, x, y, boresight: [ux, uy] | null}`.
#[derive(Serialize)]
struct TransmitterJs<'a> {
    name: &'a str,
    x: Real,
    y: Real,
    boresight: Option<[Real; 2]>,
}

/// A receiver `{name, x, y}`.
#[derive(Serialize)]
struct ReceiverJs<'a> {
    name: &'a str,
    x: Real,
    y: Real,
}

/// `{transmitters: [{name, x, y, boresight}], receivers: [{name, x, y}], links: [[tx, rx], …]}`.
#[derive(Serialize)]
pub(super) struct NodesJs<'a> {
    transmitters: Vec<TransmitterJs<'a>>,
    receivers: Vec<ReceiverJs<'a>>,
    links: Vec<[usize; 2]>,
}

impl<'a> NodesJs<'a> {
    pub(super) fn new(session: &'a Session) -> NodesJs<'a> {
        let (s, model) = (session.scenario(), session.model());
        NodesJs {
            transmitters: s
                .transmitters
                .iter()
                .zip(&model.patterns)
                .map(|(t, p)| TransmitterJs {
                    name: &t.name,
                    x: t.position_m[0],
                    y: t.position_m[1],
                    boresight: p.beam.map(|b| [b.boresight.x, b.boresight.y]),
                })
                .collect(),
            receivers: s
                .receivers
                .iter()
                .map(|r| ReceiverJs {
                    name: &r.name,
                    x: r.position_m[0],
                    y: r.position_m[1],
                })
                .collect(),
            links: model.network.links.iter().map(|l| [l.tx, l.rx]).collect(),
        }
    }
}

/// One link of a snapshot or track step: `{tx, rx, name, delay_s, sigma_s, range_sigma_label,
/// ellipse, outline, arc}`.
#[derive(Serialize)]
struct LinkJs<'a> {
    tx: usize,
    rx: usize,
    name: String,
    delay_s: Real,
    sigma_s: Real,
    range_sigma_label: String,
    ellipse: Option<EllipseView>,
    #[serde(serialize_with = "xy_points")]
    outline: &'a [Vec2],
    #[serde(serialize_with = "xy_points")]
    arc: &'a [Vec2],
}

impl<'a> LinkJs<'a> {
    fn new(l: &'a LinkSim, s: &Scenario) -> LinkJs<'a> {
        let (tx, rx) = (l.link.tx, l.link.rx);
        LinkJs {
            tx,
            rx,
            name: format!(
                "{}\u{2013}{}",
                s.transmitters[tx].name, s.receivers[rx].name
            ),
            delay_s: l.delay_s,
            sigma_s: l.sigma_s,
            range_sigma_label: label(l.range_sigma_m),
            ellipse: ellipse(l.ellipse),
            outline: &l.outline,
            arc: &l.arc,
        }
    }

    fn all(links: &'a [LinkSim], s: &Scenario) -> Vec<LinkJs<'a>> {
        links.iter().map(|l| LinkJs::new(l, s)).collect()
    }
}

/// The LM fix: `{x, y, error_m, error_label, cost, iterations, termination, converged,
/// ellipse}`.
#[derive(Serialize)]
struct FixJs {
    x: Real,
    y: Real,
    error_m: Real,
    error_label: String,
    cost: Real,
    iterations: usize,
    termination: &'static str,
    converged: bool,
    ellipse: Option<EllipseView>,
}

impl FixJs {
    fn new(f: &SnapshotFix) -> FixJs {
        let r = &f.report;
        FixJs {
            x: r.position.x,
            y: r.position.y,
            error_m: f.error_m,
            error_label: label(f.error_m),
            cost: r.cost,
            iterations: r.iterations,
            termination: r.termination.as_str(),
            converged: r.termination.converged(),
            ellipse: ellipse(f.ellipse),
        }
    }
}

/// `{truth: {x, y}, seed, links: [link], fix | null, fix_error | null, crlb, view_radius_m}`.
#[derive(Serialize)]
pub(super) struct SnapshotJs<'a> {
    truth: Position,
    seed: u64,
    links: Vec<LinkJs<'a>>,
    fix: Option<FixJs>,
    fix_error: Option<String>,
    crlb: CrlbJs,
    view_radius_m: Real,
}

impl<'a> SnapshotJs<'a> {
    pub(super) fn new(sim: &'a SnapshotSimulation, s: &Scenario) -> SnapshotJs<'a> {
        let (fix, fix_error) = match &sim.fix {
            Ok(f) => (Some(FixJs::new(f)), None),
            Err(e) => (None, Some(e.to_string())),
        };
        SnapshotJs {
            truth: Position {
                x: sim.truth.x,
                y: sim.truth.y,
            },
            seed: sim.seed,
            links: LinkJs::all(&sim.links, s),
            fix,
            fix_error,
            crlb: CrlbJs::new(&sim.crlb),
            view_radius_m: sim.view_radius_m,
        }
    }
}

/// The EKF estimate: `{x, y, vx, vy, ellipse, error_m, error_label, sigma_m, sigma_label, nis}`.
#[derive(Serialize)]
pub(super) struct EstimateJs {
    x: Real,
    y: Real,
    vx: Real,
    vy: Real,
    ellipse: Option<EllipseView>,
    error_m: Real,
    error_label: String,
    sigma_m: Real,
    sigma_label: String,
    nis: Real,
}

impl EstimateJs {
    pub(super) fn new(e: &TrackEstimate) -> EstimateJs {
        EstimateJs {
            x: e.position.x,
            y: e.position.y,
            vx: e.velocity.x,
            vy: e.velocity.y,
            ellipse: ellipse(e.ellipse),
            error_m: e.error_m,
            error_label: label(e.error_m),
            sigma_m: e.sigma_m,
            sigma_label: label(e.sigma_m),
            nis: e.nis,
        }
    }
}

/// A track step shaped like [`SnapshotJs`], the EKF estimate in place of the fix: `{step, t_s,
/// truth: {x, y, vx, vy}, links, fix: estimate, fix_error: null, crlb, view_radius_m}`.
#[derive(Serialize)]
pub(super) struct FrameJs<'a> {
    step: usize,
    t_s: Real,
    truth: PositionVelocity,
    links: Vec<LinkJs<'a>>,
    fix: EstimateJs,
    /// Always null (an estimate always exists).
    fix_error: Option<String>,
    crlb: CrlbJs,
    view_radius_m: Real,
}

impl<'a> FrameJs<'a> {
    pub(super) fn new(f: &'a TrackFrame, s: &Scenario) -> FrameJs<'a> {
        FrameJs {
            step: f.step,
            t_s: f.t_s,
            truth: PositionVelocity {
                x: f.truth.x,
                y: f.truth.y,
                vx: f.truth_velocity.x,
                vy: f.truth_velocity.y,
            },
            links: LinkJs::all(&f.links, s),
            fix: EstimateJs::new(&f.estimate),
            fix_error: None,
            crlb: CrlbJs::new(&f.crlb),
            view_radius_m: f.view_radius_m,
        }
    }
}

/// A whole track run: `{kind, seed, steps, dt_s, failed_at, t_s, truth: [[x, y]], estimates:
/// [[x, y, vx, vy]], ellipses: [ellipse | null], sigma_m, error_m, nis, measurements: [[iso-delay
/// ellipse per link | null]]}`.
#[derive(Serialize)]
pub(super) struct TrackDataJs<'a> {
    kind: &'a str,
    filter: &'static str,
    particles: Option<usize>,
    seed: u32,
    steps: usize,
    dt_s: Option<Real>,
    failed_at: Option<usize>,
    t_s: &'a [Real],
    #[serde(serialize_with = "state_positions")]
    truth: &'a [Vec4],
    #[serde(serialize_with = "states")]
    estimates: &'a [Vec4],
    ellipses: Vec<Option<EllipseView>>,
    sigma_m: Vec<Real>,
    error_m: Vec<Real>,
    nis: &'a [Real],
    measurements: Vec<Vec<Option<EllipseView>>>,
}

impl<'a> TrackDataJs<'a> {
    /// The run `run` of `filter` (simulated on `model`) with its estimates `est` (one per entry).
    pub(super) fn new(
        kind: &'a str,
        filter: FilterKind,
        seed: u32,
        steps: usize,
        run: &'a TrackRun,
        est: &[TrackEstimate],
        model: &Model,
    ) -> TrackDataJs<'a> {
        let net = &model.network;
        TrackDataJs {
            kind,
            filter: filter.name(),
            particles: match filter {
                FilterKind::Pf(c) => Some(c.particles),
                _ => None,
            },
            seed,
            steps,
            dt_s: run.t_s.get(1).copied(),
            failed_at: run.failed_at,
            t_s: &run.t_s,
            truth: &run.truth,
            estimates: &run.estimates,
            ellipses: est.iter().map(|e| ellipse(e.ellipse)).collect(),
            sigma_m: est.iter().map(|e| e.sigma_m).collect(),
            error_m: est.iter().map(|e| e.error_m).collect(),
            nis: &run.nis,
            measurements: run
                .delays_s
                .iter()
                .map(|d| {
                    d.iter()
                        .enumerate()
                        .map(|(p, t)| ellipse(net.iso_delay_ellipse(p, *t)))
                        .collect()
                })
                .collect(),
        }
    }
}

/// A Monte Carlo result so far: the core's curves `{t_s, rmse_ekf_m, rmse_pcrlb_m, nees, runs,
/// failed_runs, seed}` ([`MonteCarloResult`]) plus the study's set-up and progress
/// `{trajectories, noise_runs, trajectories_done, steps, dt_s, chunks_done, chunk_count, done}`,
/// each tracker's curves `filters: {name: {..}}` and the particle filter's `particles` and
/// `particle_budget` (null without it).
#[derive(Serialize)]
pub(super) struct MonteCarloJs<'a> {
    #[serde(flatten)]
    curves: &'a MonteCarloResult,
    trajectories: usize,
    noise_runs: usize,
    trajectories_done: usize,
    steps: usize,
    dt_s: Real,
    chunks_done: usize,
    chunk_count: usize,
    done: bool,
    #[serde(serialize_with = "filter_map")]
    filters: Vec<FilterCurvesJs<'a>>,
    particles: Option<usize>,
    particle_budget: Option<usize>,
    /// Only when a filter failed in every run (issue 24): `[{name, failed_runs, error}]`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    failed_filters: Vec<FailedFilterJs>,
}

/// A filter of a [`MonteCarloJs`] whose every run failed: its name, failed runs and the error
/// naming the setting to change and the first failure.
#[derive(Serialize)]
pub(super) struct FailedFilterJs {
    pub(super) name: &'static str,
    pub(super) failed_runs: usize,
    pub(super) error: alloc::string::String,
}

/// One tracker's curves in a [`MonteCarloJs`]: `{rmse_m, nees, runs, failed_runs, chunks_done,
/// chunk_count, runs_planned}`, keyed by `name`.
#[derive(Serialize)]
pub(super) struct FilterCurvesJs<'a> {
    #[serde(skip)]
    pub(super) name: &'static str,
    pub(super) rmse_m: &'a [Real],
    pub(super) nees: &'a [Real],
    pub(super) runs: usize,
    pub(super) failed_runs: usize,
    pub(super) chunks_done: usize,
    pub(super) chunk_count: usize,
    pub(super) runs_planned: usize,
}

/// The filters as a JSON object in their order.
fn filter_map<S: serde::Serializer>(f: &[FilterCurvesJs], s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut map = s.serialize_map(Some(f.len()))?;
    for c in f {
        map.serialize_entry(c.name, c)?;
    }
    map.end()
}

/// Where a study is, for a [`MonteCarloJs`]: the lead filter's `trajectories_done`, the work
/// items run (`chunks_done` of `chunk_count`), every filter's curves, the particle filter's
/// `particles` and `particle_budget` (`None` without it) and the filters whose every run failed.
pub(super) struct StudyProgressJs<'a> {
    pub(super) trajectories_done: usize,
    pub(super) chunks_done: usize,
    pub(super) chunk_count: usize,
    pub(super) filters: Vec<FilterCurvesJs<'a>>,
    pub(super) particles: Option<usize>,
    pub(super) particle_budget: Option<usize>,
    pub(super) failed_filters: Vec<FailedFilterJs>,
}

impl<'a> MonteCarloJs<'a> {
    /// `curves` of the study `cfg` at `progress`.
    pub(super) fn new(
        curves: &'a MonteCarloResult,
        cfg: &MonteCarloConfig,
        progress: StudyProgressJs<'a>,
    ) -> MonteCarloJs<'a> {
        let StudyProgressJs {
            trajectories_done,
            chunks_done,
            chunk_count,
            filters,
            particles,
            particle_budget,
            failed_filters,
        } = progress;
        MonteCarloJs {
            curves,
            trajectories: cfg.trajectories,
            noise_runs: cfg.noise_runs,
            trajectories_done,
            steps: cfg.steps,
            dt_s: cfg.motion.dt_s,
            chunks_done,
            chunk_count,
            done: chunks_done >= chunk_count,
            filters,
            particles,
            particle_budget,
            failed_filters,
        }
    }
}

/// A colour-bar tick `{frac, value_m, label}` (`frac ∈ [0, 1]` from the dark end).
#[derive(Serialize)]
pub(super) struct ColorbarTickJs<'a> {
    frac: Real,
    value_m: Real,
    label: &'a str,
}

impl<'a> ColorbarTickJs<'a> {
    /// The ticks of [`LogScale::ticks`](crate::present::LogScale::ticks).
    pub(super) fn all(ticks: &'a [(Real, Tick)]) -> Vec<ColorbarTickJs<'a>> {
        ticks
            .iter()
            .map(|(frac, t)| ColorbarTickJs {
                frac: *frac,
                value_m: t.value,
                label: &t.label,
            })
            .collect()
    }
}

/// A scale bar `{length_m, label}`.
#[derive(Serialize)]
pub(super) struct ScaleBarJs<'a> {
    length_m: Real,
    label: &'a str,
}

impl<'a> ScaleBarJs<'a> {
    pub(super) fn new(t: &'a Tick) -> ScaleBarJs<'a> {
        ScaleBarJs {
            length_m: t.value,
            label: &t.label,
        }
    }
}

/// The multi-target view ([`MtlView`], its own keys) plus `compute_ms`.
#[derive(Serialize)]
pub(super) struct MtlViewJs<'a> {
    #[serde(flatten)]
    pub(super) view: &'a MtlView,
    pub(super) compute_ms: f64,
}

#[cfg(test)]
mod tests;
