//! The channel front end's figures (issue 25 §4): [`draw_delays`], \[S\] Fig. 4 per link (the
//! response's delay profile as a grey image with its one colour bar, the path estimates as blue
//! dots, grey inside a static cluster, the static clusters as grey bands, the true paths dashed
//! on top, path length against time on a range axis robust to outliers), and
//! [`draw_track_errors`], \[S\] Figs. 5–6 (the track on the map, the position error over time
//! and its empirical CDF with the 90 % point). Both draw a [`crate::present`] view on any
//! plotters [`DrawingBackend`].

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::layout::{font_scale, frame_plot, segments, series_legend, titled_body, Fonts};
use super::overlay::{
    draw_overlay, MapOverlay, OverlayLine, OverlayMark, OverlayMarkKind, OverlayPath,
};
use super::panel::{check_area, draw_axes, draw_nodes, legend_entry, Chart, ChartNode};
use super::{chart_err, register_fonts, ChartError, CURVE_PALETTE};
use crate::math::{round, sqrt, Real};
use crate::present::{
    linear_ticks, DelayFigure, DelayImage, LinkDelays, StaticBand, TrackErrorView,
};
use crate::scenario::Area;

/// Colour of the true paths (the figures' red).
const TRUTH_RGB: RGBColor = CURVE_PALETTE[1];
/// Colour of the static bands.
const STATIC_RGB: RGBColor = RGBColor(110, 110, 110);
/// Grey levels of the image are quantised to this many steps (fewer, larger rectangles).
const GREY_STEPS: Real = 32.0;

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
    fn of<DB: DrawingBackend>(chart: &Chart<'_, DB>, t_range_s: [Real; 2]) -> PlotBox {
        let (x, y) = chart.plotting_area().get_pixel_range();
        PlotBox {
            x_px: [x.start, x.end],
            y_px: [y.start, y.end],
            t_range_s,
        }
    }
}

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

/// A size for the track figure: 1400 × 720.
pub fn track_errors_size() -> (u32, u32) {
    (1400, 720)
}

/// The grey of image value `v` on `[lo, hi]` dB: white at `lo`, near black at `hi`.
fn grey(v: Real, lo: Real, hi: Real) -> RGBColor {
    let f = if hi > lo {
        ((v - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let f = (f * GREY_STEPS).round() / GREY_STEPS;
    let g = (255.0 - 215.0 * f) as u8;
    RGBColor(g, g, g)
}

/// A text centred in the plotting area of `chart` (e.g. `no track`).
fn centred_note<DB: DrawingBackend>(
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
fn axis(r: [Real; 2]) -> [Real; 2] {
    if r[0].is_finite() && r[1].is_finite() && r[1] > r[0] {
        r
    } else if r[0].is_finite() {
        [r[0], r[0] + 1.0]
    } else {
        [0.0, 1.0]
    }
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
const ESTIMATE_RGB: RGBColor = CURVE_PALETTE[0];
/// Colour of the estimates inside a static cluster's ±3σ (the static paths).
const STATIC_ESTIMATE_RGB: RGBColor = RGBColor(150, 150, 150);
/// Opacity of the static bands over the image.
const STATIC_BAND_ALPHA: f64 = 0.3;

/// How the image, the bands and the estimates of a panel are drawn.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Layers {
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

/// The delay figure as SVG text of `size` px with each link's image, static bands and
/// estimates as ONE embedded PNG per panel at its plot's pixel resolution ([`super::raster`],
/// a `data:` URI) under the vector layers (axes, truth, clipped estimates' marks, legend,
/// colour bar, text): the file's size depends on the figure's pixels, not on the snapshots or
/// the estimates (a 1528-snapshot recording with 45 000 estimates: 4.4 MB as circles, issue 38
/// item 7; the images alone were 28 MB as rectangles, issue 37 item 11).
pub fn delays_svg(
    size: (u32, u32),
    fig: &DelayFigure,
    opts: &ChannelChartOptions,
) -> Result<String, ChartError> {
    let mut svg = String::new();
    let boxes = {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let boxes = draw_delays_with(&root, fig, opts, Layers::Raster, true)?;
        root.present().map_err(chart_err)?;
        boxes
    };
    let grey_range = image_range(&fig.links);
    let font_s = delays_scale(size, fig.links.len());
    let mut images = Vec::new();
    for (link, b) in fig.links.iter().zip(&boxes) {
        if link.image.is_none() && link.estimates.is_empty() && link.statics.is_empty() {
            continue;
        }
        let (w, h) = (b.x_px[1] - b.x_px[0], b.y_px[1] - b.y_px[0]);
        if w <= 0 || h <= 0 {
            continue;
        }
        let (w, h) = (w as usize, h as usize);
        let range = axis(link.range_m);
        let mut rgb = match (&link.image, grey_range) {
            (Some(img), Some(g)) => image_rgb(img, g, b.t_range_s, range, (w, h)),
            _ => alloc::vec![255u8; 3 * w * h],
        };
        raster_bands(&mut rgb, (w, h), &link.statics, range);
        raster_estimates(
            &mut rgb,
            (w, h),
            link,
            b.t_range_s,
            range,
            estimate_radius(font_s),
        );
        let png = super::raster::encode_png(w, h, &rgb)
            .ok_or_else(|| ChartError(format!("{}: the image could not be encoded", link.name)))?;
        images.push(((b.x_px[0], b.y_px[0], w as i32, h as i32), png));
    }
    super::raster::embed_pngs(&svg, &images)
        .ok_or_else(|| ChartError("the figure has no element to put the images under".into()))
}

/// The static bands over `rgb` (a `w × h` plot spanning `[r0, r1]`, row 0 at `r1`), as the
/// vector panel draws them: each band's rows blended with its grey at
/// [`STATIC_BAND_ALPHA`], its mean a one-pixel grey line.
fn raster_bands(
    rgb: &mut [u8],
    (w, h): (usize, usize),
    statics: &[StaticBand],
    [r0, r1]: [Real; 2],
) {
    let row_of = |r: Real| (r1 - r) / (r1 - r0) * h as Real;
    let RGBColor(sr, sg, sb) = STATIC_RGB;
    for band in statics {
        let (lo, hi) = (
            (band.mean_m - band.halfwidth_m).max(r0),
            (band.mean_m + band.halfwidth_m).min(r1),
        );
        if lo.partial_cmp(&hi) != Some(core::cmp::Ordering::Less) {
            continue;
        }
        let (y0, y1) = (
            round(row_of(hi)) as usize,
            (round(row_of(lo)) as usize).min(h),
        );
        for y in y0..y1 {
            for px in rgb[3 * y * w..3 * (y + 1) * w].chunks_exact_mut(3) {
                for (c, s) in px.iter_mut().zip([sr, sg, sb]) {
                    *c = blend(*c, s, STATIC_BAND_ALPHA);
                }
            }
        }
        if (r0..=r1).contains(&band.mean_m) {
            let y = (row_of(band.mean_m) as usize).min(h - 1);
            for px in rgb[3 * y * w..3 * (y + 1) * w].chunks_exact_mut(3) {
                px.copy_from_slice(&[sr, sg, sb]);
            }
        }
    }
}

/// `a` blended towards `b` by `alpha` (0: `a`, 1: `b`).
fn blend(a: u8, b: u8, alpha: Real) -> u8 {
    round(a as Real + (b as Real - a as Real) * alpha.clamp(0.0, 1.0)) as u8
}

/// The estimates inside the axes as discs of `radius` px over `rgb` (a `w × h` plot spanning
/// `[t0, t1] × [r0, r1]`, row 0 at `r1`), each pixel covered in proportion to its distance from
/// the disc's edge (anti-aliased), blue or, inside a static band, grey.
fn raster_estimates(
    rgb: &mut [u8],
    (w, h): (usize, usize),
    link: &LinkDelays,
    [t0, t1]: [Real; 2],
    [r0, r1]: [Real; 2],
    radius: i32,
) {
    let rad = radius as Real;
    for e in &link.estimates {
        if !((t0..=t1).contains(&e.t_s) && (r0..=r1).contains(&e.range_m)) {
            continue;
        }
        let cx = (e.t_s - t0) / (t1 - t0) * w as Real;
        let cy = (r1 - e.range_m) / (r1 - r0) * h as Real;
        let RGBColor(r, g, b) = estimate_rgb(&link.statics, e.range_m);
        let (x0, x1) = (
            (cx - rad - 1.0).max(0.0) as usize,
            ((cx + rad + 1.0) as usize).min(w),
        );
        let (y0, y1) = (
            (cy - rad - 1.0).max(0.0) as usize,
            ((cy + rad + 1.0) as usize).min(h),
        );
        for y in y0..y1 {
            for x in x0..x1 {
                let (dx, dy) = (x as Real + 0.5 - cx, y as Real + 0.5 - cy);
                let cover = (rad + 0.5 - sqrt(dx * dx + dy * dy)).clamp(0.0, 1.0);
                if cover > 0.0 {
                    let px = &mut rgb[3 * (y * w + x)..3 * (y * w + x) + 3];
                    for (c, v) in px.iter_mut().zip([r, g, b]) {
                        *c = blend(*c, v, cover);
                    }
                }
            }
        }
    }
}

/// The colour of an estimate at `range_m`: grey inside a static band, else blue.
fn estimate_rgb(statics: &[StaticBand], range_m: Real) -> RGBColor {
    if in_static_band(statics, range_m) {
        STATIC_ESTIMATE_RGB
    } else {
        ESTIMATE_RGB
    }
}

/// The radius of an estimate's dot at font scale `s`, px.
fn estimate_radius(s: f64) -> i32 {
    (2.6 * s).round().max(1.0) as i32
}

/// The image `img` as RGB pixels of a `w × h` plot spanning `[t0, t1] × [r0, r1]` (row 0 at
/// `r1`, the top): each pixel's centre takes the grey of the column and row it falls in (the
/// columns' edges of [`draw_image`]), white outside the image.
fn image_rgb(
    img: &DelayImage,
    [lo, hi]: [Real; 2],
    [t0, t1]: [Real; 2],
    [r0, r1]: [Real; 2],
    (w, h): (usize, usize),
) -> Vec<u8> {
    let mut rgb = alloc::vec![255u8; 3 * w * h];
    let cols = img.cols();
    if cols == 0 || img.rows == 0 {
        return rgb;
    }
    let edges = column_edges(img, t1 - t0);
    let col_of: Vec<Option<usize>> = (0..w)
        .map(|x| {
            let t = t0 + (x as Real + 0.5) / w as Real * (t1 - t0);
            let i = edges.partition_point(|&e| e <= t);
            (i >= 1 && i <= cols).then(|| i - 1)
        })
        .collect();
    for y in 0..h {
        let r = r1 - (y as Real + 0.5) / h as Real * (r1 - r0);
        let j = round((r - img.r0_m) / img.dr_m);
        if !(j >= 0.0 && j < img.rows as Real) {
            continue;
        }
        let j = j as usize;
        for (x, c) in col_of.iter().enumerate() {
            if let Some(i) = c {
                let RGBColor(v, _, _) = grey(img.db[j * cols + i], lo, hi);
                rgb[3 * (y * w + x)..3 * (y * w + x) + 3].fill(v);
            }
        }
    }
    rgb
}

/// The `cols + 1` time edges of the image's columns: half-way between neighbouring columns'
/// times, half a spacing beyond the first and last (`span/2` for a single column).
fn column_edges(img: &DelayImage, span: Real) -> Vec<Real> {
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
fn delays_scale((w, h): (u32, u32), links: usize) -> f64 {
    let ncols = if links > 1 { 2 } else { 1 };
    let nrows = links.div_ceil(ncols).max(1);
    (w as f64 / ncols as f64 / 640.0)
        .min(h as f64 / nrows as f64 / 380.0)
        .clamp(0.5, 4.0)
        .min(font_scale(w, h))
}

/// [`draw_delays_boxes`], the images, bands and estimates drawn as `layers` says, the legend in
/// the first panel when `legend`.
fn draw_delays_with<DB: DrawingBackend>(
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
fn image_range(links: &[LinkDelays]) -> Option<[Real; 2]> {
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
    let inside = |e: &&crate::present::DelayPoint| {
        (t0..=t1).contains(&e.t_s) && (r0..=r1).contains(&e.range_m)
    };
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

/// What [`draw_track_errors`] says instead of a curve: `no track` or `no truth` (`None`: the
/// curves are drawn).
fn error_note(view: &TrackErrorView) -> Option<&'static str> {
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

/// A curve panel with linear axes.
fn curve_chart<'a, DB: DrawingBackend>(
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
const LOST_RGB: RGBColor = RGBColor(200, 30, 30);

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
fn error_top(view: &TrackErrorView) -> Real {
    view.stats
        .map_or(1.0, |st| if st.max_m > 0.0 { st.max_m * 1.08 } else { 1.0 })
}

fn draw_error_time<DB: DrawingBackend>(
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

/// A dashed line between two points in data coordinates.
fn chart_dashed<DB: DrawingBackend>(
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
fn decimals(v: Real) -> String {
    if v < 10.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.1}")
    }
}

#[cfg(all(test, not(target_arch = "wasm32")))]
mod tests;
