//! The `App` class: the page's state (a core [`Session`]) and its methods, each a call into the
//! core plus conversion.

use js_sys::Float64Array;
use serde::Deserialize;
use wasm_bindgen::prelude::*;

use super::json::{to_js, CrlbJs, NodesJs, SnapshotJs};
use super::{err, now_ms, point, settings, window};
use crate::localize::{crlb_at, crlb_map, Grid};
use crate::present::simulate_snapshot;
use crate::present::Session;
use crate::scenario::Area;
use crate::{scenario::presets, Scenario};

/// The settings of `App.compute_map_in` (JSON: `{window, nx, ny}`, every field required,
/// unknown ones refused).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MapWindow {
    /// `[x_min, x_max, y_min, y_max]`, m.
    window: [f64; 4],
    /// Cells along x.
    nx: usize,
    /// Cells along y.
    ny: usize,
}

/// The page's state: a validated scenario and its compiled model.
#[wasm_bindgen]
pub struct App {
    session: Session,
}

impl App {
    fn from_scenario(scenario: crate::Result<Scenario>) -> Result<App, JsError> {
        let session = Session::new(scenario.map_err(err)?).map_err(err)?;
        Ok(App { session })
    }

    /// [`Session::edit`] with the error as an exception.
    fn edit<T>(&mut self, f: impl FnOnce(&mut Scenario) -> crate::Result<T>) -> Result<T, JsError> {
        self.session.edit(f).map_err(err)
    }

    /// The validated scenario (for Rust callers and tests).
    pub fn scenario_ref(&self) -> &Scenario {
        self.session.scenario()
    }

    /// The session (scenario and model) for the other binding files.
    pub(super) fn session(&self) -> &Session {
        &self.session
    }
}

#[wasm_bindgen]
impl App {
    /// An app from scenario JSON (schema v1, as the CLI reads); throws the validation message.
    #[wasm_bindgen(constructor)]
    pub fn new(scenario_json: &str) -> Result<App, JsError> {
        App::from_scenario(Scenario::from_json(scenario_json))
    }

    /// An app from a preset name (`sensors2019`, `iclgnss2019`).
    pub fn from_preset(name: &str) -> Result<App, JsError> {
        App::from_scenario(presets::preset(name))
    }

    /// The scenario as pretty JSON (same schema the CLI reads).
    pub fn scenario_json(&self) -> String {
        self.session.scenario().to_json()
    }

    /// The scenario as a plain JavaScript object (parsed JSON).
    pub fn scenario(&self) -> Result<JsValue, JsError> {
        to_js(self.session.scenario())
    }

    /// Replaces the scenario with parsed, validated JSON; unchanged on error.
    pub fn set_scenario_json(&mut self, json: &str) -> Result<(), JsError> {
        let s = Scenario::from_json(json).map_err(err)?;
        self.session.replace(s).map_err(err)
    }

    /// Replaces the scenario with a preset; unchanged on error.
    pub fn load_preset(&mut self, name: &str) -> Result<(), JsError> {
        let s = presets::preset(name).map_err(err)?;
        self.session.replace(s).map_err(err)
    }

    /// Number of transmitters.
    pub fn transmitter_count(&self) -> usize {
        self.session.scenario().transmitters.len()
    }

    /// Number of receivers.
    pub fn receiver_count(&self) -> usize {
        self.session.scenario().receivers.len()
    }

    /// Number of links.
    pub fn link_count(&self) -> usize {
        self.session.model().link_count()
    }

    /// Nodes for drawing: `{transmitters: [{name, x, y, boresight: [ux, uy] | null}],
    /// receivers: [{name, x, y}], links: [[tx, rx], …]}` (indices).
    pub fn nodes(&self) -> Result<JsValue, JsError> {
        to_js(&NodesJs::new(&self.session))
    }

    /// Area of interest `[x_min, x_max, y_min, y_max]`, m.
    pub fn area(&self) -> Vec<f64> {
        let a = &self.session.scenario().area_m;
        vec![a.x[0], a.x[1], a.y[0], a.y[1]]
    }

    /// Sets the area of interest (validated).
    pub fn set_area(
        &mut self,
        x_min: f64,
        x_max: f64,
        y_min: f64,
        y_max: f64,
    ) -> Result<(), JsError> {
        let area = Area {
            x: [x_min, x_max],
            y: [y_min, y_max],
        };
        self.edit(|s| s.set_area(area))
    }

    /// Moves transmitter `i` to `(x, y)`, m.
    pub fn move_transmitter(&mut self, i: usize, x: f64, y: f64) -> Result<(), JsError> {
        self.edit(|s| s.move_transmitter(i, [x, y]))
    }

    /// Moves receiver `i` to `(x, y)`, m.
    pub fn move_receiver(&mut self, i: usize, x: f64, y: f64) -> Result<(), JsError> {
        self.edit(|s| s.move_receiver(i, [x, y]))
    }

    /// Adds a transmitter at `(x, y)` with the radio settings of the last one and a fresh unique
    /// name (`TxN`); with an explicit link list it is linked to every receiver. Returns its index.
    pub fn add_transmitter(&mut self, x: f64, y: f64) -> Result<usize, JsError> {
        self.edit(|s| s.add_transmitter([x, y]))
    }

    /// Adds a receiver at `(x, y)` with the gain of the last one and a fresh unique name
    /// (`RxN`); with an explicit link list it is linked to every transmitter. Returns its index.
    pub fn add_receiver(&mut self, x: f64, y: f64) -> Result<usize, JsError> {
        self.edit(|s| s.add_receiver([x, y]))
    }

    /// Removes transmitter `i` (and its links); at least one must remain.
    pub fn remove_transmitter(&mut self, i: usize) -> Result<(), JsError> {
        self.edit(|s| s.remove_transmitter(i))
    }

    /// Removes receiver `i` (and its links); at least one must remain.
    pub fn remove_receiver(&mut self, i: usize) -> Result<(), JsError> {
        self.edit(|s| s.remove_receiver(i))
    }

    /// Carrier frequency `f_c`, Hz.
    pub fn set_carrier_hz(&mut self, v: f64) -> Result<(), JsError> {
        self.edit(|s| s.set_carrier_hz(v))
    }

    /// Bandwidth `B`, Hz.
    pub fn set_bandwidth_hz(&mut self, v: f64) -> Result<(), JsError> {
        self.edit(|s| s.set_bandwidth_hz(v))
    }

    /// Receiver noise figure, dB (replaces an explicit noise power).
    pub fn set_noise_figure_db(&mut self, v: f64) -> Result<(), JsError> {
        self.edit(|s| s.set_noise_figure_db(v))
    }

    /// Target radar cross section, m².
    pub fn set_rcs_m2(&mut self, v: f64) -> Result<(), JsError> {
        self.edit(|s| s.set_rcs_m2(v))
    }

    /// Transmit power of transmitter `i`, dBm.
    pub fn set_tx_power_dbm(&mut self, i: usize, v: f64) -> Result<(), JsError> {
        self.edit(|s| s.set_tx_power_dbm(i, v))
    }

    /// Peak antenna gain of transmitter `i`, dBi.
    pub fn set_tx_gain_dbi(&mut self, i: usize, v: f64) -> Result<(), JsError> {
        self.edit(|s| s.set_tx_gain_dbi(i, v))
    }

    /// Antenna pattern of transmitter `i`: `kind` = `"omni"` (angles ignored) or `"parabolic"`
    /// with boresight azimuth and half-power beamwidth (degrees) and floor (dB).
    pub fn set_tx_pattern(
        &mut self,
        i: usize,
        kind: &str,
        boresight_deg: f64,
        beamwidth_deg: f64,
        floor_db: f64,
    ) -> Result<(), JsError> {
        self.edit(|s| s.set_tx_pattern_kind(i, kind, boresight_deg, beamwidth_deg, floor_db))
    }

    /// Antenna gain of receiver `i`, dBi.
    pub fn set_rx_gain_dbi(&mut self, i: usize, v: f64) -> Result<(), JsError> {
        self.edit(|s| s.set_rx_gain_dbi(i, v))
    }

    /// Antenna height of transmitter `i` above the floor, m (issue 40; a non-finite value or
    /// one past the coordinate limits is the core's named error `transmitters[i].height_m`).
    pub fn set_tx_height_m(&mut self, i: usize, v: f64) -> Result<(), JsError> {
        self.edit(|s| s.set_tx_height_m(i, v))
    }

    /// Antenna height of receiver `i` above the floor, m (named error `receivers[i].height_m`).
    pub fn set_rx_height_m(&mut self, i: usize, v: f64) -> Result<(), JsError> {
        self.edit(|s| s.set_rx_height_m(i, v))
    }

    /// Height of the plane the target moves in (its body centre), m: the CRLB map, the fixes
    /// and the tracks are then computed in that plane with 3-D ranges (E1; named error
    /// `target.height_m`).
    pub fn set_target_height_m(&mut self, v: f64) -> Result<(), JsError> {
        self.edit(|s| s.set_target_height_m(v))
    }

    /// Height of the target's plane, m (0 for a planar scenario): the target read-out's, without
    /// converting the whole scenario.
    pub fn target_height_m(&self) -> f64 {
        self.session.scenario().target.height_m
    }

    /// CRLB RMSE map over the area on an `nx × ny` grid of cell centres (row-major, row 0 =
    /// lowest y) written into `out` (a `Float64Array` of `nx·ny`), m; unbounded cells are
    /// `Infinity`. Returns the kernel time, ms.
    pub fn compute_map(&self, nx: usize, ny: usize, out: &Float64Array) -> Result<f64, JsError> {
        self.map_over(self.session.scenario().area_m, nx, ny, out)
    }

    /// The same map over any window of `settings_json`, one object (JSON text): `{window:
    /// [x_min, x_max, y_min, y_max] (m), nx, ny}` (the page's zoomed and panned view): every
    /// cell computed at full resolution in the window, not a crop of the area's map. A window
    /// that is not a finite, non-empty rectangle is a named error (`window.x` / `window.y`), an
    /// unknown, missing or mistyped field `settings: invalid JSON: …` naming it.
    pub fn compute_map_in(&self, settings_json: &str, out: &Float64Array) -> Result<f64, JsError> {
        let MapWindow { window: w, nx, ny } = settings("settings", settings_json)?;
        self.map_over(window(w).map_err(err)?, nx, ny, out)
    }

    fn map_over(
        &self,
        area: Area,
        nx: usize,
        ny: usize,
        out: &Float64Array,
    ) -> Result<f64, JsError> {
        let grid = Grid::new(area, nx, ny).map_err(err)?;
        let mut buf = vec![0.0; out.length() as usize];
        let t0 = now_ms();
        crlb_map(self.session.model(), &grid, &mut buf).map_err(err)?;
        let ms = now_ms() - t0;
        out.copy_from(&buf);
        Ok(ms)
    }

    /// Centre of map cell `(i, j)` of an `nx × ny` grid over the area, `[x, y]` m.
    pub fn cell_center(
        &self,
        nx: usize,
        ny: usize,
        i: usize,
        j: usize,
    ) -> Result<Vec<f64>, JsError> {
        let grid = Grid::new(self.session.scenario().area_m, nx, ny).map_err(err)?;
        let c = grid.cell_center(i, j).map_err(err)?;
        Ok(vec![c.x, c.y])
    }

    /// CRLB at `(x, y)`: `{x, y, bounded, sigma_x_m, sigma_y_m, rmse_m, *_label, ellipse:
    /// {cx, cy, a, b, angle} }`; unbounded: `bounded: false` and nulls.
    pub fn crlb_at(&self, x: f64, y: f64) -> Result<JsValue, JsError> {
        to_js(&CrlbJs::new(&crlb_at(self.session.model(), point(x, y)?)))
    }

    /// CRLB RMSE bound at `(x, y)`, m (`Infinity` when unbounded).
    pub fn rmse_at(&self, x: f64, y: f64) -> Result<f64, JsError> {
        Ok(crlb_at(self.session.model(), point(x, y)?).rmse_m())
    }

    /// One simulated snapshot ([`simulate_snapshot`]) for a scatterer at `(x, y)` with noise
    /// stream `seed`: per link the noisy delay, its σ (and `cσ` as a label), its iso-delay
    /// ellipse (null below the LoS delay) with its `outline` (a closed polygon, `[]` when none)
    /// and `arc` (points within about `view_radius_m` of the truth, `[]` if it passes farther);
    /// the LM fix with its 1σ ellipse, or `fix: null` and `fix_error`; the CRLB (with 1σ
    /// ellipse) at the truth; `view_radius_m`, a radius around the truth holding both ellipses.
    pub fn simulate_fix(&self, x: f64, y: f64, seed: u32) -> Result<JsValue, JsError> {
        let s = self.session.scenario();
        let sim = simulate_snapshot(self.session.model(), &s.area_m, point(x, y)?, seed.into());
        to_js(&SnapshotJs::new(&sim, s))
    }
}
