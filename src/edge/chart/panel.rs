//! The panel toolkit of the metre-axis figures (the map, the plan and the multi-target scene):
//! what a map panel shows ([`MapData`], [`ChartNode`]), the plot with metre axes at equal scale,
//! the heatmap raster, the colour bar, the node markers, the legend entries and the frame. It
//! imports only `layout` of the chart module; every figure imports it.

use alloc::string::String;
use alloc::vec::Vec;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::layout::{self, axis_label, chart_err, series_legend, ChartError, Fonts};
use crate::localize::Grid;
use crate::math::Real;
use crate::present::{colorbar_ticks, format_length_m};
use crate::present::{viridis, LogScale, UNBOUNDED_RGB};
use crate::scenario::Area;

/// A map plot: metre axes in both directions.
pub(crate) type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

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
    draw_heatmap(&chart.plotting_area().strip_coord_spec(), map, scale)?;
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
    draw_axes(chart, &lay.font, ["x (m)", "y (m)"], [8, 8], None)
}

/// The axes of a plot: tick labels ([`axis_label`]), the descriptions `desc` (x, y), about
/// `labels` ticks per axis, and the grid in the (bold, light) colours `grid` or none.
pub(crate) fn draw_axes<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    font: &Fonts,
    [x_desc, y_desc]: [&str; 2],
    [x_labels, y_labels]: [usize; 2],
    grid: Option<[RGBColor; 2]>,
) -> Result<(), ChartError> {
    let mut mesh = chart.configure_mesh();
    match grid {
        None => {
            mesh.disable_mesh();
        }
        Some([bold, light]) => {
            mesh.bold_line_style(bold.stroke_width(1))
                .light_line_style(light.stroke_width(1));
        }
    }
    mesh.x_desc(x_desc)
        .y_desc(y_desc)
        .label_style(("sans-serif", font.ticks).into_font())
        .axis_desc_style(("sans-serif", font.axis).into_font())
        .x_labels(x_labels)
        .y_labels(y_labels)
        .set_all_tick_mark_size(font.ticks as i32 / 3 + 2)
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
    draw_nodes(chart, nodes, lay.font.nodes)?;
    layout::frame_plot(chart)
}

const TX_RGB: RGBColor = RGBColor(228, 26, 28);

/// The window `[x0, x1, y0, y1]` (m) a map plot shows.
pub(crate) fn plot_window<DB: DrawingBackend>(chart: &Chart<'_, DB>) -> [Real; 4] {
    let (xr, yr) = (chart.x_range(), chart.y_range());
    [xr.start, xr.end, yr.start, yr.end]
}

/// Whether the point `p` (m) lies in the window `w` = `[x0, x1, y0, y1]`.
pub(crate) fn in_window(w: [Real; 4], p: [Real; 2]) -> bool {
    (w[0]..=w[1]).contains(&p[0]) && (w[2]..=w[3]).contains(&p[1])
}

/// A legend entry `label`, drawn by `mark` (pixels about the entry's anchor), for the series
/// legend of `chart` (an empty series carries it).
pub(crate) fn legend_entry<'a, DB, E, F>(
    chart: &mut Chart<'a, DB>,
    label: &str,
    mark: F,
) -> Result<(), ChartError>
where
    DB: DrawingBackend + 'a,
    E: plotters::element::IntoDynElement<'a, DB, (i32, i32)>,
    F: Fn((i32, i32)) -> E + 'a,
{
    chart
        .draw_series(core::iter::empty::<Circle<(Real, Real), i32>>())
        .map_err(chart_err)?
        .label(label)
        .legend(mark);
    Ok(())
}

/// A `present` colour (`[r, g, b]`) as plotters'.
pub(super) fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// Fills the plotting area (pixel coordinates, origin top-left) with the map. The map is
/// resampled (nearest cell) to at most one cell per pixel, and horizontal runs of equal colour are
/// merged into one rectangle; each rectangle overlaps its right/upper neighbour by one pixel,
/// which that neighbour paints over, so vector outputs show no hairline seams.
pub(crate) fn draw_heatmap<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    map: &MapData,
    scale: Option<&LogScale>,
) -> Result<(), ChartError> {
    let (w, h) = area.dim_in_pixel();
    let (nx, ny) = (map.grid.nx, map.grid.ny);
    let (w, h) = (w as usize, h as usize);
    if w == 0 || h == 0 || nx == 0 || ny == 0 {
        return Ok(());
    }
    let (cols, rows) = (nx.min(w), ny.min(h));
    let pick = |k: usize, n_out: usize, n_src: usize| {
        (((k as Real + 0.5) * n_src as Real / n_out as Real) as usize).min(n_src - 1)
    };
    let colour = |v: Real| match scale {
        Some(s) => s.color(v),
        None => UNBOUNDED_RGB,
    };
    let x_px = |c: usize| (c * w / cols) as i32;
    let y_px = |r: usize| (h - r * h / rows) as i32; // lower edge of display row r
    let src_cols: Vec<usize> = (0..cols).map(|c| pick(c, cols, nx)).collect();
    let mut line: Vec<[u8; 3]> = Vec::with_capacity(cols);
    for r in 0..rows {
        let j = pick(r, rows, ny);
        let values = &map.values_m[j * nx..(j + 1) * nx];
        line.clear();
        line.extend(src_cols.iter().map(|&i| colour(values[i])));
        let bottom = y_px(r);
        let top = y_px(r + 1) - i32::from(r + 1 < rows);
        let mut start = 0;
        for c in 1..=cols {
            if c < cols && line[c] == line[start] {
                continue;
            }
            let right = x_px(c) + i32::from(c < cols);
            area.draw(&Rectangle::new(
                [(x_px(start), top), (right, bottom)],
                rgb(line[start]).filled(),
            ))
            .map_err(chart_err)?;
            start = c;
        }
    }
    Ok(())
}

/// Markers and name labels of the nodes inside the plotted area, plus a small legend.
pub(crate) fn draw_nodes<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    nodes: &[ChartNode],
    font_px: f64,
) -> Result<(), ChartError> {
    let s = font_px / 20.0;
    let marker = (7.0 * s).round().max(3.0) as i32;
    let w = plot_window(chart);
    let (px_x, px_y) = chart.plotting_area().get_pixel_range();
    let font = ("sans-serif", font_px).into_font();
    let plot = chart.plotting_area().clone();
    let visible = nodes.iter().filter(|n| in_window(w, n.position_m));
    for n in visible {
        let at = (n.position_m[0], n.position_m[1]);
        match n.kind {
            NodeKind::Transmitter => {
                plot.draw(&TriangleMarker::new(at, marker + 3, WHITE.filled()))
                    .map_err(chart_err)?;
                plot.draw(&TriangleMarker::new(at, marker, TX_RGB.filled()))
                    .map_err(chart_err)?;
            }
            NodeKind::Receiver => {
                plot.draw(&Circle::new(at, marker - 1, WHITE.filled()))
                    .map_err(chart_err)?;
                plot.draw(&Circle::new(at, marker - 1, BLACK.stroke_width(2)))
                    .map_err(chart_err)?;
            }
        }
        let (tw, th) = plot
            .estimate_text_size(&n.name, &TextStyle::from(font.clone()))
            .map_err(chart_err)?;
        let (tw, th) = (tw as i32, th as i32);
        let (bx, by) = plot.map_coordinate(&at);
        let pad = (3.0 * s).round() as i32;
        // Upper right of the marker unless that leaves the plot.
        let dx = if bx + marker + 2 * pad + tw < px_x.end {
            marker + pad
        } else {
            -(marker + pad + tw)
        };
        let dy = if by - marker - th - 2 * pad > px_y.start {
            -(marker + th)
        } else {
            marker
        };
        let label = EmptyElement::at(at)
            + Rectangle::new(
                [
                    (dx - pad, dy - pad - th / 5),
                    (dx + tw + pad, dy + th + pad),
                ],
                WHITE.mix(0.8).filled(),
            )
            + Text::new(n.name.clone(), (dx, dy), font.clone());
        plot.draw(&label).map_err(chart_err)?;
    }
    draw_legend(chart, nodes, marker, font_px)
}

fn draw_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    nodes: &[ChartNode],
    marker: i32,
    font_px: f64,
) -> Result<(), ChartError> {
    let has = |k: NodeKind| nodes.iter().any(|n| n.kind == k);
    if has(NodeKind::Transmitter) {
        legend_entry(chart, "transmitter", move |(x, y)| {
            TriangleMarker::new((x, y), marker, TX_RGB.filled())
        })?;
    }
    if has(NodeKind::Receiver) {
        legend_entry(chart, "receiver", move |(x, y)| {
            EmptyElement::at((x, y))
                + Circle::new((0, 0), marker - 1, WHITE.filled())
                + Circle::new((0, 0), marker - 1, BLACK.stroke_width(2))
        })?;
    }
    if has(NodeKind::Transmitter) || has(NodeKind::Receiver) {
        series_legend(
            chart,
            SeriesLabelPosition::UpperRight,
            font_px * 0.9,
            8.0 * font_px / 20.0,
            0.85,
        )?;
    }
    Ok(())
}

/// Vertical colour bar with log ticks in metres, an optional grey "unbounded" swatch below it
/// and a rotated label on the right.
pub(crate) fn draw_colorbar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    scale: Option<&LogScale>,
    has_unbounded: bool,
    label: &str,
    font: &Fonts,
) -> Result<(), ChartError> {
    draw_colorbar_marked(area, scale, has_unbounded, label, font, [false; 2], "")
}

/// [`draw_colorbar`] of a fixed scale that values pass: `clamped` = [some below `min`, some
/// above `max`] (drawn in the end colour); each such end is labelled `≤ min` or `≥ max` (its
/// tick labels too near that end left out). `suffix` follows every length label (`"/s"` makes
/// `5 cm` read `5 cm/s`: a speed).
pub(crate) fn draw_colorbar_marked<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    scale: Option<&LogScale>,
    has_unbounded: bool,
    label: &str,
    font: &Fonts,
    clamped: [bool; 2],
    suffix: &str,
) -> Result<(), ChartError> {
    let s = font.ticks / 20.0;
    let (w, h) = area.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    let bar_w = (24.0 * s).round() as i32;
    let swatch = if has_unbounded || scale.is_none() {
        (1.4 * font.ticks) as i32
    } else {
        0
    };
    let bar_h = if swatch > 0 {
        h - swatch - (0.9 * font.ticks) as i32
    } else {
        h
    };
    let tick_font = TextStyle::from(("sans-serif", font.ticks).into_font())
        .pos(Pos::new(HPos::Left, VPos::Center));
    let draw = |e: &Rectangle<(i32, i32)>| area.draw(e).map_err(chart_err);
    if let (Some(scale), true) = (scale, bar_h > 2) {
        let mut start = 0;
        let colour = |py: i32| viridis(1.0 - (py as Real + 0.5) / bar_h as Real);
        for py in 1..=bar_h {
            if py < bar_h && colour(py) == colour(start) {
                continue;
            }
            let bottom = py + i32::from(py < bar_h);
            draw(&Rectangle::new(
                [(0, start), (bar_w, bottom)],
                rgb(colour(start)).filled(),
            ))?;
            start = py;
        }
        draw(&Rectangle::new(
            [(0, 0), (bar_w, bar_h)],
            BLACK.stroke_width(1),
        ))?;
        let max_labels = (bar_h as Real / (2.0 * font.ticks)) as usize;
        let room = (1.2 * font.ticks) as i32;
        let ends = [
            (clamped[0], bar_h, "≤", scale.min),
            (clamped[1], 0, "≥", scale.max),
        ];
        for (on, y, mark, v) in ends {
            if on {
                let text = alloc::format!("{mark} {}{suffix}", format_length_m(v, 3));
                let x = bar_w + (11.0 * s) as i32;
                area.draw_text(&text, &tick_font, (x, y))
                    .map_err(chart_err)?;
            }
        }
        for t in colorbar_ticks(scale.min, scale.max, max_labels) {
            let y = ((1.0 - scale.fraction(t.value)) * bar_h as Real).round() as i32;
            let near_end =
                |(on, end, _, _): &(bool, i32, &str, Real)| *on && (y - end).abs() < room;
            let major = !t.label.is_empty() && !ends.iter().any(near_end);
            let len = ((if major { 7.0 } else { 4.0 }) * s).round() as i32;
            area.draw(&PathElement::new(
                [(bar_w, y), (bar_w + len, y)],
                BLACK.stroke_width(1),
            ))
            .map_err(chart_err)?;
            if major {
                let text = alloc::format!("{}{suffix}", t.label);
                area.draw_text(&text, &tick_font, (bar_w + len + (4.0 * s) as i32, y))
                    .map_err(chart_err)?;
            }
        }
    }
    if swatch > 0 {
        let top = h - swatch;
        draw(&Rectangle::new(
            [(0, top), (bar_w, h)],
            rgb(UNBOUNDED_RGB).filled(),
        ))?;
        draw(&Rectangle::new(
            [(0, top), (bar_w, h)],
            BLACK.stroke_width(1),
        ))?;
        area.draw_text(
            "unbounded",
            &tick_font,
            (bar_w + (6.0 * s) as i32, top + swatch / 2),
        )
        .map_err(chart_err)?;
    }
    let rotated = TextStyle::from(("sans-serif", font.axis).into_font())
        .transform(FontTransform::Rotate270)
        .pos(Pos::new(HPos::Center, VPos::Center));
    area.draw_text(
        label,
        &rotated,
        (w - (0.7 * font.axis) as i32, bar_h.max(h / 2) / 2),
    )
    .map_err(chart_err)?;
    Ok(())
}
