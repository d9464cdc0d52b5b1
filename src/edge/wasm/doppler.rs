//! The page's maps with Doppler (issue 42 §1): `App.compute_doppler_maps_in`, the position and
//! the velocity bound over one window, each [`doppler_map`] (D7) as `crlb-map --doppler
//! --quantity position|velocity` computes it, and `App.doppler_at`, the bound at one point
//! ([`DopplerDoc`], as `crlb --doppler` writes it: the map's hover read-out and pinned probe).
//! This file only converts: the settings object to a [`Grid`], a [`Cpi`] and a velocity, the
//! results to the page's typed arrays and objects. (The Save figure of these maps is
//! `App.map_svg` with its `doppler` option, export.rs.)

use js_sys::Float64Array;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;

use super::json::to_js;
use super::{err, now_ms, point, settings, window, App};
use crate::error::Error;
use crate::localize::{doppler_map, Grid, MapQuantity};
use crate::measure::Cpi;
use crate::present::{format_length_m, DopplerDoc};
use crate::Vec2;

/// The CPI of the settings (`cpi`): `N` snapshots `spacing_ms` ms apart, the floor on the
/// range rate's σ, m/s (D5). The carrier is the scenario's.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CpiSettings {
    /// `N`.
    snapshots: usize,
    /// `T`, ms (the page's unit; `T_s = spacing_ms / 1000`).
    spacing_ms: f64,
    /// `σ_floor`, m/s.
    floor_mps: f64,
}

impl CpiSettings {
    /// The core's CPI on the carrier `carrier_hz` (its named error for a bad setting).
    pub(super) fn cpi(&self, carrier_hz: f64) -> crate::Result<Cpi> {
        Cpi::new(
            carrier_hz,
            self.snapshots,
            self.spacing_ms / 1e3,
            self.floor_mps,
        )
    }
}

/// A velocity `[vx, vy]` (m/s) from JavaScript: finite, else the named error of `field`.
pub(super) fn velocity(field: &str, [vx, vy]: [f64; 2]) -> crate::Result<Vec2> {
    if vx.is_finite() && vy.is_finite() {
        Ok(Vec2::new(vx, vy))
    } else {
        Err(Error::NonFinite {
            field: field.into(),
        })
    }
}

/// The settings of `App.doppler_at` (JSON: every field required, unknown ones refused).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DopplerPointSettings {
    /// The coherent processing interval.
    cpi: CpiSettings,
    /// The target's velocity `[vx, vy]`, m/s.
    velocity_mps: [f64; 2],
}

/// `App.doppler_at`'s object: [`DopplerDoc`]'s fields (`null` where unbounded) with the point,
/// `bounded` and the labels of its three bounds.
#[derive(Serialize)]
struct DopplerAtJs {
    x: f64,
    y: f64,
    /// The bound with Doppler is finite (position and velocity).
    bounded: bool,
    #[serde(flatten)]
    doc: DopplerDoc,
    /// `position_rmse_m` as text (`"4.26 mm"`), `"unbounded"` when null.
    position_label: String,
    /// `velocity_rmse_mps` as text (`"1.2 cm/s"`), `"unbounded"` when null.
    velocity_label: String,
    /// `delay_only_position_rmse_m` as text, `"unbounded"` when null.
    delay_only_label: String,
}

/// A bound as text with `suffix` after its unit, `"unbounded"` for `None`.
fn bound_label(v: Option<f64>, suffix: &str) -> String {
    match v {
        Some(v) => format!("{}{suffix}", format_length_m(v, 3)),
        None => "unbounded".into(),
    }
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
        let cpi = cpi
            .cpi(self.session().scenario().radio.carrier_hz)
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

    /// The bound with delays and range rates at `(x, y)` m (issue 42 §1; the map's hover
    /// read-out and pinned probe): `settings_json`, one object (JSON text) `{cpi: {snapshots,
    /// spacing_ms, floor_mps}, velocity_mps: [vx, vy]}` as `compute_doppler_maps_in` takes it.
    /// Returns `{x, y, bounded, cpi: {snapshots, spacing_s, wavelength_m, floor_mps},
    /// velocity_mps, position_rmse_m, velocity_rmse_mps, delay_only_position_rmse_m, fim,
    /// links: [{range_rate_mps, sigma_range_rate_mps}], position_label, velocity_label,
    /// delay_only_label}`: the document `doppler` of `crlb --doppler --at x,y` (the same
    /// numbers, bit for bit, with `--cpi-spacing-s` = `spacing_ms / 1000`), `null` for a
    /// singular bound (label `unbounded`), never NaN. `position_rmse_m` equals the cell of
    /// `compute_doppler_maps_in`'s position map at that point. A bad point or setting throws
    /// the core's named error (`x`, `cpi.snapshots`, `velocity_mps`, `settings: invalid JSON: …`).
    pub fn doppler_at(&self, x: f64, y: f64, settings_json: &str) -> Result<JsValue, JsError> {
        let p = point(x, y)?;
        let DopplerPointSettings { cpi, velocity_mps } = settings("settings", settings_json)?;
        let v = velocity("velocity_mps", velocity_mps).map_err(err)?;
        let cpi = cpi
            .cpi(self.session().scenario().radio.carrier_hz)
            .map_err(err)?;
        let doc = DopplerDoc::at(self.session().model(), [p.x, p.y], [v.x, v.y], &cpi);
        to_js(&DopplerAtJs {
            x,
            y,
            bounded: doc.position_rmse_m.is_some() && doc.velocity_rmse_mps.is_some(),
            position_label: bound_label(doc.position_rmse_m, ""),
            velocity_label: bound_label(doc.velocity_rmse_mps, "/s"),
            delay_only_label: bound_label(doc.delay_only_position_rmse_m, ""),
            doc,
        })
    }
}
