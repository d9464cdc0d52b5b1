//! The page's "Save figure" as SVG: the figures drawn by the same plotters chart code as the CLI
//! ([`crate::chart`]) through plotters' SVG backend into a `String`. `App.map_svg` draws the CRLB
//! map figure of the app's scenario (with a placed target's snapshot; with its `doppler` option
//! the position or velocity map with Doppler as `crlb-map --doppler --quantity … --out f.svg`
//! draws it, titles from [`DopplerMapText`]), `Track.map_svg` the map
//! with a simulated track, [`tracking_chart_svg`] the Monte Carlo RMSE chart of the tracking
//! view (the canvas chart's [`draw_tracking_chart`](super::draw_tracking_chart) code) and
//! [`mtl_scene_svg`] the multi-target scene ([`crate::chart::draw_mtl_scene`]). Every
//! error is an exception whose message starts with the function's name; nothing here runs until
//! the page's Save figure button is pressed.

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Deserialize;
use wasm_bindgen::prelude::*;

use super::doppler::{velocity, CpiSettings};
use super::tracking::Track;
use super::{settings, window, App};
use crate::chart::{
    crlb_map_svg, default_titles, draw_mtl_scene, scenario_nodes, scene_window, suggested_size,
    ChartOptions, MapData, MapOverlay, SceneChartOptions,
};
use crate::error::{limits, Error};
use crate::localize::{crlb_map, doppler_map, Grid, MapQuantity};
use crate::measure::Cpi;
use crate::present::{mtl_view, DopplerMapText, MtlScene};
use crate::present::{simulate_snapshot, LogScale};
use crate::scenario::Area;
use crate::{Model, Scenario, Vec2};

/// Largest width or height of an exported figure, px.
pub const MAX_FIGURE_PX: u32 = 8000;

/// Largest map grid (cells per side) of an exported map figure.
pub const MAX_FIGURE_RES: usize = 1024;

/// Default map grid of an exported map figure (cells per side).
const DEFAULT_RES: usize = 256;

/// A placed target: position (m) and noise seed, as `App.simulate_fix` takes them.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TargetOpt {
    x: f64,
    y: f64,
    seed: u32,
}

/// The options of a map figure (all optional; `""` is all defaults).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct MapOptions {
    /// `[x_min, x_max, y_min, y_max]`, m: the window shown (default: the scenario's area).
    #[serde(default)]
    window: Option<[f64; 4]>,
    /// Map grid, cells per side (default 256).
    #[serde(default)]
    res: Option<usize>,
    /// Title (default: `Position CRLB — <scenario>`).
    #[serde(default)]
    title: Option<String>,
    /// The snapshot target (App.map_svg only).
    #[serde(default)]
    target: Option<TargetOpt>,
    /// `[min, max]`, m: a locked colour range (values outside it in the end colours, marked
    /// `≤`/`≥` on the colour bar); default the range of the map's finite values.
    #[serde(default)]
    scale: Option<[f64; 2]>,
    /// The map with Doppler instead of the delay-only one (App.map_svg only).
    #[serde(default)]
    doppler: Option<DopplerOpt>,
}

/// A map with Doppler: `{cpi: {snapshots, spacing_ms, floor_mps}, velocity_mps: [vx, vy],
/// quantity: "position" | "velocity"}` (every field required), as `App.compute_doppler_maps_in`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DopplerOpt {
    cpi: CpiSettings,
    velocity_mps: [f64; 2],
    quantity: QuantityOpt,
}

/// `"position"` or `"velocity"` (`crlb-map --quantity`).
#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum QuantityOpt {
    Position,
    Velocity,
}

/// What a map figure maps: the delay-only bound, or `quantity` with Doppler over `cpi` for a
/// target moving at `velocity` (m/s).
enum Kernel {
    Delay,
    Doppler {
        cpi: Cpi,
        velocity: Vec2,
        quantity: MapQuantity,
    },
}

impl Kernel {
    /// The kernel of `opts` on the carrier `carrier_hz` (a bad CPI or velocity: the named error).
    fn of(opts: &MapOptions, carrier_hz: f64) -> crate::Result<Kernel> {
        let Some(d) = &opts.doppler else {
            return Ok(Kernel::Delay);
        };
        Ok(Kernel::Doppler {
            cpi: d.cpi.cpi(carrier_hz)?,
            velocity: velocity("doppler.velocity_mps", d.velocity_mps)?,
            quantity: match d.quantity {
                QuantityOpt::Position => MapQuantity::Position,
                QuantityOpt::Velocity => MapQuantity::Velocity,
            },
        })
    }
}

/// The locked colour range `[min, max]` (m) as a scale: finite, `0 < min < max`, else the named
/// error of `scale.min` or `scale.max`.
pub(super) fn locked_scale([min, max]: [f64; 2]) -> crate::Result<LogScale> {
    for (field, v) in [("scale.min", min), ("scale.max", max)] {
        if !v.is_finite() {
            return Err(Error::NonFinite {
                field: field.into(),
            });
        }
    }
    if min <= 0.0 {
        return Err(Error::NotPositive {
            field: "scale.min".into(),
            value: min,
        });
    }
    LogScale::new(min, max).ok_or_else(|| Error::OutOfRange {
        field: "scale.max".into(),
        value: max,
        allowed: "above scale.min",
    })
}

fn fail(func: &str, e: impl core::fmt::Display) -> JsError {
    JsError::new(&format!("{func}: {e}"))
}

/// A figure's options from JSON (`""`: all defaults); malformed JSON or an unknown field is the
/// named parse error.
fn parse_options<T: serde::de::DeserializeOwned + Default>(
    func: &str,
    json: &str,
) -> Result<T, JsError> {
    if json.trim().is_empty() {
        return Ok(T::default());
    }
    serde_json::from_str(json).map_err(|e| {
        fail(
            func,
            Error::Parse {
                message: e.to_string(),
            },
        )
    })
}

/// `v` within `min..=MAX_FIGURE_PX`, else the named size error of `field`: every exported
/// figure's pixel check.
pub(super) fn figure_px(field: &'static str, v: u32, min: u32) -> crate::Result<u32> {
    if (min..=MAX_FIGURE_PX).contains(&v) {
        Ok(v)
    } else {
        Err(Error::SizeLimit {
            field,
            value: v as usize,
            min: min as usize,
            max: MAX_FIGURE_PX as usize,
        })
    }
}

/// `(width, height)` checked: width in `200..=MAX_FIGURE_PX`, height 0 (fit the plot: the
/// chart's `suggested_size`) or in `150..=MAX_FIGURE_PX`.
fn figure_size(area: Option<&Area>, width: u32, height: u32) -> crate::Result<(u32, u32)> {
    let check = figure_px;
    let w = check("width", width, 200)?;
    match (height, area) {
        (0, Some(a)) => Ok(suggested_size(a, w)),
        (0, None) => Ok((w, (w * 3 / 5).max(150))),
        (h, _) => Ok((w, check("height", h, 150)?)),
    }
}

/// The map figure of `model` (the scenario `s`) over the options' window at their grid, with
/// `overlay`, as SVG text.
fn map_figure(
    func: &str,
    s: &Scenario,
    model: &Model,
    opts: &MapOptions,
    overlay: &MapOverlay,
    (width, height): (u32, u32),
) -> Result<String, JsError> {
    let area = match opts.window {
        Some(w) => window(w).map_err(|e| fail(func, e))?,
        None => s.area_m,
    };
    let res = opts.res.unwrap_or(DEFAULT_RES);
    if !(8..=MAX_FIGURE_RES).contains(&res) {
        return Err(fail(
            func,
            Error::SizeLimit {
                field: "res",
                value: res,
                min: 8,
                max: MAX_FIGURE_RES,
            },
        ));
    }
    let size = figure_size(Some(&area), width, height).map_err(|e| fail(func, e))?;
    let grid = Grid::new(area, res, res).map_err(|e| fail(func, e))?;
    let kernel = Kernel::of(opts, s.radio.carrier_hz).map_err(|e| fail(func, e))?;
    let mut values = vec![0.0; grid.len()];
    let (title, subtitle) = default_titles(s, &grid);
    let scale = match opts.scale {
        Some(v) => Some(locked_scale(v).map_err(|e| fail(func, e))?),
        None => None,
    };
    let chart_opts = match &kernel {
        Kernel::Delay => {
            crlb_map(model, &grid, &mut values).map_err(|e| fail(func, e))?;
            ChartOptions {
                title: opts.title.clone().unwrap_or(title),
                subtitle: Some(subtitle),
                scale,
                ..ChartOptions::default()
            }
        }
        Kernel::Doppler {
            cpi,
            velocity: v,
            quantity,
        } => {
            doppler_map(model, &grid, cpi, *v, *quantity, &mut values)
                .map_err(|e| fail(func, e))?;
            let t = DopplerMapText::new(*quantity, cpi, [v.x, v.y], &subtitle);
            ChartOptions {
                title: opts.title.clone().unwrap_or(t.title),
                subtitle: Some(t.subtitle),
                scale,
                colorbar_label: t.colorbar_label,
                value_suffix: t.value_suffix,
            }
        }
    };
    let map = MapData {
        grid,
        values_m: &values,
    };
    let nodes = scenario_nodes(s);
    crlb_map_svg(size, &map, &nodes, overlay, &chart_opts)
        .map(|(svg, _)| svg)
        .map_err(|e| fail(func, e))
}

/// The SVG text of `size` px that `draw` writes through plotters' SVG backend; its error (or the
/// backend's) is the exception `func: …`.
fn render_svg<E: core::fmt::Display>(
    func: &str,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), E>,
) -> Result<String, JsError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(&root).map_err(|e| fail(func, e))?;
        root.present().map_err(|e| fail(func, e))?;
    }
    Ok(svg)
}

#[wasm_bindgen]
impl App {
    /// The CRLB map figure of the current scenario as SVG text, drawn by the CLI's chart code
    /// (`crlb-map --out map.svg`): the map, the nodes, the colour bar and, with a `target`, its
    /// simulated snapshot (iso-delay ellipses, LM fix, CRLB ellipse; as `simulate_fix`).
    /// `width` 200 … 8000 px, `height` 0 (fit the plot) or 150 … 8000 px. `options_json`: `""`
    /// or `{window?: [x_min, x_max, y_min, y_max] (m; default the area), res?: cells per side
    /// (8 … 1024, default 256), title?: text, target?: {x, y, seed}, scale?: [min, max] (m, a
    /// locked colour range; m/s on a velocity map), doppler?: {cpi: {snapshots, spacing_ms,
    /// floor_mps}, velocity_mps: [vx, vy], quantity: "position" | "velocity"}}`. With `doppler`
    /// the map is that bound with Doppler (issue 42 §1), titled, labelled and drawn as `crlb-map
    /// --doppler --quantity … --out f.svg` draws it (`--cpi-spacing-s` = `spacing_ms / 1000`),
    /// its subtitle also naming the σṙ floor ([`DopplerMapText`]). The map is one embedded PNG
    /// image. Throws `map_svg: …`.
    pub fn map_svg(&self, width: u32, height: u32, options_json: &str) -> Result<String, JsError> {
        const F: &str = "map_svg";
        let opts: MapOptions = parse_options(F, options_json)?;
        let (s, model) = (self.session().scenario(), self.session().model());
        let overlay = match &opts.target {
            Some(t) => {
                limits::COORDINATE_M
                    .check("target.x", t.x)
                    .and_then(|_| limits::COORDINATE_M.check("target.y", t.y))
                    .map_err(|e| fail(F, e))?;
                let sim = simulate_snapshot(model, &s.area_m, Vec2::new(t.x, t.y), t.seed.into());
                MapOverlay::snapshot(&sim)
            }
            None => MapOverlay::default(),
        };
        map_figure(F, s, model, &opts, &overlay, (width, height))
    }
}

#[wasm_bindgen]
impl Track {
    /// The CRLB map figure of the track's scenario with the track up to step `step` as SVG text
    /// (the map, nodes, colour bar, the truth path, the filter's track and its 1σ ellipses
    /// magnified `magnify` times, the target and the estimate at `step`), drawn by the CLI's
    /// chart code. Sizes and `options_json` as `App.map_svg` (`target` is not allowed). Throws
    /// `Track.map_svg: …`.
    pub fn map_svg(
        &self,
        width: u32,
        height: u32,
        step: usize,
        magnify: f64,
        options_json: &str,
    ) -> Result<String, JsError> {
        const F: &str = "Track.map_svg";
        let opts: MapOptions = parse_options(F, options_json)?;
        if opts.target.is_some() {
            return Err(fail(
                F,
                "target: a track's figure shows the track, not a target",
            ));
        }
        if opts.doppler.is_some() {
            return Err(fail(
                F,
                "doppler: a track's figure shows the delay-only map",
            ));
        }
        if !(magnify.is_finite() && magnify > 0.0) {
            return Err(fail(
                F,
                Error::NotPositive {
                    field: "magnify".into(),
                    value: magnify,
                },
            ));
        }
        let (s, model, run, filter) = self.parts();
        let name = filter.name().to_uppercase();
        let overlay = MapOverlay::track(run, step, magnify, &name);
        map_figure(F, s, model, &opts, &overlay, (width, height))
    }
}

/// The tracking view's Monte Carlo chart ([`draw_tracking_chart`](super::draw_tracking_chart),
/// the same arguments) as SVG text of `width × height` px (200 … 8000 × 150 … 8000; height 0:
/// 3/5 of the width). Throws `tracking_chart_svg: …` on malformed JSON or a bad size.
#[wasm_bindgen]
pub fn tracking_chart_svg(
    result_json: &str,
    title: &str,
    subtitle: &str,
    caption: &str,
    width: u32,
    height: u32,
) -> Result<String, JsError> {
    const F: &str = "tracking_chart_svg";
    let size = figure_size(None, width, height).map_err(|e| fail(F, e))?;
    render_svg(F, size, |root| {
        super::chart::draw_result(root, result_json, title, subtitle, caption).map(|_| ())
    })
}

/// The options of a scene figure (all optional; `""` is all defaults).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct SceneOptions {
    /// `[x_min, x_max, y_min, y_max]`, m (default: the region with a 4 % margin).
    #[serde(default)]
    window: Option<[f64; 4]>,
    /// Title (default: the scene's counts).
    #[serde(default)]
    title: Option<String>,
}

/// The multi-target scene figure of `scene_json` (the page's scene, schema
/// [`MtlScene`]) as SVG text: its view computed by the core ([`mtl_view`], as `mtl_view_of`) and
/// drawn by [`draw_mtl_scene`] — the region, discs, blocked segments, range ellipses, seeds,
/// hypotheses, detections, targets and nodes. `width` 200 … 8000 px, `height` 0 (fit the plot)
/// or 150 … 8000 px. `options_json`: `""` or `{window?: [x_min, x_max, y_min, y_max] (m),
/// title?: text}`. Throws `mtl_scene_svg: …` with the core's named error.
#[wasm_bindgen]
pub fn mtl_scene_svg(
    scene_json: &str,
    width: u32,
    height: u32,
    options_json: &str,
) -> Result<String, JsError> {
    const F: &str = "mtl_scene_svg";
    let opts: SceneOptions = parse_options(F, options_json)?;
    let scene = MtlScene::from_json(scene_json).map_err(|e| fail(F, e))?;
    let area = match opts.window {
        Some(w) => window(w).map_err(|e| fail(F, e))?,
        None => scene_window(&scene),
    };
    let size = figure_size(Some(&area), width, height).map_err(|e| fail(F, e))?;
    let view = mtl_view(&scene).map_err(|e| fail(F, e))?;
    let chart_opts = SceneChartOptions {
        title: opts.title,
        subtitle: None,
        window: Some(area),
    };
    render_svg(F, size, |root| {
        draw_mtl_scene(root, &scene, &view, &chart_opts)
    })
}

/// A data file's format: `"csv"` or `"json"`, else the named error of `func`.
fn data_format(func: &str, format: &str) -> Result<bool, JsError> {
    match format {
        "csv" => Ok(true),
        "json" => Ok(false),
        other => Err(fail(
            func,
            Error::Parse {
                message: format!("format: \"{other}\" is not csv or json"),
            },
        )),
    }
}

/// A number of a CSV file: Rust's shortest text that reads back as the same `f64`; empty for a
/// non-finite value (an unbounded cell).
fn csv_num(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        String::new()
    }
}

/// The grid of an exported map.
#[derive(serde::Serialize)]
struct MapGridJs {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    nx: usize,
    ny: usize,
}

/// The JSON of an exported map ([`map_data_text`]).
#[derive(serde::Serialize)]
struct MapDataJs<'a> {
    scenario: &'a str,
    quantity: String,
    units: &'static str,
    grid: MapGridJs,
    x_m: Vec<f64>,
    y_m: Vec<f64>,
    order: &'static str,
    rmse_m: Vec<Option<f64>>,
    unbounded: &'static str,
}

/// The settings of [`map_data_text`] (JSON: `{window, nx, ny, scenario, format}`, every field
/// required, unknown ones refused).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MapDataSettings {
    /// `[x_min, x_max, y_min, y_max]`, m: the map's window.
    window: [f64; 4],
    /// Cells along x.
    nx: usize,
    /// Cells along y.
    ny: usize,
    /// The scenario's name (the JSON's `scenario`).
    scenario: String,
    /// `csv` or `json`.
    format: String,
    /// The map is a bound with Doppler (issue 42 §1): `{cpi, velocity_mps, quantity}` as
    /// `map_svg`'s; absent: the delay-only snapshot bound.
    #[serde(default)]
    doppler: Option<DopplerOpt>,
}

/// The CRLB map `values` (m, row-major, row `j` at the `j`-th lowest y, as `App.compute_map_in`
/// writes them) as a data file, with `settings_json`, one object (JSON text): `{window: [x0,
/// x1, y0, y1] (m, the map's window), nx, ny (its grid), scenario (its name), format}`:
/// `format` `"csv"`: a header `x_m,y_m,rmse_m` and one line per cell (cell centres, rows from
/// the lowest y; an unbounded cell's `rmse_m` empty); `"json"`: `{scenario, quantity, units,
/// grid: {x0, x1, y0, y1, nx, ny}, x_m: [centres], y_m: [centres], order: "row-major, y
/// ascending", rmse_m: [nx·ny values, null where unbounded], unbounded}`. Every number is the
/// core's, written so that it reads back as the same `f64`. Throws `map_data_text: …` (an
/// unknown, missing or mistyped setting: `map_data_text: invalid JSON: …` naming it). With
/// `doppler: {cpi: {snapshots, spacing_ms, floor_mps}, velocity_mps, quantity}` the values are
/// that bound with Doppler (`App.compute_doppler_maps_in`'s): the JSON's `quantity` says so
/// (the CPI, velocity and floor as the figure's subtitle writes them, [`DopplerMapText`]); a
/// velocity map's column is `rmse_mps` (CSV) and its units `m/s`.
#[wasm_bindgen]
pub fn map_data_text(values: &[f64], settings_json: &str) -> Result<String, JsError> {
    const F: &str = "map_data_text";
    let MapDataSettings {
        window: [x0, x1, y0, y1],
        nx,
        ny,
        scenario,
        format,
        doppler,
    } = settings(F, settings_json)?;
    let csv = data_format(F, &format)?;
    // What the values are: the delay-only bound, or a bound with Doppler (its CPI checked).
    let (quantity, units, column) = match &doppler {
        None => (
            String::from("CRLB RMSE bound sqrt(σx² + σy²) of a snapshot fix"),
            "m",
            "rmse_m",
        ),
        Some(d) => {
            // The label reads N, T and the floor, not the wavelength: any positive carrier
            // validates them.
            let cpi = d.cpi.cpi(1.0).map_err(|e| fail(F, e))?;
            let v = velocity("doppler.velocity_mps", d.velocity_mps).map_err(|e| fail(F, e))?;
            let (what, units, column) = match d.quantity {
                QuantityOpt::Position => ("position RMSE bound sqrt(σx² + σy²)", "m", "rmse_m"),
                QuantityOpt::Velocity => {
                    ("velocity RMSE bound sqrt(σvx² + σvy²)", "m/s", "rmse_mps")
                }
            };
            let t = DopplerMapText::new(MapQuantity::Position, &cpi, [v.x, v.y], "");
            (
                format!(
                    "CRLB {what} with delays and range rates (Doppler){}",
                    t.subtitle
                ),
                units,
                column,
            )
        }
    };
    let area = window([x0, x1, y0, y1]).map_err(|e| fail(F, e))?;
    let grid = Grid::new(area, nx, ny).map_err(|e| fail(F, e))?;
    if values.len() != grid.len() {
        return Err(fail(
            F,
            Error::LengthMismatch {
                field: "map values (nx × ny)",
                expected: grid.len(),
                found: values.len(),
            },
        ));
    }
    if csv {
        let mut out = format!("x_m,y_m,{column}\n");
        for j in 0..ny {
            for i in 0..nx {
                let v = values[j * nx + i];
                out.push_str(&format!("{},{},{}\n", grid.x(i), grid.y(j), csv_num(v)));
            }
        }
        return Ok(out);
    }
    let doc = MapDataJs {
        scenario: &scenario,
        quantity,
        units,
        grid: MapGridJs {
            x0,
            x1,
            y0,
            y1,
            nx,
            ny,
        },
        x_m: (0..nx).map(|i| grid.x(i)).collect(),
        y_m: (0..ny).map(|j| grid.y(j)).collect(),
        order: "row-major, y ascending: rmse_m[j * nx + i] is at (x_m[i], y_m[j])",
        rmse_m: values.iter().map(|v| v.is_finite().then_some(*v)).collect(),
        unbounded:
            "null: the Fisher matrix is singular there (no unbiased estimator has a finite RMSE)",
    };
    serde_json::to_string(&doc).map_err(|e| fail(F, e))
}

/// The JSON of an exported track ([`Track::data_text`]).
#[derive(serde::Serialize)]
struct TrackDataJs<'a> {
    scenario: &'a str,
    filter: &'a str,
    units: &'static str,
    failed_at: Option<usize>,
    t_s: &'a [f64],
    truth: Vec<[f64; 4]>,
    estimate: Vec<[f64; 4]>,
    covariance: Vec<[f64; 16]>,
}

/// The state names of the CSV columns.
const STATE: [&str; 4] = ["x_m", "y_m", "vx_mps", "vy_mps"];

#[wasm_bindgen]
impl Track {
    /// The simulated track as a data file, one row per entry: time, the true state, the filter's
    /// estimate and its covariance `P` (4 × 4 over x, y, vx, vy; m, m/s). `format` `"csv"`:
    /// columns `t_s, truth_x_m, truth_y_m, truth_vx_mps, truth_vy_mps, est_x_m, …, est_vy_mps,
    /// P_0_0, P_0_1, …, P_3_3` (row-major); `"json"`: `{scenario, filter, units, failed_at, t_s,
    /// truth: [[x, y, vx, vy]], estimate: [[…]], covariance: [[16 values, row-major]]}`. The
    /// core's numbers, written to read back as the same `f64`. Throws `Track.data_text: …`.
    pub fn data_text(&self, format: &str) -> Result<String, JsError> {
        const F: &str = "Track.data_text";
        let csv = data_format(F, format)?;
        let (s, _, run, filter) = self.parts();
        let n = run.estimates.len().min(run.truth.len()).min(run.t_s.len());
        let v4 = |v: &crate::math::Vec4| [v[0], v[1], v[2], v[3]];
        let p16 = |p: &crate::math::Mat4| {
            let mut out = [0.0; 16];
            for r in 0..4 {
                for c in 0..4 {
                    out[4 * r + c] = p[(r, c)];
                }
            }
            out
        };
        if csv {
            let mut head: Vec<String> = vec!["t_s".into()];
            head.extend(STATE.iter().map(|k| format!("truth_{k}")));
            head.extend(STATE.iter().map(|k| format!("est_{k}")));
            head.extend((0..16).map(|k| format!("P_{}_{}", k / 4, k % 4)));
            let mut out = head.join(",");
            out.push('\n');
            for k in 0..n {
                let mut row = vec![csv_num(run.t_s[k])];
                row.extend(v4(&run.truth[k]).map(csv_num));
                row.extend(v4(&run.estimates[k]).map(csv_num));
                row.extend(p16(&run.covariances[k]).map(csv_num));
                out.push_str(&row.join(","));
                out.push('\n');
            }
            return Ok(out);
        }
        let doc = TrackDataJs {
            scenario: &s.name,
            filter: filter.name(),
            units: "m, m/s, s; covariance row-major over (x, y, vx, vy)",
            failed_at: run.failed_at,
            t_s: &run.t_s[..n],
            truth: run.truth[..n].iter().map(v4).collect(),
            estimate: run.estimates[..n].iter().map(v4).collect(),
            covariance: run.covariances[..n].iter().map(p16).collect(),
        };
        serde_json::to_string(&doc).map_err(|e| fail(F, e))
    }
}
