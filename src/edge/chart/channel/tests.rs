use alloc::string::String;
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::delays::{grey, image_range, ESTIMATE_RGB, STATIC_ESTIMATE_RGB};
use super::delays_svg::image_rgb;
use super::shared::axis;
use super::*;
use crate::channel::DelayEstimate;
use crate::edge::chart::{ChartError, ChartNode};
use crate::math::{cos, sin, Complex, Real, PI, SPEED_OF_LIGHT};
use crate::present::{
    delay_image, delay_points, track_errors, DelayFigure, DelayPoint, ImageConfig, LinkDelays,
    SegmentSpan, StaticBand, TrackErrorView, TruthCurve,
};
use crate::scenario::Area;

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
    // Issue 38 item 7: ONE colour bar (the image's), the estimates in one colour (grey inside
    // a static cluster, as the docs and the legend say).
    assert_eq!(n("estimate amplitude 20·log₁₀|α| (dB)"), 0);
    assert_eq!(n("response power (dB)"), 1);
    assert_eq!(n("estimate"), 1);
    assert_eq!(n("estimate in a static cluster"), 1);
    // 2 links × 50 snapshots × 2 paths estimates + the legend's two markers.
    assert_eq!(count(&svg, "circle"), 202);
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let circle_fill = |c: &str| {
        doc.descendants()
            .filter(|n| n.has_tag_name("circle") && n.attribute("fill") == Some(c))
            .count()
    };
    // The static path at 20 m (inside its band) grey, the pedestrian's blue.
    assert_eq!(circle_fill("#969696"), 2 * 50 + 1);
    assert_eq!(circle_fill("#0072B2"), 2 * 50 + 1);
    // The image: at least one grey cell per column; the dashed truth lines.
    assert!(count(&svg, "rect") > 50 + 4 * 4, "{}", count(&svg, "rect"));
    // The truth vermillion, drawn over panel 0's estimates (after them in the document).
    let truth_at = svg.find("#D55E00").expect("truth vermillion");
    assert_eq!(
        svg[..truth_at].matches("<circle").count(),
        100,
        "panel 0's estimates first, the truth over them"
    );
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
    // Every panel with an image, estimates or bands (all four have bands).
    assert_eq!(images.len(), 4);
    let vector = render(
        size,
        |r| draw_delays(r, &fig, &opts),
        |r| draw_delays(r, &fig, &opts),
    );
    // The cells and the bands are gone (the other rectangles — colour bar, frames — stay), the
    // estimates too (in the PNG; issue 38 item 7): only the legend's two markers are circles;
    // the texts stay.
    let cells = count(&vector, "rect") - count(&svg, "rect");
    assert!(cells > 1000, "{cells} cells");
    assert_eq!(count(&svg, "circle"), 2);
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

/// A tiny standard base64 decoder (the test reads the PNGs the SVG embeds).
pub(super) fn unbase64(s: &str) -> Vec<u8> {
    let val = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    };
    let mut out = Vec::new();
    for q in s.as_bytes().chunks(4) {
        let n = q.iter().enumerate().fold(0u32, |n, (i, &c)| {
            if c == b'=' {
                n
            } else {
                n | (val(c) as u32) << (18 - 6 * i)
            }
        });
        let bytes = q.iter().filter(|&&c| c != b'=').count() - 1;
        out.extend_from_slice(&n.to_be_bytes()[1..1 + bytes]);
    }
    out
}

/// The RGB pixels of an 8-bit RGB PNG written by `raster::encode_png` (filter 0 rows).
pub(super) fn png_rgb(png: &[u8]) -> (usize, usize, Vec<u8>) {
    use std::io::Read;
    let w = u32::from_be_bytes(png[16..20].try_into().unwrap()) as usize;
    let h = u32::from_be_bytes(png[20..24].try_into().unwrap()) as usize;
    let len = u32::from_be_bytes(png[33..37].try_into().unwrap()) as usize;
    assert_eq!(&png[37..41], b"IDAT");
    let mut raw = Vec::new();
    flate2::read::ZlibDecoder::new(&png[41..41 + len])
        .read_to_end(&mut raw)
        .unwrap();
    let rgb = raw
        .chunks_exact(1 + 3 * w)
        .flat_map(|row| row[1..].to_vec())
        .collect();
    (w, h, rgb)
}

/// A recording-sized figure: `snapshots` snapshots at 20 Hz on four links, each with a
/// chirp-z image of 241 frequencies over a noisy multipath channel (600 × 300 cells), 12
/// estimates per snapshot (the walker, statics and false alarms everywhere), a static band,
/// the truth, and one outlier at 370 m.
fn recording_figure(snapshots: usize) -> DelayFigure {
    let mut seed = 12345u64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as Real / (1u64 << 53) as Real
    };
    let t: Vec<Real> = (0..snapshots).map(|k| k as Real * 0.05).collect();
    let ped = |t: Real| 25.0 + 15.0 * (0.1 * t).sin();
    let f: Vec<Real> = (0..241).map(|k| (k as Real - 120.0) * 0.5e6).collect();
    let mut links = Vec::new();
    for p in 0..4 {
        let cfr: Vec<Vec<Complex>> = t
            .iter()
            .map(|&ts| {
                f.iter()
                    .map(|&fk| {
                        let mut h: Complex = [(12.0 + p as Real, 0.01), (ped(ts), 0.003)]
                            .iter()
                            .map(|&(r, a)| {
                                let ph = -2.0 * PI * fk * r / SPEED_OF_LIGHT;
                                Complex::new(a * cos(ph), a * sin(ph))
                            })
                            .sum();
                        h += Complex::new(1e-4 * (rnd() - 0.5), 1e-4 * (rnd() - 0.5));
                        h
                    })
                    .collect()
            })
            .collect();
        let image = delay_image(
            &f,
            &t,
            |s| cfr[s].as_slice(),
            &ImageConfig::new([0.0, 60.0]),
        )
        .unwrap();
        let est: Vec<Vec<DelayEstimate>> = t
            .iter()
            .map(|&ts| {
                (0..12)
                    .map(|k| {
                        let r = match k {
                            0 => ped(ts),
                            1 => 12.0 + p as Real,
                            _ => 60.0 * rnd(),
                        };
                        DelayEstimate {
                            delay_s: r / SPEED_OF_LIGHT,
                            amplitude: 1e-3 * (1.0 + rnd()),
                            sigma_s: None,
                        }
                    })
                    .collect()
            })
            .collect();
        let mut points = delay_points(&t, &est);
        points[7].range_m = 370.0;
        let statics = vec![StaticBand {
            mean_m: 12.0 + p as Real,
            halfwidth_m: 0.6,
        }];
        let truth = vec![TruthCurve {
            kind: "person".into(),
            primary: true,
            points: t.iter().map(|&ts| (ts, ped(ts))).collect(),
        }];
        links.push(LinkDelays {
            name: format!("Tx → Rx{}", p + 1),
            range_m: crate::present::suggest_range_m(&points, &statics, &truth, Real::INFINITY),
            image: Some(image),
            estimates: points,
            statics,
            truth,
        });
    }
    DelayFigure::new(&t, links)
}

/// Issue 38 item 7: the SVG of a 1528-snapshot recording with 12 estimates per snapshot and
/// link (73 000 estimates; as circles they alone were 4.4 MB in a real run, 28 MB with the
/// image as rectangles) stays under 2 MB: the images, bands and estimates are one PNG per
/// panel. The PNG holds the estimates (blue pixels) and the static ones grey; the axis is
/// robust to the outlier at 370 m, which is marked at the edge and counted in the panel.
#[test]
fn the_svg_of_a_long_recording_stays_small() {
    let fig = recording_figure(1528);
    let n_est: usize = fig.links.iter().map(|l| l.estimates.len()).sum();
    assert_eq!(n_est, 4 * 1528 * 12);
    for l in &fig.links {
        assert!(
            l.range_m[1] < 70.0,
            "{}: axis {:?} stretched by the outlier",
            l.name,
            l.range_m
        );
    }
    let opts = ChannelChartOptions {
        title: "Delay estimates per link".into(),
        subtitle: Some("1528 snapshots".into()),
    };
    let svg = delays_svg(delays_size(4), &fig, &opts).unwrap();
    println!(
        "delays SVG of 1528 snapshots, {n_est} estimates: {} bytes",
        svg.len()
    );
    assert!(svg.len() < 2_000_000, "{} bytes", svg.len());
    let doc = roxmltree::Document::parse(&svg).expect("well-formed SVG");
    assert_eq!(
        doc.descendants()
            .filter(|n| n.has_tag_name("circle"))
            .count(),
        2,
        "the estimates are in the PNGs, only the legend's markers are circles"
    );
    let tx = texts(&svg);
    // Each link's outlier: counted in its panel, one triangle at the top edge.
    let note = "1 off the axis (marked at its edge)";
    assert_eq!(tx.iter().filter(|t| *t == note).count(), 4, "{tx:?}");
    assert_eq!(
        doc.descendants()
            .filter(|n| n.has_tag_name("polygon"))
            .count(),
        4
    );
    let images: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("image"))
        .collect();
    assert_eq!(images.len(), 4);
    let href = images[0].attribute("href").unwrap();
    let png = unbase64(
        href.strip_prefix(super::super::raster::PNG_DATA_URI)
            .unwrap(),
    );
    let (w, h, rgb) = png_rgb(&png);
    assert_eq!(rgb.len(), 3 * w * h);
    let px = |c: [u8; 3]| rgb.chunks_exact(3).filter(|p| *p == c).count();
    let RGBColor(r, g, b) = ESTIMATE_RGB;
    let RGBColor(sr, sg, sb) = STATIC_ESTIMATE_RGB;
    assert!(px([r, g, b]) > 1000, "{} estimate pixels", px([r, g, b]));
    assert!(
        px([sr, sg, sb]) > 100,
        "{} static-estimate pixels",
        px([sr, sg, sb])
    );
}
