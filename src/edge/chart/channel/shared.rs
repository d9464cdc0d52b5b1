//! What the channel figures share: their options ([`ChannelChartOptions`]), the plotting box a
//! page draws a time cursor over ([`PlotBox`]), the colours of truth, statics and losses, and the
//! small drawing helpers (a centred note, a safe axis range, a curve panel, dashes, decimals).

use alloc::format;
use alloc::string::String;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::super::layout::Fonts;
use super::super::panel::{draw_axes, Chart};
use super::super::{chart_err, ChartError, CURVE_PALETTE};
use crate::math::Real;

/// Colour of the true paths (the figures' red).
pub(super) const TRUTH_RGB: RGBColor = CURVE_PALETTE[1];
/// Colour of the static bands.
pub(super) const STATIC_RGB: RGBColor = RGBColor(110, 110, 110);

/// Title and subtitle of a figure of this module.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ChannelChartOptions {
    /// Title line.
    pub title: String,
    /// Optional smaller second line.
    pub subtitle: Option<String>,
}

/// Where a drawn panel's plotting area lies on the backend, and the time it spans: what a
/// page needs to draw a time cursor over a figure drawn here.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlotBox {
    /// Left and right pixel columns of the plotting area (backend pixels).
    pub x_px: [i32; 2],
    /// Top and bottom pixel rows of the plotting area (backend pixels).
    pub y_px: [i32; 2],
    /// The time axis `[t_left, t_right]`, s.
    pub t_range_s: [Real; 2],
}

impl PlotBox {
    /// The plotting area of `chart`, whose x axis spans `t_range_s`.
    pub(super) fn of<DB: DrawingBackend>(chart: &Chart<'_, DB>, t_range_s: [Real; 2]) -> PlotBox {
        let (x, y) = chart.plotting_area().get_pixel_range();
        PlotBox {
            x_px: [x.start, x.end],
            y_px: [y.start, y.end],
            t_range_s,
        }
    }
}

/// A text centred in the plotting area of `chart` (e.g. `no track`).
pub(super) fn centred_note<DB: DrawingBackend>(
    chart: &Chart<'_, DB>,
    text: &str,
    font: &Fonts,
) -> Result<(), ChartError> {
    let plot = chart.plotting_area().strip_coord_spec();
    let (w, h) = plot.dim_in_pixel();
    let style = TextStyle::from(("sans-serif", font.axis).into_font())
        .color(&RGBColor(90, 90, 90))
        .pos(Pos::new(HPos::Center, VPos::Center));
    plot.draw_text(text, &style, (w as i32 / 2, h as i32 / 2))
        .map_err(chart_err)
}

/// A finite, increasing axis range from `r` (`[0, 1]` otherwise).
pub(super) fn axis(r: [Real; 2]) -> [Real; 2] {
    if r[0].is_finite() && r[1].is_finite() && r[1] > r[0] {
        r
    } else if r[0].is_finite() {
        [r[0], r[0] + 1.0]
    } else {
        [0.0, 1.0]
    }
}

/// A curve panel with linear axes.
pub(super) fn curve_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    x: [Real; 2],
    y: [Real; 2],
    (x_desc, y_desc): (&str, &str),
    font: &Fonts,
    s: f64,
) -> Result<Chart<'a, DB>, ChartError> {
    let mut chart = ChartBuilder::on(area)
        .margin((10.0 * s) as u32)
        .x_label_area_size((font.ticks + font.axis + 20.0 * s) as u32)
        .y_label_area_size((2.4 * font.ticks + font.axis + 20.0 * s) as u32)
        .build_cartesian_2d(x[0]..x[1], y[0]..y[1])
        .map_err(chart_err)?;
    draw_axes(
        &mut chart,
        font,
        [x_desc, y_desc],
        [8, 6],
        Some([RGBColor(215, 215, 215), RGBColor(240, 240, 240)]),
    )?;
    Ok(chart)
}

/// Colour of a segment's loss (the map's ring, the error chart's dashed line).
pub(super) const LOST_RGB: RGBColor = RGBColor(200, 30, 30);

/// A dashed line between two points in data coordinates.
pub(super) fn chart_dashed<DB: DrawingBackend>(
    plot: &DrawingArea<
        DB,
        plotters::coord::cartesian::Cartesian2d<
            plotters::coord::types::RangedCoordf64,
            plotters::coord::types::RangedCoordf64,
        >,
    >,
    pts: [(Real, Real); 2],
    dash: u32,
    gap: u32,
    style: ShapeStyle,
) -> Result<(), ChartError> {
    plot.draw(&plotters::element::DashedPathElement::new(
        pts, dash, gap, style,
    ))
    .map_err(chart_err)
}

/// `v` with 2 decimals below 10 and 1 from there (m in labels).
pub(super) fn decimals(v: Real) -> String {
    if v < 10.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.1}")
    }
}
