//! The track figure, \[S\] Figs. 5–6 ([`draw_track_errors`]): the track on the map, the position
//! error over time and its empirical CDF with the 90 % point.

use alloc::format;
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::super::layout::{frame_plot, series_legend, titled_body, Fonts};
use super::super::overlay::{
    draw_overlay, MapOverlay, OverlayLine, OverlayMark, OverlayMarkKind, OverlayPath,
};
use super::super::panel::{check_area, draw_axes, draw_nodes, ChartNode};
use super::super::{chart_err, register_fonts, ChartError, CURVE_PALETTE};
use crate::math::Real;
use crate::present::TrackErrorView;
use crate::scenario::Area;

use super::error_time::{draw_error_time, error_note, error_top};
use super::shared::{
    centred_note, chart_dashed, curve_chart, decimals, ChannelChartOptions, LOST_RGB, TRUTH_RGB,
};

/// A size for the track figure: 1400 × 720.
pub fn track_errors_size() -> (u32, u32) {
    (1400, 720)
}

/// `area` widened about its centre so that it fills a `pw × ph` pixel plot at equal scale.
fn equal_scale(area: &Area, pw: f64, ph: f64) -> ([Real; 2], [Real; 2]) {
    let (xs, ys) = (area.x[1] - area.x[0], area.y[1] - area.y[0]);
    let (cx, cy) = (0.5 * (area.x[0] + area.x[1]), 0.5 * (area.y[0] + area.y[1]));
    let aspect = (pw / ph.max(1.0)).max(1e-3);
    if xs / ys > aspect {
        let ys = xs / aspect;
        (area.x, [cy - 0.5 * ys, cy + 0.5 * ys])
    } else {
        let xs = ys * aspect;
        ([cx - 0.5 * xs, cx + 0.5 * xs], area.y)
    }
}

/// Draws the track figure onto `root` (filled white first): on the left the map of `area` at
/// equal scale with `nodes`, the true path (dashed) and the estimated track; on the right the
/// position error `‖r̂ − r‖` over time and its empirical CDF with the 90 % point marked and its
/// value printed. A track that never starts, or no truth, is said in words (no curve). Does not
/// call `present()`.
pub fn draw_track_errors<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    view: &TrackErrorView,
    nodes: &[ChartNode],
    area: &Area,
    opts: &ChannelChartOptions,
) -> Result<(), ChartError> {
    register_fonts();
    check_area(area)?;
    let (w, h) = root.dim_in_pixel();
    let s = (w as f64 / 1400.0).min(h as f64 / 640.0).clamp(0.5, 4.0);
    let (font, body) = titled_body(root, s, &opts.title, opts.subtitle.as_deref())?;
    let (bw, _) = body.dim_in_pixel();
    let (left, right) = body.split_horizontally(bw * 52 / 100);
    draw_track_map(&left, view, nodes, area, &font, s)?;
    let (top, bottom) = {
        let (_, rh) = right.dim_in_pixel();
        right.split_vertically(rh / 2)
    };
    let note = error_note(view);
    draw_error_time(&top, view, note, &font, s)?;
    draw_error_cdf(&bottom, view, note, &font, s)
}

fn draw_track_map<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    view: &TrackErrorView,
    nodes: &[ChartNode],
    map: &Area,
    font: &Fonts,
    s: f64,
) -> Result<(), ChartError> {
    let (w, h) = area.dim_in_pixel();
    let (xl, yl, m) = (
        font.ticks + font.axis + 20.0 * s,
        2.4 * font.ticks + font.axis + 20.0 * s,
        10.0 * s,
    );
    let (x, y) = equal_scale(map, w as f64 - yl - 2.0 * m, h as f64 - xl - 2.0 * m);
    let mut chart = ChartBuilder::on(area)
        .margin(m as u32)
        .x_label_area_size(xl as u32)
        .y_label_area_size(yl as u32)
        .build_cartesian_2d(x[0]..x[1], y[0]..y[1])
        .map_err(chart_err)?;
    draw_axes(&mut chart, font, ["x (m)", "y (m)"], [8, 8], None)?;
    let mut overlay = MapOverlay::default();
    let path = |label: &str, k: usize, run: &Vec<[Real; 2]>, line| OverlayPath {
        label: (k == 0).then(|| label.into()),
        points_m: run.clone(),
        closed: false,
        line,
    };
    overlay.paths.extend(
        view.truth_m
            .iter()
            .enumerate()
            .map(|(k, r)| path("truth", k, r, OverlayLine::Truth)),
    );
    overlay.paths.extend(
        view.track_m
            .iter()
            .enumerate()
            .map(|(k, r)| path("track", k, r, OverlayLine::Track)),
    );
    if let Some(p) = view.track_m.first().and_then(|r| r.first()) {
        overlay.marks.push(OverlayMark {
            label: Some("track start".into()),
            position_m: *p,
            kind: OverlayMarkKind::Start,
        });
    }
    draw_overlay(&mut chart, &overlay, font.nodes)?;
    // Where each lost segment ended: a red ring.
    let ring = (6.0 * s).round().max(3.0) as i32;
    for p in view.segments.iter().filter_map(|g| g.lost_m) {
        chart
            .plotting_area()
            .draw(&Circle::new(
                (p[0], p[1]),
                ring,
                LOST_RGB.stroke_width((2.0 * s).round().max(1.0) as u32),
            ))
            .map_err(chart_err)?;
    }
    draw_nodes(&mut chart, nodes, font.nodes)?;
    if nodes.is_empty() && !overlay.is_empty() {
        series_legend(
            &mut chart,
            SeriesLabelPosition::UpperRight,
            font.ticks * 0.9,
            8.0 * s,
            0.85,
        )?;
    }
    if view.track_m.is_empty() {
        centred_note(&chart, "no track", font)?;
    }
    frame_plot(&chart)
}

fn draw_error_cdf<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    view: &TrackErrorView,
    note: Option<&str>,
    font: &Fonts,
    s: f64,
) -> Result<(), ChartError> {
    let top = error_top(view);
    let chart = curve_chart(
        area,
        [0.0, top],
        [0.0, 1.0],
        ("position error e (m)", "empirical CDF F(e)"),
        font,
        s,
    )?;
    let width = (2.0 * s).round().max(1.0) as u32;
    let plot = chart.plotting_area();
    if !view.cdf.is_empty() {
        let mut steps = Vec::with_capacity(2 * view.cdf.len() + 2);
        let mut prev = 0.0;
        steps.push((0.0, 0.0));
        for &(e, f) in &view.cdf {
            steps.push((e, prev));
            steps.push((e, f));
            prev = f;
        }
        steps.push((top, prev));
        plot.draw(&PathElement::new(
            steps,
            CURVE_PALETTE[0].stroke_width(width),
        ))
        .map_err(chart_err)?;
    }
    if let Some(st) = view.stats {
        let p90 = st.p90_m;
        let dashed = TRUTH_RGB.stroke_width(width.div_ceil(2));
        let (d, g) = ((6.0 * s) as u32, (4.0 * s) as u32);
        chart_dashed(plot, [(0.0, 0.9), (p90, 0.9)], d, g, dashed)?;
        chart_dashed(plot, [(p90, 0.0), (p90, 0.9)], d, g, dashed)?;
        let r = (5.0 * s).round().max(2.0) as i32;
        let label = format!("90 %: {} m", decimals(p90));
        let style = TextStyle::from(("sans-serif", font.ticks).into_font()).color(&TRUTH_RGB);
        // The label right of the marker, or left of it near the right edge.
        let dx = if p90 > 0.6 * top {
            -(r + (6.5 * font.ticks) as i32)
        } else {
            r + 4
        };
        plot.draw(
            &(EmptyElement::at((p90, 0.9))
                + Circle::new((0, 0), r, TRUTH_RGB.filled())
                + Text::new(label, (dx, -(font.ticks as i32) - r), style)),
        )
        .map_err(chart_err)?;
    }
    if let Some(n) = note {
        centred_note(&chart, n, font)?;
    }
    frame_plot(&chart)
}
