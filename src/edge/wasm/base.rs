//! What every binding shares: the module start (panics routed to the console), the presets,
//! and the conversions at the JavaScript edge (a core error to an exception, a settings object's
//! JSON to the binding's serde struct, two numbers to a checked point).

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use wasm_bindgen::prelude::*;

use crate::error::{limits, Error};
use crate::scenario::{presets, Area};
use crate::Vec2;

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
pub(super) fn err(e: Error) -> JsError {
    JsError::new(&e.to_string())
}

/// The settings object of a binding: `json`, the JSON text of one object (the page passes
/// `JSON.stringify({…})`, as for `ChannelJob`'s settings), read into the binding's serde struct
/// `T` (which refuses unknown fields). Malformed JSON, a missing, unknown or mistyped field
/// (a non-finite number is `null` in JSON) is the core's [`Error::Parse`] naming the field,
/// prefixed by `what`: `settings: invalid JSON: dt_s: invalid type: null, expected f64 …`.
pub(super) fn settings<T: serde::de::DeserializeOwned>(
    what: &str,
    json: &str,
) -> Result<T, JsError> {
    crate::scenario::parse_json(json).map_err(|e| JsError::new(&format!("{what}: {e}")))
}

/// A window `[x_min, x_max, y_min, y_max]` (m) from JavaScript: a finite, non-empty rectangle,
/// else the named error of `window.x` / `window.y`.
pub(super) fn window([x0, x1, y0, y1]: [f64; 4]) -> Result<Area, Error> {
    let a = Area {
        x: [x0, x1],
        y: [y0, y1],
    };
    a.validate_as(["window.x", "window.y"])?;
    Ok(a)
}

/// Checks a rectangle `[x_min, x_max, y_min, y_max]` (m) that the page reads from its URL option
/// `name` (`view`, the map's window, or `roi`, the Plan panel's region) with the core's rule for
/// areas ([`Area::validate_as`]: finite, within [`limits::COORDINATE_M`], min < max and a span of
/// at least [`limits::MIN_AREA_SPAN_M`] on both axes), so the page and the core share one
/// definition (issue 24). Throws the named error (`view.x`, `view.y`, `roi.x`, `roi.y`; another
/// name is checked as `window.x` / `window.y`).
#[wasm_bindgen]
pub fn check_rect(
    name: &str,
    x_min: f64,
    x_max: f64,
    y_min: f64,
    y_max: f64,
) -> Result<(), JsError> {
    let fields = match name {
        "view" => ["view.x", "view.y"],
        "roi" => ["roi.x", "roi.y"],
        _ => ["window.x", "window.y"],
    };
    Area {
        x: [x_min, x_max],
        y: [y_min, y_max],
    }
    .validate_as(fields)
    .map_err(err)
}

/// Checks a point `(x, y)` (m) that the page reads from its URL option `name` (e.g. `target`)
/// with the core's coordinate range ([`limits::COORDINATE_M`]); throws the named error
/// (`target.x`, `target.y`) (issue 24).
#[wasm_bindgen]
pub fn check_point(name: &str, x: f64, y: f64) -> Result<(), JsError> {
    limits::COORDINATE_M
        .check(&format!("{name}.x"), x)
        .map_err(err)?;
    limits::COORDINATE_M
        .check(&format!("{name}.y"), y)
        .map_err(err)
}

/// A point from JavaScript numbers, which must be finite (named `x`, `y`).
pub(super) fn point(x: f64, y: f64) -> Result<Vec2, JsError> {
    limits::COORDINATE_M.check("x", x).map_err(err)?;
    limits::COORDINATE_M.check("y", y).map_err(err)?;
    Ok(Vec2::new(x, y))
}

/// Milliseconds from the worker's (or page's) `performance.now()` (`Date.now()` without one):
/// the one clock of the bindings' own timings.
pub(super) fn now_ms() -> f64 {
    let g = js_sys::global();
    js_sys::Reflect::get(&g, &JsValue::from_str("performance"))
        .ok()
        .and_then(|p| {
            let f: js_sys::Function = js_sys::Reflect::get(&p, &JsValue::from_str("now"))
                .ok()?
                .dyn_into()
                .ok()?;
            f.call0(&p).ok()?.as_f64()
        })
        .unwrap_or_else(js_sys::Date::now)
}
