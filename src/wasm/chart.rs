//! The tracking chart on a `<canvas>`: [`draw_tracking_rmse`] (plotters) through
//! `plotters-canvas`, fed with a `MonteCarloJob.result_json()` text.

use plotters::prelude::IntoDrawingArea;
use plotters_canvas::CanvasBackend;
use serde::Deserialize;
use wasm_bindgen::prelude::*;
use web_sys::HtmlCanvasElement;

use crate::chart::{draw_tracking_rmse, TrackingChartOptions, TrackingPanel};
use crate::error::Error;

/// The curves read from a result (other keys are ignored; `null` is a gap).
#[derive(Deserialize, Default)]
struct Curves {
    t_s: Vec<f64>,
    rmse_ekf_m: Vec<Option<f64>>,
    rmse_pcrlb_m: Vec<Option<f64>>,
}

fn drawable(v: &Option<f64>) -> bool {
    v.is_some_and(|v| v.is_finite() && v > 0.0)
}

/// Draws ε_EKF(t) (solid) and ε_PCRLB(t) (dashed) from `result_json` (a Monte Carlo result;
/// `""` draws empty axes) onto `canvas` at its pixel size, with a figure `title`, optional
/// `subtitle` and a panel `caption`. Returns how many curves were drawn (0 … 2). Throws on
/// malformed JSON or a drawing failure.
#[wasm_bindgen]
pub fn draw_tracking_chart(
    canvas: HtmlCanvasElement,
    result_json: &str,
    title: &str,
    subtitle: &str,
    caption: &str,
) -> Result<u32, JsError> {
    let c: Curves = if result_json.trim().is_empty() {
        Curves::default()
    } else {
        serde_json::from_str(result_json).map_err(|e| {
            super::err(Error::Parse {
                message: e.to_string(),
            })
        })?
    };
    let ekf: Vec<f64> = c.rmse_ekf_m.iter().map(|v| v.unwrap_or(f64::NAN)).collect();
    let root = CanvasBackend::with_canvas_object(canvas)
        .ok_or_else(|| JsError::new("chart: the canvas has no 2-D context"))?
        .into_drawing_area();
    let panel = TrackingPanel {
        title: caption,
        t_s: &c.t_s,
        rmse_ekf_m: &ekf,
        rmse_pcrlb_m: &c.rmse_pcrlb_m,
    };
    let opts = TrackingChartOptions {
        title: title.to_string(),
        subtitle: (!subtitle.is_empty()).then(|| subtitle.to_string()),
    };
    let js = |e: &dyn core::fmt::Display| JsError::new(&e.to_string());
    draw_tracking_rmse(&root, &[panel], &opts).map_err(|e| js(&e))?;
    root.present().map_err(|e| js(&e))?;
    let series = [
        c.rmse_ekf_m.iter().any(drawable),
        c.rmse_pcrlb_m.iter().any(drawable),
    ];
    Ok(series.iter().filter(|s| **s).count() as u32)
}
