//! WebAssembly bindings for the page: a thin wrapper over the core, no math here.
//!
//! [`App`] holds a validated [`Scenario`] and its compiled [`Model`]. Every edit is applied to a
//! copy that is validated (by compiling it) before it replaces the state, so a rejected edit
//! leaves the app unchanged. Errors cross to JavaScript as exceptions (`JsError`) carrying the
//! core [`Error`]'s one-line message, which names the offending field; nothing panics on input.
//! Objects are handed over as parsed JSON (serde_json), whose non-finite numbers become `null`,
//! so no NaN reaches JavaScript; unbounded map cells are `Infinity` in the typed array.

use js_sys::{Float64Array, Uint8ClampedArray};
use serde_json::{json, Value};
use wasm_bindgen::prelude::*;

use crate::colormap::{fill_rgba, viridis, LogScale, UNBOUNDED_RGB};
use crate::crlb::{crlb_at, crlb_map, CrlbPoint, Grid};
use crate::ellipse::Ellipse;
use crate::error::Error;
use crate::lm::{locate, DelayMeasurements, LmConfig};
use crate::math::SPEED_OF_LIGHT;
use crate::scenario::{Pattern, Receiver, Transmitter};
use crate::simulate::{noisy_delays, rng};
use crate::ticks::{format_length_m, linear_ticks, log_length_ticks, scale_bar as core_scale_bar};
use crate::{presets, Model, Scenario, Vec2};

#[wasm_bindgen]
extern "C" {
    /// `performance.now()`, ms (window or worker).
    #[wasm_bindgen(js_namespace = performance, js_name = now)]
    fn performance_now() -> f64;
}

/// Module start: route Rust panics to `console.error` with their message.
#[wasm_bindgen(start)]
pub fn start() {
    console_error_panic_hook::set_once();
}

fn err(e: Error) -> JsError {
    JsError::new(&e.to_string())
}

/// Parsed JSON for JavaScript (numbers that are not finite are already `null` in `Value`).
fn to_js(v: &Value) -> Result<JsValue, JsError> {
    js_sys::JSON::parse(&v.to_string()).map_err(|_| JsError::new("internal error: bad JSON"))
}

fn finite(field: &str, v: f64) -> Result<(), JsError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(err(Error::NonFinite {
            field: field.to_string(),
        }))
    }
}

fn point(x: f64, y: f64) -> Result<Vec2, JsError> {
    finite("x", x)?;
    finite("y", y)?;
    Ok(Vec2::new(x, y))
}

fn ellipse_json(e: Option<Ellipse>) -> Value {
    match e {
        Some(e) => json!({
            "cx": e.center.x, "cy": e.center.y,
            "a": e.semi_major, "b": e.semi_minor, "angle": e.angle_rad,
        }),
        None => Value::Null,
    }
}

fn crlb_json(c: &CrlbPoint) -> Value {
    match c.bound {
        Some(b) => json!({
            "x": c.position.x, "y": c.position.y, "bounded": true,
            "sigma_x_m": b.sigma_x_m, "sigma_y_m": b.sigma_y_m, "rmse_m": b.rmse_m,
            "rmse_label": format_length_m(b.rmse_m, 3),
            "sigma_x_label": format_length_m(b.sigma_x_m, 3),
            "sigma_y_label": format_length_m(b.sigma_y_m, 3),
            "ellipse": ellipse_json(c.ellipse()),
        }),
        None => json!({
            "x": c.position.x, "y": c.position.y, "bounded": false,
            "sigma_x_m": null, "sigma_y_m": null, "rmse_m": null,
            "rmse_label": "unbounded", "sigma_x_label": "\u{221e}", "sigma_y_label": "\u{221e}",
            "ellipse": null,
        }),
    }
}

/// First name `prefix1`, `prefix2`, … not used by any node.
fn fresh_name(s: &Scenario, prefix: &str) -> String {
    let taken = |n: &str| {
        s.transmitters.iter().any(|t| t.name == n) || s.receivers.iter().any(|r| r.name == n)
    };
    (1..)
        .map(|i| format!("{prefix}{i}"))
        .find(|n| !taken(n))
        .unwrap_or_default()
}

/// The page's state: a validated scenario and its compiled model.
#[wasm_bindgen]
pub struct App {
    scenario: Scenario,
    model: Model,
}

impl App {
    fn from_scenario(scenario: Scenario) -> Result<App, JsError> {
        let model = Model::new(&scenario).map_err(err)?;
        Ok(App { scenario, model })
    }

    /// Applies `f` to a copy; commits only if the result validates and compiles.
    fn edit(
        &mut self,
        f: impl FnOnce(&mut Scenario) -> Result<(), JsError>,
    ) -> Result<(), JsError> {
        let mut s = self.scenario.clone();
        f(&mut s)?;
        let model = Model::new(&s).map_err(err)?;
        self.scenario = s;
        self.model = model;
        Ok(())
    }

    fn tx_index(&self, i: usize) -> Result<usize, JsError> {
        let n = self.scenario.transmitters.len();
        if i < n {
            Ok(i)
        } else {
            Err(JsError::new(&format!(
                "transmitters[{i}]: no such transmitter (there are {n})"
            )))
        }
    }

    fn rx_index(&self, i: usize) -> Result<usize, JsError> {
        let n = self.scenario.receivers.len();
        if i < n {
            Ok(i)
        } else {
            Err(JsError::new(&format!(
                "receivers[{i}]: no such receiver (there are {n})"
            )))
        }
    }

    /// The validated scenario (for Rust callers and tests).
    pub fn scenario_ref(&self) -> &Scenario {
        &self.scenario
    }
}

#[wasm_bindgen]
impl App {
    /// An app from scenario JSON (schema v1, as the CLI reads); throws the validation message.
    #[wasm_bindgen(constructor)]
    pub fn new(scenario_json: &str) -> Result<App, JsError> {
        App::from_scenario(Scenario::from_json(scenario_json).map_err(err)?)
    }

    /// An app from a preset name (`sensors2019`, `iclgnss2019`).
    pub fn from_preset(name: &str) -> Result<App, JsError> {
        App::from_scenario(presets::preset(name).map_err(err)?)
    }

    /// The scenario as pretty JSON (same schema the CLI reads).
    pub fn scenario_json(&self) -> String {
        self.scenario.to_json()
    }

    /// The scenario as a plain JavaScript object (parsed JSON).
    pub fn scenario(&self) -> Result<JsValue, JsError> {
        let v = serde_json::to_value(&self.scenario).map_err(|e| JsError::new(&e.to_string()))?;
        to_js(&v)
    }

    /// Replaces the scenario with parsed, validated JSON; unchanged on error.
    pub fn set_scenario_json(&mut self, json: &str) -> Result<(), JsError> {
        let s = Scenario::from_json(json).map_err(err)?;
        self.edit(|cur| {
            *cur = s;
            Ok(())
        })
    }

    /// Replaces the scenario with a preset; unchanged on error.
    pub fn load_preset(&mut self, name: &str) -> Result<(), JsError> {
        let s = presets::preset(name).map_err(err)?;
        self.edit(|cur| {
            *cur = s;
            Ok(())
        })
    }

    /// Number of transmitters.
    pub fn transmitter_count(&self) -> usize {
        self.scenario.transmitters.len()
    }

    /// Number of receivers.
    pub fn receiver_count(&self) -> usize {
        self.scenario.receivers.len()
    }

    /// Number of links.
    pub fn link_count(&self) -> usize {
        self.model.link_count()
    }

    /// Nodes for drawing: `{transmitters: [{name, x, y, boresight: [ux, uy] | null}],
    /// receivers: [{name, x, y}], links: [[tx, rx], …]}` (indices).
    pub fn nodes(&self) -> Result<JsValue, JsError> {
        let net = &self.model.network;
        let tx: Vec<Value> = self
            .scenario
            .transmitters
            .iter()
            .zip(&self.model.patterns)
            .map(|(t, p)| {
                json!({
                    "name": t.name, "x": t.position_m[0], "y": t.position_m[1],
                    "boresight": p.beam.map(|b| [b.boresight.x, b.boresight.y]),
                })
            })
            .collect();
        let rx: Vec<Value> = self
            .scenario
            .receivers
            .iter()
            .map(|r| json!({"name": r.name, "x": r.position_m[0], "y": r.position_m[1]}))
            .collect();
        let links: Vec<[usize; 2]> = net.links.iter().map(|l| [l.tx, l.rx]).collect();
        to_js(&json!({"transmitters": tx, "receivers": rx, "links": links}))
    }

    /// Area of interest `[x_min, x_max, y_min, y_max]`, m.
    pub fn area(&self) -> Vec<f64> {
        let a = &self.scenario.area_m;
        std::vec![a.x[0], a.x[1], a.y[0], a.y[1]]
    }

    /// Sets the area of interest (validated).
    pub fn set_area(
        &mut self,
        x_min: f64,
        x_max: f64,
        y_min: f64,
        y_max: f64,
    ) -> Result<(), JsError> {
        self.edit(|s| {
            s.area_m.x = [x_min, x_max];
            s.area_m.y = [y_min, y_max];
            Ok(())
        })
    }

    /// Moves transmitter `i` to `(x, y)`, m.
    pub fn move_transmitter(&mut self, i: usize, x: f64, y: f64) -> Result<(), JsError> {
        let i = self.tx_index(i)?;
        self.edit(|s| {
            s.transmitters[i].position_m = [x, y];
            Ok(())
        })
    }

    /// Moves receiver `i` to `(x, y)`, m.
    pub fn move_receiver(&mut self, i: usize, x: f64, y: f64) -> Result<(), JsError> {
        let i = self.rx_index(i)?;
        self.edit(|s| {
            s.receivers[i].position_m = [x, y];
            Ok(())
        })
    }

    /// Adds a transmitter at `(x, y)` with the radio settings of the last one and a fresh unique
    /// name (`TxN`); with an explicit link list it is linked to every receiver. Returns its index.
    pub fn add_transmitter(&mut self, x: f64, y: f64) -> Result<usize, JsError> {
        self.edit(|s| {
            let mut t: Transmitter = s.transmitters.last().cloned().ok_or_else(|| {
                err(Error::EmptyNodeList {
                    field: "transmitters",
                })
            })?;
            t.name = fresh_name(s, "Tx");
            t.position_m = [x, y];
            if let crate::scenario::LinkSpec::List(l) = &mut s.links {
                l.extend(s.receivers.iter().map(|r| [t.name.clone(), r.name.clone()]));
            }
            s.transmitters.push(t);
            Ok(())
        })?;
        Ok(self.scenario.transmitters.len() - 1)
    }

    /// Adds a receiver at `(x, y)` with the gain of the last one and a fresh unique name
    /// (`RxN`); with an explicit link list it is linked to every transmitter. Returns its index.
    pub fn add_receiver(&mut self, x: f64, y: f64) -> Result<usize, JsError> {
        self.edit(|s| {
            let gain_dbi = s.receivers.last().map_or(0.0, |r| r.gain_dbi);
            let r = Receiver {
                name: fresh_name(s, "Rx"),
                position_m: [x, y],
                gain_dbi,
            };
            if let crate::scenario::LinkSpec::List(l) = &mut s.links {
                l.extend(
                    s.transmitters
                        .iter()
                        .map(|t| [t.name.clone(), r.name.clone()]),
                );
            }
            s.receivers.push(r);
            Ok(())
        })?;
        Ok(self.scenario.receivers.len() - 1)
    }

    /// Removes transmitter `i` (and its links); at least one must remain.
    pub fn remove_transmitter(&mut self, i: usize) -> Result<(), JsError> {
        let i = self.tx_index(i)?;
        self.edit(|s| {
            let t = s.transmitters.remove(i);
            if let crate::scenario::LinkSpec::List(l) = &mut s.links {
                l.retain(|p| p[0] != t.name);
            }
            Ok(())
        })
    }

    /// Removes receiver `i` (and its links); at least one must remain.
    pub fn remove_receiver(&mut self, i: usize) -> Result<(), JsError> {
        let i = self.rx_index(i)?;
        self.edit(|s| {
            let r = s.receivers.remove(i);
            if let crate::scenario::LinkSpec::List(l) = &mut s.links {
                l.retain(|p| p[1] != r.name);
            }
            Ok(())
        })
    }

    /// Carrier frequency `f_c`, Hz.
    pub fn set_carrier_hz(&mut self, v: f64) -> Result<(), JsError> {
        self.edit(|s| {
            s.radio.carrier_hz = v;
            Ok(())
        })
    }

    /// Bandwidth `B`, Hz.
    pub fn set_bandwidth_hz(&mut self, v: f64) -> Result<(), JsError> {
        self.edit(|s| {
            s.radio.bandwidth_hz = v;
            Ok(())
        })
    }

    /// Receiver noise figure, dB (replaces an explicit noise power).
    pub fn set_noise_figure_db(&mut self, v: f64) -> Result<(), JsError> {
        self.edit(|s| {
            s.radio.noise_figure_db = Some(v);
            s.radio.noise_power_dbm = None;
            Ok(())
        })
    }

    /// Target radar cross section, m².
    pub fn set_rcs_m2(&mut self, v: f64) -> Result<(), JsError> {
        self.edit(|s| {
            s.target.rcs_m2 = v;
            Ok(())
        })
    }

    /// Transmit power of transmitter `i`, dBm.
    pub fn set_tx_power_dbm(&mut self, i: usize, v: f64) -> Result<(), JsError> {
        let i = self.tx_index(i)?;
        self.edit(|s| {
            s.transmitters[i].power_dbm = v;
            Ok(())
        })
    }

    /// Peak antenna gain of transmitter `i`, dBi.
    pub fn set_tx_gain_dbi(&mut self, i: usize, v: f64) -> Result<(), JsError> {
        let i = self.tx_index(i)?;
        self.edit(|s| {
            s.transmitters[i].gain_dbi = v;
            Ok(())
        })
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
        let i = self.tx_index(i)?;
        let pattern = match kind {
            "omni" => Pattern::Omni,
            "parabolic" => Pattern::Parabolic {
                boresight_deg,
                beamwidth_deg,
                floor_db,
            },
            other => {
                return Err(JsError::new(&format!(
                    "transmitters[{i}].pattern.kind: unknown pattern \"{other}\" (known: omni, parabolic)"
                )))
            }
        };
        self.edit(|s| {
            s.transmitters[i].pattern = pattern;
            Ok(())
        })
    }

    /// Antenna gain of receiver `i`, dBi.
    pub fn set_rx_gain_dbi(&mut self, i: usize, v: f64) -> Result<(), JsError> {
        let i = self.rx_index(i)?;
        self.edit(|s| {
            s.receivers[i].gain_dbi = v;
            Ok(())
        })
    }

    /// CRLB RMSE map over the area on an `nx × ny` grid of cell centres (row-major, row 0 =
    /// lowest y) written into `out` (a `Float64Array` of `nx·ny`), m; unbounded cells are
    /// `Infinity`. Returns the kernel time, ms.
    pub fn compute_map(&self, nx: usize, ny: usize, out: &Float64Array) -> Result<f64, JsError> {
        let grid = Grid::new(self.scenario.area_m, nx, ny).map_err(err)?;
        if out.length() as usize != grid.len() {
            return Err(err(Error::LengthMismatch {
                field: "map buffer",
                expected: grid.len(),
                found: out.length() as usize,
            }));
        }
        let mut buf = std::vec![0.0; grid.len()];
        let t0 = performance_now();
        crlb_map(&self.model, &grid, &mut buf).map_err(err)?;
        let ms = performance_now() - t0;
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
        let grid = Grid::new(self.scenario.area_m, nx, ny).map_err(err)?;
        if i >= nx || j >= ny {
            return Err(JsError::new(&format!(
                "cell ({i}, {j}) is outside the {nx}x{ny} grid"
            )));
        }
        Ok(std::vec![grid.x(i), grid.y(j)])
    }

    /// CRLB at `(x, y)`: `{x, y, bounded, sigma_x_m, sigma_y_m, rmse_m, *_label, ellipse:
    /// {cx, cy, a, b, angle} }`; unbounded: `bounded: false` and nulls.
    pub fn crlb_at(&self, x: f64, y: f64) -> Result<JsValue, JsError> {
        to_js(&crlb_json(&crlb_at(&self.model, point(x, y)?)))
    }

    /// CRLB RMSE bound at `(x, y)`, m (`Infinity` when unbounded).
    pub fn rmse_at(&self, x: f64, y: f64) -> Result<f64, JsError> {
        Ok(crlb_at(&self.model, point(x, y)?)
            .bound
            .map_or(f64::INFINITY, |b| b.rmse_m))
    }

    /// One simulated snapshot for a scatterer at `(x, y)` with noise stream `seed`: per link the
    /// noisy delay, its σ (and `cσ` as a label) and iso-delay ellipse (null when below the LoS delay) with its
    /// `outline` (a closed polygon, `[]` when none) for drawing; the LM fix
    /// (grid-search start, σ from the link budget at the truth) with its 1σ ellipse, or
    /// `fix: null` and `fix_error`; the CRLB (with 1σ ellipse) at the truth; `view_radius_m`,
    /// a radius around the truth that holds both ellipses (for a zoom inset), and per link `arc`:
    /// points of its iso-delay ellipse within about that radius (`[]` if it passes farther).
    pub fn simulate_fix(&self, x: f64, y: f64, seed: u32) -> Result<JsValue, JsError> {
        let r = point(x, y)?;
        let net = &self.model.network;
        let mut g = rng(u64::from(seed), 0);
        let delays = noisy_delays(&self.model, r, &mut g);
        let sigmas = self.model.sigma_delays(r);
        let measured: Vec<Option<f64>> = delays.iter().copied().map(Some).collect();
        let m = DelayMeasurements {
            delays_s: &measured,
            sigmas_s: &sigmas,
        };
        let crlb = crlb_at(&self.model, r);
        let mut radius = crlb.ellipse().map_or(0.0, |e| e.semi_major);
        let (fix, fix_error) =
            match locate(net, &m, &LmConfig::default(), None, &self.scenario.area_m) {
                Ok(rep) => {
                    let e = rep
                        .covariance_m2
                        .and_then(|c| Ellipse::from_covariance(rep.position, &c, 1.0));
                    let miss = (rep.position - r).norm();
                    radius = radius.max(miss + e.map_or(0.0, |e| e.semi_major));
                    (
                        json!({
                            "x": rep.position.x, "y": rep.position.y,
                            "error_m": miss, "error_label": format_length_m(miss, 3),
                            "cost": rep.cost, "iterations": rep.iterations,
                            "termination": rep.termination.as_str(),
                            "converged": rep.termination.converged(),
                            "ellipse": ellipse_json(e),
                        }),
                        Value::Null,
                    )
                }
                Err(e) => (Value::Null, Value::String(e.to_string())),
            };
        if !(radius.is_finite() && radius > 0.0) {
            radius = 0.05;
        }
        let view_radius = 1.6 * radius;
        let links: Vec<Value> = (0..net.link_count())
            .map(|p| {
                let l = net.links[p];
                let e = net.iso_delay_ellipse(p, delays[p]);
                let arc: Vec<[f64; 2]> = e.map_or_else(Vec::new, |e| {
                    e.arc_near(r, view_radius, 48)
                        .iter()
                        .map(|q| [q.x, q.y])
                        .collect()
                });
                let outline: Vec<[f64; 2]> = e.map_or_else(Vec::new, |e| {
                    e.polygon(160).iter().map(|q| [q.x, q.y]).collect()
                });
                json!({
                    "tx": l.tx, "rx": l.rx,
                    "name": format!("{}\u{2013}{}", self.scenario.transmitters[l.tx].name,
                                    self.scenario.receivers[l.rx].name),
                    "delay_s": delays[p], "sigma_s": sigmas[p],
                    "range_sigma_label": format_length_m(SPEED_OF_LIGHT * sigmas[p], 3),
                    "ellipse": ellipse_json(e),
                    "outline": outline,
                    "arc": arc,
                })
            })
            .collect();
        to_js(&json!({
            "truth": {"x": x, "y": y},
            "seed": seed,
            "links": links,
            "fix": fix,
            "fix_error": fix_error,
            "crlb": crlb_json(&crlb),
            "view_radius_m": view_radius,
        }))
    }
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

/// Colours a map (`values`, m) into `rgba` (4 bytes per value, e.g. an `ImageData.data`) on the
/// log scale spanning its finite values. Returns `[min, max]` of the scale, m; `[Infinity,
/// Infinity]` (and all grey) when no cell is bounded.
#[wasm_bindgen]
pub fn render_map_rgba(
    values: &Float64Array,
    rgba: &Uint8ClampedArray,
) -> Result<Vec<f64>, JsError> {
    let n = values.length() as usize;
    if rgba.length() as usize != 4 * n {
        return Err(err(Error::LengthMismatch {
            field: "rgba buffer (4 bytes per map value)",
            expected: 4 * n,
            found: rgba.length() as usize,
        }));
    }
    let v = values.to_vec();
    let mut px = std::vec![0u8; 4 * n];
    let range = match LogScale::spanning(&v) {
        Some(scale) => {
            fill_rgba(&v, &scale, &mut px);
            std::vec![scale.min, scale.max]
        }
        None => {
            for p in px.chunks_exact_mut(4) {
                p.copy_from_slice(&[UNBOUNDED_RGB[0], UNBOUNDED_RGB[1], UNBOUNDED_RGB[2], 255]);
            }
            std::vec![f64::INFINITY, f64::INFINITY]
        }
    };
    rgba.copy_from(&px);
    Ok(range)
}

/// `n` RGBA pixels of the colour bar, dark (small error) first.
#[wasm_bindgen]
pub fn colorbar_rgba(n: usize) -> Vec<u8> {
    let n = n.clamp(2, 4096);
    (0..n)
        .flat_map(|i| {
            let c = viridis(i as f64 / (n - 1) as f64);
            [c[0], c[1], c[2], 255]
        })
        .collect()
}

/// The colour of unbounded cells, `[r, g, b]`.
#[wasm_bindgen]
pub fn unbounded_rgb() -> Vec<u8> {
    UNBOUNDED_RGB.to_vec()
}

/// Ticks of the log colour bar for a scale `[min, max]`, m: `[{frac, value_m, label}]` with
/// `frac ∈ [0, 1]` from the dark end. Empty for an invalid scale.
#[wasm_bindgen]
pub fn colorbar_ticks(min: f64, max: f64) -> Result<JsValue, JsError> {
    let ticks: Vec<Value> = match (min.is_finite() && max.is_finite() && min > 0.0 && max > min)
        .then_some(LogScale { min, max })
    {
        Some(scale) => log_length_ticks(min, max)
            .into_iter()
            .map(|t| json!({"frac": scale.fraction(t.value), "value_m": t.value, "label": t.label}))
            .collect(),
        None => Vec::new(),
    };
    to_js(&Value::Array(ticks))
}

/// Linear axis ticks over `[lo, hi]` (about `max_count`): `[{value, label}]`.
#[wasm_bindgen]
pub fn axis_ticks(lo: f64, hi: f64, max_count: usize) -> Result<JsValue, JsError> {
    let t: Vec<Value> = linear_ticks(lo, hi, max_count)
        .into_iter()
        .map(|t| json!({"value": t.value, "label": t.label}))
        .collect();
    to_js(&Value::Array(t))
}

/// A length as text with a readable unit (`"4.26 mm"`, `"17.7 cm"`, `"∞"`).
#[wasm_bindgen]
pub fn format_length(m: f64, significant: usize) -> String {
    format_length_m(m, significant)
}

/// A scale bar no longer than `max_len_m`: `{length_m, label}`, or null.
#[wasm_bindgen]
pub fn scale_bar(max_len_m: f64) -> Result<JsValue, JsError> {
    to_js(&match core_scale_bar(max_len_m) {
        Some(t) => json!({"length_m": t.value, "label": t.label}),
        None => Value::Null,
    })
}
