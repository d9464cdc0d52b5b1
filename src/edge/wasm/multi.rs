//! Several people at once for the page's tracking view (issue 41 §2), run in a Web Worker:
//! [`track_people`] simulates walkers over the scenario's walk region
//! ([`study::simulate_people`](crate::study::simulate_people) over
//! [`study::walk_region`](crate::study::walk_region)), tracks their delay scans
//! ([`study::track_multi`](crate::study::track_multi)) and scores the track
//! ([`study::score_multi`](crate::study::score_multi)) — the same calls, defaults and numbers as
//! the CLI's `simulate-walk --walkers N --seed S` then `track --targets auto --truth`.
//! [`draw_people_chart`] draws its GOSPA per scan with the core's curve figure.

use alloc::string::String;
use alloc::vec::Vec;

use plotters::prelude::IntoDrawingArea;
use plotters_canvas::CanvasBackend;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;
use web_sys::HtmlCanvasElement;

use super::json::to_json;
use super::{err, now_ms, settings};
use crate::chart::draw_gospa_chart;
use crate::error::{Cancel, Error};
use crate::present::{format_length_m, track_ellipses, EllipseView};
use crate::study::{
    score_multi, simulate_people, track_multi_clocked, walk_region, MultiScoreDoc, MultiSettings,
    MultiTrackOutput, MultiTruth, Walkers,
};
use crate::track::multi::MultiKind;
use crate::{Model, Scenario};

/// The walk's duration, s (the CLI's `simulate-walk` default).
pub const PEOPLE_DURATION_S: f64 = 10.0;
/// The scan interval, s (the CLI's `simulate-walk --dt` default).
pub const PEOPLE_DT_S: f64 = 0.1;
/// The walkers' process noise (the CLI's `simulate-walk --process-noise` default).
pub const PEOPLE_PROCESS_NOISE: f64 = 0.5;
/// GOSPA's cut-off `c`, m (the CLI's `track --gospa-c` default).
pub const PEOPLE_GOSPA_C_M: f64 = 1.0;

/// The settings of [`track_people`] (JSON: `{walkers?, paths?, method, seed, settings?}`;
/// unknown fields refused).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PeopleRequest {
    /// People walking on the planned paths (1 … 5); with `paths`, absent or their count.
    #[serde(default)]
    walkers: Option<usize>,
    /// Drawn paths `[x0, y0, x1, y1]`, m (1 … 5): one walker each, instead of the plans.
    #[serde(default)]
    paths: Option<Vec<[f64; 4]>>,
    /// `pmb` or `gnn`.
    method: String,
    /// The simulation's seed.
    seed: u64,
    /// The tracker's and the simulator's settings (absent fields take their defaults).
    #[serde(default)]
    settings: Option<MultiSettings>,
}

/// The walk region, `{x: [x0, x1], y: [y0, y1]}` m.
#[derive(Serialize)]
struct RegionJs {
    x: [f64; 2],
    y: [f64; 2],
}

/// The document [`track_people`] returns.
#[derive(Serialize)]
struct PeopleDoc<'a> {
    walkers: usize,
    seed: u64,
    dt_s: f64,
    region_m: RegionJs,
    truth: &'a MultiTruth,
    track: &'a MultiTrackOutput,
    score: &'a MultiScoreDoc,
    ellipses: Vec<Vec<Option<EllipseView>>>,
    gospa_label: String,
    timing_ms: TimingJs,
}

/// Where [`track_people`]'s time went, ms (the worker's `performance.now()`): the simulation
/// of the walk and its delay scans, the tracking — of it the setup (the birth grid, built once
/// per model, and reading the scans) and the scans themselves — and the score and ellipses.
#[derive(Serialize)]
struct TimingJs {
    simulate: f64,
    track: f64,
    setup: f64,
    scans: f64,
    score: f64,
}

/// Simulates and tracks several people on scenario JSON `scenario_json` (schema v1) for
/// `request_json`, one object (JSON text): `{walkers (1 … 5), paths?, method ("pmb" | "gnn"),
/// seed, settings?}` (`paths`: drawn walker paths `[[x0, y0, x1, y1], …]` in m, 1 … 5, each
/// walked in a straight line at constant velocity over the run instead of the planned walkers
/// — the CLI's `simulate-walk --path`; `walkers` may then be left out, else it must equal their
/// count; `settings`: the fields of [`MultiSettings`], each optional, the CLI's defaults;
/// `method` replaces its `method`). The walk lasts [`PEOPLE_DURATION_S`] at [`PEOPLE_DT_S`]
/// with process noise [`PEOPLE_PROCESS_NOISE`] over the scenario's walk region; the score's `c`
/// is [`PEOPLE_GOSPA_C_M`]. Returns JSON text: `{walkers, seed, dt_s, region_m: {x, y}, truth
/// (the CLI's truth.json), track (the CLI's `track --targets auto` document), score (its
/// `score`), ellipses (per scan, per reported target in `track.targets`' order, the 1σ position
/// ellipse `{cx, cy, a, b, angle}` or null), gospa_label (the chart's legend), timing_ms
/// (`{simulate, track, setup, scans, score}`, ms; `setup` and `scans` are `track`'s parts)}`. Throws the core's named error on bad input.
#[wasm_bindgen]
pub fn track_people(scenario_json: &str, request_json: &str) -> Result<String, JsError> {
    let scenario = Scenario::from_json(scenario_json).map_err(err)?;
    let model = Model::new(&scenario).map_err(err)?;
    let PeopleRequest {
        walkers,
        paths,
        method,
        seed,
        settings: given,
    } = settings("settings", request_json)?;
    let walkers = people_walkers(walkers, paths).map_err(err)?;
    let count = walkers.count();
    let mut cfg = given.unwrap_or_default();
    cfg.method = MultiKind::parse(&method).map_err(err)?;
    let steps = crate::track::step_count(PEOPLE_DURATION_S, PEOPLE_DT_S) + 1;
    let region = walk_region(&scenario.area_m);
    let t0 = now_ms();
    let (measurements, truth) = simulate_people(
        &model,
        &region,
        walkers,
        steps,
        PEOPLE_DT_S,
        PEOPLE_PROCESS_NOISE,
        &cfg,
        seed,
    )
    .map_err(err)?;
    let t1 = now_ms();
    let (track, clocked) = track_multi_clocked(
        &model,
        &scenario.area_m,
        &measurements,
        None,
        &cfg,
        Cancel::NEVER,
        &now_ms,
    )
    .map_err(err)?;
    let t2 = now_ms();
    let score = score_multi(&track, &truth, PEOPLE_GOSPA_C_M).map_err(err)?;
    let ellipses = track_ellipses(&track);
    let gospa_label = gospa_label(score.c_m, score.mean_gospa_m);
    to_json(&PeopleDoc {
        walkers: count,
        seed,
        dt_s: PEOPLE_DT_S,
        region_m: RegionJs {
            x: region.x,
            y: region.y,
        },
        truth: &truth,
        track: &track,
        score: &score,
        ellipses,
        gospa_label,
        timing_ms: TimingJs {
            simulate: t1 - t0,
            track: t2 - t1,
            setup: clocked.setup,
            scans: clocked.scans,
            score: now_ms() - t2,
        },
    })
}

/// The walkers of a request: its drawn `paths` (`walkers`, if given, must be their count) or
/// its `walkers` count; neither is [`Error::InvalidFile`] `walkers`.
fn people_walkers(walkers: Option<usize>, paths: Option<Vec<[f64; 4]>>) -> Result<Walkers, Error> {
    match (walkers, paths) {
        (_, Some(p)) => {
            if let Some(n) = walkers.filter(|&n| n != p.len()) {
                return Err(Error::InvalidFile {
                    field: "walkers".into(),
                    reason: alloc::format!("{n} walkers but {} drawn paths", p.len()),
                });
            }
            let w = Walkers::Drawn(p.iter().map(|q| ([q[0], q[1]], [q[2], q[3]])).collect());
            w.check()?;
            Ok(w)
        }
        (Some(n), None) => Ok(Walkers::Count(n)),
        (None, None) => Err(Error::InvalidFile {
            field: "walkers".into(),
            reason: "missing: give walkers (1 … 5) or drawn paths".into(),
        }),
    }
}

/// The chart's legend: `GOSPA (c = 1 m, p = 2), mean 0.123 m`.
fn gospa_label(c_m: f64, mean_m: f64) -> String {
    alloc::format!(
        "GOSPA (c = {}, p = 2), mean {}",
        format_length_m(c_m, 3),
        format_length_m(mean_m, 3)
    )
}

/// What [`draw_people_chart`] reads of a [`track_people`] document (other keys ignored).
#[derive(Deserialize)]
struct ChartDoc {
    track: ChartTrack,
    score: ChartScore,
    gospa_label: String,
}

#[derive(Deserialize)]
struct ChartTrack {
    t_s: Vec<f64>,
}

#[derive(Deserialize)]
struct ChartScore {
    gospa_m: Vec<Option<f64>>,
}

/// Draws the GOSPA of a [`track_people`] document per scan against time (the core's curve
/// figure, [`draw_gospa_chart`]; the legend gives the mean) onto `canvas` at its pixel size, with a
/// `title` and optional `subtitle`; `""` as the document draws empty axes. Returns the points
/// drawn. Throws on a malformed document or a drawing failure.
#[wasm_bindgen]
pub fn draw_people_chart(
    canvas: HtmlCanvasElement,
    doc_json: &str,
    title: &str,
    subtitle: &str,
) -> Result<u32, JsError> {
    let (t_s, gospa, label) = if doc_json.trim().is_empty() {
        (Vec::new(), Vec::new(), String::new())
    } else {
        let d: ChartDoc = serde_json::from_str(doc_json).map_err(|e| {
            err(Error::Parse {
                message: e.to_string(),
            })
        })?;
        let g: Vec<f64> = d
            .score
            .gospa_m
            .iter()
            .map(|g| g.unwrap_or(f64::NAN))
            .collect();
        (d.track.t_s, g, d.gospa_label)
    };
    let root = CanvasBackend::with_canvas_object(canvas)
        .ok_or_else(|| JsError::new("chart: the canvas has no 2-D context"))?
        .into_drawing_area();
    let drawn = draw_gospa_chart(
        &root,
        &t_s,
        &gospa,
        &label,
        title,
        subtitle,
        PEOPLE_DURATION_S,
    )
    .map_err(|e| JsError::new(&e.to_string()))?;
    root.present().map_err(|e| JsError::new(&e.to_string()))?;
    Ok(drawn)
}
