//! Curve figures of the multi-target experiments (spec `multi-target.md` §8): ROC plots (Figs. 3
//! and 4, `P_D` against `P_FA`) and the missed-detection plot of Fig. 5 (`1 − P_D` against
//! `T_b`). Generic over the plotters [`DrawingBackend`] (SVG and PNG in the CLI, a `<canvas>` in
//! the browser); same fonts, title band and tick labels as the other figures.
//!
//! Each [`CurveSeries`] is a polyline and/or markers in one palette colour, so two curves that
//! coincide stay visible: draw one as a line and the other as open markers over it.

use alloc::string::String;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::layout::{font_scale, frame_plot, segments, series_legend, titled_body};
use super::{axis_label, chart_err, register_fonts, ChartError};
use crate::math::Real;

/// The curve colours: the colour-blind-safe Okabe–Ito palette (M. Okabe and K. Ito, "Color
/// Universal Design", 2008) on a white chart: blue, vermillion, bluish green, orange, reddish
/// purple, sky blue.
pub const CURVE_PALETTE: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(230, 159, 0),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
];

/// How the points of a curve are joined.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineKind {
    /// Not joined (markers only).
    None,
    /// Solid line.
    Solid,
    /// Dashed line.
    Dashed,
}

/// The marker drawn at every point of a curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// No marker.
    None,
    /// Small filled disc.
    Dot,
    /// Larger open circle (draws well over a line of the same colour).
    Ring,
    /// Filled triangle.
    Triangle,
    /// Diagonal cross.
    Cross,
    /// Open square.
    Square,
}

/// One curve of the figure.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveSeries<'a> {
    /// Legend text.
    pub label: String,
    /// Points `(x, y)` in drawing order; non-finite points are skipped (and break the line).
    pub points: &'a [(Real, Real)],
    /// Index into [`CURVE_PALETTE`] (wraps around).
    pub colour: usize,
    /// Line between the points.
    pub line: LineKind,
    /// Marker at each point.
    pub marker: Marker,
}

/// Text, axes and legend placement of a curve figure.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveChartOptions {
    /// Title line.
    pub title: String,
    /// Optional smaller second line.
    pub subtitle: Option<String>,
    /// x-axis description.
    pub x_desc: String,
    /// y-axis description.
    pub y_desc: String,
    /// x range `(lo, hi)`, `lo < hi`.
    pub x_range: (Real, Real),
    /// y range `(lo, hi)`, `lo < hi`.
    pub y_range: (Real, Real),
    /// Where the legend goes.
    pub legend: SeriesLabelPosition,
}

impl CurveChartOptions {
    /// A ROC figure: `P_FA` on x and `P_D` on y, both on `[0, 1]`, legend lower right.
    pub fn roc(title: String, subtitle: Option<String>) -> CurveChartOptions {
        CurveChartOptions {
            title,
            subtitle,
            x_desc: "false-alarm probability P_FA".into(),
            y_desc: "detection probability P_D".into(),
            x_range: (0.0, 1.0),
            y_range: (0.0, 1.0),
            legend: SeriesLabelPosition::LowerRight,
        }
    }
}

/// The default figure size, px.
pub fn curve_chart_size() -> (u32, u32) {
    (1000, 800)
}

/// Draws the figure onto `root` (filled white first): title band, axes with grid, every curve of
/// `series` in order (later ones on top) and the legend. Does not call `present()`.
///
/// Errors: [`ChartError`] for an empty or inverted axis range, or a backend failure.
pub fn draw_curves<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    series: &[CurveSeries],
    opts: &CurveChartOptions,
) -> Result<(), ChartError> {
    register_fonts();
    for (name, (lo, hi)) in [("x", opts.x_range), ("y", opts.y_range)] {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(ChartError(alloc::format!(
                "{name} range [{lo}, {hi}] is empty"
            )));
        }
    }
    let (w, h) = root.dim_in_pixel();
    let s = font_scale(w, h);
    let (font, body) = titled_body(root, s, &opts.title, opts.subtitle.as_deref())?;
    let (x0, x1) = opts.x_range;
    let (y0, y1) = opts.y_range;
    let mut chart = ChartBuilder::on(&body)
        .margin_top((6.0 * s) as u32)
        .margin_right((18.0 * s) as u32)
        .margin_left((6.0 * s) as u32)
        .x_label_area_size((font.ticks + font.axis + 26.0 * s) as u32)
        .y_label_area_size((2.2 * font.ticks + font.axis + 26.0 * s) as u32)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(chart_err)?;
    chart
        .configure_mesh()
        .bold_line_style(RGBColor(200, 200, 200).stroke_width(1))
        .light_line_style(RGBColor(235, 235, 235).stroke_width(1))
        .x_desc(opts.x_desc.as_str())
        .y_desc(opts.y_desc.as_str())
        .label_style(("sans-serif", font.ticks).into_font())
        .axis_desc_style(("sans-serif", font.axis).into_font())
        .x_labels(11)
        .y_labels(11)
        .set_all_tick_mark_size(font.ticks as i32 / 3 + 2)
        .x_label_formatter(&|v| axis_label(*v))
        .y_label_formatter(&|v| axis_label(*v))
        .draw()
        .map_err(chart_err)?;

    let width = (2.0 * s).round().max(1.0) as u32;
    let r = (5.0 * s).round().max(2.0) as i32;
    let (dash, gap) = ((9.0 * s) as u32, (5.0 * s) as u32);
    for c in series {
        let colour = CURVE_PALETTE[c.colour % CURVE_PALETTE.len()];
        let stroke = colour.stroke_width(width);
        for part in segments(c.points.iter().copied(), |x, y| {
            x.is_finite() && y.is_finite()
        }) {
            match c.line {
                LineKind::None => {}
                LineKind::Solid => {
                    chart
                        .draw_series(LineSeries::new(part, stroke))
                        .map_err(chart_err)?;
                }
                LineKind::Dashed => {
                    chart
                        .draw_series(DashedLineSeries::new(part, dash, gap, stroke))
                        .map_err(chart_err)?;
                }
            }
        }
        let pts = c
            .points
            .iter()
            .copied()
            .filter(|(x, y)| x.is_finite() && y.is_finite());
        let fill = colour.filled();
        let open = colour.stroke_width(width);
        let legend_line = match c.line {
            LineKind::None => TRANSPARENT.stroke_width(width),
            _ => stroke,
        };
        // A series without elements that carries the legend entry.
        macro_rules! label {
            () => {
                chart
                    .draw_series(core::iter::empty::<EmptyElement<(Real, Real), DB>>())
                    .map_err(chart_err)?
                    .label(c.label.as_str())
            };
        }
        let line = move |(x, y): (i32, i32)| {
            EmptyElement::at((x, y)) + PathElement::new([(0, 0), (20, 0)], legend_line)
        };
        match c.marker {
            Marker::None => {
                label!().legend(line);
            }
            Marker::Dot => {
                chart
                    .draw_series(pts.map(|p| Circle::new(p, r * 3 / 4, fill)))
                    .map_err(chart_err)?;
                label!().legend(move |at| line(at) + Circle::new((10, 0), r * 3 / 4, fill));
            }
            Marker::Ring => {
                chart
                    .draw_series(pts.map(|p| Circle::new(p, r + 2, open)))
                    .map_err(chart_err)?;
                label!().legend(move |at| line(at) + Circle::new((10, 0), r + 2, open));
            }
            Marker::Triangle => {
                chart
                    .draw_series(pts.map(|p| TriangleMarker::new(p, r + 1, fill)))
                    .map_err(chart_err)?;
                label!().legend(move |at| line(at) + TriangleMarker::new((10, 0), r + 1, fill));
            }
            Marker::Cross => {
                chart
                    .draw_series(pts.map(|p| Cross::new(p, r, open)))
                    .map_err(chart_err)?;
                label!().legend(move |at| line(at) + Cross::new((10, 0), r, open));
            }
            Marker::Square => {
                let square =
                    move |p| EmptyElement::at(p) + Rectangle::new([(-r, -r), (r, r)], open);
                chart.draw_series(pts.map(square)).map_err(chart_err)?;
                label!()
                    .legend(move |at| line(at) + Rectangle::new([(10 - r, -r), (10 + r, r)], open));
            }
        }
    }
    series_legend(
        &mut chart,
        opts.legend.clone(),
        font.ticks * 0.9,
        8.0 * s,
        0.9,
    )?;
    frame_plot(&chart)
}

#[cfg(test)]
mod tests;
