//! The figures of a several-people run (issue 41 §2; the page's "Several people" and the CLI's
//! `track --targets auto`): the map at one scan ([`draw_people_map`]: the nodes on metre axes,
//! every true path dashed, every labelled track up to the scan in its own colour — the page's
//! link palette, [`LINK_RGB`], by the track's place in the document's `tracks` — with its label
//! `#n`, its position and its 1σ ellipse magnified as on the page) and the GOSPA per scan
//! ([`draw_gospa_chart`], the core's curve figure). Both draw on any [`DrawingBackend`]: SVG or
//! PNG natively, a `<canvas>` in the page.

use alloc::string::String;
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::clip::{clip_polygon, clipped_runs};
use super::layout::{self, chart_err, register_fonts, ChartError};
use super::panel::{check_area, draw_metre_axes, finish_panel, metre_chart, rgb};
use super::panel::{in_window, legend_entry, plot_window, ChartNode};
use super::roc::{draw_curves, CurveChartOptions, CurveSeries, LineKind, Marker};
use crate::math::Real;
use crate::measure::Ellipse;
use crate::present::{PeopleMapView, LINK_RGB};
use crate::scenario::Area;
use crate::study::{MultiTrackOutput, MultiTruth};

/// Points per drawn ellipse.
const ELLIPSE_POINTS: usize = 72;
/// The true paths' colour on the white figure (the page draws them white on the dark map).
const TRUTH_RGB: RGBColor = RGBColor(60, 60, 60);

/// The colour of a track at place `i` in the document's `tracks` (the page's `linkColor(i)`).
pub fn people_rgb(i: usize) -> [u8; 3] {
    LINK_RGB[i % LINK_RGB.len()]
}

/// The default title and subtitle of the map of `view` (of a run of `track` against `truth` on
/// the scenario `scenario_name`, ellipses magnified `magnify` times): `Several people — <name>`
/// and the walkers, method, scan, time and magnification.
pub fn people_titles(
    scenario_name: &str,
    track: &MultiTrackOutput,
    truth: &MultiTruth,
    view: &PeopleMapView,
    magnify: Real,
) -> (String, String) {
    let walkers = match truth.targets.iter().map(Vec::len).max().unwrap_or(0) {
        0 => String::new(),
        1 => "1 walker · ".into(),
        n => alloc::format!("{n} walkers · "),
    };
    (
        alloc::format!("Several people — {scenario_name}"),
        alloc::format!(
            "{walkers}{} · scan {} of 0–{}, t = {} s · 1σ ellipses ×{}",
            track.method.to_uppercase(),
            view.step,
            track.t_s.len().saturating_sub(1),
            view.t_s,
            magnify
        ),
    )
}

/// Options of the map figure.
#[derive(Debug, Clone, PartialEq)]
pub struct PeopleChartOptions {
    /// Title line.
    pub title: String,
    /// Optional smaller second line.
    pub subtitle: Option<String>,
    /// The window shown, m.
    pub window: Area,
    /// The ellipses drawn `magnify` times their 1σ size (finite, > 0; else 1).
    pub magnify: Real,
}

/// Draws the map figure of `view` ([`crate::present::people_map_view`]) with `nodes` onto `root`
/// (filled white first). Does not call `present()`.
pub fn draw_people_map<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    nodes: &[ChartNode],
    view: &PeopleMapView,
    opts: &PeopleChartOptions,
) -> Result<(), ChartError> {
    register_fonts();
    check_area(&opts.window)?;
    root.fill(&WHITE).map_err(chart_err)?;
    let lay = layout::Layout::new(root, &opts.window, opts.subtitle.is_some());
    layout::draw_titles(
        root,
        &lay.font,
        &lay.band,
        &opts.title,
        opts.subtitle.as_deref(),
    )?;
    let chart_area = root.clone().shrink(lay.chart_origin, lay.chart_size);
    let mut chart = metre_chart(&chart_area, &lay, &opts.window)?;
    draw_metre_axes(&mut chart, &lay)?;

    let font_px = lay.font.nodes;
    let s = font_px / 20.0;
    let width = (2.0 * s).round().max(1.0) as u32;
    let thin = (1.2 * s).round().max(1.0) as u32;
    let dash = (8.0 * s).round().max(2.0) as i32;
    let half = (9.0 * s).round().max(4.0) as i32;
    let dot = (4.0 * s).round().max(2.0) as i32;
    let w = plot_window(&chart);
    let plot = chart.plotting_area().clone();
    let halo = BLACK.mix(0.55).stroke_width(width + 3);
    let magnify = if opts.magnify.is_finite() && opts.magnify > 0.0 {
        opts.magnify
    } else {
        1.0
    };

    for path in &view.truth {
        for run in clipped_runs(path, false, w) {
            plot.draw(&DashedPathElement::new(
                run,
                dash,
                dash / 2,
                TRUTH_RGB.stroke_width(thin),
            ))
            .map_err(chart_err)?;
        }
    }
    if !view.truth.is_empty() {
        legend_entry(&mut chart, "true path", move |(x, y)| {
            EmptyElement::at((x, y))
                + DashedPathElement::new(
                    vec![(-half, 0), (half, 0)],
                    4,
                    3,
                    TRUTH_RGB.stroke_width(thin),
                )
        })?;
    }

    let font = ("sans-serif", font_px).into_font();
    for t in &view.tracks {
        let colour = rgb(people_rgb(t.colour));
        for r in t.runs.iter().filter(|r| r.len() > 1) {
            for run in clipped_runs(r, false, w) {
                plot.draw(&PathElement::new(run.clone(), halo))
                    .map_err(chart_err)?;
                plot.draw(&PathElement::new(run, colour.stroke_width(width)))
                    .map_err(chart_err)?;
            }
        }
        if let Some(e) = &t.ellipse {
            let e = Ellipse {
                semi_major: e.semi_major * magnify,
                semi_minor: e.semi_minor * magnify,
                ..*e
            };
            let pts: Vec<[Real; 2]> = e
                .polygon(ELLIPSE_POINTS)
                .iter()
                .map(|p| [p.x, p.y])
                .collect();
            let poly: Vec<(Real, Real)> = pts.iter().map(|p| (p[0], p[1])).collect();
            let clipped = clip_polygon(&poly, w);
            if clipped.len() > 2 {
                plot.draw(&Polygon::new(clipped, colour.mix(0.2).filled()))
                    .map_err(chart_err)?;
            }
            for run in clipped_runs(&pts, true, w) {
                plot.draw(&PathElement::new(run, colour.stroke_width(width)))
                    .map_err(chart_err)?;
            }
        }
        let label = alloc::format!("#{}", t.label);
        if let Some(p) = t.position.filter(|p| in_window(w, *p)) {
            let style = font.clone().color(&colour);
            plot.draw(
                &(EmptyElement::at((p[0], p[1]))
                    + Circle::new((0, 0), dot + 1, BLACK.mix(0.6).filled())
                    + Circle::new((0, 0), dot, colour.filled())
                    + Text::new(label.clone(), (dot + 3, -(font_px as i32) - dot), style)),
            )
            .map_err(chart_err)?;
        }
        let name = alloc::format!("track {label}");
        legend_entry(&mut chart, &name, move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(-half, 0), (half, 0)], halo)
                + PathElement::new(vec![(-half, 0), (half, 0)], colour.stroke_width(width))
        })?;
    }
    finish_panel(&mut chart, nodes, &lay)
}

/// Draws the GOSPA per scan (`gospa_m[k]` at `t_s[k]`; a non-finite value is a gap) against
/// time with the core's curve figure ([`draw_curves`]), one series labelled `label`, with
/// `title` and `subtitle` (`""`: none); with no point the axes span `[0, empty_t_end_s]` s.
/// Returns the finite points drawn. Does not call `present()`.
pub fn draw_gospa_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    t_s: &[Real],
    gospa_m: &[Real],
    label: &str,
    title: &str,
    subtitle: &str,
    empty_t_end_s: Real,
) -> Result<u32, ChartError> {
    let points: Vec<(Real, Real)> = t_s.iter().copied().zip(gospa_m.iter().copied()).collect();
    let finite = || points.iter().filter(|p| p.0.is_finite() && p.1.is_finite());
    let t_end = finite().map(|p| p.0).fold(0.0, Real::max);
    let top = finite().map(|p| p.1).fold(0.0, Real::max);
    let opts = CurveChartOptions {
        title: title.into(),
        subtitle: (!subtitle.is_empty()).then(|| subtitle.into()),
        x_desc: "time t (s)".into(),
        y_desc: "GOSPA (m)".into(),
        x_range: (0.0, if t_end > 0.0 { t_end } else { empty_t_end_s }),
        y_range: (0.0, if top > 0.0 { 1.1 * top } else { 1.0 }),
        legend: SeriesLabelPosition::UpperRight,
    };
    let series = [CurveSeries {
        label: label.into(),
        points: &points,
        colour: 0,
        line: LineKind::Solid,
        marker: Marker::None,
    }];
    let shown = if points.is_empty() {
        &[][..]
    } else {
        &series[..]
    };
    draw_curves(root, shown, &opts)?;
    Ok(finite().count() as u32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chart::scenario_nodes;
    use crate::math::Vec2;
    use crate::present::PeopleTrackView;
    use crate::scenario::presets;

    /// One line per track in its palette colour (by its place, wrapping), its label, the true
    /// paths dashed, the nodes; PNG-free so it runs everywhere.
    #[test]
    fn the_map_draws_each_track_in_its_colour_with_its_label() {
        let s = presets::sensors2019();
        let track = |label: u64, colour: usize, y: Real| PeopleTrackView {
            label,
            colour,
            runs: vec![vec![[2.0, y], [4.0, y + 0.5], [6.0, y + 0.25]]],
            position: Some([6.0, y + 0.25]),
            ellipse: Some(Ellipse {
                center: Vec2::new(6.0, y + 0.25),
                semi_major: 0.2,
                semi_minor: 0.1,
                angle_rad: 0.3,
            }),
        };
        let view = PeopleMapView {
            step: 3,
            t_s: 0.3,
            truth: vec![vec![[2.0, 1.0], [6.0, 1.0]], vec![[2.0, 3.0], [6.0, 3.0]]],
            tracks: vec![track(4, 0, 1.0), track(7, 1, 2.0), track(12, 9, 3.0)],
        };
        let opts = PeopleChartOptions {
            title: "people".into(),
            subtitle: Some("sub".into()),
            window: s.area_m,
            magnify: 2.0,
        };
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (900, 700)).into_drawing_area();
            draw_people_map(&root, &scenario_nodes(&s), &view, &opts).unwrap();
            root.present().unwrap();
        }
        let doc = roxmltree::Document::parse(&svg).expect("well-formed SVG");
        let texts: Vec<&str> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .map(|n| n.text().unwrap_or("").trim())
            .collect();
        for t in &view.tracks {
            let label = alloc::format!("#{}", t.label);
            assert_eq!(texts.iter().filter(|x| **x == label).count(), 1, "{label}");
            let legend = alloc::format!("track #{}", t.label);
            assert_eq!(
                texts.iter().filter(|x| **x == legend).count(),
                1,
                "{legend}"
            );
            // Its line (3 points, width 2 px at this size) in its colour: the page's linkColor.
            let [r, g, b] = LINK_RGB[t.colour % LINK_RGB.len()];
            let hex = alloc::format!("#{r:02X}{g:02X}{b:02X}");
            let lines = doc
                .descendants()
                .filter(|n| n.has_tag_name("polyline"))
                .filter(|n| n.attribute("stroke") == Some(hex.as_str()))
                .filter(|n| {
                    n.attribute("points")
                        .unwrap_or("")
                        .split_whitespace()
                        .count()
                        == 3
                })
                .count();
            let same = view
                .tracks
                .iter()
                .filter(|u| u.colour % LINK_RGB.len() == t.colour % LINK_RGB.len())
                .count();
            assert_eq!(lines, same, "one track line in {hex} for {label}");
        }
        assert_eq!(people_rgb(9), LINK_RGB[1]);
        assert_eq!(texts.iter().filter(|x| **x == "true path").count(), 1);
        for n in s
            .transmitters
            .iter()
            .map(|t| &t.name)
            .chain(s.receivers.iter().map(|r| &r.name))
        {
            assert!(texts.contains(&n.as_str()), "node {n}");
        }
    }

    /// The GOSPA chart counts the finite points it drew (a gap is not one).
    #[test]
    fn the_gospa_chart_draws_the_finite_points() {
        let mut svg = String::new();
        let n = {
            let root = SVGBackend::with_string(&mut svg, (600, 360)).into_drawing_area();
            let t = [0.0, 0.1, 0.2, 0.3];
            let g = [0.5, f64::NAN, 0.25, 0.125];
            let n = draw_gospa_chart(&root, &t, &g, "GOSPA", "title", "", 10.0).unwrap();
            root.present().unwrap();
            n
        };
        assert_eq!(n, 3);
        let doc = roxmltree::Document::parse(&svg).expect("well-formed SVG");
        let texts: Vec<&str> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .map(|n| n.text().unwrap_or("").trim())
            .collect();
        for t in ["title", "GOSPA (m)", "time t (s)", "GOSPA"] {
            assert!(texts.contains(&t), "{t} in {texts:?}");
        }
    }
}
