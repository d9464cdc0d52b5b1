//! "Save figure" and "Export data" of the tracking view's "Several people" run (issue 41 §2):
//! [`people_map_svg`] (the map at a scan, [`crate::chart::draw_people_map`] of
//! [`crate::present::people_map_view`]), [`people_chart_svg`] (the GOSPA chart,
//! [`crate::chart::draw_gospa_chart`], the canvas chart's code) and [`people_data_text`]
//! ([`crate::present::people_data_text`]: CSV or JSON). Each reads the document `track_people`
//! returned; every error is an exception whose message starts with the function's name.

use alloc::string::String;
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Deserialize;
use wasm_bindgen::prelude::*;

use super::{window, PEOPLE_DURATION_S};
use crate::chart::{
    draw_gospa_chart, draw_people_map, people_titles, scenario_nodes, suggested_size,
    PeopleChartOptions,
};
use crate::error::{Error, Result};
use crate::present::{people_data_text as data_text, people_doc_from_json, people_map_view};
use crate::Scenario;

use super::export::figure_px;

fn fail(func: &str, e: impl core::fmt::Display) -> JsError {
    JsError::new(&alloc::format!("{func}: {e}"))
}

/// The SVG text of `size` px that `draw` writes through plotters' SVG backend.
fn render_svg<T, E: core::fmt::Display>(
    func: &str,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> core::result::Result<T, E>,
) -> core::result::Result<String, JsError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(&root).map_err(|e| fail(func, e))?;
        root.present().map_err(|e| fail(func, e))?;
    }
    Ok(svg)
}

/// The options of [`people_map_svg`] (all optional; `""` is all defaults).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct PeopleMapOptions {
    /// `[x_min, x_max, y_min, y_max]`, m (default: the scenario's area).
    #[serde(default)]
    window: Option<[f64; 4]>,
    /// Title (default: `Several people — <scenario>`).
    #[serde(default)]
    title: Option<String>,
}

/// The map figure of a `track_people` document `doc_text` (JSON text) run on scenario JSON
/// `scenario_json` (the run's scenario: its nodes are drawn) at scan `step` (past the end: the
/// last) as SVG text: the nodes, every true path dashed, every labelled track up to the scan in
/// the page's colour of its place in `track.tracks`, its label `#n`, its position and its 1σ
/// ellipse magnified `magnify` times. `width` 200 … 8000 px, `height` 0 (fit the plot) or 150
/// … 8000 px. `options_json`: `""` or `{window?: [x_min, x_max, y_min, y_max] (m; default the
/// scenario's area), title?: text}`. Throws `people_map_svg: …` with the core's named error.
#[wasm_bindgen]
pub fn people_map_svg(
    scenario_json: &str,
    doc_text: &str,
    width: u32,
    height: u32,
    step: usize,
    magnify: f64,
    options_json: &str,
) -> core::result::Result<String, JsError> {
    const F: &str = "people_map_svg";
    let opts: PeopleMapOptions = if options_json.trim().is_empty() {
        PeopleMapOptions::default()
    } else {
        serde_json::from_str(options_json).map_err(|e| {
            fail(
                F,
                Error::Parse {
                    message: e.to_string(),
                },
            )
        })?
    };
    if !(magnify.is_finite() && magnify > 0.0) {
        return Err(fail(
            F,
            Error::NotPositive {
                field: "magnify".into(),
                value: magnify,
            },
        ));
    }
    let scenario = Scenario::from_json(scenario_json).map_err(|e| fail(F, e))?;
    let run = people_doc_from_json(doc_text).map_err(|e| fail(F, e))?;
    let view = people_map_view(&run.track, &run.truth, step).map_err(|e| fail(F, e))?;
    let area = match opts.window {
        Some(w) => window(w).map_err(|e| fail(F, e))?,
        None => scenario.area_m,
    };
    let w = figure_px("width", width, 200).map_err(|e| fail(F, e))?;
    let size = if height == 0 {
        suggested_size(&area, w)
    } else {
        (w, figure_px("height", height, 150).map_err(|e| fail(F, e))?)
    };
    let (title, subtitle) = people_titles(&scenario.name, &run.track, &run.truth, &view, magnify);
    let chart_opts = PeopleChartOptions {
        title: opts.title.unwrap_or(title),
        subtitle: Some(subtitle),
        window: area,
        magnify,
    };
    let nodes = scenario_nodes(&scenario);
    render_svg(F, size, |root| {
        draw_people_map(root, &nodes, &view, &chart_opts)
    })
}

/// What the GOSPA chart reads of a `track_people` document (other keys ignored).
#[derive(Deserialize)]
struct ChartDocIn {
    track: ChartTrackIn,
    score: ChartScoreIn,
    gospa_label: String,
}

#[derive(Deserialize)]
struct ChartTrackIn {
    t_s: Vec<f64>,
}

#[derive(Deserialize)]
struct ChartScoreIn {
    gospa_m: Vec<Option<f64>>,
}

/// The GOSPA chart of a `track_people` document (`""`: empty axes) on `root`, with `title` and
/// `subtitle`: the canvas chart's code (`draw_people_chart`) for any backend. Returns the points
/// drawn.
pub(super) fn draw_people_doc_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    doc_json: &str,
    title: &str,
    subtitle: &str,
) -> Result<u32> {
    let (t, g, label) = if doc_json.trim().is_empty() {
        (Vec::new(), Vec::new(), String::new())
    } else {
        let d: ChartDocIn = serde_json::from_str(doc_json).map_err(|e| Error::Parse {
            message: e.to_string(),
        })?;
        let g = d
            .score
            .gospa_m
            .iter()
            .map(|v| v.unwrap_or(f64::NAN))
            .collect();
        (d.track.t_s, g, d.gospa_label)
    };
    draw_gospa_chart(root, &t, &g, &label, title, subtitle, PEOPLE_DURATION_S).map_err(|e| {
        Error::InvalidFile {
            field: "chart".into(),
            reason: e.to_string(),
        }
    })
}

/// The GOSPA chart of a `track_people` document (`draw_people_chart`'s figure, the same
/// arguments) as SVG text of `width × height` px (200 … 8000 × 150 … 8000; height 0: 3/5 of the
/// width). Throws `people_chart_svg: …` on a malformed document or a bad size.
#[wasm_bindgen]
pub fn people_chart_svg(
    doc_text: &str,
    title: &str,
    subtitle: &str,
    width: u32,
    height: u32,
) -> core::result::Result<String, JsError> {
    const F: &str = "people_chart_svg";
    let w = figure_px("width", width, 200).map_err(|e| fail(F, e))?;
    let h = if height == 0 {
        (w * 3 / 5).max(150)
    } else {
        figure_px("height", height, 150).map_err(|e| fail(F, e))?
    };
    render_svg(F, (w, h), |root| {
        draw_people_doc_chart(root, doc_text, title, subtitle)
    })
}

/// A `track_people` document as a data file ([`crate::present::people_data_text`]): `format`
/// `"csv"` (one row per true person and per reported target per scan: `scan, t_s, kind (truth |
/// track), label, x_m, y_m, vx_mps, vy_mps, existence, P_0_0 … P_3_3`) or `"json"` (`{units,
/// truth, track, score}`, GOSPA and its parts per scan in `score`). Every number is the
/// document's, written to read back as the same `f64`. Throws `people_data_text: …`.
#[wasm_bindgen]
pub fn people_data_text(doc_text: &str, format: &str) -> core::result::Result<String, JsError> {
    const F: &str = "people_data_text";
    let run = people_doc_from_json(doc_text).map_err(|e| fail(F, e))?;
    data_text(&run, format).map_err(|e| fail(F, e))
}
