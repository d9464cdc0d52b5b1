//! The delay figure, \[S\] Fig. 4 per link ([`draw_delays`]): the response's delay profile as a
//! grey image with its one colour bar, the path estimates as blue dots, grey inside a static
//! cluster, the static clusters as grey bands, the true paths dashed on top, path length against
//! time on a range axis robust to outliers.

use alloc::format;
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::super::layout::{font_scale, frame_plot, segments, series_legend, titled_body, Fonts};
use super::super::panel::{draw_axes, legend_entry, Chart};
use super::super::{chart_err, register_fonts, ChartError, CURVE_PALETTE};
use crate::math::Real;
use crate::present::{linear_ticks, DelayFigure, DelayImage, DelayPoint, LinkDelays, StaticBand};

use super::shared::{axis, centred_note, ChannelChartOptions, PlotBox, STATIC_RGB, TRUTH_RGB};

/// Grey levels of the image are quantised to this many steps (fewer, larger rectangles).
const GREY_STEPS: Real = 32.0;

/// A size for the delay figure of `links` panels: two columns from two links on (1400 × 900
/// for 2 × 2), one panel 1000 × 620.
pub fn delays_size(links: usize) -> (u32, u32) {
    match links {
        0 | 1 => (1000, 620),
        n => {
            let rows = n.div_ceil(2).min(8) as u32;
            (1400, 120 + 390 * rows)
        }
    }
}

/// The grey of image value `v` on `[lo, hi]` dB: white at `lo`, near black at `hi`.
pub(super) fn grey(v: Real, lo: Real, hi: Real) -> RGBColor {
    let f = if hi > lo {
        ((v - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let f = (f * GREY_STEPS).round() / GREY_STEPS;
    let g = (255.0 - 215.0 * f) as u8;
    RGBColor(g, g, g)
}

/// Draws the delay figure onto `root` (filled white first): the title band, one panel per link
/// (two columns from two links on) on the figure's time axis, and on the right ONE colour bar,
/// the image's (grey, one scale for every link). In each panel, bottom to top: the response's
/// delay profile (grey), the static clusters (grey bands), the estimates (blue dots; grey
/// inside a static cluster's ±3σ, as the tracker gates them: E4), the estimates beyond the
/// axis as triangles at its edge (the axis is robust to outliers:
/// [`crate::present::suggest_range_m`]), the truth (vermillion dashes over a white halo, so it
/// shows over the estimates). A link without estimates says so; a figure without links says
/// `no links`. Does not call `present()`.
pub fn draw_delays<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &DelayFigure,
    opts: &ChannelChartOptions,
) -> Result<(), ChartError> {
    draw_delays_boxes(root, fig, opts).map(|_| ())
}

/// As [`draw_delays`], returning each link panel's [`PlotBox`] (in the order of `fig.links`).
pub fn draw_delays_boxes<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &DelayFigure,
    opts: &ChannelChartOptions,
) -> Result<Vec<PlotBox>, ChartError> {
    draw_delays_with(root, fig, opts, Layers::Vector, true)
}

/// As [`draw_delays_boxes`] without the legend in the first panel (the page shows its own,
/// with the time cursor it draws over the chart).
pub fn draw_delays_panels<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &DelayFigure,
    opts: &ChannelChartOptions,
) -> Result<Vec<PlotBox>, ChartError> {
    draw_delays_with(root, fig, opts, Layers::Vector, false)
}

/// Colour of the estimates.
pub(super) const ESTIMATE_RGB: RGBColor = CURVE_PALETTE[0];
/// Colour of the estimates inside a static cluster's ±3σ (the static paths).
pub(super) const STATIC_ESTIMATE_RGB: RGBColor = RGBColor(150, 150, 150);
/// Opacity of the static bands over the image.
pub(super) const STATIC_BAND_ALPHA: f64 = 0.3;

/// How the image, the bands and the estimates of a panel are drawn.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Layers {
    /// As plotters elements (a canvas, a PNG, the vector figure of the tests).
    Vector,
    /// Not at all: the caller puts them under the panel as one raster image ([`delays_svg`]).
    Raster,
}

/// Whether an estimate at `range_m` lies inside one of `statics` (a static cluster's ±3σ,
/// where the tracker gates it away: E4).
fn in_static_band(statics: &[StaticBand], range_m: Real) -> bool {
    statics
        .iter()
        .any(|b| (range_m - b.mean_m).abs() <= b.halfwidth_m)
}

/// The colour of an estimate at `range_m`: grey inside a static band, else blue.
pub(super) fn estimate_rgb(statics: &[StaticBand], range_m: Real) -> RGBColor {
    if in_static_band(statics, range_m) {
        STATIC_ESTIMATE_RGB
    } else {
        ESTIMATE_RGB
    }
}

/// The radius of an estimate's dot at font scale `s`, px.
pub(super) fn estimate_radius(s: f64) -> i32 {
    (2.6 * s).round().max(1.0) as i32
}

/// Half the length of a range-rate tick at font scale `s`, px.
pub(super) fn rate_tick_half_px(s: f64) -> Real {
    (9.0 * s).max(3.0)
}

/// The range-rate tick of `e` (issue 42 §5) on a plot of `w × h` px spanning `[t0, t1] ×
/// [r0, r1]`: the segment through `(t, c·τ)` with the slope `d(c·τ)/dt = ṙ`, `half_px` long on
/// each side *on screen* (so a fast and a slow path get ticks of one length, their angle the
/// rate), as data coordinates `[(t_a, r_a), (t_b, r_b)]`; `None` without a rate or on a
/// degenerate plot.
pub(super) fn rate_tick(
    e: &DelayPoint,
    [t0, t1]: [Real; 2],
    [r0, r1]: [Real; 2],
    (w, h): (Real, Real),
    half_px: Real,
) -> Option<[(Real, Real); 2]> {
    let [rate, _] = e.range_rate_mps?;
    // Pixels per second along t and per metre along r.
    let (kt, kr) = (w / (t1 - t0), h / (r1 - r0));
    let norm = crate::math::sqrt(kt * kt + rate * kr * (rate * kr));
    if !(norm.is_finite() && norm > 0.0) {
        return None;
    }
    let dt = half_px / norm;
    Some([
        (e.t_s - dt, e.range_m - rate * dt),
        (e.t_s + dt, e.range_m + rate * dt),
    ])
}

/// The `cols + 1` time edges of the image's columns: half-way between neighbouring columns'
/// times, half a spacing beyond the first and last (`span/2` for a single column).
pub(super) fn column_edges(img: &DelayImage, span: Real) -> Vec<Real> {
    let t = &img.t_s;
    let cols = t.len();
    let half = if cols > 1 {
        0.5 * (t[1] - t[0])
    } else {
        0.5 * span
    };
    (0..=cols)
        .map(|i| {
            if i == 0 {
                t[0] - half
            } else if i == cols {
                t[cols - 1]
                    + if cols > 1 {
                        0.5 * (t[cols - 1] - t[cols - 2])
                    } else {
                        half
                    }
            } else {
                0.5 * (t[i - 1] + t[i])
            }
        })
        .collect()
}

/// The font scale of the delay figure of `links` panels on a `w × h` figure.
pub(super) fn delays_scale((w, h): (u32, u32), links: usize) -> f64 {
    let ncols = if links > 1 { 2 } else { 1 };
    let nrows = links.div_ceil(ncols).max(1);
    (w as f64 / ncols as f64 / 640.0)
        .min(h as f64 / nrows as f64 / 380.0)
        .clamp(0.5, 4.0)
        .min(font_scale(w, h))
}

/// [`draw_delays_boxes`], the images, bands and estimates drawn as `layers` says, the legend in
/// the first panel when `legend`.
pub(super) fn draw_delays_with<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &DelayFigure,
    opts: &ChannelChartOptions,
    layers: Layers,
    legend: bool,
) -> Result<Vec<PlotBox>, ChartError> {
    register_fonts();
    for l in &fig.links {
        if let Some(img) = &l.image {
            if img.db.len() != img.rows * img.cols() {
                return Err(ChartError(format!(
                    "{}: image has {} values for {} rows × {} columns",
                    l.name,
                    img.db.len(),
                    img.rows,
                    img.cols()
                )));
            }
        }
    }
    let (w, h) = root.dim_in_pixel();
    let n = fig.links.len();
    let ncols = if n > 1 { 2 } else { 1 };
    let nrows = n.div_ceil(ncols).max(1);
    let s = delays_scale((w, h), n);
    let (font, body) = titled_body(root, s, &opts.title, opts.subtitle.as_deref())?;
    let (bw, bh) = body.dim_in_pixel();
    let grey_range = image_range(&fig.links);
    let bars_w = if grey_range.is_some() {
        (((24.0 + 16.0) * s + 3.0 * font.ticks + 1.4 * font.axis) as u32).min(bw / 4)
    } else {
        0
    };
    let (panels, bar) = body.split_horizontally(bw.saturating_sub(bars_w));
    if n == 0 {
        let style = TextStyle::from(("sans-serif", font.axis).into_font())
            .pos(Pos::new(HPos::Center, VPos::Center));
        panels
            .draw_text(
                "no links",
                &style,
                ((bw - bars_w) as i32 / 2, bh as i32 / 2),
            )
            .map_err(chart_err)?;
    }
    let areas = panels.split_evenly((nrows, ncols));
    let mut boxes = Vec::with_capacity(fig.links.len());
    for (k, (area, link)) in areas.iter().zip(&fig.links).enumerate() {
        boxes.push(draw_link(
            area,
            fig,
            link,
            grey_range,
            layers,
            legend && k == 0,
            &font,
            s,
        )?);
    }
    if let Some(r) = grey_range {
        let bar_h = (bh as f64 * 0.8) as u32;
        let bar = bar.shrink((0, (bh - bar_h) as i32 / 2), (bars_w, bar_h));
        draw_db_bar(
            &bar,
            r,
            |v| grey(v, r[0], r[1]),
            "response power (dB)",
            &font,
        )?;
    }
    Ok(boxes)
}

/// The shared scale of the images: from the lowest floor to the highest maximum, dB.
pub(super) fn image_range(links: &[LinkDelays]) -> Option<[Real; 2]> {
    let (lo, hi) = links
        .iter()
        .filter_map(|l| l.image.as_ref())
        .map(|i| i.db_range)
        .filter(|r| r[0].is_finite() && r[1].is_finite())
        .fold((Real::INFINITY, Real::NEG_INFINITY), |(a, b), r| {
            (a.min(r[0]), b.max(r[1]))
        });
    (lo.is_finite() && hi > lo).then_some([lo, hi])
}

/// One link's panel.
#[allow(clippy::too_many_arguments)]
fn draw_link<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    fig: &DelayFigure,
    link: &LinkDelays,
    grey_range: Option<[Real; 2]>,
    layers: Layers,
    legend: bool,
    font: &Fonts,
    s: f64,
) -> Result<PlotBox, ChartError> {
    let [t0, t1] = axis(fig.t_range_s);
    let [r0, r1] = axis(link.range_m);
    let mut chart = ChartBuilder::on(area)
        .caption(&link.name, ("sans-serif", font.axis * 1.05).into_font())
        .margin((8.0 * s) as u32)
        .x_label_area_size((font.ticks + font.axis + 20.0 * s) as u32)
        .y_label_area_size((2.6 * font.ticks + font.axis + 20.0 * s) as u32)
        .build_cartesian_2d(t0..t1, r0..r1)
        .map_err(chart_err)?;
    draw_axes(
        &mut chart,
        font,
        ["time t (s)", "path length c·τ (m)"],
        [8, 7],
        None,
    )?;
    let vector = layers == Layers::Vector;
    if let (Some(img), Some(g), true) = (&link.image, grey_range, vector) {
        draw_image(&mut chart, img, g, [t0, t1, r0, r1])?;
    }
    for (k, b) in link.statics.iter().enumerate() {
        let (lo, hi) = (
            (b.mean_m - b.halfwidth_m).max(r0),
            (b.mean_m + b.halfwidth_m).min(r1),
        );
        if lo.partial_cmp(&hi) != Some(core::cmp::Ordering::Less) {
            continue;
        }
        if vector {
            chart
                .draw_series([Rectangle::new(
                    [(t0, lo), (t1, hi)],
                    STATIC_RGB.mix(STATIC_BAND_ALPHA).filled(),
                )])
                .map_err(chart_err)?;
            if (r0..=r1).contains(&b.mean_m) {
                chart
                    .draw_series([PathElement::new(
                        [(t0, b.mean_m), (t1, b.mean_m)],
                        STATIC_RGB.stroke_width(1),
                    )])
                    .map_err(chart_err)?;
            }
        }
        if legend && k == 0 {
            let sz = (6.0 * s) as i32;
            legend_entry(&mut chart, "static cluster ±3σ", move |(x, y)| {
                Rectangle::new(
                    [(x - 2 * sz, y - sz / 2), (x + 2 * sz, y + sz / 2)],
                    STATIC_RGB.mix(0.5).filled(),
                )
            })?;
        }
    }
    // The estimates: inside the axes as dots, beyond it (outliers the robust axis leaves out)
    // as triangles at its edge, one per few pixels of time.
    let radius = estimate_radius(s);
    let inside = |e: &&DelayPoint| (t0..=t1).contains(&e.t_s) && (r0..=r1).contains(&e.range_m);
    let has_rates = link.estimates.iter().any(|e| e.range_rate_mps.is_some());
    let tick_width = (1.6 * s).round().max(1.0) as u32;
    if vector && has_rates {
        let (w, h) = chart.plotting_area().dim_in_pixel();
        let half = rate_tick_half_px(s);
        let ticks = link.estimates.iter().filter(inside).filter_map(|e| {
            let seg = rate_tick(e, [t0, t1], [r0, r1], (w as Real, h as Real), half)?;
            let rgb = estimate_rgb(&link.statics, e.range_m);
            Some(PathElement::new(seg, rgb.stroke_width(tick_width)))
        });
        chart.draw_series(ticks).map_err(chart_err)?;
    }
    if vector {
        chart
            .draw_series(link.estimates.iter().filter(inside).map(|e| {
                Circle::new(
                    (e.t_s, e.range_m),
                    radius,
                    estimate_rgb(&link.statics, e.range_m).filled(),
                )
            }))
            .map_err(chart_err)?;
    }
    if legend && !link.estimates.is_empty() {
        legend_entry(&mut chart, "estimate", move |(x, y)| {
            Circle::new((x, y), radius + 1, ESTIMATE_RGB.filled())
        })?;
        if has_rates {
            let d = rate_tick_half_px(s) as i32 * 2 / 3;
            legend_entry(
                &mut chart,
                "range rate ṙ = slope of the tick",
                move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(
                            [(-d, d / 2), (d, -d / 2)],
                            ESTIMATE_RGB.stroke_width(tick_width),
                        )
                        + Circle::new((0, 0), radius, ESTIMATE_RGB.filled())
                },
            )?;
        }
        if link
            .estimates
            .iter()
            .any(|e| in_static_band(&link.statics, e.range_m))
        {
            legend_entry(&mut chart, "estimate in a static cluster", move |(x, y)| {
                Circle::new((x, y), radius + 1, STATIC_ESTIMATE_RGB.filled())
            })?;
        }
    }
    let off = draw_clipped(&chart, link, [t0, t1], [r0, r1], radius + 1)?;
    if off > 0 {
        // Bottom left: the first panel's legend sits upper right and can span the width.
        let style = TextStyle::from(("sans-serif", font.ticks * 0.8).into_font())
            .color(&ESTIMATE_RGB)
            .pos(Pos::new(HPos::Left, VPos::Bottom));
        let pad = (6.0 * s) as i32;
        let label = format!("{off} off the axis (marked at its edge)");
        let area = chart.plotting_area().strip_coord_spec();
        let (_, h) = area.dim_in_pixel();
        // On a white box: the response image beneath can be dark.
        let (w_text, h_text) = area.estimate_text_size(&label, &style).map_err(chart_err)?;
        let (x, y) = (pad, h as i32 - pad);
        let m = (2.0 * s) as i32;
        area.draw(&Rectangle::new(
            [
                (x - m, y - h_text as i32 - m),
                (x + w_text as i32 + m, y + m),
            ],
            WHITE.mix(0.85).filled(),
        ))
        .map_err(chart_err)?;
        area.draw_text(&label, &style, (x, y)).map_err(chart_err)?;
    }
    // The truth on top: a white halo under vermillion dashes.
    let width = (2.0 * s).round().max(1.0) as u32;
    let (dash, gap) = ((8.0 * s) as u32, (5.0 * s) as u32);
    let mut kinds: Vec<&str> = Vec::new();
    for c in &link.truth {
        let (style, halo) = if c.primary {
            (
                TRUTH_RGB.stroke_width(width),
                WHITE
                    .mix(0.85)
                    .stroke_width(width + 2 * (s.round().max(1.0) as u32)),
            )
        } else {
            (
                TRUTH_RGB.mix(0.45).stroke_width(width.div_ceil(2)),
                WHITE.mix(0.6).stroke_width(width.div_ceil(2) + 2),
            )
        };
        let inside = |t: Real, r: Real| t.is_finite() && r.is_finite() && (r0..=r1).contains(&r);
        for part in segments(c.points.iter().copied(), inside) {
            chart
                .draw_series(LineSeries::new(part.iter().copied(), halo))
                .map_err(chart_err)?;
            chart
                .draw_series(DashedLineSeries::new(part, dash, gap, style))
                .map_err(chart_err)?;
        }
        if legend && !kinds.contains(&c.kind.as_str()) {
            kinds.push(&c.kind);
            legend_entry(&mut chart, &format!("truth: {}", c.kind), move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new([(-12, 0), (-3, 0)], style)
                    + PathElement::new([(3, 0), (12, 0)], style)
            })?;
        }
    }
    if link.estimates.is_empty() {
        centred_note(&chart, "no estimates", font)?;
    }
    if legend {
        series_legend(
            &mut chart,
            SeriesLabelPosition::UpperRight,
            font.ticks * 0.85,
            6.0 * s,
            0.85,
        )?;
    }
    frame_plot(&chart)?;
    Ok(PlotBox::of(&chart, [t0, t1]))
}

/// The estimates of `link` beyond the range axis `[r0, r1]` (within the time axis) as
/// triangles of `size` px at its edge (pointing up at the top, down at the bottom), one per
/// 3 px of time and edge; returns how many estimates are beyond.
fn draw_clipped<DB: DrawingBackend>(
    chart: &Chart<'_, DB>,
    link: &LinkDelays,
    [t0, t1]: [Real; 2],
    [r0, r1]: [Real; 2],
    size: i32,
) -> Result<usize, ChartError> {
    let (w, _) = chart.plotting_area().dim_in_pixel();
    let mut seen: Vec<(bool, i64)> = Vec::new();
    let mut off = 0;
    for e in &link.estimates {
        if !(t0..=t1).contains(&e.t_s) || (r0..=r1).contains(&e.range_m) || !e.range_m.is_finite() {
            continue;
        }
        off += 1;
        let up = e.range_m > r1;
        let bucket = ((e.t_s - t0) / (t1 - t0) * w as Real / 3.0) as i64;
        if seen.contains(&(up, bucket)) {
            continue;
        }
        seen.push((up, bucket));
        // The tip on the edge, pointing out of the plot, the base inside.
        let (edge, base) = if up {
            (r1, size + size / 2)
        } else {
            (r0, -(size + size / 2))
        };
        let tri = alloc::vec![(0, 0), (-size, base), (size, base)];
        chart
            .plotting_area()
            .draw(
                &(EmptyElement::at((e.t_s, edge))
                    + Polygon::new(tri, estimate_rgb(&link.statics, e.range_m).filled())),
            )
            .map_err(chart_err)?;
    }
    Ok(off)
}

/// The image in data coordinates: per column (from the middle between its time and its
/// neighbours'), runs of rows of one grey merged into one rectangle.
fn draw_image<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    img: &DelayImage,
    [lo, hi]: [Real; 2],
    [t0, t1, r0, r1]: [Real; 4],
) -> Result<(), ChartError> {
    let cols = img.cols();
    if cols == 0 || img.rows == 0 {
        return Ok(());
    }
    let edges = column_edges(img, t1 - t0);
    let edge = |i: usize| edges[i];
    let clamp_t = |v: Real| v.clamp(t0, t1);
    let row_edge = |j: usize| (img.r0_m + (j as Real - 0.5) * img.dr_m).clamp(r0, r1);
    let mut cells = Vec::new();
    for i in 0..cols {
        let (x0, x1) = (clamp_t(edge(i)), clamp_t(edge(i + 1)));
        if x0.partial_cmp(&x1) != Some(core::cmp::Ordering::Less) {
            continue;
        }
        let mut start = 0;
        for j in 1..=img.rows {
            let c = grey(img.db[start * cols + i], lo, hi);
            if j < img.rows && grey(img.db[j * cols + i], lo, hi) == c {
                continue;
            }
            let (y0, y1) = (row_edge(start), row_edge(j));
            if y1 > y0 && c != RGBColor(255, 255, 255) {
                cells.push(Rectangle::new([(x0, y0), (x1, y1)], c.filled()));
            }
            start = j;
        }
    }
    chart.draw_series(cells).map_err(chart_err)?;
    Ok(())
}

/// A vertical linear colour bar over `[lo, hi]` dB with ticks and a rotated label.
fn draw_db_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    [lo, hi]: [Real; 2],
    colour: impl Fn(Real) -> RGBColor,
    label: &str,
    font: &Fonts,
) -> Result<(), ChartError> {
    let s = font.ticks / 20.0;
    let (w, h) = area.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    let bar_w = (22.0 * s).round() as i32;
    let steps = h.clamp(1, 256);
    for k in 0..steps {
        let (y0, y1) = (k * h / steps, ((k + 1) * h / steps + 1).min(h));
        let v = hi - (k as Real + 0.5) / steps as Real * (hi - lo);
        area.draw(&Rectangle::new([(0, y0), (bar_w, y1)], colour(v).filled()))
            .map_err(chart_err)?;
    }
    area.draw(&Rectangle::new(
        [(0, 0), (bar_w, h - 1)],
        BLACK.stroke_width(1),
    ))
    .map_err(chart_err)?;
    let tick_font = TextStyle::from(("sans-serif", font.ticks).into_font())
        .pos(Pos::new(HPos::Left, VPos::Center));
    let max_labels = ((h as Real) / (2.2 * font.ticks)).max(2.0) as usize;
    for t in linear_ticks(lo, hi, max_labels) {
        let y = ((hi - t.value) / (hi - lo) * h as Real).round() as i32;
        let len = (6.0 * s).round() as i32;
        area.draw(&PathElement::new(
            [(bar_w, y), (bar_w + len, y)],
            BLACK.stroke_width(1),
        ))
        .map_err(chart_err)?;
        area.draw_text(&t.label, &tick_font, (bar_w + len + (3.0 * s) as i32, y))
            .map_err(chart_err)?;
    }
    let rotated = TextStyle::from(("sans-serif", font.axis * 0.9).into_font())
        .transform(FontTransform::Rotate270)
        .pos(Pos::new(HPos::Center, VPos::Center));
    area.draw_text(label, &rotated, (w - (0.6 * font.axis) as i32, h / 2))
        .map_err(chart_err)
}
