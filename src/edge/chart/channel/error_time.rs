//! The position error over time ([`draw_error_time_chart`], the middle panel of
//! [`super::draw_track_errors`]): the error curve, the track's segments (C11) as shaded gaps and
//! dashed losses, the error's summary.

use alloc::format;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::super::layout::{frame_plot, segments, titled_body, Fonts};
use super::super::panel::Chart;
use super::super::{chart_err, register_fonts, ChartError, CURVE_PALETTE};
use crate::math::Real;
use crate::present::TrackErrorView;

use super::shared::{
    axis, centred_note, curve_chart, decimals, ChannelChartOptions, PlotBox, LOST_RGB,
};

/// What [`draw_track_errors`] says instead of a curve: `no track` or `no truth` (`None`: the
/// curves are drawn).
pub(super) fn error_note(view: &TrackErrorView) -> Option<&'static str> {
    if view.track_start.is_none() {
        Some("no track")
    } else if view.stats.is_none() {
        Some("no truth")
    } else {
        None
    }
}

/// A size for the error-over-time chart alone: 1000 × 420.
pub fn error_time_size() -> (u32, u32) {
    (1000, 420)
}

/// Draws the error-over-time panel of [`draw_track_errors`] alone onto `root` (filled white
/// first; the title band, then the panel, with the same `no track` / `no truth` notes) and
/// returns its [`PlotBox`]. Does not call `present()`.
pub fn draw_error_time_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    view: &TrackErrorView,
    opts: &ChannelChartOptions,
) -> Result<PlotBox, ChartError> {
    register_fonts();
    let (w, h) = root.dim_in_pixel();
    let s = (w as f64 / 1000.0).min(h as f64 / 420.0).clamp(0.5, 4.0);
    let (font, body) = titled_body(root, s, &opts.title, opts.subtitle.as_deref())?;
    draw_error_time(&body, view, error_note(view), &font, s)
}

/// The track's segments (C11) on the error-over-time chart `[t0, t1] × [0, top]`: the time
/// outside every segment shaded grey (before the first, between two, after one lost at the
/// end), at each loss a dashed red line labelled with its reason (`lost: innovation`), at each
/// start a green tick on the time axis. Nothing without segments.
fn draw_segment_marks<DB: DrawingBackend>(
    chart: &Chart<'_, DB>,
    view: &TrackErrorView,
    t: [Real; 2],
    top: Real,
    font: &Fonts,
    s: f64,
) -> Result<(), ChartError> {
    if view.segments.is_empty() {
        return Ok(());
    }
    let plot = chart.plotting_area();
    let shade = RGBColor(225, 225, 225).mix(0.6).filled();
    let mut from = t[0];
    for g in &view.segments {
        if g.t_first_s > from {
            plot.draw(&Rectangle::new([(from, 0.0), (g.t_first_s, top)], shade))
                .map_err(chart_err)?;
        }
        from = g.lost_s.unwrap_or(g.t_last_s).max(g.t_last_s);
    }
    if view.segments.last().is_some_and(|g| g.lost_s.is_some()) && from < t[1] {
        plot.draw(&Rectangle::new([(from, 0.0), (t[1], top)], shade))
            .map_err(chart_err)?;
    }
    let width = (1.5 * s).round().max(1.0) as u32;
    let tick = 0.04 * top;
    let style = TextStyle::from(("sans-serif", font.ticks * 0.85).into_font())
        .color(&LOST_RGB)
        .pos(Pos::new(HPos::Right, VPos::Top));
    for g in &view.segments {
        plot.draw(&PathElement::new(
            [(g.t_first_s, 0.0), (g.t_first_s, tick)],
            RGBColor(20, 140, 40).stroke_width(2 * width),
        ))
        .map_err(chart_err)?;
        let (Some(at), Some(label)) = (g.lost_s, g.loss_label()) else {
            continue;
        };
        // A dashed line: 12 dashes over the height.
        let dash = top / 24.0;
        for k in 0..12 {
            let y0 = 2.0 * k as Real * dash;
            plot.draw(&PathElement::new(
                [(at, y0), (at, y0 + dash)],
                LOST_RGB.stroke_width(width),
            ))
            .map_err(chart_err)?;
        }
        plot.draw(&Text::new(label, (at, 0.97 * top), style.clone()))
            .map_err(chart_err)?;
    }
    Ok(())
}

/// The largest error with room above it, m (1 m without errors).
pub(super) fn error_top(view: &TrackErrorView) -> Real {
    view.stats
        .map_or(1.0, |st| if st.max_m > 0.0 { st.max_m * 1.08 } else { 1.0 })
}

pub(super) fn draw_error_time<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    view: &TrackErrorView,
    note: Option<&str>,
    font: &Fonts,
    s: f64,
) -> Result<PlotBox, ChartError> {
    let t = axis([
        view.t_s.first().copied().unwrap_or(0.0),
        view.t_s.last().copied().unwrap_or(1.0),
    ]);
    let chart = curve_chart(
        area,
        t,
        [0.0, error_top(view)],
        ("time t (s)", "position error (m)"),
        font,
        s,
    )?;
    let width = (2.0 * s).round().max(1.0) as u32;
    let points = view
        .t_s
        .iter()
        .zip(&view.error_m)
        .map(|(&t, e)| (t, e.unwrap_or(Real::NAN)));
    draw_segment_marks(&chart, view, t, error_top(view), font, s)?;
    for part in segments(points, |t, e| t.is_finite() && e.is_finite()) {
        chart
            .plotting_area()
            .draw(&PathElement::new(
                part,
                CURVE_PALETTE[0].stroke_width(width),
            ))
            .map_err(chart_err)?;
    }
    if let Some(st) = view.stats {
        let text = format!(
            "median {} m · 90 % {} m · max {} m · {} % below 1 m",
            decimals(st.median_m),
            decimals(st.p90_m),
            decimals(st.max_m),
            decimals(100.0 * st.fraction_below_1m),
        );
        let style = TextStyle::from(("sans-serif", font.ticks * 0.9).into_font())
            .color(&RGBColor(60, 60, 60));
        let pad = (8.0 * s) as i32;
        chart
            .plotting_area()
            .strip_coord_spec()
            .draw_text(&text, &style, (pad, pad))
            .map_err(chart_err)?;
    }
    if let Some(n) = note {
        centred_note(&chart, n, font)?;
    }
    frame_plot(&chart)?;
    Ok(PlotBox::of(&chart, t))
}
