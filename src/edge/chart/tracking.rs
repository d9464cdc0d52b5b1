//! The tracking figure of [S] Fig. 3 (spec §10): the EKF's position RMSE `ε_EKF(t)` (§9.5)
//! against the posterior CRLB `ε_PCRLB(t)` (§8, E9) over time, on a logarithmic metre axis, one
//! panel per scenario side by side. Generic over the plotters [`DrawingBackend`]: SVG and PNG in
//! the CLI, a `<canvas>` in the browser; same fonts, title band and tick labels as the map figure.

use alloc::string::String;
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::layout::{
    fitting_size, font_scale, frame_plot, segments, series_legend, titled_body, Fonts,
};
use super::{axis_label, chart_err, register_fonts, ChartError, CURVE_PALETTE};
use crate::math::Real;
use crate::present::colorbar_ticks;
use crate::present::nice_below;

/// Colour of the PCRLB curve (dashed): the palette's red.
const PCRLB_RGB: RGBColor = CURVE_PALETTE[1];
/// Colours of the RMSE curves of [`draw_tracking_filters`], in curve order: the figures'
/// palette without its red, which is the bound's (the first is the EKF curve's colour; cycled
/// beyond four).
const CURVE_RGB: [RGBColor; 4] = [
    CURVE_PALETTE[0],
    CURVE_PALETTE[2],
    CURVE_PALETTE[4],
    CURVE_PALETTE[3],
];
/// Line styles of the RMSE curves, in curve order as [`CURVE_RGB`]: `None` solid, else `(dash,
/// gap)` px at scale 1 — EKF solid, UKF dotted, PF long dashes (the bound's dashes are 9, 5), so
/// the curves differ without colour too (on the canvas, in the SVG and in the legend).
const CURVE_DASH: [Option<(f64, f64)>; 4] =
    [None, Some((2.5, 3.5)), Some((16.0, 5.0)), Some((6.0, 3.0))];
/// The legend label of the PCRLB curve.
const PCRLB_LABEL: &str = "posterior CRLB  ε_PCRLB";
/// Length of a legend's line sample, px.
const LEGEND_LINE_PX: i32 = 24;

/// One named RMSE curve of a [`FiltersPanel`].
#[derive(Debug, Clone, Copy)]
pub struct FilterCurve<'a> {
    /// Legend label, e.g. `UKF RMSE`.
    pub label: &'a str,
    /// The RMSE, m, one per time (empty: not drawn; non-finite: a gap).
    pub rmse_m: &'a [Real],
}

/// One panel of [`draw_tracking_filters`]: several trackers' RMSE curves of one scenario.
#[derive(Debug, Clone, Copy)]
pub struct FiltersPanel<'a> {
    /// Panel caption, e.g. `Scenario II`.
    pub title: &'a str,
    /// Times `t_n`, s (ascending).
    pub t_s: &'a [Real],
    /// The RMSE curves, in distinct colours and line styles (the first solid in the EKF's blue).
    pub curves: &'a [FilterCurve<'a>],
    /// `ε_PCRLB(t_n)`, m, one per time (empty: not drawn; `None`: a gap).
    pub rmse_pcrlb_m: &'a [Option<Real>],
    /// A last legend row of text without a mark, e.g. what a failed run is
    /// ([`crate::study::FAILED_NOTE`]); `None`: none.
    pub legend_note: Option<&'a str>,
}

/// Title and subtitle of the figure.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrackingChartOptions {
    /// Title line.
    pub title: String,
    /// Optional smaller second line (run counts, step).
    pub subtitle: Option<String>,
}

/// A figure size for `panels` panels side by side (1000 × 620 px for one, 620 × 580 per panel
/// for several).
pub fn tracking_size(panels: usize) -> (u32, u32) {
    match panels {
        0 | 1 => (1000, 620),
        n => (n.min(8) as u32 * 620, 580),
    }
}

/// The y range `[lo, hi]`, m: the positive values of every panel, with a margin, widened to
/// 1-2-5 numbers.
fn y_range(panels: &[FiltersPanel]) -> (Real, Real) {
    let values = panels.iter().flat_map(|p| {
        let curves = p.curves.iter().flat_map(|c| c.rmse_m.iter().copied());
        curves.chain(p.rmse_pcrlb_m.iter().flatten().copied())
    });
    let (min, max) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((Real::INFINITY, 0.0 as Real), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !(min.is_finite() && max > 0.0) {
        return (1e-3, 1.0);
    }
    // A little room so that no curve runs along the frame.
    let (min, max) = (min / 1.15, max * 1.05);
    let lo = nice_below(min).map_or(min, |(m, k)| crate::present::decimal(m, k));
    let hi = match nice_below(max) {
        Some((m, k)) if crate::present::decimal(m, k) >= max => max,
        Some((1, k)) => crate::present::decimal(2, k),
        Some((2, k)) => crate::present::decimal(5, k),
        Some((_, k)) => crate::present::decimal(1, k + 1),
        None => max,
    };
    if hi > lo {
        (lo, hi)
    } else {
        (lo / 2.0, lo * 2.0)
    }
}

/// Draws the tracking figure onto `root` (filled white first): the title band, then one panel
/// per entry of `panels` side by side with a shared y range, each with one or more trackers'
/// labelled RMSE curves (labels: [`crate::study::curve_label`]), each in its own colour and line
/// style ([`CURVE_DASH`]: the first solid in the EKF's blue) with its label and a sample of its
/// line in the legend, next to the dashed PCRLB — \[S\]
/// Fig. 3 with the EKF alone. The one entry point of the CLI's and the page's tracking charts.
/// Returns the shared y range `(lo, hi)`, m. Does not call `present()`.
pub fn draw_tracking_filters<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    panels: &[FiltersPanel],
    opts: &TrackingChartOptions,
) -> Result<(Real, Real), ChartError> {
    register_fonts();
    for p in panels {
        let bad = p
            .curves
            .iter()
            .map(|c| (c.label, c.rmse_m.len()))
            .chain([("PCRLB", p.rmse_pcrlb_m.len())])
            .find(|&(_, n)| n != 0 && n != p.t_s.len());
        if let Some((label, n)) = bad {
            return Err(ChartError(alloc::format!(
                "{}: {} times but {n} values of {label}",
                p.title,
                p.t_s.len(),
            )));
        }
    }
    draw_panels(root, panels, opts)
}

/// The figure of checked `panels`.
fn draw_panels<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    panels: &[FiltersPanel],
    opts: &TrackingChartOptions,
) -> Result<(Real, Real), ChartError> {
    let (w, h) = root.dim_in_pixel();
    let n = panels.len().max(1);
    // Panels side by side are shown scaled down as one wide figure: larger text per panel.
    let s = if n > 1 {
        (w as f64 / n as f64 / 520.0)
            .min(h as f64 / 480.0)
            .clamp(0.5, 4.0)
    } else {
        font_scale(w, h)
    };
    let (font, body) = titled_body(root, s, &opts.title, opts.subtitle.as_deref())?;
    let range = y_range(panels);
    for (k, (area, panel)) in body.split_evenly((1, n)).iter().zip(panels).enumerate() {
        // The y range is shared: its title only on the first panel.
        let y_desc = if k == 0 { "position RMSE" } else { "" };
        draw_panel(area, panel, range, y_desc, &font, s)?;
    }
    Ok(range)
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &FiltersPanel,
    (lo, hi): (Real, Real),
    y_desc: &str,
    font: &Fonts,
    s: f64,
) -> Result<(), ChartError> {
    let t_max = p.t_s.last().copied().filter(|t| t.is_finite() && *t > 0.0);
    let t_max = t_max.unwrap_or(1.0);
    let (_, h) = area.dim_in_pixel();
    let max_labels = ((h as f64 - 3.0 * font.ticks) / (1.6 * font.ticks)).max(2.0) as usize;
    let ticks = colorbar_ticks(lo, hi, max_labels);
    let (major, minor): (Vec<_>, Vec<_>) = ticks.into_iter().partition(|t| !t.label.is_empty());
    let labels: Vec<(Real, String)> = major.iter().map(|t| (t.value, t.label.clone())).collect();
    let y_axis = (lo..hi)
        .log_scale()
        .with_key_points(major.iter().map(|t| t.value).collect())
        .with_light_points(minor.iter().map(|t| t.value));
    // The caption shrinks to the panel's width (long failure notes of several filters).
    let (w, _) = area.dim_in_pixel();
    let caption_size = fitting_size(area, p.title, font.axis * 1.1, 0.96 * w as f64);
    let mut chart = ChartBuilder::on(area)
        .caption(p.title, ("sans-serif", caption_size).into_font())
        .margin_top((6.0 * s) as u32)
        .margin_right((18.0 * s) as u32)
        .margin_left((6.0 * s) as u32)
        .x_label_area_size((font.ticks + font.axis + 26.0 * s) as u32)
        .y_label_area_size((2.8 * font.ticks + font.axis + 26.0 * s) as u32)
        .build_cartesian_2d(0.0..t_max, y_axis)
        .map_err(chart_err)?;
    let y_label = |v: &Real| {
        labels
            .iter()
            .find(|(x, _)| (x - v).abs() <= 1e-9 * x.abs())
            .map_or_else(String::new, |(_, l)| l.clone())
    };
    chart
        .configure_mesh()
        .bold_line_style(RGBColor(200, 200, 200).stroke_width(1))
        .light_line_style(RGBColor(235, 235, 235).stroke_width(1))
        .x_max_light_lines(1)
        .x_desc("time t (s)")
        .y_desc(y_desc)
        .label_style(("sans-serif", font.ticks).into_font())
        .axis_desc_style(("sans-serif", font.axis).into_font())
        .x_labels(11)
        .set_all_tick_mark_size(font.ticks as i32 / 3 + 2)
        .x_label_formatter(&|v| axis_label(*v))
        .y_label_formatter(&y_label)
        .draw()
        .map_err(chart_err)?;

    let width = (2.0 * s).round().max(1.0) as u32;
    let pcrlb = PCRLB_RGB.stroke_width(width);
    let (dash, gap) = ((9.0 * s) as u32, (5.0 * s) as u32);
    // Drawable on the log axis: finite, `v > 0`.
    let drawable = |t: Real, v: Real| t.is_finite() && v.is_finite() && v > 0.0;
    for (c, curve) in p.curves.iter().enumerate() {
        let style = CURVE_RGB[c % CURVE_RGB.len()].stroke_width(width);
        let dash = CURVE_DASH[c % CURVE_DASH.len()].map(|(d, g)| {
            (
                ((d * s).round() as u32).max(1),
                ((g * s).round() as u32).max(1),
            )
        });
        let parts = segments(
            p.t_s.iter().copied().zip(curve.rmse_m.iter().copied()),
            drawable,
        );
        for (k, part) in parts.into_iter().enumerate() {
            let series = match dash {
                None => chart.draw_series(LineSeries::new(part, style)),
                Some((d, g)) => chart.draw_series(DashedLineSeries::new(part, d, g, style)),
            }
            .map_err(chart_err)?;
            if k == 0 {
                // The legend's sample in the curve's own line style.
                series.label(curve.label).legend(move |(x, y)| {
                    let (d, g) = dash.unwrap_or((LEGEND_LINE_PX as u32, 0));
                    DashedPathElement::new([(x, y), (x + LEGEND_LINE_PX, y)], d, g, style)
                });
            }
        }
    }
    let bound = p.rmse_pcrlb_m.iter().map(|v| v.unwrap_or(Real::NAN));
    let pcrlb_parts = segments(p.t_s.iter().copied().zip(bound), drawable);
    for (k, part) in pcrlb_parts.into_iter().enumerate() {
        let series = chart
            .draw_series(DashedLineSeries::new(part, dash, gap, pcrlb))
            .map_err(chart_err)?;
        if k == 0 {
            series.label(PCRLB_LABEL).legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new([(0, 0), (10, 0)], pcrlb)
                    + PathElement::new([(14, 0), (24, 0)], pcrlb)
            });
        }
    }
    if let Some(note) = p.legend_note {
        chart
            .draw_series(core::iter::empty::<EmptyElement<(Real, Real), DB>>())
            .map_err(chart_err)?
            .label(note)
            .legend(|(x, y)| EmptyElement::at((x, y)));
    }
    // The legend fits the plot's width (a narrow canvas, long failure notes): its font shrinks
    // so the widest row, its line sample (plotters' 30 px), its margins and plotters' 5 px from
    // the plot's edge fit, so no sample is cut at the plot's left edge.
    let margin = 8.0 * s;
    let (plot_w, _) = chart.plotting_area().dim_in_pixel();
    let room = plot_w as f64 - 30.0 - 2.0 * margin - 10.0;
    let legend_font = p
        .curves
        .iter()
        .map(|c| c.label)
        .chain([PCRLB_LABEL])
        .chain(p.legend_note)
        .map(|label| fitting_size(area, label, font.ticks * 0.95, room))
        .fold(font.ticks * 0.95, f64::min);
    series_legend(
        &mut chart,
        SeriesLabelPosition::UpperRight,
        legend_font,
        margin,
        0.9,
    )?;
    frame_plot(&chart)
}

#[cfg(test)]
mod tests;
