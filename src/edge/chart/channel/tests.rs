use super::*;
use crate::channel::DelayEstimate;
use crate::math::{cos, sin, Complex, PI, SPEED_OF_LIGHT};
use crate::present::{
    delay_image, delay_points, track_errors, DelayPoint, ImageConfig, SegmentSpan, StaticBand,
    TruthCurve,
};

/// The SVG of `draw` on a `size` canvas, and the same drawn into an RGB buffer (PNG backend).
fn render(
    size: (u32, u32),
    draw: impl Fn(&DrawingArea<SVGBackend, Shift>) -> Result<(), ChartError>,
    draw_png: impl Fn(&DrawingArea<BitMapBackend, Shift>) -> Result<(), ChartError>,
) -> String {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(&root).unwrap();
        root.present().unwrap();
    }
    let mut buf = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        draw_png(&root).unwrap();
        root.present().unwrap();
    }
    // Not all white: something was drawn.
    assert!(buf.iter().any(|&b| b < 200));
    assert!(
        !svg.contains("NaN") && !svg.contains("inf"),
        "non-finite in the SVG"
    );
    svg
}

fn texts(svg: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg).expect("well-formed SVG");
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| n.text().unwrap_or("").trim().to_string())
        .collect()
}

fn count(svg: &str, tag: &str) -> usize {
    let doc = roxmltree::Document::parse(svg).unwrap();
    doc.descendants().filter(|n| n.has_tag_name(tag)).count()
}

/// A walk's figure: four links; link 0 with an image of two paths (a static one at 20 m and the
/// pedestrian's from 25 to 40 m), link 1 without truth, link 2 without estimates, link 3 bare.
fn figure() -> DelayFigure {
    let t: Vec<Real> = (0..50).map(|k| k as Real * 0.1).collect();
    let ped = |t: Real| 25.0 + 3.0 * t;
    let n = 64;
    let f: Vec<Real> = (0..n).map(|k| (k as Real - 31.5) * 2e6).collect();
    let cfr: Vec<Vec<Complex>> = t
        .iter()
        .map(|&ts| {
            f.iter()
                .map(|&fk| {
                    [(20.0, 0.01), (ped(ts), 0.003)]
                        .iter()
                        .map(|&(r, a)| {
                            let ph = -2.0 * PI * fk * r / SPEED_OF_LIGHT;
                            Complex::new(a * cos(ph), a * sin(ph))
                        })
                        .sum()
                })
                .collect()
        })
        .collect();
    let mut cfg = ImageConfig::new([0.0, 60.0]);
    cfg.rows = 60;
    let image = delay_image(&f, &t, |s| cfr[s].as_slice(), &cfg).unwrap();
    let est: Vec<Vec<DelayEstimate>> = t
        .iter()
        .map(|&ts| {
            [(20.0, 0.01), (ped(ts), 0.003)]
                .iter()
                .map(|&(r, a)| DelayEstimate {
                    delay_s: r / SPEED_OF_LIGHT,
                    amplitude: a,
                    sigma_s: None,
                })
                .collect()
        })
        .collect();
    let points: Vec<DelayPoint> = delay_points(&t, &est);
    let statics = vec![StaticBand {
        mean_m: 20.0,
        halfwidth_m: 0.5,
    }];
    let truth = vec![
        TruthCurve {
            kind: "pedestrian".into(),
            primary: true,
            points: t.iter().map(|&ts| (ts, ped(ts))).collect(),
        },
        TruthCurve {
            kind: "los".into(),
            primary: false,
            points: t.iter().map(|&ts| (ts, 20.0)).collect(),
        },
    ];
    let link = |name: &str, image, estimates, truth| LinkDelays {
        name: name.into(),
        range_m: [0.0, 60.0],
        image,
        estimates,
        statics: statics.clone(),
        truth,
    };
    DelayFigure::new(
        &t,
        vec![
            link("Tx → Rx1", Some(image), points.clone(), truth.clone()),
            link("Tx → Rx2", None, points, Vec::new()),
            link("Tx → Rx3", None, Vec::new(), truth),
            link("Tx → Rx4", None, Vec::new(), Vec::new()),
        ],
    )
}

#[test]
fn delay_figure_has_a_panel_per_link_the_image_the_points_and_labels() {
    let fig = figure();
    let opts = ChannelChartOptions {
        title: "Delays".into(),
        subtitle: Some("simulated walk".into()),
    };
    let size = delays_size(4);
    let svg = render(
        size,
        |r| draw_delays(r, &fig, &opts),
        |r| draw_delays(r, &fig, &opts),
    );
    let tx = texts(&svg);
    let n = |s: &str| tx.iter().filter(|t| *t == s).count();
    assert_eq!(n("time t (s)"), 4, "{tx:?}");
    assert_eq!(n("path length c·τ (m)"), 4);
    for name in ["Tx → Rx1", "Tx → Rx2", "Tx → Rx3", "Tx → Rx4"] {
        assert_eq!(n(name), 1, "{name}");
    }
    assert_eq!(n("no estimates"), 2);
    assert_eq!(n("truth: pedestrian"), 1);
    assert_eq!(n("truth: los"), 1);
    assert_eq!(n("static cluster ±3σ"), 1);
    assert_eq!(n("estimate amplitude 20·log₁₀|α| (dB)"), 1);
    assert_eq!(n("response power (dB)"), 1);
    // 2 links × 50 snapshots × 2 paths estimates + the legend's marker.
    assert_eq!(count(&svg, "circle"), 201);
    // The image: at least one grey cell per column; the dashed truth lines.
    assert!(count(&svg, "rect") > 50 + 4 * 4, "{}", count(&svg, "rect"));
    assert!(svg.contains("#D55E00"), "truth vermillion");
}

#[test]
fn empty_delay_figures_draw() {
    let opts = ChannelChartOptions::default();
    let none = DelayFigure::new(&[], Vec::new());
    let svg = render(
        (800, 500),
        |r| draw_delays(r, &none, &opts),
        |r| draw_delays(r, &none, &opts),
    );
    assert!(texts(&svg).iter().any(|t| t == "no links"));
    let mut fig = figure();
    fig.links.truncate(1);
    fig.links[0].estimates.clear();
    fig.amplitude_db_range = None;
    let svg = render(
        (1000, 620),
        |r| draw_delays(r, &fig, &opts),
        |r| draw_delays(r, &fig, &opts),
    );
    assert!(texts(&svg).iter().any(|t| t == "no estimates"));
    let mut bad = figure();
    bad.links[0].image.as_mut().unwrap().db.pop();
    let mut s = String::new();
    let root = SVGBackend::with_string(&mut s, (800, 500)).into_drawing_area();
    let e = draw_delays(&root, &bad, &opts).unwrap_err();
    assert!(e.0.contains("Tx → Rx1"), "{}", e.0);
}

fn nodes() -> Vec<ChartNode> {
    use crate::chart::NodeKind;
    vec![
        ChartNode {
            name: "Tx".into(),
            position_m: [0.0, 0.0],
            kind: NodeKind::Transmitter,
        },
        ChartNode {
            name: "Rx1".into(),
            position_m: [10.0, 0.0],
            kind: NodeKind::Receiver,
        },
    ]
}

#[test]
fn track_figure_marks_the_90_percent_point() {
    let t: Vec<Real> = (0..20).map(|k| k as Real * 0.5).collect();
    let truth: Vec<Option<[Real; 4]>> = t.iter().map(|&ts| Some([ts, 2.0, 1.0, 0.0])).collect();
    // Errors 0.1·k m from snapshot 2 on: 0.2 … 1.9 m (18 of them); the 90 % quantile is the
    // ⌈16.2⌉ = 17th smallest, 1.8 m.
    let states: Vec<Option<[Real; 4]>> = t
        .iter()
        .enumerate()
        .map(|(k, &ts)| (k >= 2).then_some([ts, 2.0 + 0.1 * k as Real, 1.0, 0.0]))
        .collect();
    let view = track_errors(&t, &states, &truth).unwrap();
    assert!((view.stats.unwrap().p90_m - 1.8).abs() < 1e-12);
    let area = Area {
        x: [-1.0, 12.0],
        y: [-2.0, 6.0],
    };
    let opts = ChannelChartOptions {
        title: "Track".into(),
        subtitle: None,
    };
    let draw = |v: &TrackErrorView| {
        let v = v.clone();
        let n = nodes();
        render(
            track_errors_size(),
            |r| draw_track_errors(r, &v, &n, &area, &opts),
            |r| draw_track_errors(r, &v, &n, &area, &opts),
        )
    };
    let svg = draw(&view);
    let tx = texts(&svg);
    assert!(tx.iter().any(|t| t == "90 %: 1.80 m"), "{tx:?}");
    // 18 errors 0.2 … 1.9 m: median the 9th = 1.0 m, 8 of 18 = 44.4 % strictly below 1 m.
    let stats = "median 1.00 m · 90 % 1.80 m · max 1.90 m · 44.4 % below 1 m";
    assert!(tx.iter().any(|t| t == stats), "{tx:?}");
    for label in [
        "x (m)",
        "time t (s)",
        "position error (m)",
        "empirical CDF F(e)",
        "truth",
        "track",
        "Rx1",
    ] {
        assert!(tx.iter().any(|t| t == label), "{label} in {tx:?}");
    }
    assert!(!tx.iter().any(|t| t == "no track"));
    // The track never starts: said, no curve, no NaN.
    let never = track_errors(&t, &vec![None; 20], &truth).unwrap();
    let svg = draw(&never);
    let tx = texts(&svg);
    assert!(
        tx.iter().filter(|t| *t == "no track").count() >= 3,
        "{tx:?}"
    );
    assert!(!tx.iter().any(|t| t.starts_with("90 %")));
    // No truth: the map still shows the track.
    let bare = track_errors(&t, &states, &[]).unwrap();
    let tx = texts(&draw(&bare));
    assert!(tx.iter().any(|t| t == "no truth") && tx.iter().any(|t| t == "track"));
}

/// A track lost once (innovation, at 3.5 s) and restarted: the error chart labels the loss,
/// the map rings where it was lost; a track without segments has neither.
#[test]
fn track_figure_marks_losses() {
    let t: Vec<Real> = (0..20).map(|k| k as Real * 0.5).collect();
    let truth: Vec<Option<[Real; 4]>> = t.iter().map(|&ts| Some([ts, 2.0, 1.0, 0.0])).collect();
    let states: Vec<Option<[Real; 4]>> = t
        .iter()
        .enumerate()
        .map(|(k, &ts)| ((2..=6).contains(&k) || k >= 10).then_some([ts, 2.2, 1.0, 0.0]))
        .collect();
    let mut view = track_errors(&t, &states, &truth).unwrap();
    let area = Area {
        x: [-1.0, 12.0],
        y: [-2.0, 6.0],
    };
    let opts = ChannelChartOptions {
        title: "Track".into(),
        subtitle: None,
    };
    let draw = |v: &TrackErrorView| {
        let v = v.clone();
        let n = nodes();
        render(
            track_errors_size(),
            |r| draw_track_errors(r, &v, &n, &area, &opts),
            |r| draw_track_errors(r, &v, &n, &area, &opts),
        )
    };
    let before = draw(&view);
    assert!(!texts(&before).iter().any(|t| t.starts_with("lost")));
    view.segments = vec![
        SegmentSpan {
            first: 2,
            last: 6,
            t_first_s: 1.0,
            t_last_s: 3.0,
            end: "innovation".into(),
            lost_s: Some(3.5),
            lost_m: Some([3.0, 2.2]),
        },
        SegmentSpan {
            first: 10,
            last: 19,
            t_first_s: 5.0,
            t_last_s: 9.5,
            end: "end".into(),
            lost_s: None,
            lost_m: None,
        },
    ];
    let svg = draw(&view);
    let tx = texts(&svg);
    assert_eq!(
        tx.iter().filter(|t| *t == "lost: innovation").count(),
        1,
        "{tx:?}"
    );
    assert_eq!(count(&svg, "circle"), count(&before, "circle") + 1);
    // Shading before the first segment and in the gap: two more rectangles.
    assert_eq!(count(&svg, "rect"), count(&before, "rect") + 2);
}

/// Issue 37 item 11: the SVG the CLI and the page write holds each link's image as ONE
/// embedded PNG (at its plot's pixel size, under the vector layers), not one rectangle per run
/// of grey, so the file stops growing with the imaged columns. Checked against the cells the
/// vector figure draws: the PNG's pixel under the middle of each image column and row is the
/// grey of that cell (an independent lookup: time → nearest column, range → nearest row).
#[test]
fn the_svg_embeds_each_image_as_one_png() {
    let fig = figure();
    let opts = ChannelChartOptions::default();
    let size = delays_size(4);
    let svg = delays_svg(size, &fig, &opts).unwrap();
    let doc = roxmltree::Document::parse(&svg).expect("well-formed SVG");
    let images: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("image"))
        .collect();
    assert_eq!(images.len(), 1, "only link 0 has an image");
    let vector = render(
        size,
        |r| draw_delays(r, &fig, &opts),
        |r| draw_delays(r, &fig, &opts),
    );
    // The cells are gone (the other rectangles — colour bars, bands, frames — stay); the
    // circles and texts stay.
    let cells = count(&vector, "rect") - count(&svg, "rect");
    assert!(cells > 1000, "{cells} cells");
    assert_eq!(count(&svg, "circle"), count(&vector, "circle"));
    assert_eq!(texts(&svg), texts(&vector));
    // The image's pixels, as given to the PNG encoder (tested on its own in `raster`).
    let boxes = {
        let mut s = String::new();
        let root = SVGBackend::with_string(&mut s, size).into_drawing_area();
        draw_delays_boxes(&root, &fig, &opts).unwrap()
    };
    let b = boxes[0];
    let (w, h) = (
        (b.x_px[1] - b.x_px[0]) as usize,
        (b.y_px[1] - b.y_px[0]) as usize,
    );
    let attr = |k: &str| images[0].attribute(k).unwrap().parse::<i32>().unwrap();
    assert_eq!(
        (attr("x"), attr("y"), attr("width"), attr("height")),
        (b.x_px[0], b.y_px[0], w as i32, h as i32)
    );
    let img = fig.links[0].image.as_ref().unwrap();
    let g = image_range(&fig.links).unwrap();
    let range = axis(fig.links[0].range_m);
    let rgb = image_rgb(img, g, b.t_range_s, range, (w, h));
    let [t0, t1] = b.t_range_s;
    let mut checked = 0;
    for (i, &tc) in img.t_s.iter().enumerate() {
        let x = ((tc - t0) / (t1 - t0) * w as Real) as usize;
        if x >= w {
            continue;
        }
        for j in 0..img.rows {
            let r = img.r0_m + j as Real * img.dr_m;
            if !(range[0]..range[1]).contains(&r) {
                continue;
            }
            let y = ((range[1] - r) / (range[1] - range[0]) * h as Real) as usize;
            if y >= h {
                continue;
            }
            // Only pixels whose centre lies in the cell (not on a boundary).
            let tx = t0 + (x as Real + 0.5) / w as Real * (t1 - t0);
            let ry = range[1] - (y as Real + 0.5) / h as Real * (range[1] - range[0]);
            let nearest_col = img
                .t_s
                .iter()
                .enumerate()
                .min_by(|a, b| (a.1 - tx).abs().total_cmp(&(b.1 - tx).abs()))
                .unwrap()
                .0;
            let nearest_row = ((ry - img.r0_m) / img.dr_m).round() as usize;
            if nearest_col != i || nearest_row != j {
                continue;
            }
            let RGBColor(want, _, _) = grey(img.db[j * img.cols() + i], g[0], g[1]);
            assert_eq!(rgb[3 * (y * w + x)], want, "column {i}, row {j}");
            checked += 1;
        }
    }
    assert!(checked > 500, "{checked} pixels checked");
}
