//! The multi-target scene figure (\[A\], spec `multi-target.md`; what the page's multi-target view
//! shows, in the figures' white style): the region `R`, the scatterer discs (diameter `D`), every
//! node–target segment (a blocked one dashed red, M3), each TRP's range ellipses (§5.1: a target's
//! direct path (DP) solid in the TRP's colour, clutter dotted grey, ranges that a detection's
//! matching uses thicker), the ellipse-intersection seeds and the hypotheses alive after the last stage
//! (§4), the detections (orange; a false alarm pink, M12) over the true targets, and the nodes,
//! on metre axes at equal scale. Everything is clipped to the window shown.

use alloc::string::String;
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::clip::{clip_polygon, clipped_runs};
use super::layout::{self, chart_err, register_fonts, ChartError};
use super::panel::{check_area, draw_metre_axes, finish_panel, metre_chart};
use super::panel::{in_window, legend_entry, plot_window, Chart, ChartNode, NodeKind};
use super::roc::CURVE_PALETTE;
use crate::math::Real;
use crate::measure::Ellipse;
use crate::present::EllipseView;
use crate::present::{MtlScene, MtlView};
use crate::scenario::Area;
use crate::Vec2;

/// Points per drawn range ellipse and per disc.
const OUTLINE_POINTS: usize = 96;
/// Margin around the region in the default window, as a fraction of its larger side.
const MARGIN_FRACTION: Real = 0.04;

const REGION_FILL: RGBColor = RGBColor(241, 243, 247);
const REGION_EDGE: RGBColor = RGBColor(150, 156, 168);
const DISC_RGB: RGBColor = RGBColor(120, 128, 142);
const BLOCKED_RGB: RGBColor = CURVE_PALETTE[1];
const CLUTTER_RGB: RGBColor = RGBColor(128, 128, 128);
const SEED_RGB: RGBColor = RGBColor(90, 90, 90);
const HYPOTHESIS_RGB: RGBColor = CURVE_PALETTE[4];
const DETECTED_RGB: RGBColor = RGBColor(255, 127, 14);
const FALSE_ALARM_RGB: RGBColor = RGBColor(227, 119, 194);

/// Options of the scene figure.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneChartOptions {
    /// Title (default: [`scene_titles`]).
    pub title: Option<String>,
    /// Subtitle (default: [`scene_titles`]).
    pub subtitle: Option<String>,
    /// The window shown (default: the region with a margin of 4 % of its larger side).
    pub window: Option<Area>,
}

/// The default window of `scene`: its region with a margin of 4 % of the larger side.
pub fn scene_window(scene: &MtlScene) -> Area {
    let [x0, x1, y0, y1] = scene.region;
    let m = MARGIN_FRACTION * (x1 - x0).max(y1 - y0);
    Area {
        x: [x0 - m, x1 + m],
        y: [y0 - m, y1 + m],
    }
}

/// The default title and subtitle: the scene's counts, and the detection result with the
/// thresholds and the blocking model.
pub fn scene_titles(scene: &MtlScene, view: &MtlView) -> (String, String) {
    let m = &view.metrics;
    (
        alloc::format!(
            "Multi-target localization — {} Tx, {} Rx, {} targets, {} discs",
            scene.transmitters.len(),
            scene.receivers.len(),
            scene.targets.len(),
            scene.discs.len()
        ),
        alloc::format!(
            "K̂/K = {}/{} · N_D = {} · N_FA = {} · {} ranges · T_e = {} σ · T_b = {} nats · seed {}",
            m.estimates,
            m.targets,
            m.detected,
            m.false_alarms,
            view.mpcs,
            scene.t_e,
            scene.t_b,
            scene.seed
        ),
    )
}

/// The nodes of `scene` named as on the page: `Tx1`, …, then `Rx1`, ….
pub fn scene_nodes(scene: &MtlScene) -> Vec<ChartNode> {
    let named = |prefix: &str, kind: NodeKind, list: &[[Real; 2]]| -> Vec<ChartNode> {
        list.iter()
            .enumerate()
            .map(|(i, p)| ChartNode {
                name: alloc::format!("{prefix}{}", i + 1),
                position_m: *p,
                kind,
            })
            .collect()
    };
    let mut nodes = named("Tx", NodeKind::Transmitter, &scene.transmitters);
    nodes.extend(named("Rx", NodeKind::Receiver, &scene.receivers));
    nodes
}

/// Draws the scene figure of `scene` and its `view` ([`crate::present::mtl_view`]) onto `root`
/// (filled white first). Does not call `present()`.
pub fn draw_mtl_scene<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    scene: &MtlScene,
    view: &MtlView,
    opts: &SceneChartOptions,
) -> Result<(), ChartError> {
    register_fonts();
    let window = opts.window.unwrap_or_else(|| scene_window(scene));
    check_area(&window)?;
    let (title, subtitle) = scene_titles(scene, view);
    let title = opts.title.clone().unwrap_or(title);
    let subtitle = opts.subtitle.clone().unwrap_or(subtitle);

    root.fill(&WHITE).map_err(chart_err)?;
    let lay = layout::Layout::new(root, &window, true);
    layout::draw_titles(root, &lay.font, &lay.band, &title, Some(&subtitle))?;
    let chart_area = root.clone().shrink(lay.chart_origin, lay.chart_size);
    let mut chart = metre_chart(&chart_area, &lay, &window)?;
    draw_metre_axes(&mut chart, &lay)?;
    draw_layers(&mut chart, scene, view, lay.font.nodes)?;
    finish_panel(&mut chart, &scene_nodes(scene), &lay)
}

fn outline(e: &EllipseView) -> Vec<[Real; 2]> {
    Ellipse {
        center: Vec2::new(e.cx, e.cy),
        semi_major: e.a,
        semi_minor: e.b,
        angle_rad: e.angle,
    }
    .polygon(OUTLINE_POINTS)
    .iter()
    .map(|p| [p.x, p.y])
    .collect()
}

fn disc(c: [Real; 2], radius: Real) -> Vec<[Real; 2]> {
    outline(&EllipseView {
        cx: c[0],
        cy: c[1],
        a: radius,
        b: radius,
        angle: 0.0,
    })
}

/// Region, discs, segments, ellipses, seeds, hypotheses, targets and detections, with their
/// legend entries; line widths and markers scale with `font_px` as the nodes' do.
fn draw_layers<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    scene: &MtlScene,
    view: &MtlView,
    font_px: f64,
) -> Result<(), ChartError> {
    let s = font_px / 20.0;
    let thin = (1.2 * s).round().max(1.0) as u32;
    let bold = (2.6 * s).round().max(2.0) as u32;
    let dash = (7.0 * s).round().max(2.0) as i32;
    let dot = (2.5 * s).round().max(1.0) as i32;
    let size = (6.0 * s).round().max(3.0) as i32;
    let half = (9.0 * s).round().max(4.0) as i32;
    let w = plot_window(chart);
    let inside = |p: [Real; 2]| in_window(w, p);
    let plot = chart.plotting_area().clone();
    let line = |points: &[[Real; 2]], closed: bool, style: ShapeStyle| -> Result<(), ChartError> {
        for run in clipped_runs(points, closed, w) {
            plot.draw(&PathElement::new(run, style))
                .map_err(chart_err)?;
        }
        Ok(())
    };
    let dashed = |points: &[[Real; 2]], closed: bool, d: i32, gap: i32, style: ShapeStyle| {
        for run in clipped_runs(points, closed, w) {
            plot.draw(&DashedPathElement::new(run, d, gap, style))
                .map_err(chart_err)?;
        }
        Ok::<(), ChartError>(())
    };
    let fill = |points: &[[Real; 2]], style: ShapeStyle| -> Result<(), ChartError> {
        let pts: Vec<(Real, Real)> = points.iter().map(|p| (p[0], p[1])).collect();
        let clipped = clip_polygon(&pts, w);
        if clipped.len() > 2 {
            plot.draw(&Polygon::new(clipped, style))
                .map_err(chart_err)?;
        }
        Ok(())
    };

    // The region.
    let [x0, x1, y0, y1] = scene.region;
    let region = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]];
    fill(&region, REGION_FILL.filled())?;
    line(&region, true, REGION_EDGE.stroke_width(thin))?;
    legend_entry(chart, "region R", move |(x, y)| {
        Rectangle::new(
            [(x - half, y - half / 2), (x + half, y + half / 2)],
            REGION_FILL.filled(),
        )
    })?;

    // Scatterer discs.
    for c in &scene.discs {
        let d = disc(*c, scene.diameter / 2.0);
        fill(&d, DISC_RGB.mix(0.45).filled())?;
        line(&d, true, DISC_RGB.stroke_width(thin))?;
    }
    if !scene.discs.is_empty() {
        let label = alloc::format!("disc, D = {} m", scene.diameter);
        legend_entry(chart, &label, move |(x, y)| {
            Circle::new((x, y), half / 2 + 1, DISC_RGB.mix(0.45).filled())
        })?;
    }

    // Node–target segments: LoS thin grey, blocked dashed red.
    let mut any_blocked = false;
    for seg in &view.segments {
        let pts = [seg.a, seg.b];
        if seg.blocked {
            any_blocked = true;
            dashed(
                &pts,
                false,
                dash,
                dash / 2,
                BLOCKED_RGB.stroke_width(thin + 1),
            )?;
        } else {
            line(&pts, false, BLACK.mix(0.18).stroke_width(thin))?;
        }
    }
    if any_blocked {
        legend_entry(chart, "blocked LoS", move |(x, y)| {
            PathElement::new(
                vec![(x - half, y), (x + half, y)],
                BLOCKED_RGB.stroke_width(thin + 1),
            )
        })?;
    }

    // Range ellipses: direct paths in their TRP's colour, clutter dotted grey; matched thicker.
    let (mut any_dp, mut any_clutter) = (false, false);
    for trp in &view.trps {
        let colour = CURVE_PALETTE[trp.trp % CURVE_PALETTE.len()];
        for r in &trp.ranges {
            let Some(e) = &r.ellipse else { continue };
            let pts = outline(e);
            let width = if r.matched_by.is_empty() { thin } else { bold };
            if r.target.is_some() {
                any_dp = true;
                line(&pts, true, colour.mix(0.85).stroke_width(width))?;
            } else {
                any_clutter = true;
                dashed(&pts, true, dot, dot, CLUTTER_RGB.stroke_width(width))?;
            }
        }
    }
    if any_dp {
        let c = CURVE_PALETTE[0];
        legend_entry(chart, "DP range (colour: TRP)", move |(x, y)| {
            PathElement::new(vec![(x - half, y), (x + half, y)], c.stroke_width(thin))
        })?;
    }
    if any_clutter {
        legend_entry(chart, "clutter", move |(x, y)| {
            PathElement::new(
                vec![
                    (x - half, y),
                    (x - half / 3, y),
                    (x + half / 3, y),
                    (x + half, y),
                ],
                CLUTTER_RGB.stroke_width(thin),
            )
        })?;
    }
    legend_entry(chart, "matched range", move |(x, y)| {
        PathElement::new(vec![(x - half, y), (x + half, y)], BLACK.stroke_width(bold))
    })?;

    // Seeds and hypotheses.
    let dot_r = (2.0 * s).round().max(1.0) as i32;
    for seed in view.seeds.iter().filter(|q| inside(q.x)) {
        plot.draw(&Circle::new(
            (seed.x[0], seed.x[1]),
            dot_r,
            SEED_RGB.filled(),
        ))
        .map_err(chart_err)?;
    }
    if !view.seeds.is_empty() {
        legend_entry(chart, "seed", move |(x, y)| {
            Circle::new((x, y), dot_r, SEED_RGB.filled())
        })?;
    }
    let sq = size / 2 + 1;
    for h in view.hypotheses.iter().filter(|h| inside(h.x)) {
        let at = (h.x[0], h.x[1]);
        plot.draw(
            &(EmptyElement::at(at)
                + Rectangle::new([(-sq, -sq), (sq, sq)], HYPOTHESIS_RGB.stroke_width(thin))),
        )
        .map_err(chart_err)?;
    }
    if !view.hypotheses.is_empty() {
        legend_entry(chart, "hypothesis", move |(x, y)| {
            Rectangle::new(
                [(x - sq, y - sq), (x + sq, y + sq)],
                HYPOTHESIS_RGB.stroke_width(thin),
            )
        })?;
    }

    // True targets (black crosses on a white halo), then the detections (rings).
    let cross = move |at: (i32, i32), style: ShapeStyle| {
        EmptyElement::at(at)
            + PathElement::new(vec![(-size, -size), (size, size)], style)
            + PathElement::new(vec![(-size, size), (size, -size)], style)
    };
    let halo = WHITE.stroke_width(bold + 3);
    let ink = BLACK.stroke_width(bold);
    for t in view.targets.iter().filter(|t| inside(t.x)) {
        let at = (t.x[0], t.x[1]);
        let mark = |style: ShapeStyle| {
            EmptyElement::at(at)
                + PathElement::new(vec![(-size, -size), (size, size)], style)
                + PathElement::new(vec![(-size, size), (size, -size)], style)
        };
        plot.draw(&mark(halo)).map_err(chart_err)?;
        plot.draw(&mark(ink)).map_err(chart_err)?;
    }
    if !view.targets.is_empty() {
        legend_entry(chart, "target", move |(x, y)| cross((x, y), ink))?;
    }
    let ring = size + 3;
    let (mut hits, mut misses) = (false, false);
    for d in view.detected.iter().filter(|d| inside(d.x)) {
        let colour = if d.hit { DETECTED_RGB } else { FALSE_ALARM_RGB };
        hits |= d.hit;
        misses |= !d.hit;
        plot.draw(&Circle::new(
            (d.x[0], d.x[1]),
            ring,
            colour.stroke_width(bold),
        ))
        .map_err(chart_err)?;
    }
    if hits {
        legend_entry(chart, "detected", move |(x, y)| {
            Circle::new((x, y), ring, DETECTED_RGB.stroke_width(bold))
        })?;
    }
    if misses {
        legend_entry(chart, "false alarm", move |(x, y)| {
            Circle::new((x, y), ring, FALSE_ALARM_RGB.stroke_width(bold))
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{draw_mtl_scene, scene_window, SceneChartOptions};
    use crate::chart::clip::clip_polygon;
    use crate::present::{mtl_view, MtlScene};
    use crate::scenario::Area;
    use plotters::prelude::*;

    /// Sutherland–Hodgman against hand-worked cases: a square half outside keeps its inside
    /// half; one wholly outside vanishes; one inside is unchanged.
    #[test]
    fn polygon_clipping() {
        let sq = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        let half = clip_polygon(&sq, [0.0, 5.0, -5.0, 5.0]);
        let area = |p: &[(f64, f64)]| {
            0.5 * (0..p.len())
                .map(|i| {
                    let (a, b) = (p[i], p[(i + 1) % p.len()]);
                    a.0 * b.1 - b.0 * a.1
                })
                .sum::<f64>()
        };
        assert!((area(&half) - 2.0).abs() < 1e-12, "{half:?}");
        assert!(half.iter().all(|p| p.0 >= 0.0));
        assert!(clip_polygon(&sq, [2.0, 3.0, 2.0, 3.0]).is_empty());
        assert_eq!(clip_polygon(&sq, [-2.0, 2.0, -2.0, 2.0]), sq.to_vec());
    }

    /// The V-B scene as SVG: the nodes' labels, the legend of every layer present, one target
    /// cross pair per target in the default window, and nothing of a node outside a window.
    #[test]
    fn vb_scene_draws_every_layer_with_its_legend() {
        let scene = MtlScene::vb();
        let view = mtl_view(&scene).unwrap();
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (900, 820)).into_drawing_area();
            draw_mtl_scene(&root, &scene, &view, &SceneChartOptions::default()).unwrap();
            root.present().unwrap();
        }
        let doc = roxmltree::Document::parse(&svg).unwrap();
        let texts: Vec<String> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .map(|n| n.text().unwrap_or("").trim().to_string())
            .collect();
        for name in ["Tx1", "Tx2", "Tx3", "Rx1", "Rx2", "Rx3"] {
            assert_eq!(texts.iter().filter(|t| *t == name).count(), 1, "{name}");
        }
        for label in [
            "region R",
            "disc, D = 0.6 m",
            "blocked LoS",
            "DP range (colour: TRP)",
            "clutter",
            "target",
            "detected",
            "transmitter",
            "receiver",
        ] {
            assert!(
                texts.iter().any(|t| t == label),
                "legend {label} in {texts:?}"
            );
        }
        assert!(
            texts.iter().any(|t| t.starts_with("K̂/K = 2/2")),
            "{texts:?}"
        );
        let w = scene_window(&scene);
        assert!((w.x[0] + 0.4).abs() < 1e-12 && (w.y[1] - 10.4).abs() < 1e-12);

        // A window around the middle only: the corner nodes' labels are gone.
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (600, 600)).into_drawing_area();
            let opts = SceneChartOptions {
                window: Some(Area {
                    x: [3.0, 7.0],
                    y: [3.0, 7.0],
                }),
                ..SceneChartOptions::default()
            };
            draw_mtl_scene(&root, &scene, &view, &opts).unwrap();
            root.present().unwrap();
        }
        let outside: Vec<String> = super::scene_nodes(&scene)
            .into_iter()
            .filter(|n| {
                !(3.0..=7.0).contains(&n.position_m[0]) || !(3.0..=7.0).contains(&n.position_m[1])
            })
            .map(|n| n.name)
            .collect();
        assert!(!outside.is_empty());
        let doc = roxmltree::Document::parse(&svg).unwrap();
        let texts: Vec<&str> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .map(|n| n.text().unwrap_or("").trim())
            .collect();
        for name in &outside {
            assert!(
                !texts.contains(&name.as_str()),
                "{name} drawn outside the window"
            );
        }
    }
}
