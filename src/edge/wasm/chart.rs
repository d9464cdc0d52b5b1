//! The tracking chart on a `<canvas>`: [`draw_tracking_filters`] (plotters) through
//! `plotters-canvas`, fed with a `MonteCarloJob.result_json()` text — one RMSE curve per
//! tracker of the result next to the PCRLB, as the CLI's `montecarlo --filters` figure.

use plotters::coord::Shift;
use plotters::prelude::{DrawingArea, DrawingBackend, IntoDrawingArea};
use plotters_canvas::CanvasBackend;
use serde::Deserialize;
use wasm_bindgen::prelude::*;
use web_sys::HtmlCanvasElement;

use crate::chart::{draw_tracking_filters, FilterCurve, FiltersPanel, TrackingChartOptions};
use crate::error::Error;

/// One tracker's curve in a result (other keys are ignored; `null` is a gap).
#[derive(Deserialize)]
struct FilterRmse {
    rmse_m: Vec<Option<f64>>,
    runs: usize,
    #[serde(default)]
    failed_runs: usize,
}

/// The curves read from a result (other keys are ignored; `null` is a gap).
#[derive(Deserialize, Default)]
struct Curves {
    t_s: Vec<f64>,
    #[serde(default)]
    rmse_ekf_m: Vec<Option<f64>>,
    rmse_pcrlb_m: Vec<Option<f64>>,
    #[serde(default)]
    filters: Option<serde_json::Map<String, serde_json::Value>>,
    #[serde(default)]
    particles: Option<usize>,
}

/// The legend label of filter `name` with its failed runs out of those run so far:
/// `EKF RMSE (0/200 failed)`, `PF RMSE (3/192 failed, 1000 particles)`.
fn label(name: &str, f: &FilterRmse, particles: Option<usize>) -> String {
    let base = crate::study::failed_label(name, f.failed_runs, f.runs + f.failed_runs);
    match (name, particles) {
        ("pf", Some(n)) => format!("{}, {n} particles)", base.trim_end_matches(')')),
        _ => base,
    }
}

fn drawable(v: &Option<f64>) -> bool {
    v.is_some_and(|v| v.is_finite() && v > 0.0)
}

/// Draws each tracker's RMSE (one colour and line style per filter — EKF solid, UKF dotted, PF
/// long dashes —, in the order EKF, UKF, PF, each
/// labelled with its failed runs, the legend's last row saying what failed means; a result
/// without `filters` draws `rmse_ekf_m` as the EKF's) and ε_PCRLB(t) (dashed) from
/// `result_json` (a Monte Carlo result; `""` draws empty axes) onto `canvas` at its pixel size,
/// with a figure `title`, optional `subtitle` and a panel `caption`. Returns how many curves were
/// drawn (0 … filters + 1). Throws on malformed JSON or a drawing failure.
#[wasm_bindgen]
pub fn draw_tracking_chart(
    canvas: HtmlCanvasElement,
    result_json: &str,
    title: &str,
    subtitle: &str,
    caption: &str,
) -> Result<u32, JsError> {
    let root = CanvasBackend::with_canvas_object(canvas)
        .ok_or_else(|| JsError::new("chart: the canvas has no 2-D context"))?
        .into_drawing_area();
    draw_result(&root, result_json, title, subtitle, caption).map_err(|e| JsError::new(&e))
}

/// What [`draw_tracking_chart`] draws, on any backend (the canvas, or SVG for the page's figure
/// export); presents the drawing. Returns how many curves were drawn, or the error's message.
pub(super) fn draw_result<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    result_json: &str,
    title: &str,
    subtitle: &str,
    caption: &str,
) -> Result<u32, String> {
    let parse = |e: serde_json::Error| {
        Error::Parse {
            message: e.to_string(),
        }
        .to_string()
    };
    let c: Curves = if result_json.trim().is_empty() {
        Curves::default()
    } else {
        serde_json::from_str(result_json).map_err(parse)?
    };
    let series: Vec<(String, Vec<Option<f64>>)> = match c.filters {
        // In a fixed order (the first curve takes the EKF's blue), whatever the map's order.
        Some(mut map) if !map.is_empty() => ["ekf", "ukf", "pf"]
            .into_iter()
            .filter_map(|name| map.remove(name).map(|v| (name, v)))
            .map(|(name, v)| {
                let f: FilterRmse = serde_json::from_value(v).map_err(parse)?;
                Ok((label(name, &f, c.particles), f.rmse_m))
            })
            .collect::<Result<_, String>>()?,
        _ if c.rmse_ekf_m.is_empty() => Vec::new(),
        _ => vec![(crate::study::curve_label("ekf", false), c.rmse_ekf_m)],
    };
    let values: Vec<Vec<f64>> = series
        .iter()
        .map(|(_, v)| v.iter().map(|x| x.unwrap_or(f64::NAN)).collect())
        .collect();
    let curves: Vec<FilterCurve> = series
        .iter()
        .zip(&values)
        .map(|((label, _), v)| FilterCurve { label, rmse_m: v })
        .collect();
    let panel = FiltersPanel {
        title: caption,
        t_s: &c.t_s,
        curves: &curves,
        rmse_pcrlb_m: &c.rmse_pcrlb_m,
        legend_note: (!curves.is_empty()).then_some(crate::study::FAILED_NOTE),
    };
    let opts = TrackingChartOptions {
        title: title.to_string(),
        subtitle: (!subtitle.is_empty()).then(|| subtitle.to_string()),
    };
    draw_tracking_filters(root, &[panel], &opts).map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())?;
    let drawn = series
        .iter()
        .filter(|(_, v)| v.iter().any(drawable))
        .count();
    Ok((drawn + usize::from(c.rmse_pcrlb_m.iter().any(drawable))) as u32)
}
