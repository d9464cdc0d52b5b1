//! The network-plan figure (`filters-and-planning.md` §3): the CRLB maps of the scenario before
//! and after a plan side by side on one shared log colour scale (one colour bar), the region of
//! interest outlined on both, the nodes as the map figure draws them, and on the after panel each
//! moved node's path (base → improvements → result) with its start and end marked.

use alloc::format;
use alloc::string::String;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::clip::clip_segment;
use super::layout::{self, chart_err, register_fonts, ChartError, Fonts, TitleBand};
use super::panel::{self, check_area, finish_panel, map_panel, Chart, ChartNode, MapData};
use crate::math::Real;
use crate::plan::Objective;
use crate::present::{format_length_m, LogScale, PlanObjectiveJson};
use crate::scenario::Area;

/// Colour of the moved nodes' paths.
const PATH_RGB: RGBColor = RGBColor(255, 127, 14);
/// Colour of the ROI outline.
const ROI_RGB: RGBColor = WHITE;

/// One map of the figure: its caption, the map and the nodes drawn on it.
#[derive(Debug, Clone, Copy)]
pub struct PlanPanel<'a> {
    /// Caption above the map, e.g. `before: p90 24.6 cm` ([`plan_caption`]).
    pub caption: &'a str,
    /// The map (both panels must share the area).
    pub map: MapData<'a>,
    /// The nodes of this panel's scenario.
    pub nodes: &'a [ChartNode],
}

/// A moved node's path: its positions from the base layout to the result, m.
#[derive(Debug, Clone, Copy)]
pub struct PlanPath<'a> {
    /// `[x, y]` points, start first (at least one).
    pub points_m: &'a [[Real; 2]],
}

/// Text of the plan figure.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanChartOptions {
    /// Title line.
    pub title: String,
    /// Optional smaller second line under the title.
    pub subtitle: Option<String>,
    /// Label of the shared colour bar.
    pub colorbar_label: String,
}

impl Default for PlanChartOptions {
    fn default() -> Self {
        PlanChartOptions {
            title: "Network plan".into(),
            subtitle: None,
            colorbar_label: "RMSE bound √(σx² + σy²)".into(),
        }
    }
}

/// `which: objective value`, e.g. `before: p90 24.6 cm`, `after: coverage ≤ 10 cm 83.2 %`,
/// `before: mean ∞ (412 unbounded cells)`.
pub fn plan_caption(which: &str, objective: &PlanObjectiveJson, after: bool) -> String {
    let (value, unbounded) = if after {
        (objective.after, objective.unbounded_after)
    } else {
        (objective.before, objective.unbounded_before)
    };
    let coverage = match Objective::parse(&objective.label) {
        Ok(Objective::Coverage { threshold_m }) => Some(threshold_m),
        _ => None,
    };
    let name = match coverage {
        Some(t) => format!("coverage ≤ {}", format_length_m(t, 3)),
        None => objective.kind.clone(),
    };
    let text = match (value, coverage) {
        (Some(v), Some(_)) => format!("{:.1} %", 100.0 * v),
        (Some(v), None) => format_length_m(v, 3),
        (None, _) if unbounded > 0 => format!("∞ ({unbounded} unbounded cells)"),
        (None, _) => "∞".into(),
    };
    format!("{which}: {name} {text}")
}

/// The pixel layout: the title band, a caption band, two equal-scale plots side by side and the
/// colour bar right of them.
struct PlanLayout {
    panels: [layout::Layout; 2],
    caption_y: i32,
    caption_font: f64,
}

/// The font scale of a `w × h` two-panel figure (1 at 1600 px wide).
fn plan_font_scale(w: u32, h: u32) -> f64 {
    (w as f64 / 1600.0).min(h as f64 / 360.0).clamp(0.5, 4.0)
}

fn px(v: f64) -> u32 {
    v.round().max(1.0) as u32
}

impl PlanLayout {
    fn for_size(w: u32, h: u32, area: &Area, subtitle: bool) -> PlanLayout {
        let (wf, hf) = (w as f64, h as f64);
        let s = plan_font_scale(w, h);
        let font = Fonts::scaled(s);
        let band = TitleBand::new(s, &font, subtitle);
        let caption_font = 1.1 * font.axis;
        let caption_h = 1.6 * caption_font;
        let pad = band.pad;
        let x_label_area = font.ticks + font.axis + 26.0 * s;
        let y_label_area = 2.2 * font.ticks + font.axis + 26.0 * s;
        let (m_top, m_right) = (10.0 * s, 12.0 * s);
        let (panel_gap, bar_gap) = (30.0 * s, 22.0 * s);
        let bar_block = 24.0 * s + 10.0 * s + 4.4 * font.ticks + 12.0 * s + 1.4 * font.axis;
        let frame = y_label_area + m_right;
        let avail_w =
            ((wf - 2.0 * pad - 2.0 * frame - panel_gap - bar_gap - bar_block) / 2.0).max(10.0);
        let avail_h = (hf - band.height - caption_h - m_top - x_label_area - pad).max(10.0);
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
        let panel_w = frame + pw;
        let block_w = 2.0 * panel_w + panel_gap + bar_gap + bar_block;
        let x0 = ((wf - block_w) / 2.0).max(0.0);
        let y0 = band.height + caption_h + ((avail_h - ph) / 2.0).max(0.0);
        let bar_x = x0 + 2.0 * panel_w + panel_gap + bar_gap;
        let panel = |k: usize| layout::Layout {
            font,
            band,
            chart_origin: ((x0 + k as f64 * (panel_w + panel_gap)) as i32, y0 as i32),
            chart_size: (px(panel_w), px(m_top + ph + x_label_area)),
            plot_margin_top: px(m_top),
            plot_margin_right: px(m_right),
            x_label_area: px(x_label_area),
            y_label_area: px(y_label_area),
            bar_origin: (bar_x as i32, (y0 + m_top) as i32),
            bar_size: (px(bar_block), px(ph)),
        };
        PlanLayout {
            panels: [panel(0), panel(1)],
            caption_y: (y0 + m_top - 0.25 * caption_h) as i32,
            caption_font,
        }
    }

    /// Height the figure needs at width `w`.
    fn needed_height(&self) -> f64 {
        let p = &self.panels[0];
        p.chart_origin.1 as f64 + p.chart_size.1 as f64 + p.band.pad
    }
}

/// A figure size `(width, height)` for the plan figure of `area` `width` pixels wide (200..=8000,
/// 1600 is a good default): the height the two equal-scale plots need, within 25 %–100 % of the
/// width.
pub fn plan_chart_size(area: &Area, width: u32) -> (u32, u32) {
    let width = width.clamp(200, 8000);
    let (lo, hi) = (width / 4, width);
    let mut height = hi;
    for _ in 0..4 {
        let lay = PlanLayout::for_size(width, height, area, true);
        height = (lay.needed_height().ceil() as u32).clamp(lo, hi);
    }
    (width, height)
}

/// The colour scale spanning the finite positive values of both maps.
fn shared_scale(a: &[Real], b: &[Real]) -> Option<LogScale> {
    match (LogScale::spanning(a), LogScale::spanning(b)) {
        (Some(x), Some(y)) => LogScale::new(x.min.min(y.min), x.max.max(y.max)),
        (x, y) => x.or(y),
    }
}

/// Draws the plan figure onto `root` (filled white first): the titles, the `before` and `after`
/// maps side by side on one log colour scale spanning both (one colour bar), `roi` outlined on
/// both, each panel's nodes, and on the after panel the `paths` with a square at each start and a
/// ring round each end. Returns the shared scale and the unbounded cells of both maps. Does not
/// call `present()`.
pub fn draw_plan_maps<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    before: &PlanPanel,
    after: &PlanPanel,
    roi: &Area,
    paths: &[PlanPath],
    opts: &PlanChartOptions,
) -> Result<super::ChartSummary, ChartError> {
    register_fonts();
    for p in [before, after] {
        if p.map.values_m.len() != p.map.grid.len() {
            return Err(ChartError(format!(
                "{}: map has {} values for a {}x{} grid",
                p.caption,
                p.map.values_m.len(),
                p.map.grid.nx,
                p.map.grid.ny
            )));
        }
    }
    let area = before.map.grid.area;
    if after.map.grid.area != area {
        return Err(ChartError(
            "the before and after maps cover different areas".into(),
        ));
    }
    check_area(&area)?;
    roi.validate_as(["roi.x", "roi.y"]).map_err(chart_err)?;
    let scale = shared_scale(before.map.values_m, after.map.values_m);
    let unbounded = |m: &MapData| {
        m.values_m
            .iter()
            .filter(|v| !(v.is_finite() && **v > 0.0))
            .count()
    };
    let unbounded_cells = unbounded(&before.map) + unbounded(&after.map);

    root.fill(&WHITE).map_err(chart_err)?;
    let (w, h) = root.dim_in_pixel();
    let lay = PlanLayout::for_size(w, h, &area, opts.subtitle.is_some());
    let first = &lay.panels[0];
    layout::draw_titles(
        root,
        &first.font,
        &first.band,
        &opts.title,
        opts.subtitle.as_deref(),
    )?;
    let caption_style = TextStyle::from(("sans-serif", lay.caption_font).into_font())
        .pos(Pos::new(HPos::Center, VPos::Bottom));
    for (k, (panel, l)) in [before, after].iter().zip(&lay.panels).enumerate() {
        let plot_w = l.chart_size.0 as i32 - l.y_label_area as i32 - l.plot_margin_right as i32;
        let centre = l.chart_origin.0 + l.y_label_area as i32 + plot_w / 2;
        root.draw_text(panel.caption, &caption_style, (centre, lay.caption_y))
            .map_err(chart_err)?;
        let chart_area = root.clone().shrink(l.chart_origin, l.chart_size);
        let mut chart = map_panel(&chart_area, l, &panel.map, scale.as_ref())?;
        draw_roi(&mut chart, roi, l.font.nodes)?;
        if k == 1 {
            draw_paths(&mut chart, paths, l.font.nodes)?;
        }
        finish_panel(&mut chart, panel.nodes, l)?;
    }
    let bar_area = root.clone().shrink(first.bar_origin, first.bar_size);
    panel::draw_colorbar(
        &bar_area,
        scale.as_ref(),
        unbounded_cells > 0,
        &opts.colorbar_label,
        &first.font,
    )?;
    Ok(super::ChartSummary {
        scale,
        unbounded_cells,
    })
}

/// The ROI as a dashed white rectangle over a thin black one (visible on every colour), with a
/// legend entry.
fn draw_roi<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    roi: &Area,
    font_px: f64,
) -> Result<(), ChartError> {
    let s = font_px / 20.0;
    let corners = [
        (roi.x[0], roi.y[0]),
        (roi.x[1], roi.y[0]),
        (roi.x[1], roi.y[1]),
        (roi.x[0], roi.y[1]),
        (roi.x[0], roi.y[0]),
    ];
    let width = (2.0 * s).round().max(1.0) as u32;
    let dash = (9.0 * s).round().max(2.0) as i32;
    chart
        .draw_series(core::iter::once(PathElement::new(
            corners,
            BLACK.stroke_width(width + 2),
        )))
        .map_err(chart_err)?;
    chart
        .draw_series(core::iter::once(DashedPathElement::new(
            corners,
            dash,
            dash / 2,
            ROI_RGB.stroke_width(width),
        )))
        .map_err(chart_err)?
        .label("ROI")
        .legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + Rectangle::new([(-8, -5), (8, 5)], BLACK.stroke_width(width + 2))
                + Rectangle::new([(-8, -5), (8, 5)], ROI_RGB.stroke_width(width))
        });
    Ok(())
}

/// Each path as an orange line over a black halo (segments with round joins), a hollow square at its start and a ring
/// round its end (the node's marker, drawn later, sits inside), with a legend entry.
fn draw_paths<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    paths: &[PlanPath],
    font_px: f64,
) -> Result<(), ChartError> {
    let s = font_px / 20.0;
    let marker = (7.0 * s).round().max(3.0) as i32;
    let width = (2.0 * s).round().max(1.0) as u32;
    let square = marker;
    let ring = marker + (5.0 * s).round() as i32;
    let (xr, yr) = (chart.x_range(), chart.y_range());
    let view = [xr.start, xr.end, yr.start, yr.end];
    let shown =
        |q: (Real, Real)| (view[0]..=view[1]).contains(&q.0) && (view[2]..=view[3]).contains(&q.1);
    for p in paths {
        let points: alloc::vec::Vec<(Real, Real)> =
            p.points_m.iter().map(|q| (q[0], q[1])).collect();
        let (Some(&start), Some(&end)) = (points.first(), points.last()) else {
            continue;
        };
        // The parts of the segments inside the plotted area (plotters would pin points outside
        // it to the frame, bending the lines).
        let segments: alloc::vec::Vec<[(Real, Real); 2]> = points
            .windows(2)
            .filter_map(|w| clip_segment(w[0], w[1], view))
            .collect();
        let plot = chart.plotting_area();
        // Segment by segment with round joins: a polyline's miter joins spike at sharp turns.
        for (colour, w) in [(BLACK, width + 2), (PATH_RGB, width)] {
            for seg in &segments {
                plot.draw(&PathElement::new(seg.to_vec(), colour.stroke_width(w)))
                    .map_err(chart_err)?;
            }
            let joint = (w as i32 / 2).max(1);
            let inner = points.iter().skip(1).take(points.len().saturating_sub(2));
            for &q in inner.filter(|&&q| shown(q)) {
                plot.draw(&Circle::new(q, joint, colour.filled()))
                    .map_err(chart_err)?;
            }
        }
        if shown(start) {
            let start_mark = EmptyElement::at(start)
                + Rectangle::new(
                    [(-square, -square), (square, square)],
                    BLACK.stroke_width(width + 2),
                )
                + Rectangle::new(
                    [(-square, -square), (square, square)],
                    PATH_RGB.stroke_width(width),
                );
            plot.draw(&start_mark).map_err(chart_err)?;
        }
        if shown(end) {
            let end_mark = EmptyElement::at(end)
                + Circle::new((0, 0), ring, BLACK.stroke_width(width + 2))
                + Circle::new((0, 0), ring, PATH_RGB.stroke_width(width));
            plot.draw(&end_mark).map_err(chart_err)?;
        }
    }
    if !paths.is_empty() {
        let half = marker.max(4);
        panel::legend_entry(chart, "moved: start □ → end ○", move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(
                    [(-2 * half, 0), (2 * half, 0)],
                    PATH_RGB.stroke_width(width),
                )
        })?;
    }
    Ok(())
}
