//! Layout shared by every figure: the pixel layout of the map figure (title band, an equal-scale
//! plot with 1 m in x = 1 m in y centred in the remaining space, the colour bar right of it), the
//! font scale, titles, legends, the plot frame and the curve segments. Everything scales with the
//! image size.

use plotters::coord::{CoordTranslate, Shift};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use alloc::string::{String, ToString};
use alloc::vec::Vec;
use core::fmt;

use crate::math::Real;
use crate::scenario::Area;

/// Font sizes in pixels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Fonts {
    pub title: f64,
    pub subtitle: f64,
    pub axis: f64,
    pub ticks: f64,
    pub nodes: f64,
}

impl Fonts {
    /// The sizes at scale `s` (1 = a 1000 px wide figure).
    pub fn scaled(s: f64) -> Fonts {
        Fonts {
            title: 32.0 * s,
            subtitle: 20.0 * s,
            axis: 23.0 * s,
            ticks: 20.0 * s,
            nodes: 20.0 * s,
        }
    }
}

/// The scale of the fonts for a `w × h` figure (1 at 1000 px wide, bounded by the height).
pub(crate) fn font_scale(w: u32, h: u32) -> f64 {
    (w as f64 / 1000.0).min(h as f64 / 360.0).clamp(0.5, 4.0)
}

/// The title band at the top of a figure, in pixels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TitleBand {
    /// Top of the title text.
    pub title_y: i32,
    /// Top of the subtitle text.
    pub subtitle_y: i32,
    /// Height of the band.
    pub height: f64,
    /// Outer padding of the figure.
    pub pad: f64,
}

impl TitleBand {
    /// The band for fonts `font` at scale `s`, with or without a subtitle.
    pub fn new(s: f64, font: &Fonts, subtitle: bool) -> TitleBand {
        let pad = 12.0 * s;
        TitleBand {
            title_y: pad as i32,
            subtitle_y: (pad + 1.25 * font.title) as i32,
            height: pad
                + 1.25 * font.title
                + if subtitle { 1.35 * font.subtitle } else { 0.0 }
                + 0.5 * pad,
            pad,
        }
    }
}

/// Where everything goes, in pixels of the root area.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    pub font: Fonts,
    pub band: TitleBand,
    pub chart_origin: (i32, i32),
    pub chart_size: (u32, u32),
    pub plot_margin_top: u32,
    pub plot_margin_right: u32,
    pub x_label_area: u32,
    pub y_label_area: u32,
    pub bar_origin: (i32, i32),
    pub bar_size: (u32, u32),
}

fn px(v: f64) -> u32 {
    v.round().max(1.0) as u32
}

impl Layout {
    /// The layout for an image of `root`'s size showing `area`.
    pub fn new<DB: DrawingBackend>(
        root: &DrawingArea<DB, Shift>,
        area: &Area,
        subtitle: bool,
    ) -> Layout {
        let (w, h) = root.dim_in_pixel();
        Layout::for_size(w, h, area, subtitle)
    }

    pub fn for_size(w: u32, h: u32, area: &Area, subtitle: bool) -> Layout {
        let (wf, hf) = (w as f64, h as f64);
        let s = font_scale(w, h);
        let font = Fonts::scaled(s);
        let band = TitleBand::new(s, &font, subtitle);
        let (pad, title_band) = (band.pad, band.height);
        let x_label_area = font.ticks + font.axis + 26.0 * s;
        let y_label_area = 2.2 * font.ticks + font.axis + 26.0 * s;
        let (m_top, m_right) = (10.0 * s, 12.0 * s);
        let gap = 22.0 * s;
        let bar_block = 24.0 * s + 10.0 * s + 4.4 * font.ticks + 12.0 * s + 1.4 * font.axis;
        let avail_w = (wf - 2.0 * pad - y_label_area - m_right - gap - bar_block).max(10.0);
        let avail_h = (hf - title_band - m_top - x_label_area - pad).max(10.0);
        let (xspan, yspan) = (area.x[1] - area.x[0], area.y[1] - area.y[0]);
        let aspect = if xspan > 0.0 && yspan > 0.0 && (xspan / yspan).is_finite() {
            xspan / yspan
        } else {
            1.0
        };
        let (pw, ph) = if avail_w / avail_h > aspect {
            (avail_h * aspect, avail_h)
        } else {
            (avail_w, avail_w / aspect)
        };
        let (pw, ph) = (pw.max(10.0).floor(), ph.max(10.0).floor());
        let block_w = y_label_area + pw + m_right + gap + bar_block;
        let x0 = ((wf - block_w) / 2.0).max(0.0);
        let y0 = title_band + ((avail_h - ph) / 2.0).max(0.0);
        Layout {
            font,
            band,
            chart_origin: (x0 as i32, y0 as i32),
            chart_size: (
                px(y_label_area + pw + m_right),
                px(m_top + ph + x_label_area),
            ),
            plot_margin_top: px(m_top),
            plot_margin_right: px(m_right),
            x_label_area: px(x_label_area),
            y_label_area: px(y_label_area),
            bar_origin: (
                (x0 + y_label_area + pw + m_right + gap) as i32,
                (y0 + m_top) as i32,
            ),
            bar_size: (px(bar_block), px(ph)),
        }
    }
}

/// A figure size `(width, height)` for an image `width` pixels wide whose equal-scale plot of
/// `area` fills the width; the height is kept within 30 %–140 % of the width.
pub fn suggested_size(area: &Area, width: u32) -> (u32, u32) {
    let width = width.clamp(200, 8000);
    let (lo, hi) = (width * 3 / 10, width * 7 / 5);
    // Start tall (the plot is then width-limited) and keep the height it needs; the font scale
    // depends on the height, so settle it in a few rounds.
    let mut height = hi;
    for _ in 0..4 {
        let lay = Layout::for_size(width, height, area, true);
        let needed = lay.band.height + lay.chart_size.1 as f64 + lay.band.pad;
        height = (needed.ceil() as u32).clamp(lo, hi);
    }
    (width, height)
}

/// Fills `root` white, draws the title band (scaled by `s`) and returns the fonts and the area
/// below the band, with side margins: the frame shared by the curve figures.
pub(crate) fn titled_body<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    s: f64,
    title: &str,
    subtitle: Option<&str>,
) -> Result<(Fonts, DrawingArea<DB, Shift>), ChartError> {
    let (w, h) = root.dim_in_pixel();
    let font = Fonts::scaled(s);
    let band = TitleBand::new(s, &font, subtitle.is_some());
    root.fill(&WHITE).map_err(chart_err)?;
    draw_titles(root, &font, &band, title, subtitle)?;
    let body = root.clone().shrink(
        (band.pad as i32, band.height as i32),
        (
            w.saturating_sub(2 * band.pad as u32),
            h.saturating_sub(band.height as u32 + band.pad as u32 / 2),
        ),
    );
    Ok((font, body))
}

/// Title and subtitle, centred in the band; a line wider than the figure less its padding is
/// drawn smaller, to fit ([`fitting_size`]), so no text is cut at the edges.
pub(crate) fn draw_titles<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    font: &Fonts,
    band: &TitleBand,
    title: &str,
    subtitle: Option<&str>,
) -> Result<(), ChartError> {
    let (w, _) = root.dim_in_pixel();
    let room = w as f64 - 2.0 * band.pad;
    let centre = Pos::new(HPos::Center, VPos::Top);
    let size = fitting_size(root, title, font.title, room);
    let style = TextStyle::from(("sans-serif", size).into_font()).pos(centre);
    root.draw_text(title, &style, (w as i32 / 2, band.title_y))
        .map_err(chart_err)?;
    if let Some(sub) = subtitle {
        let grey = RGBColor(70, 70, 70);
        let size = fitting_size(root, sub, font.subtitle, room);
        let style = TextStyle::from(("sans-serif", size).into_font())
            .color(&grey)
            .pos(centre);
        root.draw_text(sub, &style, (w as i32 / 2, band.subtitle_y))
            .map_err(chart_err)?;
    }
    Ok(())
}

/// The font size, px, at which `text` (sans-serif) is at most `room` px wide on `root`: `size`
/// when it fits, else `size` scaled down to fit (the backend's own text measure).
pub(crate) fn fitting_size<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
    room: f64,
) -> f64 {
    let wide = root
        .estimate_text_size(text, &("sans-serif", size).into_text_style(root))
        .map_or(0, |(tw, _)| tw) as f64;
    if wide > room && room > 0.0 {
        size * room / wide
    } else {
        size
    }
}

/// The series legend of `chart`: a white box (opacity `background`) with a black border at
/// `position`, labels at `font_px`, `margin_px` from the plot's edges.
pub(crate) fn series_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    font_px: f64,
    margin_px: f64,
    background: f64,
) -> Result<(), ChartError> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(background))
        .border_style(BLACK)
        .label_font(("sans-serif", font_px).into_font())
        .margin(margin_px as i32)
        .draw()
        .map_err(chart_err)
}

/// A one-pixel black frame around the plotting area of `chart`.
pub(crate) fn frame_plot<DB: DrawingBackend, CT: CoordTranslate>(
    chart: &ChartContext<'_, DB, CT>,
) -> Result<(), ChartError> {
    let plot = chart.plotting_area();
    let (w, h) = plot.dim_in_pixel();
    plot.strip_coord_spec()
        .draw(&Rectangle::new(
            [(0, 0), (w as i32 - 1, h as i32 - 1)],
            BLACK.stroke_width(1),
        ))
        .map_err(chart_err)
}

/// The runs of consecutive points that `keep` accepts (a curve is drawn as one line per run, so
/// a gap shows where values are missing or unbounded).
pub(crate) fn segments(
    points: impl IntoIterator<Item = (Real, Real)>,
    keep: impl Fn(Real, Real) -> bool,
) -> Vec<Vec<(Real, Real)>> {
    let mut out = Vec::new();
    let mut run = Vec::new();
    for (x, y) in points {
        if keep(x, y) {
            run.push((x, y));
        } else if !run.is_empty() {
            out.push(core::mem::take(&mut run));
        }
    }
    if !run.is_empty() {
        out.push(run);
    }
    out
}

/// A drawing failure (backend I/O, font problems) or inconsistent input, as text.
#[derive(Debug, Clone, PartialEq)]
pub struct ChartError(pub String);

impl fmt::Display for ChartError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "chart: {}", self.0)
    }
}

impl std::error::Error for ChartError {}

pub(crate) fn chart_err<E: fmt::Display>(e: E) -> ChartError {
    ChartError(e.to_string())
}

/// Registers the bundled DejaVu Sans as plotters' `sans-serif` font (native only; in the browser
/// the page's fonts are used). Idempotent; [`draw_crlb_map`](super::draw_crlb_map) calls it.
#[cfg(not(target_arch = "wasm32"))]
pub fn register_fonts() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The bundled file is a valid TrueType font; a failure would only lose the text.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../../../assets/DejaVuSans.ttf"),
        );
    });
}

/// No-op in the browser (the canvas uses the page's fonts).
#[cfg(target_arch = "wasm32")]
pub fn register_fonts() {}

/// Axis tick label: integers without decimals, otherwise up to two decimals; a typographic
/// minus sign (as the page's labels).
pub(crate) fn axis_label(v: Real) -> String {
    let s = if (v - v.round()).abs() < 1e-9 {
        alloc::format!("{}", v.round() as i64)
    } else {
        let s = alloc::format!("{v:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    s.replace('-', "\u{2212}")
}
