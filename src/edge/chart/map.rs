//! The CRLB map figure: the RMSE bound `√(σx² + σy²)` (spec §7, S24) on the log colour scale of
//! [`crate::present::LogScale`] (the same colours as the page), unbounded cells in grey, a colour
//! bar labelled in metres, the nodes with their names, metre axes at equal scale and a title.

use alloc::string::{String, ToString};
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::layout::{self, chart_err, register_fonts, ChartError};
use super::overlay::MapOverlay;
use super::panel::{self, check_area, finish_panel, map_panel, ChartNode, MapData, NodeKind};

use crate::localize::Grid;
use crate::math::Real;
use crate::present::LogScale;
use crate::scenario::Scenario;

/// The transmitters and receivers of a scenario, in scenario order.
pub fn scenario_nodes(s: &Scenario) -> Vec<ChartNode> {
    let tx = s.transmitters.iter().map(|t| ChartNode {
        name: t.name.clone(),
        position_m: t.position_m,
        kind: NodeKind::Transmitter,
    });
    let rx = s.receivers.iter().map(|r| ChartNode {
        name: r.name.clone(),
        position_m: r.position_m,
        kind: NodeKind::Receiver,
    });
    tx.chain(rx).collect()
}

/// Text and scale of a figure.
#[derive(Debug, Clone, PartialEq)]
pub struct ChartOptions {
    /// Title line.
    pub title: String,
    /// Optional smaller second line under the title.
    pub subtitle: Option<String>,
    /// Colour scale; `None` spans the finite values of the map (as the page does).
    pub scale: Option<LogScale>,
    /// Label of the colour bar.
    pub colorbar_label: String,
    /// Follows every colour-bar length label: `""` for metres, `"/s"` for a speed map.
    pub value_suffix: String,
}

impl Default for ChartOptions {
    fn default() -> Self {
        ChartOptions {
            title: "Position CRLB".to_string(),
            subtitle: None,
            scale: None,
            colorbar_label: "RMSE bound √(σx² + σy²)".to_string(),
            value_suffix: String::new(),
        }
    }
}

/// What was drawn: the scale actually used and how many cells were unbounded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartSummary {
    /// The colour scale (`None` if no cell is bounded).
    pub scale: Option<LogScale>,
    /// Cells drawn grey.
    pub unbounded_cells: usize,
}

/// Draws the CRLB map figure onto `root` (which is filled white first) and returns the scale used.
/// Does not call `present()`.
pub fn draw_crlb_map<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    map: &MapData,
    nodes: &[ChartNode],
    opts: &ChartOptions,
) -> Result<ChartSummary, ChartError> {
    draw_crlb_map_with(root, map, nodes, &MapOverlay::default(), opts)
}

/// The CRLB map figure ([`draw_crlb_map_with`]) of `size` px as SVG text with the map embedded
/// as ONE image ([`super::raster`]: a PNG at the grid's resolution, a `data:` URI) under the
/// vector layers (axes, overlay, nodes, colour bar, text), instead of one rectangle per run of
/// equal colour. Also returns the scale used.
pub fn crlb_map_svg(
    size: (u32, u32),
    map: &MapData,
    nodes: &[ChartNode],
    overlay: &MapOverlay,
    opts: &ChartOptions,
) -> Result<(String, ChartSummary), ChartError> {
    let mut svg = String::new();
    let (summary, plot) = {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let drawn = draw_map_figure(&root, map, nodes, overlay, opts, false)?;
        root.present().map_err(chart_err)?;
        drawn
    };
    let rgb = super::raster::map_rgb(map, summary.scale.as_ref());
    let png = super::raster::encode_png(map.grid.nx, map.grid.ny, &rgb)
        .ok_or_else(|| ChartError("the map image could not be encoded".to_string()))?;
    let svg = super::raster::embed_png(&svg, plot, &png)
        .ok_or_else(|| ChartError("the figure has no element to put the map under".to_string()))?;
    Ok((svg, summary))
}

/// [`draw_crlb_map`] with `overlay` drawn over the map, under the nodes (its labelled lines and
/// markers join the legend).
pub fn draw_crlb_map_with<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    map: &MapData,
    nodes: &[ChartNode],
    overlay: &MapOverlay,
    opts: &ChartOptions,
) -> Result<ChartSummary, ChartError> {
    draw_map_figure(root, map, nodes, overlay, opts, true).map(|(summary, _)| summary)
}

/// [`draw_crlb_map_with`], the cells drawn only when `cells` (else the caller puts the map's
/// image under the plot); also returns the plot's pixel rectangle.
fn draw_map_figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    map: &MapData,
    nodes: &[ChartNode],
    overlay: &MapOverlay,
    opts: &ChartOptions,
    cells: bool,
) -> Result<(ChartSummary, super::raster::PlotPixels), ChartError> {
    register_fonts();
    if map.values_m.len() != map.grid.len() {
        return Err(ChartError(alloc::format!(
            "map has {} values for a {}x{} grid",
            map.values_m.len(),
            map.grid.nx,
            map.grid.ny
        )));
    }
    check_area(&map.grid.area)?;
    let scale = opts
        .scale
        .filter(|s| s.min.is_finite() && s.max > s.min && s.min > 0.0)
        .or_else(|| LogScale::spanning(map.values_m));
    let unbounded_cells = map
        .values_m
        .iter()
        .filter(|v| !(v.is_finite() && **v > 0.0))
        .count();

    root.fill(&WHITE).map_err(chart_err)?;
    let lay = layout::Layout::new(root, &map.grid.area, opts.subtitle.is_some());
    layout::draw_titles(
        root,
        &lay.font,
        &lay.band,
        &opts.title,
        opts.subtitle.as_deref(),
    )?;

    let chart_area = root.clone().shrink(lay.chart_origin, lay.chart_size);
    let mut chart = if cells {
        map_panel(&chart_area, &lay, map, scale.as_ref())?
    } else {
        let mut chart = panel::metre_chart(&chart_area, &lay, &map.grid.area)?;
        panel::draw_metre_axes(&mut chart, &lay)?;
        chart
    };
    let (px, py) = chart.plotting_area().get_pixel_range();
    let plot = (px.start, py.start, px.end - px.start, py.end - py.start);
    let clamped = scale.map_or([false; 2], |s| s.clamped(map.values_m));
    if !overlay.is_empty() {
        super::overlay::draw_overlay(&mut chart, overlay, lay.font.nodes)?;
    }
    finish_panel(&mut chart, nodes, &lay)?;

    let bar_area = root.clone().shrink(lay.bar_origin, lay.bar_size);
    panel::draw_colorbar_marked(
        &bar_area,
        scale.as_ref(),
        unbounded_cells > 0,
        &opts.colorbar_label,
        &lay.font,
        clamped,
        &opts.value_suffix,
    )?;
    Ok((
        ChartSummary {
            scale,
            unbounded_cells,
        },
        plot,
    ))
}

/// The default title and subtitle of a scenario's map figure.
pub fn default_titles(s: &Scenario, grid: &Grid) -> (String, String) {
    (
        alloc::format!("Position CRLB — {}", s.name),
        alloc::format!(
            "{} Tx, {} Rx, {} links · B = {} MHz · {}×{} grid",
            s.transmitters.len(),
            s.receivers.len(),
            s.link_indices().map(|l| l.len()).unwrap_or(0),
            trim_num(s.radio.bandwidth_hz / 1e6),
            grid.nx,
            grid.ny
        ),
    )
}

fn trim_num(v: Real) -> String {
    let s = alloc::format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
