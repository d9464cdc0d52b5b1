//! The delay figure's range-rate ticks (issue 42 §5): each estimate with a range rate is drawn
//! with a tick of slope `d(c·τ)/dt = ṙ` through it, the same in the vector panel and in the
//! SVG's rasterised layer. The expected pixels come from the panel's own [`PlotBox`] (the
//! data-to-pixel map the test applies itself), not from the drawing code.

use alloc::string::String;
use alloc::vec::Vec;

use plotters::prelude::*;

use super::delays::{ESTIMATE_RGB, STATIC_ESTIMATE_RGB};
use super::tests::{png_rgb, unbase64};
use super::*;
use crate::math::Real;
use crate::present::{DelayFigure, DelayPoint, LinkDelays, StaticBand, TruthCurve};

/// The walker's path length, m, at `t` s: 25 m + 3 m/s · t.
fn walker(t: Real) -> Real {
    25.0 + 3.0 * t
}

/// One link over 5 s: the walker (ṙ = 3 m/s) and a static path at 20 m (ṙ = 0), 11 scans
/// 0.5 s apart, each with `[ṙ, σ]` when `rates`; a static band at 20 m and the walker's truth.
fn figure(rates: bool) -> DelayFigure {
    let t: Vec<Real> = (0..11).map(|k| k as Real * 0.5).collect();
    let point = |t_s: Real, range_m: Real, rate: Real| DelayPoint {
        t_s,
        range_m,
        amplitude_db: -60.0,
        range_rate_mps: rates.then_some([rate, 0.1]),
    };
    let estimates = t
        .iter()
        .flat_map(|&ts| [point(ts, walker(ts), 3.0), point(ts, 20.0, 0.0)])
        .collect();
    DelayFigure::new(
        &t,
        alloc::vec![LinkDelays {
            name: "Tx → Rx1".into(),
            range_m: [10.0, 50.0],
            image: None,
            estimates,
            statics: alloc::vec![StaticBand {
                mean_m: 20.0,
                halfwidth_m: 0.5,
            }],
            truth: alloc::vec![TruthCurve {
                kind: "person".into(),
                primary: true,
                points: t.iter().map(|&ts| (ts, walker(ts))).collect(),
            }],
        }],
    )
}

/// The pixel of `(t, r)` in `b` (continuous; `y` down), and the pixels per second and metre.
fn pixel_map(b: &PlotBox, range: [Real; 2]) -> (impl Fn(Real, Real) -> (Real, Real), Real, Real) {
    let [t0, t1] = b.t_range_s;
    let (w, h) = (
        (b.x_px[1] - b.x_px[0]) as Real,
        (b.y_px[1] - b.y_px[0]) as Real,
    );
    let (x0, y0) = (b.x_px[0] as Real, b.y_px[0] as Real);
    let [r0, r1] = range;
    (
        move |t: Real, r: Real| (x0 + (t - t0) / (t1 - t0) * w, y0 + (r1 - r) / (r1 - r0) * h),
        w / (t1 - t0),
        h / (r1 - r0),
    )
}

fn hex(RGBColor(r, g, b): RGBColor) -> String {
    alloc::format!("#{r:02X}{g:02X}{b:02X}")
}

#[test]
fn each_rate_is_a_tick_of_its_slope_through_its_estimate() {
    let fig = figure(true);
    let opts = ChannelChartOptions::default();
    let size = delays_size(1);
    let mut svg = String::new();
    let boxes = {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let b = draw_delays_boxes(&root, &fig, &opts).unwrap();
        root.present().unwrap();
        b
    };
    let link = &fig.links[0];
    let (to_px, kt, kr) = pixel_map(&boxes[0], link.range_m);
    let doc = roxmltree::Document::parse(&svg).unwrap();
    // Two-point polylines in the estimates' colours: the ticks (and the legend's one).
    let ticks: Vec<(String, [(Real, Real); 2])> = doc
        .descendants()
        .filter(|n| n.has_tag_name("polyline"))
        .filter_map(|n| {
            let stroke = n.attribute("stroke")?.to_uppercase();
            let pts: Vec<(Real, Real)> = n
                .attribute("points")?
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect();
            let ours = stroke == hex(ESTIMATE_RGB) || stroke == hex(STATIC_ESTIMATE_RGB);
            (ours && pts.len() == 2).then(|| (stroke, [pts[0], pts[1]]))
        })
        .collect();
    // One tick per estimate (22) and the legend's.
    assert_eq!(ticks.len(), link.estimates.len() + 1, "{ticks:?}");
    let s = super::delays::delays_scale(size, 1);
    let half = super::delays::rate_tick_half_px(s);
    for e in &link.estimates {
        let (cx, cy) = to_px(e.t_s, e.range_m);
        // Plotters rounds its own pixel map (up to 2 px from the plot box's continuous one).
        // At the time axis' ends the plot clips the tick's outer half (plotters moves the cut
        // end by up to 2 px): there only its place is checked.
        let [xl, xr] = boxes[0].x_px.map(|v| v as Real);
        let clipped = cx - half < xl || cx + half > xr;
        let found: Vec<_> = ticks
            .iter()
            .filter(|(_, [a, b])| {
                let (mx, my) = (0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1));
                let mid = (mx - cx).abs() <= 2.0 && (my - cy).abs() <= 2.0;
                let end = |p: &(Real, Real)| (p.0 - cx).abs() <= 2.5 && (p.1 - cy).abs() <= 2.5;
                if clipped {
                    end(a) || end(b)
                } else {
                    mid
                }
            })
            .collect();
        assert_eq!(found.len(), 1, "one tick through {e:?} at ({cx}, {cy})");
        let (stroke, [a, b]) = found[0];
        let want = if e.range_m == 20.0 {
            STATIC_ESTIMATE_RGB
        } else {
            ESTIMATE_RGB
        };
        assert_eq!(*stroke, hex(want));
        if clipped {
            continue;
        }
        // Its screen direction is (kt, −ṙ·kr) (y down), its length 2·half; the endpoints are
        // whole pixels, so each is within ½ px (diagonal √½) of the exact one.
        let rate = e.range_rate_mps.unwrap()[0];
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len = (dx * dx + dy * dy).sqrt();
        assert!(
            (len - 2.0 * half).abs() <= 1.5,
            "length {len} vs {}",
            2.0 * half
        );
        let angle = (-dy).atan2(dx);
        let want_angle = (rate * kr).atan2(kt);
        assert!(
            (angle - want_angle).abs() <= (1.5 / len).atan(),
            "{e:?}: angle {angle} vs {want_angle}"
        );
    }
    // The walker's ticks lie along its true curve: both ends of each tick within 1.5 px of the
    // truth line (slope 3 m/s), every tick but the two the axis' ends cut (module docs).
    let (a, b) = (to_px(0.0, walker(0.0)), to_px(5.0, walker(5.0)));
    let dist = |p: (Real, Real)| {
        let (ux, uy) = (b.0 - a.0, b.1 - a.1);
        ((p.0 - a.0) * uy - (p.1 - a.1) * ux).abs() / (ux * ux + uy * uy).sqrt()
    };
    let walker_ticks = ticks
        .iter()
        .filter(|(s, _)| *s == hex(ESTIMATE_RGB))
        .filter(|(_, [p, q])| dist(*p) <= 1.5 && dist(*q) <= 1.5)
        .count();
    assert!(
        walker_ticks >= 9,
        "{walker_ticks} of 11 ticks along the truth"
    );
}

#[test]
fn the_rasterised_layer_draws_the_same_ticks() {
    let opts = ChannelChartOptions::default();
    let size = delays_size(1);
    let s = super::delays::delays_scale(size, 1);
    let half = super::delays::rate_tick_half_px(s);
    let png_of = |fig: &DelayFigure| {
        let svg = delays_svg(size, fig, &opts).unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap();
        let href = doc
            .descendants()
            .find(|n| n.has_tag_name("image"))
            .unwrap()
            .attribute("href")
            .unwrap()
            .to_string();
        let png = unbase64(
            href.strip_prefix(super::super::raster::PNG_DATA_URI)
                .unwrap(),
        );
        png_rgb(&png)
    };
    let (with, without) = (figure(true), figure(false));
    let boxes = {
        let mut svg = String::new();
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw_delays_boxes(&root, &with, &opts).unwrap()
    };
    let (to_px, kt, kr) = pixel_map(&boxes[0], with.links[0].range_m);
    let (x0, y0) = (boxes[0].x_px[0] as Real, boxes[0].y_px[0] as Real);
    let (w, _, rgb) = png_of(&with);
    let (_, _, bare) = png_of(&without);
    let at = |img: &[u8], (x, y): (Real, Real)| {
        let (i, j) = ((x - x0) as usize, (y - y0) as usize);
        [
            img[3 * (j * w + i)],
            img[3 * (j * w + i) + 1],
            img[3 * (j * w + i) + 2],
        ]
    };
    let RGBColor(r, g, b) = ESTIMATE_RGB;
    let blue = [r, g, b];
    let near = |p: [u8; 3], q: [u8; 3]| p.iter().zip(q).all(|(a, b)| a.abs_diff(b) <= 40);
    let mut checked = 0;
    for e in with.links[0].estimates.iter().filter(|e| e.range_m != 20.0) {
        let (cx, cy) = to_px(e.t_s, e.range_m);
        let rate = e.range_rate_mps.unwrap()[0];
        let norm = (kt * kt + rate * kr * rate * kr).sqrt();
        let (ux, uy) = (kt / norm, -rate * kr / norm);
        // Two thirds along the tick: past the dot (radius 2.6·s), inside the tick.
        let d = 2.0 / 3.0 * half;
        for sign in [-1.0, 1.0] {
            let along = (cx + sign * d * ux, cy + sign * d * uy);
            let across = (cx - sign * d * uy, cy + sign * d * ux);
            if along.0 < x0 + 1.0 || along.0 > boxes[0].x_px[1] as Real - 1.0 {
                continue; // the first and last scans' outer halves leave the plot
            }
            assert!(near(at(&rgb, along), blue), "{e:?}: {:?}", at(&rgb, along));
            assert_eq!(at(&rgb, across), [255, 255, 255], "{e:?} across");
            assert_eq!(at(&bare, along), [255, 255, 255], "{e:?} without rates");
            checked += 1;
        }
    }
    assert!(checked >= 20, "{checked}");
}
