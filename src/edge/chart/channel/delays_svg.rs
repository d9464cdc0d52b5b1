//! The delay figure as SVG with its image layers rasterised ([`delays_svg`]): each panel's
//! image, static bands and estimates become one embedded PNG under the vector layers.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use plotters::prelude::*;

use super::super::{chart_err, ChartError};
use crate::math::{round, sqrt, Real};
use crate::present::{DelayFigure, DelayImage, LinkDelays, StaticBand};

use super::delays::{
    column_edges, delays_scale, draw_delays_with, estimate_radius, estimate_rgb, grey, image_range,
    rate_tick, rate_tick_half_px, Layers, STATIC_BAND_ALPHA,
};
use super::shared::{axis, ChannelChartOptions, STATIC_RGB};

/// The delay figure as SVG text of `size` px with each link's image, static bands and
/// estimates as ONE embedded PNG per panel at its plot's pixel resolution ([`super::super::raster`],
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
        raster_ticks(&mut rgb, (w, h), link, b.t_range_s, range, font_s);
        raster_estimates(
            &mut rgb,
            (w, h),
            link,
            b.t_range_s,
            range,
            estimate_radius(font_s),
        );
        let png = super::super::raster::encode_png(w, h, &rgb)
            .ok_or_else(|| ChartError(format!("{}: the image could not be encoded", link.name)))?;
        images.push(((b.x_px[0], b.y_px[0], w as i32, h as i32), png));
    }
    super::super::raster::embed_pngs(&svg, &images)
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

/// The range-rate ticks of the estimates inside the axes ([`rate_tick`], issue 42 §5) over
/// `rgb` (a `w × h` plot spanning `[t0, t1] × [r0, r1]`, row 0 at `r1`), as the vector panel
/// draws them: segments of the vector line's width, each pixel covered in proportion to its
/// distance from the segment (anti-aliased), in the estimate's colour.
fn raster_ticks(
    rgb: &mut [u8],
    (w, h): (usize, usize),
    link: &LinkDelays,
    [t0, t1]: [Real; 2],
    [r0, r1]: [Real; 2],
    font_s: f64,
) {
    let half_width = 0.5 * round(1.6 * font_s).max(1.0);
    let half_px = rate_tick_half_px(font_s);
    let px = |(t, r): (Real, Real)| {
        (
            (t - t0) / (t1 - t0) * w as Real,
            (r1 - r) / (r1 - r0) * h as Real,
        )
    };
    for e in &link.estimates {
        if !((t0..=t1).contains(&e.t_s) && (r0..=r1).contains(&e.range_m)) {
            continue;
        }
        let Some([a, b]) = rate_tick(e, [t0, t1], [r0, r1], (w as Real, h as Real), half_px) else {
            continue;
        };
        let ((ax, ay), (bx, by)) = (px(a), px(b));
        let RGBColor(cr, cg, cb) = estimate_rgb(&link.statics, e.range_m);
        let reach = half_width + 1.0;
        let (x0, x1) = (
            (ax.min(bx) - reach).max(0.0) as usize,
            ((ax.max(bx) + reach).max(0.0) as usize).min(w),
        );
        let (y0, y1) = (
            (ay.min(by) - reach).max(0.0) as usize,
            ((ay.max(by) + reach).max(0.0) as usize).min(h),
        );
        let (dx, dy) = (bx - ax, by - ay);
        let len2 = dx * dx + dy * dy;
        for y in y0..y1 {
            for x in x0..x1 {
                let (qx, qy) = (x as Real + 0.5 - ax, y as Real + 0.5 - ay);
                let u = if len2 > 0.0 {
                    ((qx * dx + qy * dy) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (ex, ey) = (qx - u * dx, qy - u * dy);
                let cover = (half_width + 0.5 - sqrt(ex * ex + ey * ey)).clamp(0.0, 1.0);
                if cover > 0.0 {
                    let p = &mut rgb[3 * (y * w + x)..3 * (y * w + x) + 3];
                    for (c, v) in p.iter_mut().zip([cr, cg, cb]) {
                        *c = blend(*c, v, cover);
                    }
                }
            }
        }
    }
}

/// The image `img` as RGB pixels of a `w × h` plot spanning `[t0, t1] × [r0, r1]` (row 0 at
/// `r1`, the top): each pixel's centre takes the grey of the column and row it falls in (the
/// columns' edges of [`draw_image`]), white outside the image.
pub(super) fn image_rgb(
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
