//! WebAssembly bindings for the page: a thin edge over the core, no math here.
//!
//! [`App`] wraps a core [`Session`](crate::present::Session) (a validated scenario and its
//! compiled model; rejected edits change nothing). This layer only checks the numbers JavaScript
//! hands over, calls the core and converts the results: objects as serde structs, serialised by
//! one helper to parsed JSON (serde_json, whose non-finite numbers become `null`, so no NaN
//! reaches JavaScript), maps as typed arrays (unbounded cells are `Infinity`), and errors as
//! exceptions (`JsError`) carrying the core [`Error`]'s one-line message, which names the
//! offending field; nothing panics on input.
//!
//! Files: `app.rs` (the `App` class), `render.rs` (colours, ticks and labels for drawing),
//! `json.rs` (the page's object shapes and `to_js`), `tracking.rs` (`App.simulate_track` and the
//! `Track` it returns), `montecarlo.rs` (`MonteCarloJob`, run chunk by chunk in a Web Worker),
//! `chart.rs` (the plotters ε_EKF / ε_PCRLB chart on a canvas), `mtl.rs` (the multi-target view
//! of a scene, [`crate::mtl::view`]).

use wasm_bindgen::prelude::*;

use crate::error::Error;
use crate::{scenario::presets, Vec2};

mod app;
mod chart;
mod json;
mod montecarlo;
mod mtl;
mod render;
mod tracking;

pub use app::App;
pub use chart::draw_tracking_chart;
pub use montecarlo::MonteCarloJob;
pub use mtl::{mtl_check_scene, mtl_default_scene, mtl_view_of, MtlSession};
pub use render::{
    axis_ticks, colorbar_rgba, colorbar_ticks, format_length, render_map_rgba, scale_bar,
    unbounded_rgb,
};
pub use tracking::{drag_velocity, track_steps, Track, MAX_TRACK_STEPS};

/// Module start: route Rust panics to `console.error` with their message.
#[wasm_bindgen(start)]
pub fn start() {
    console_error_panic_hook::set_once();
}

/// Names of the presets.
#[wasm_bindgen]
pub fn preset_names() -> Vec<String> {
    presets::PRESET_NAMES
        .iter()
        .map(|s| s.to_string())
        .collect()
}

/// A preset's scenario JSON.
#[wasm_bindgen]
pub fn preset_json(name: &str) -> Result<String, JsError> {
    Ok(presets::preset(name).map_err(err)?.to_json())
}

/// A core error as a JavaScript exception with its message.
fn err(e: Error) -> JsError {
    JsError::new(&e.to_string())
}

/// A point from JavaScript numbers, which must be finite (named `x`, `y`).
fn point(x: f64, y: f64) -> Result<Vec2, JsError> {
    for (field, v) in [("x", x), ("y", y)] {
        if !v.is_finite() {
            return Err(err(Error::NonFinite {
                field: field.to_string(),
            }));
        }
    }
    Ok(Vec2::new(x, y))
}
