//! Overlays of the map figure: lines and markers in metres drawn over the CRLB map, under the
//! nodes (which [`super::draw_crlb_map_with`] draws last): a placed target with its simulated
//! snapshot (iso-delay ellipses, the LM fix and its 1σ ellipse, the CRLB 1σ ellipse), or a
//! simulated track (the truth path, the filter's track and its magnified 1σ ellipses). The page's
//! figure export draws them as the page's canvas does, through the same chart code as the CLI.

use alloc::string::{String, ToString};
use alloc::vec::Vec;

use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::clip::clipped_runs;
use super::layout::chart_err;
use super::panel::{in_window, legend_entry, plot_window, Chart};
use super::ChartError;
use crate::math::Real;
use crate::measure::Ellipse;
use crate::present::{SnapshotSimulation, LINK_RGB};
use crate::track::TrackRun;

/// Points per drawn covariance ellipse.
const ELLIPSE_POINTS: usize = 72;

/// Colour of a filter's track, its ellipses and the LM fix (the page's orange).
const TRACK_RGB: RGBColor = RGBColor(255, 127, 14);
/// Colour of the CRLB ellipse (the page's light blue).
const CRLB_RGB: RGBColor = RGBColor(92, 200, 255);
/// The colour of link `i` ([`LINK_RGB`], as the page's).
fn link_rgb(i: usize) -> RGBColor {
    super::panel::rgb(LINK_RGB[i % LINK_RGB.len()])
}

/// How an [`OverlayPath`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OverlayLine {
    /// A true path: white, dashed, on a dark halo.
    Truth,
    /// A filter's track: orange, solid, on a dark halo.
    Track,
    /// The iso-delay ellipse of link `i` (thin, in the page's colour of that link).
    IsoDelay(usize),
    /// A filter's or the LM fix's 1σ ellipse (thin orange).
    Covariance,
    /// The CRLB 1σ ellipse (dashed light blue).
    Crlb,
}

/// A polyline in metres (closed when `closed`), clipped to the plotted area.
#[derive(Debug, Clone, PartialEq)]
pub struct OverlayPath {
    /// Legend entry (the first path of each label is listed once).
    pub label: Option<String>,
    /// `[x, y]` points, m.
    pub points_m: Vec<[Real; 2]>,
    /// Closes the path back to its first point.
    pub closed: bool,
    /// Line style.
    pub line: OverlayLine,
}

/// A marker's shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OverlayMarkKind {
    /// The true target: a white cross on a dark halo.
    Target,
    /// An estimate (LM fix, a filter's current state): an orange ring.
    Estimate,
    /// The start of a path: a small white dot.
    Start,
}

/// A marker at a point in metres (drawn only inside the plotted area).
#[derive(Debug, Clone, PartialEq)]
pub struct OverlayMark {
    /// Legend entry.
    pub label: Option<String>,
    /// Position, m.
    pub position_m: [Real; 2],
    /// Shape.
    pub kind: OverlayMarkKind,
}

/// Everything drawn over the map: paths first (in order), then the marks.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MapOverlay {
    /// Lines.
    pub paths: Vec<OverlayPath>,
    /// Markers.
    pub marks: Vec<OverlayMark>,
}

fn ellipse_path(
    e: &Ellipse,
    magnify: Real,
    line: OverlayLine,
    label: Option<String>,
) -> OverlayPath {
    let e = Ellipse {
        semi_major: e.semi_major * magnify,
        semi_minor: e.semi_minor * magnify,
        ..*e
    };
    OverlayPath {
        label,
        points_m: e
            .polygon(ELLIPSE_POINTS)
            .iter()
            .map(|p| [p.x, p.y])
            .collect(),
        closed: true,
        line,
    }
}

impl MapOverlay {
    /// True when nothing is drawn.
    pub fn is_empty(&self) -> bool {
        self.paths.is_empty() && self.marks.is_empty()
    }

    /// A snapshot as the page's map shows it: each link's iso-delay ellipse, the CRLB 1σ ellipse
    /// at the truth, the LM fix with its 1σ ellipse (when there is a fix) and the target.
    pub fn snapshot(sim: &SnapshotSimulation) -> MapOverlay {
        let mut o = MapOverlay::default();
        for (i, l) in sim.links.iter().enumerate() {
            if l.outline.len() >= 3 {
                o.paths.push(OverlayPath {
                    label: (i == 0).then(|| "iso-delay (measured)".to_string()),
                    points_m: l.outline.iter().map(|p| [p.x, p.y]).collect(),
                    closed: true,
                    line: OverlayLine::IsoDelay(i),
                });
            }
        }
        if let Some(e) = sim.crlb.ellipse() {
            let label = Some("CRLB 1σ".to_string());
            o.paths
                .push(ellipse_path(&e, 1.0, OverlayLine::Crlb, label));
        }
        if let Ok(fix) = &sim.fix {
            if let Some(e) = &fix.ellipse {
                o.paths
                    .push(ellipse_path(e, 1.0, OverlayLine::Covariance, None));
            }
            let p = fix.report.position;
            o.marks.push(OverlayMark {
                label: Some("LM fix ±1σ".into()),
                position_m: [p.x, p.y],
                kind: OverlayMarkKind::Estimate,
            });
        }
        o.marks.push(OverlayMark {
            label: Some("target".into()),
            position_m: [sim.truth.x, sim.truth.y],
            kind: OverlayMarkKind::Target,
        });
        o
    }

    /// A track up to step `step` as the page's tracking view shows it: the whole truth path, the
    /// filter's (`filter`, e.g. `EKF`) track up to `step`, its 1σ ellipses magnified `magnify`
    /// times (about 20 along the way and the current one), the true position at `step` and the
    /// estimate there. `step` past the end shows the last entry.
    pub fn track(run: &TrackRun, step: usize, magnify: Real, filter: &str) -> MapOverlay {
        let mut o = MapOverlay::default();
        let n = run.truth.len().min(run.estimates.len());
        if n == 0 {
            return o;
        }
        let step = step.min(n - 1);
        let magnify = if magnify.is_finite() && magnify > 0.0 {
            magnify
        } else {
            1.0
        };
        o.paths.push(OverlayPath {
            label: Some("truth".into()),
            points_m: run.truth.iter().map(|x| [x[0], x[1]]).collect(),
            closed: false,
            line: OverlayLine::Truth,
        });
        let stride = (n as Real / 20.0).round().max(1.0) as usize;
        let ellipse_at = |k: usize| {
            run.covariances.get(k).and_then(|p| {
                let x = &run.estimates[k];
                crate::present::position_ellipse(x, p, 1.0)
            })
        };
        let mag = super::axis_label(magnify);
        let mut first = true;
        for k in (stride..step).step_by(stride).chain(core::iter::once(step)) {
            if let Some(e) = ellipse_at(k) {
                let label = first.then(|| alloc::format!("{filter} 1σ ×{mag}"));
                first = false;
                o.paths
                    .push(ellipse_path(&e, magnify, OverlayLine::Covariance, label));
            }
        }
        o.paths.push(OverlayPath {
            label: Some(alloc::format!("{filter} track")),
            points_m: run.estimates[..=step]
                .iter()
                .map(|x| [x[0], x[1]])
                .collect(),
            closed: false,
            line: OverlayLine::Track,
        });
        let start = &run.truth[0];
        o.marks.push(OverlayMark {
            label: None,
            position_m: [start[0], start[1]],
            kind: OverlayMarkKind::Start,
        });
        let (t, x) = (&run.truth[step], &run.estimates[step]);
        o.marks.push(OverlayMark {
            label: None,
            position_m: [x[0], x[1]],
            kind: OverlayMarkKind::Estimate,
        });
        o.marks.push(OverlayMark {
            label: Some("target".into()),
            position_m: [t[0], t[1]],
            kind: OverlayMarkKind::Target,
        });
        o
    }
}

/// A marker of `kind` at `at` (metres on a chart, pixels in a legend), `$size` px across its
/// arms, lines `$width` px: one element type for every kind (unused parts are transparent, which
/// the backends skip).
macro_rules! mark {
    ($at:expr, $kind:expr, $size:expr, $width:expr) => {{
        let (kind, r, w): (OverlayMarkKind, i32, u32) = ($kind, $size, $width);
        let none = TRANSPARENT.stroke_width(1);
        let halo = BLACK.mix(0.6).stroke_width(w + 3);
        let (cross_halo, cross, ring_halo, ring, rr) = match kind {
            OverlayMarkKind::Target => (halo, WHITE.stroke_width(w), none, none, r),
            OverlayMarkKind::Estimate => (none, none, halo, TRACK_RGB.stroke_width(w), r + 2),
            OverlayMarkKind::Start => (
                none,
                none,
                BLACK.mix(0.6).stroke_width(2),
                WHITE.filled(),
                (r / 2).max(2),
            ),
        };
        EmptyElement::at($at)
            + PathElement::new(vec![(-r, -r), (r, r)], cross_halo)
            + PathElement::new(vec![(-r, r), (r, -r)], cross_halo)
            + PathElement::new(vec![(-r, -r), (r, r)], cross)
            + PathElement::new(vec![(-r, r), (r, -r)], cross)
            + Circle::new((0, 0), rr, ring_halo)
            + Circle::new((0, 0), rr, ring)
    }};
}

/// The (halo, line) styles of a path in the legend.
fn legend_styles(line: OverlayLine, width: u32, thin: u32) -> (ShapeStyle, ShapeStyle) {
    let halo = BLACK.mix(0.55).stroke_width(width + 3);
    let none = TRANSPARENT.stroke_width(1);
    match line {
        OverlayLine::Truth => (halo, WHITE.stroke_width(width)),
        OverlayLine::Track => (halo, TRACK_RGB.stroke_width(width)),
        OverlayLine::IsoDelay(i) => (
            BLACK.mix(0.35).stroke_width(thin + 2),
            link_rgb(i).stroke_width(thin),
        ),
        OverlayLine::Covariance => (none, TRACK_RGB.stroke_width(thin)),
        OverlayLine::Crlb => (
            BLACK.mix(0.35).stroke_width(thin + 3),
            CRLB_RGB.stroke_width(thin + 1),
        ),
    }
}

/// Draws `overlay` on a map panel (metre coordinates) with line widths and markers scaled to
/// `font_px` (as the nodes), and adds one legend entry per label.
pub(crate) fn draw_overlay<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    overlay: &MapOverlay,
    font_px: f64,
) -> Result<(), ChartError> {
    let s = font_px / 20.0;
    let width = (2.0 * s).round().max(1.0) as u32;
    let thin = (1.2 * s).round().max(1.0) as u32;
    let dash = (8.0 * s).round().max(2.0) as i32;
    let view = plot_window(chart);
    let halo = BLACK.mix(0.55).stroke_width(width + 3);
    let mut labelled: Vec<String> = Vec::new();
    for path in &overlay.paths {
        let plot = chart.plotting_area().clone();
        for run in clipped_runs(&path.points_m, path.closed, view) {
            let solid = |style: ShapeStyle| {
                plot.draw(&PathElement::new(run.clone(), style))
                    .map_err(chart_err)
            };
            let dashed = |d: i32, gap: i32, style: ShapeStyle| {
                plot.draw(&DashedPathElement::new(run.iter().copied(), d, gap, style))
                    .map_err(chart_err)
            };
            match path.line {
                OverlayLine::Truth => {
                    solid(halo)?;
                    dashed(dash, dash / 2, WHITE.stroke_width(width))?;
                }
                OverlayLine::Track => {
                    solid(halo)?;
                    solid(TRACK_RGB.stroke_width(width))?;
                }
                OverlayLine::IsoDelay(i) => {
                    solid(link_rgb(i).mix(0.85).stroke_width(thin))?;
                }
                OverlayLine::Covariance => solid(TRACK_RGB.mix(0.9).stroke_width(thin))?,
                OverlayLine::Crlb => dashed(dash / 2, dash / 3, CRLB_RGB.stroke_width(thin + 1))?,
            }
        }
        if let Some(label) = &path.label {
            if !labelled.contains(label) {
                labelled.push(label.clone());
                let (h, l) = legend_styles(path.line, width, thin);
                let half = (9.0 * s).round().max(4.0) as i32;
                legend_entry(chart, label, move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(-half, 0), (half, 0)], h)
                        + PathElement::new(vec![(-half, 0), (half, 0)], l)
                })?;
            }
        }
    }
    let size = (6.0 * s).round().max(3.0) as i32;
    for m in &overlay.marks {
        if !in_window(view, m.position_m) {
            continue;
        }
        let at = (m.position_m[0], m.position_m[1]);
        chart
            .plotting_area()
            .draw(&mark!(at, m.kind, size, width))
            .map_err(chart_err)?;
        if let Some(label) = &m.label {
            if !labelled.contains(label) {
                labelled.push(label.clone());
                let kind = m.kind;
                legend_entry(chart, label, move |(x, y)| mark!((x, y), kind, size, width))?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::MapOverlay;
    use crate::chart::clip::clipped_runs;
    use crate::chart::{draw_crlb_map_with, scenario_nodes, ChartOptions, MapData};
    use crate::localize::{crlb_map, Grid};
    use crate::present::simulate_snapshot;
    use crate::{scenario::presets, Model, Vec2};
    use plotters::prelude::*;

    /// A target's snapshot over the map (SVG): its legend entries join the nodes'.
    #[test]
    fn snapshot_overlay_is_drawn_with_its_legend() {
        let s = presets::sensors2019();
        let model = Model::new(&s).unwrap();
        let grid = Grid::new(s.area_m, 24, 24).unwrap();
        let mut v = vec![0.0; grid.len()];
        crlb_map(&model, &grid, &mut v).unwrap();
        let sim = simulate_snapshot(&model, &s.area_m, Vec2::new(4.0, 1.0), 3);
        let overlay = MapOverlay::snapshot(&sim);
        assert!(!overlay.is_empty());
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (900, 700)).into_drawing_area();
            let map = MapData { grid, values_m: &v };
            draw_crlb_map_with(
                &root,
                &map,
                &scenario_nodes(&s),
                &overlay,
                &ChartOptions::default(),
            )
            .unwrap();
            root.present().unwrap();
        }
        let doc = roxmltree::Document::parse(&svg).expect("well-formed SVG");
        let texts: Vec<&str> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .map(|n| n.text().unwrap_or("").trim())
            .collect();
        for label in [
            "target",
            "LM fix ±1σ",
            "CRLB 1σ",
            "iso-delay (measured)",
            "Tx",
        ] {
            let n = texts.iter().filter(|t| **t == label).count();
            assert_eq!(n, 1, "{label} in {texts:?}");
        }
    }

    #[test]
    fn runs_break_where_the_line_leaves_the_view() {
        let v = [0.0, 10.0, 0.0, 10.0];
        let pts = [
            [1.0, 1.0],
            [5.0, 1.0],
            [15.0, 1.0],
            [15.0, 5.0],
            [5.0, 5.0],
            [2.0, 5.0],
        ];
        let runs = clipped_runs(&pts, false, v);
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0], vec![(1.0, 1.0), (5.0, 1.0), (10.0, 1.0)]);
        assert_eq!(runs[1], vec![(10.0, 5.0), (5.0, 5.0), (2.0, 5.0)]);
        let square = [[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]];
        assert_eq!(clipped_runs(&square, true, v)[0].len(), 4);
        assert!(clipped_runs(&[[20.0, 20.0], [30.0, 30.0]], false, v).is_empty());
    }
}
