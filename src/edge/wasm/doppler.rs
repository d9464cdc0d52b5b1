//! The page's maps with Doppler (issue 42 §1): `App.compute_doppler_maps_in`, the position and
//! the velocity bound over one window, each [`doppler_map`] (D7) as `crlb-map --doppler
//! --quantity position|velocity` computes it. This file only converts: the settings object to a
//! [`Grid`], a [`Cpi`] and a velocity, the two maps to the page's typed arrays.

use js_sys::Float64Array;
use serde::Deserialize;
use wasm_bindgen::prelude::*;

use super::{err, now_ms, settings, window, App};
use crate::localize::{doppler_map, Grid, MapQuantity};
use crate::measure::Cpi;
use crate::Vec2;

/// The CPI of the settings (`cpi`): `N` snapshots `spacing_ms` ms apart, the floor on the
/// range rate's σ, m/s (D5). The carrier is the scenario's.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CpiSettings {
    /// `N`.
    snapshots: usize,
    /// `T`, ms (the page's unit; `T_s = spacing_ms / 1000`).
    spacing_ms: f64,
    /// `σ_floor`, m/s.
    floor_mps: f64,
}

/// The settings of `App.compute_doppler_maps_in` (JSON: every field required, unknown ones
/// refused).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DopplerMapSettings {
    /// `[x_min, x_max, y_min, y_max]`, m.
    window: [f64; 4],
    /// Cells along x.
    nx: usize,
    /// Cells along y.
    ny: usize,
    /// The coherent processing interval.
    cpi: CpiSettings,
    /// The target's velocity `[vx, vy]`, m/s.
    velocity_mps: [f64; 2],
}

#[wasm_bindgen]
impl App {
    /// The bound with delays and range rates over a window (issue 42 §1): `settings_json`, one
    /// object (JSON text) `{window: [x_min, x_max, y_min, y_max] (m), nx, ny, cpi: {snapshots,
    /// spacing_ms, floor_mps}, velocity_mps: [vx, vy]}`; `position` gets the position bound (m)
    /// and `velocity` the velocity bound (m/s), each a `Float64Array` of `nx·ny` cells (row 0 =
    /// lowest y), `Infinity` where the information is singular; the same numbers as `crlb-map
    /// --doppler --quantity position|velocity` on that grid with `--cpi-spacing-s` = `spacing_ms
    /// / 1000`. Returns the kernel time of both maps, ms. A bad setting throws the core's named
    /// error (`cpi.snapshots`, `cpi.spacing_s`, `cpi.floor_mps`, `velocity`, `window.x`, …;
    /// `settings: invalid JSON: …` for an unknown, missing or mistyped field).
    pub fn compute_doppler_maps_in(
        &self,
        settings_json: &str,
        position: &Float64Array,
        velocity: &Float64Array,
    ) -> Result<f64, JsError> {
        let DopplerMapSettings {
            window: w,
            nx,
            ny,
            cpi,
            velocity_mps: [vx, vy],
        } = settings("settings", settings_json)?;
        let grid = Grid::new(window(w).map_err(err)?, nx, ny).map_err(err)?;
        let model = self.session().model();
        let carrier_hz = self.session().scenario().radio.carrier_hz;
        let cpi = Cpi::new(
            carrier_hz,
            cpi.snapshots,
            cpi.spacing_ms / 1e3,
            cpi.floor_mps,
        )
        .map_err(err)?;
        let v = Vec2::new(vx, vy);
        let mut pos = vec![0.0; position.length() as usize];
        let mut vel = vec![0.0; velocity.length() as usize];
        let t0 = now_ms();
        doppler_map(model, &grid, &cpi, v, MapQuantity::Position, &mut pos).map_err(err)?;
        doppler_map(model, &grid, &cpi, v, MapQuantity::Velocity, &mut vel).map_err(err)?;
        let ms = now_ms() - t0;
        position.copy_from(&pos);
        velocity.copy_from(&vel);
        Ok(ms)
    }
}
