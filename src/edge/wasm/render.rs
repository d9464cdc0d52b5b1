//! Drawing helpers: map colouring into the caller's buffers, the colour bar, axis ticks and
//! length labels, all computed by the core ([`crate::present`], [`crate::present`]).

use js_sys::{Float64Array, Uint8ClampedArray};
use wasm_bindgen::prelude::*;

use super::err;
use super::json::{to_js, ColorbarTickJs, ScaleBarJs};
use crate::present::{self, LogScale, LINK_RGB, UNBOUNDED_RGB};
use crate::present::{format_length_m, linear_ticks};

/// Colours a map (`values`, m) into `rgba` (4 bytes per value, e.g. an `ImageData.data`) on the
/// log scale spanning its finite values. Returns `[min, max]` of the scale, m; `[Infinity,
/// Infinity]` (and all grey) when no cell is bounded.
#[wasm_bindgen]
pub fn render_map_rgba(
    values: &Float64Array,
    rgba: &Uint8ClampedArray,
) -> Result<Vec<f64>, JsError> {
    let mut px = vec![0u8; rgba.length() as usize];
    let scale = present::render_rgba(&values.to_vec(), &mut px).map_err(err)?;
    rgba.copy_from(&px);
    Ok(match scale {
        Some(s) => vec![s.min, s.max],
        None => vec![f64::INFINITY, f64::INFINITY],
    })
}

/// Colours a map (`values`, m) into `rgba` on the fixed log scale `[min, max]` (a locked colour
/// range: values outside it take the end colours). Returns `[min, max, below, above]`: the scale
/// and how many bounded cells lie below `min` and above `max`. Throws `render_map_rgba_locked:
/// …` for a bad range (finite, 0 < min < max) or buffer length.
#[wasm_bindgen]
pub fn render_map_rgba_locked(
    values: &Float64Array,
    rgba: &Uint8ClampedArray,
    min: f64,
    max: f64,
) -> Result<Vec<f64>, JsError> {
    const F: &str = "render_map_rgba_locked";
    let scale =
        super::export::locked_scale([min, max]).map_err(|e| JsError::new(&format!("{F}: {e}")))?;
    let values = values.to_vec();
    let mut px = vec![0u8; rgba.length() as usize];
    if !present::fill_rgba(&values, &scale, &mut px) {
        return Err(JsError::new(&format!(
            "{F}: the rgba buffer has {} bytes for {} values (4 per value)",
            px.len(),
            values.len()
        )));
    }
    rgba.copy_from(&px);
    let [below, above] = scale.clamped_counts(&values);
    Ok(vec![scale.min, scale.max, below as f64, above as f64])
}

/// `n` RGBA pixels of the colour bar, dark (small error) first.
#[wasm_bindgen]
pub fn colorbar_rgba(n: usize) -> Vec<u8> {
    present::colorbar_rgba(n)
}

/// The colour of unbounded cells, `[r, g, b]`.
#[wasm_bindgen]
pub fn unbounded_rgb() -> Vec<u8> {
    UNBOUNDED_RGB.to_vec()
}

/// The links' colours ([`crate::present::LINK_RGB`]), `[r, g, b]` each, flat: link `i` takes
/// entry `i mod (len / 3)`.
#[wasm_bindgen]
pub fn link_rgb() -> Vec<u8> {
    LINK_RGB.concat()
}

/// Ticks of the log colour bar for a scale `[min, max]`, m: `[{frac, value_m, label}]` with
/// `frac ∈ [0, 1]` from the dark end; minor ticks have an empty label. The same algorithm as
/// the figures' bars ([`crate::present::colorbar_ticks`]), with at most `max_labels` labels
/// (none given: no thinning). Empty for an invalid scale.
#[wasm_bindgen]
pub fn colorbar_ticks(min: f64, max: f64, max_labels: Option<usize>) -> Result<JsValue, JsError> {
    let ticks = LogScale::new(min, max)
        .map(|s| s.ticks(max_labels.unwrap_or(usize::MAX)))
        .unwrap_or_default();
    to_js(&ColorbarTickJs::all(&ticks))
}

/// Most ticks [`axis_ticks`] asks the core for: a plot axis never needs more, and the core's
/// integer tick indices stay far from overflow (`linear_ticks` multiplies them in `i64`).
pub const MAX_AXIS_TICKS: usize = 100;

/// Linear axis ticks over `[lo, hi]` (about `max_count`, at most [`MAX_AXIS_TICKS`]):
/// `[{value, label}]`.
#[wasm_bindgen]
pub fn axis_ticks(lo: f64, hi: f64, max_count: usize) -> Result<JsValue, JsError> {
    to_js(&linear_ticks(lo, hi, max_count.min(MAX_AXIS_TICKS)))
}

/// A length as text with a readable unit (`"4.26 mm"`, `"17.7 cm"`, `"∞"`).
#[wasm_bindgen]
pub fn format_length(m: f64, significant: usize) -> String {
    format_length_m(m, significant)
}

/// A scale bar no longer than `max_len_m`: `{length_m, label}`, or null.
#[wasm_bindgen]
pub fn scale_bar(max_len_m: f64) -> Result<JsValue, JsError> {
    let bar = present::scale_bar(max_len_m);
    to_js(&bar.as_ref().map(ScaleBarJs::new))
}
