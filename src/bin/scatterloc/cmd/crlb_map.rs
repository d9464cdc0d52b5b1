//! `scatterloc crlb-map`: the RMSE bound over a grid, written as JSON, SVG or PNG.

use std::time::Instant;

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;
use serde_json::json;

use scatterloc::chart::{
    check_area, crlb_map_svg, default_titles, draw_crlb_map, scenario_nodes, suggested_size,
};
use scatterloc::chart::{ChartError, ChartNode, ChartOptions, MapData, MapOverlay};
use scatterloc::localize::{doppler_map, Grid, MapQuantity};
use scatterloc::native::{crlb_map_parallel, fast_path};
use scatterloc::present::DopplerMapText;
use scatterloc::scenario::Area;
use scatterloc::{Error, Scenario, Vec2};

use super::flags::at_flag;
use super::io::{emit_summary, model_of, read_scenario};
use super::output::{check_writable, write_figure, write_json_file, Figure, Format};
use crate::cli::CrlbMapArgs;
use crate::failure::CliError;

/// Default grid side.
const DEFAULT_N: usize = 256;

/// The scenario's area with the `--x-min` … `--y-max` overrides applied.
fn area_of(args: &CrlbMapArgs, s: &Scenario) -> Result<Area, CliError> {
    let mut a = s.area_m;
    a.x = [args.x_min.unwrap_or(a.x[0]), args.x_max.unwrap_or(a.x[1])];
    a.y = [args.y_min.unwrap_or(a.y[0]), args.y_max.unwrap_or(a.y[1])];
    for (axis, [lo, hi]) in [("x", a.x), ("y", a.y)] {
        if lo >= hi {
            return Err(CliError::usage(format!(
                "--{axis}-min/--{axis}-max: the minimum {lo} must be below the maximum {hi} \
                 (defaults from area_m.{axis})"
            )));
        }
        if !(hi - lo).is_finite() {
            return Err(CliError::usage(format!(
                "--{axis}-min/--{axis}-max: the extent {hi:?} - ({lo:?}) overflows"
            )));
        }
    }
    Ok(a)
}

fn grid_of(args: &CrlbMapArgs, area: Area) -> Result<Grid, CliError> {
    let nx = args.nx.unwrap_or(DEFAULT_N);
    let ny = args.ny.unwrap_or(DEFAULT_N);
    Grid::new(area, nx, ny).map_err(|e| match e {
        Error::SizeLimit { field, .. } if field == "nx" || field == "ny" => {
            CliError::usage(format!("--{e}"))
        }
        Error::SizeLimit {
            value, min, max, ..
        } => CliError::usage(format!(
            "--nx * --ny: {value} cells is outside the allowed range {min}..={max}"
        )),
        other => CliError::usage(format!("area: {other}")),
    })
}

/// `scatterloc crlb-map`.
pub fn crlb_map(args: &CrlbMapArgs) -> Result<(), CliError> {
    let out = args.out.as_str();
    let format = Format::of("out", out, &[Format::Json, Format::Svg, Format::Png])?;
    let s = read_scenario(&args.scenario)?;
    let area = area_of(args, &s)?;
    let grid = grid_of(args, area)?;
    if format != Format::Json {
        check_area(&area).map_err(|e| at_flag("x-min .. --y-max", e))?;
    }
    let size = figure_size(args, &area)?;
    let model = model_of(&s)?;
    // Before the work: a FIFO, link or device at --out is refused now (issue 24).
    check_writable("out", out)?;

    let velocity = args.quantity == "velocity";
    if velocity && !args.doppler.on {
        return Err(CliError::usage(
            "--quantity velocity: needs --doppler (delays alone bound no velocity)".to_string(),
        ));
    }
    let cpi = match args.doppler.on {
        true => Some(super::scenario::cpi_of(&args.doppler, &s)?),
        false => None,
    };

    let t0 = Instant::now();
    let mut values = vec![0.0; grid.len()];
    let quantity = if velocity {
        MapQuantity::Velocity
    } else {
        MapQuantity::Position
    };
    match &cpi {
        Some(cpi) => {
            let [vx, vy] = args.doppler.velocity;
            doppler_map(&model, &grid, cpi, Vec2::new(vx, vy), quantity, &mut values)
                .map_err(|e| CliError::usage(e.to_string()))?;
        }
        None => crlb_map_parallel(&model, &grid, &mut values, 0)
            .map_err(|e| CliError::output(e.to_string()))?,
    }
    let compute_ms = t0.elapsed().as_secs_f64() * 1e3;
    // A speed map's labels: m/s, its colour bar's lengths read as speeds.
    let unit = if velocity { "mps" } else { "m" };

    let t1 = Instant::now();
    match format {
        Format::Json => write_json(out, &grid, &values, velocity)?,
        Format::Svg | Format::Png => {
            let (title, subtitle) = default_titles(&s, &grid);
            // With Doppler, the texts the page's Save figure writes too (one home).
            let (title, subtitle, label, suffix) = match &cpi {
                None => (
                    title,
                    subtitle,
                    ChartOptions::default().colorbar_label,
                    String::new(),
                ),
                Some(c) => {
                    let t = DopplerMapText::new(quantity, c, args.doppler.velocity, &subtitle);
                    (t.title, t.subtitle, t.colorbar_label, t.value_suffix)
                }
            };
            let opts = ChartOptions {
                title: args.title.clone().unwrap_or(title),
                subtitle: Some(subtitle),
                colorbar_label: label,
                value_suffix: suffix,
                ..ChartOptions::default()
            };
            let figure = MapFigure {
                map: MapData {
                    grid,
                    values_m: &values,
                },
                nodes: scenario_nodes(&s),
                opts,
            };
            write_figure("out", out, format, size, &figure)?;
        }
    }
    let write_ms = t1.elapsed().as_secs_f64() * 1e3;

    let finite = values.iter().copied().filter(|v| v.is_finite());
    let min = finite.clone().fold(f64::INFINITY, f64::min);
    let max = finite.fold(f64::NEG_INFINITY, f64::max);
    let summary = json!({
        "out": out,
        "format": format.name(),
        "nx": grid.nx,
        "ny": grid.ny,
        "x_range_m": area.x,
        "y_range_m": area.y,
        "compute_ms": round3(compute_ms),
        "kernel": if cpi.is_some() { "doppler" } else { fast_path().name() },
        "write_ms": round3(write_ms),
        format!("min_{unit}"): min,
        format!("max_{unit}"): max,
        "unbounded_cells": values.iter().filter(|v| !v.is_finite()).count(),
    });
    emit_summary(&summary.to_string())
}

fn round3(v: f64) -> f64 {
    (v * 1e3).round() / 1e3
}

fn figure_size(args: &CrlbMapArgs, area: &Area) -> Result<(u32, u32), CliError> {
    let dim =
        |name: &str, v: Option<usize>, lo: usize, hi: usize| -> Result<Option<u32>, CliError> {
            match v {
                Some(v) if (lo..=hi).contains(&v) => Ok(Some(v as u32)),
                Some(v) => Err(CliError::usage(format!(
                    "--{name}: {v} is outside the allowed range {lo}..={hi} pixels"
                ))),
                None => Ok(None),
            }
        };
    let w = dim("width", args.width, 200, 8000)?;
    let h = dim("height", args.height, 150, 8000)?;
    let (sw, sh) = suggested_size(area, w.unwrap_or(1000));
    Ok((sw, h.unwrap_or(sh)))
}

#[derive(Serialize)]
struct MapJson<'a> {
    x_m: Vec<f64>,
    y_m: Vec<f64>,
    /// Rows of `nx` values; serde_json writes the `+∞` of unbounded cells as `null`.
    #[serde(skip_serializing_if = "Option::is_none")]
    rmse_bound_m: Option<Vec<&'a [f64]>>,
    /// The same for `--quantity velocity`, m/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    velocity_rmse_bound_mps: Option<Vec<&'a [f64]>>,
}

fn write_json(path: &str, grid: &Grid, values: &[f64], velocity: bool) -> Result<(), CliError> {
    let rows = Some(values.chunks(grid.nx).collect());
    let (rmse_bound_m, velocity_rmse_bound_mps) =
        if velocity { (None, rows) } else { (rows, None) };
    let doc = MapJson {
        x_m: (0..grid.nx).map(|i| grid.x(i)).collect(),
        y_m: (0..grid.ny).map(|j| grid.y(j)).collect(),
        rmse_bound_m,
        velocity_rmse_bound_mps,
    };
    write_json_file("out", path, &doc)
}

/// The map figure of [`draw_crlb_map`] as a [`Figure`].
struct MapFigure<'a> {
    map: MapData<'a>,
    nodes: Vec<ChartNode>,
    opts: ChartOptions,
}

impl Figure for MapFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError> {
        draw_crlb_map(root, &self.map, &self.nodes, &self.opts).map(|_| ())
    }

    fn svg(&self, size: (u32, u32)) -> Option<Result<String, ChartError>> {
        let none = MapOverlay::default();
        Some(crlb_map_svg(size, &self.map, &self.nodes, &none, &self.opts).map(|(svg, _)| svg))
    }
}
