//! The CRLB map figure: the RMSE bound `√(σx² + σy²)` (spec §7, S24) on the log colour scale of
//! [`crate::present::LogScale`] (the same colours as the page), unbounded cells in grey, a colour
//! bar labelled in metres, the nodes with their names, metre axes at equal scale and a title.

use alloc::string::{String, ToString};
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::axis_label;
use super::layout::{self, chart_err, register_fonts, ChartError};
use super::overlay::MapOverlay;
use super::raster::{self, Chart};

use crate::localize::Grid;
use crate::math::Real;
use crate::present::LogScale;
use crate::scenario::{Area, Scenario};

/// A computed map: the grid and its values, row-major with row `j` at `y_j` (ascending y), m;
/// `+∞` (or any non-finite value) marks an unbounded cell. This is what [`crate::localize::crlb_map`]
/// writes.
#[derive(Debug, Clone, Copy)]
pub struct MapData<'a> {
    /// The grid of cell centres.
    pub grid: Grid,
    /// `grid.len()` values, m.
    pub values_m: &'a [Real],
}

/// What a node is, which sets its marker.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeKind {
    /// Drawn as a red triangle.
    Transmitter,
    /// Drawn as a white circle.
    Receiver,
}

/// A named node to mark on the map.
#[derive(Debug, Clone, PartialEq)]
pub struct ChartNode {
    /// Label drawn next to the marker.
    pub name: String,
    /// Position, m.
    pub position_m: [Real; 2],
    /// Marker kind.
    pub kind: NodeKind,
}

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
}

impl Default for ChartOptions {
    fn default() -> Self {
        ChartOptions {
            title: "Position CRLB".to_string(),
            subtitle: None,
            scale: None,
            colorbar_label: "RMSE bound √(σx² + σy²)".to_string(),
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

/// Fails unless both ranges of `area` can be drawn: finite, increasing, a span that does not
/// overflow and is not too thin for axis ticks (relative to the coordinates' magnitude).
pub fn check_area(area: &Area) -> Result<(), ChartError> {
    area.validate().map_err(chart_err)?;
    for (axis, [lo, hi]) in [("x", area.x), ("y", area.y)] {
        let span = hi - lo;
        if !(span.is_finite() && span > 1e-9 * lo.abs().max(hi.abs())) {
            return Err(ChartError(alloc::format!(
                "the {axis} range [{lo:?}, {hi:?}] cannot be drawn (span overflows or is too thin)"
            )));
        }
    }
    Ok(())
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

/// [`draw_crlb_map`] with `overlay` drawn over the map, under the nodes (its labelled lines and
/// markers join the legend).
pub fn draw_crlb_map_with<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    map: &MapData,
    nodes: &[ChartNode],
    overlay: &MapOverlay,
    opts: &ChartOptions,
) -> Result<ChartSummary, ChartError> {
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
    let mut chart = map_panel(&chart_area, &lay, map, scale.as_ref())?;
    if !overlay.is_empty() {
        super::overlay::draw_overlay(&mut chart, overlay, lay.font.nodes)?;
    }
    finish_panel(&mut chart, nodes, &lay)?;

    let bar_area = root.clone().shrink(lay.bar_origin, lay.bar_size);
    raster::draw_colorbar(
        &bar_area,
        scale.as_ref(),
        unbounded_cells > 0,
        &opts.colorbar_label,
        &lay.font,
    )?;
    Ok(ChartSummary {
        scale,
        unbounded_cells,
    })
}

/// The plot of one map in `chart_area` (laid out by `lay`): the coloured cells on `scale` (grey
/// where unbounded or without a scale) and metre axes at equal scale. Overlays go on the returned
/// chart, then [`finish_panel`] draws the nodes and the frame.
pub(crate) fn map_panel<'a, DB: DrawingBackend + 'a>(
    chart_area: &'a DrawingArea<DB, Shift>,
    lay: &layout::Layout,
    map: &MapData,
    scale: Option<&LogScale>,
) -> Result<Chart<'a, DB>, ChartError> {
    let mut chart = metre_chart(chart_area, lay, &map.grid.area)?;
    raster::draw_heatmap(&chart.plotting_area().strip_coord_spec(), map, scale)?;
    draw_metre_axes(&mut chart, lay)?;
    Ok(chart)
}

/// A plot of `area` in `chart_area` laid out by `lay`: metres on both axes at equal scale (the
/// layout sized the plot to `area`'s aspect); nothing drawn yet.
pub(crate) fn metre_chart<'a, DB: DrawingBackend + 'a>(
    chart_area: &'a DrawingArea<DB, Shift>,
    lay: &layout::Layout,
    area: &Area,
) -> Result<Chart<'a, DB>, ChartError> {
    ChartBuilder::on(chart_area)
        .margin_top(lay.plot_margin_top)
        .margin_right(lay.plot_margin_right)
        .x_label_area_size(lay.x_label_area)
        .y_label_area_size(lay.y_label_area)
        .build_cartesian_2d(area.x[0]..area.x[1], area.y[0]..area.y[1])
        .map_err(chart_err)
}

/// The metre axes of a [`metre_chart`]: tick labels, `x (m)`, `y (m)`, no mesh.
pub(crate) fn draw_metre_axes<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    lay: &layout::Layout,
) -> Result<(), ChartError> {
    let tick_font = ("sans-serif", lay.font.ticks).into_font();
    let axis_font = ("sans-serif", lay.font.axis).into_font();
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .label_style(tick_font)
        .axis_desc_style(axis_font)
        .x_labels(8)
        .y_labels(8)
        .set_all_tick_mark_size(lay.font.ticks as i32 / 3 + 2)
        .x_label_formatter(&|v| axis_label(*v))
        .y_label_formatter(&|v| axis_label(*v))
        .draw()
        .map_err(chart_err)
}

/// The nodes (with the legend of every labelled series) and the frame of a [`map_panel`].
pub(crate) fn finish_panel<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    nodes: &[ChartNode],
    lay: &layout::Layout,
) -> Result<(), ChartError> {
    raster::draw_nodes(chart, nodes, lay.font.nodes)?;
    layout::frame_plot(chart)
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
