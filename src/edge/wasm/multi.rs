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

use plotters::prelude::{IntoDrawingArea, SeriesLabelPosition};
use plotters_canvas::CanvasBackend;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;
use web_sys::HtmlCanvasElement;

use super::json::to_json;
use super::{err, settings};
use crate::chart::{draw_curves, CurveChartOptions, CurveSeries, LineKind, Marker};
use crate::error::{Cancel, Error};
use crate::math::{Mat4, Vec4};
use crate::present::{format_length_m, position_ellipse, EllipseView};
use crate::study::{
    score_multi, simulate_people, track_multi, walk_region, MultiScoreDoc, MultiSettings,
    MultiTrackOutput, MultiTruth,
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

/// The settings of [`track_people`] (JSON: `{walkers, method, seed, settings?}`; unknown fields
/// refused).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PeopleRequest {
    /// People walking (1 … 5).
    walkers: usize,
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
}

/// Simulates and tracks several people on scenario JSON `scenario_json` (schema v1) for
/// `request_json`, one object (JSON text): `{walkers (1 … 5), method ("pmb" | "gnn"), seed,
/// settings?}` (`settings`: the fields of [`MultiSettings`], each optional, the CLI's defaults;
/// `method` replaces its `method`). The walk lasts [`PEOPLE_DURATION_S`] at [`PEOPLE_DT_S`]
/// with process noise [`PEOPLE_PROCESS_NOISE`] over the scenario's walk region; the score's `c`
/// is [`PEOPLE_GOSPA_C_M`]. Returns JSON text: `{walkers, seed, dt_s, region_m: {x, y}, truth
/// (the CLI's truth.json), track (the CLI's `track --targets auto` document), score (its
/// `score`), ellipses (per scan, per reported target in `track.targets`' order, the 1σ position
/// ellipse `{cx, cy, a, b, angle}` or null), gospa_label (the chart's legend)}`. Throws the
/// core's named error on bad input.
#[wasm_bindgen]
pub fn track_people(scenario_json: &str, request_json: &str) -> Result<String, JsError> {
    let scenario = Scenario::from_json(scenario_json).map_err(err)?;
    let model = Model::new(&scenario).map_err(err)?;
    let PeopleRequest {
        walkers,
        method,
        seed,
        settings: given,
    } = settings("settings", request_json)?;
    let mut cfg = given.unwrap_or_default();
    cfg.method = MultiKind::parse(&method).map_err(err)?;
    let steps = crate::track::step_count(PEOPLE_DURATION_S, PEOPLE_DT_S) + 1;
    let region = walk_region(&scenario.area_m);
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
    let track = track_multi(
        &model,
        &scenario.area_m,
        &measurements,
        None,
        &cfg,
        Cancel::NEVER,
    )
    .map_err(err)?;
    let score = score_multi(&track, &truth, PEOPLE_GOSPA_C_M).map_err(err)?;
    let ellipses = track
        .targets
        .iter()
        .map(|scan| {
            scan.iter()
                .map(|t| {
                    let cov = Mat4::from_fn(|i, j| t.covariance[i][j]);
                    position_ellipse(&Vec4::from(t.state), &cov, 1.0).map(EllipseView::from)
                })
                .collect()
        })
        .collect();
    let gospa_label = gospa_label(score.c_m, score.mean_gospa_m);
    to_json(&PeopleDoc {
        walkers,
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
    })
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
/// figure, [`draw_curves`]; the legend gives the mean) onto `canvas` at its pixel size, with a
/// `title` and optional `subtitle`; `""` as the document draws empty axes. Returns the points
/// drawn. Throws on a malformed document or a drawing failure.
#[wasm_bindgen]
pub fn draw_people_chart(
    canvas: HtmlCanvasElement,
    doc_json: &str,
    title: &str,
    subtitle: &str,
) -> Result<u32, JsError> {
    let (points, label) = if doc_json.trim().is_empty() {
        (Vec::new(), String::new())
    } else {
        let d: ChartDoc = serde_json::from_str(doc_json).map_err(|e| {
            err(Error::Parse {
                message: e.to_string(),
            })
        })?;
        let p: Vec<(f64, f64)> = d
            .track
            .t_s
            .iter()
            .zip(&d.score.gospa_m)
            .map(|(&t, g)| (t, g.unwrap_or(f64::NAN)))
            .collect();
        (p, d.gospa_label)
    };
    let finite = || points.iter().filter(|p| p.0.is_finite() && p.1.is_finite());
    let t_end = finite().map(|p| p.0).fold(0.0, f64::max);
    let top = finite().map(|p| p.1).fold(0.0, f64::max);
    let opts = CurveChartOptions {
        title: title.into(),
        subtitle: (!subtitle.is_empty()).then(|| subtitle.into()),
        x_desc: "time t (s)".into(),
        y_desc: "GOSPA (m)".into(),
        x_range: (
            0.0,
            if t_end > 0.0 {
                t_end
            } else {
                PEOPLE_DURATION_S
            },
        ),
        y_range: (0.0, if top > 0.0 { 1.1 * top } else { 1.0 }),
        legend: SeriesLabelPosition::UpperRight,
    };
    let series = [CurveSeries {
        label,
        points: &points,
        colour: 0,
        line: LineKind::Solid,
        marker: Marker::None,
    }];
    let shown = if points.is_empty() {
        &[][..]
    } else {
        &series[..]
    };
    let root = CanvasBackend::with_canvas_object(canvas)
        .ok_or_else(|| JsError::new("chart: the canvas has no 2-D context"))?
        .into_drawing_area();
    draw_curves(&root, shown, &opts).map_err(|e| JsError::new(&e.to_string()))?;
    root.present().map_err(|e| JsError::new(&e.to_string()))?;
    Ok(finite().count() as u32)
}
