use alloc::vec;
use alloc::vec::Vec;

use super::geometry::{dist, v};
use super::rays::body_centre;
use super::signal::cis_neg;
use super::synthesize::synthesize;
use super::*;
use crate::error::limits::{self, MAX_CHANNEL_SAMPLES};
use crate::error::{Cancel, Error};
use crate::math::{
    atan2, cos, db_to_linear, dbm_to_watt, round, sin, sqrt, Complex, Real, Vec2, PI,
    SPEED_OF_LIGHT,
};
use crate::measure::Model;
use crate::scenario::presets::sensors2019;
use crate::scenario::Scenario;

/// A scene without walls or scatterers and a short straight walk (10 snapshots).
fn bare_scene() -> ChannelScene {
    let mut s = ChannelScene::hangar();
    s.walls.clear();
    s.scatterers.clear();
    s.walk = Walk {
        waypoints_m: vec![[2.0, 4.0], [16.0, 4.0]],
        speed_mps: 1.4,
        turn_radius_m: 2.5,
    };
    s.duration_s = Some(9.0 * DEFAULT_DT_S);
    s
}

fn setup() -> (Scenario, Model) {
    let sc = sensors2019();
    let m = Model::new(&sc).unwrap();
    (sc, m)
}

fn abs2(z: Complex) -> Real {
    z.re * z.re + z.im * z.im
}

fn rel(a: Real, b: Real) -> Real {
    (a - b).abs() / b.abs()
}

#[test]
fn los_power_is_friis_in_every_bin() {
    let (sc, m) = setup();
    let (rec, truth) = synthesize(&sc, &m, &bare_scene(), false, 1, false, Cancel::NEVER).unwrap();
    let lambda = SPEED_OF_LIGHT / sc.radio.carrier_hz;
    for p in 0..m.link_count() {
        let (tx, rx) = m.network.link_nodes(p);
        let d = dist(tx, rx);
        let gtx = m.patterns[0].gain_toward((rx - tx) / d);
        let k = lambda / (4.0 * PI * d);
        let friis = dbm_to_watt(37.0) * gtx * db_to_linear(8.0) * k * k;
        let los = &truth.paths[0][p];
        assert_eq!(los.len(), 1);
        assert_eq!(los[0].kind, PathKind::Los);
        assert!(rel(los[0].power_w, friis) < 1e-12);
        assert!(rel(los[0].delay_s, d / SPEED_OF_LIGHT) < 1e-15);
        // One path: |H[n]|² = |α|² in every bin (the phasor recursion keeps the modulus).
        for h in rec.response(0, p) {
            assert!(rel(abs2(*h), friis) < 1e-9, "{} vs {friis}", abs2(*h));
        }
    }
}

#[test]
fn phases_follow_the_delay_across_the_band() {
    // H[n+1]/H[n] = e^{−j2πΔfτ} for a single path, through the re-anchoring points.
    let (sc, m) = setup();
    let scene = bare_scene();
    let (rec, truth) = synthesize(&sc, &m, &scene, false, 1, false, Cancel::NEVER).unwrap();
    let df = sc.radio.bandwidth_hz / scene.subcarriers as Real;
    let tau = truth.paths[0][1][0].delay_s;
    let step = cis_neg(df * tau);
    let h = rec.response(0, 1);
    for n in 0..h.len() - 1 {
        let r = h[n + 1] / h[n];
        assert!(abs2(r - step) < 1e-18, "bin {n}");
    }
    // Carrier phase: H at f = 0 (the middle bin) is √P e^{−j2π f_c τ}.
    let mid = h[(h.len() - 1) / 2];
    let want = cis_neg(sc.radio.carrier_hz * tau) * sqrt(truth.paths[0][1][0].power_w);
    assert!(abs2(mid - want) / abs2(want) < 1e-18);
}

#[test]
fn scatterer_power_over_noise_is_the_model_snr() {
    for rcs in [0.5, 5.0] {
        let (mut sc, _) = setup();
        sc.target.rcs_m2 = rcs;
        let m = Model::new(&sc).unwrap();
        let mut scene = bare_scene();
        let r = Vec2::new(20.0, 14.0);
        scene.scatterers = vec![PointScatterer {
            position_m: [r.x, r.y],
            rcs_m2: rcs,
        }];
        let (_, truth) = synthesize(&sc, &m, &scene, false, 1, false, Cancel::NEVER).unwrap();
        for p in 0..m.link_count() {
            let sp = truth.paths[0][p]
                .iter()
                .find(|t| t.kind == PathKind::Scatterer)
                .unwrap();
            assert!(rel(sp.power_w, m.received_power_w(p, r)) < 1e-12);
            assert!(rel(sp.power_w / m.noise_power_w, m.snr(p, r)) < 1e-12);
            assert!(rel(sp.delay_s, m.network.delay(p, r)) < 1e-12);
        }
    }
}

#[test]
fn processing_gain_enters_through_the_noise() {
    // C3: N|α|²/σ² is E8's SNR, processing gain included.
    let (mut sc, _) = setup();
    sc.radio.processing_gain_db = Some(20.0);
    let m = Model::new(&sc).unwrap();
    let mut scene = bare_scene();
    let r = Vec2::new(20.0, 14.0);
    scene.scatterers = vec![PointScatterer {
        position_m: [r.x, r.y],
        rcs_m2: 1.0,
    }];
    let (rec, truth) = synthesize(&sc, &m, &scene, false, 1, false, Cancel::NEVER).unwrap();
    let nv = rec.noise_var.as_ref().unwrap();
    for (p, &nvp) in nv.iter().enumerate() {
        let sp = truth.paths[0][p][1];
        assert_eq!(sp.kind, PathKind::Scatterer);
        let snr = scene.subcarriers as Real * sp.power_w / nvp;
        assert!(rel(snr, m.snr(p, r)) < 1e-12);
    }
}

#[test]
fn walker_truth_power_is_the_model_received_power() {
    let (sc, m) = setup();
    let (_, truth) = synthesize(&sc, &m, &bare_scene(), true, 3, false, Cancel::NEVER).unwrap();
    for (s, st) in truth.states.iter().enumerate() {
        let r = Vec2::new(st[0], st[1]);
        for p in 0..m.link_count() {
            let b = truth.paths[s][p]
                .iter()
                .find(|t| t.kind == PathKind::Body)
                .unwrap();
            assert!(rel(b.power_w, m.received_power_w(p, r)) < 1e-12);
            assert!(rel(b.delay_s, m.network.delay(p, r)) < 1e-12);
        }
    }
}

#[test]
fn wall_delay_is_the_image_method() {
    let (sc, m) = setup();
    let mut scene = bare_scene();
    let c = 24.0;
    scene.walls = vec![Wall {
        a_m: [-8.0, c],
        b_m: [30.0, c],
        gamma: -0.6,
    }];
    let (_, truth) = synthesize(&sc, &m, &scene, false, 1, false, Cancel::NEVER).unwrap();
    let lambda = SPEED_OF_LIGHT / sc.radio.carrier_hz;
    for p in 0..m.link_count() {
        let (tx, rx) = m.network.link_nodes(p);
        // Image of Rx in y = c: (x, 2c − y).
        let img = Vec2::new(rx.x, 2.0 * c - rx.y);
        let len = dist(tx, img);
        let w = truth.paths[0][p]
            .iter()
            .find(|t| t.kind == PathKind::Wall)
            .expect("every receiver sees the wall");
        assert!(rel(w.delay_s, len / SPEED_OF_LIGHT) < 1e-14);
        // The reflection point: where Tx–image crosses y = c.
        let t = (c - tx.y) / (img.y - tx.y);
        let q = tx + (img - tx) * t;
        let gtx = m.patterns[0].gain_toward((q - tx) / dist(tx, q));
        let k = lambda / (4.0 * PI * len);
        let want = dbm_to_watt(37.0) * gtx * db_to_linear(8.0) * k * k * 0.36;
        assert!(rel(w.power_w, want) < 1e-12);
    }
    // A wall too short to hold the reflection point gives no path.
    scene.walls[0].a_m = [28.0, c];
    let (_, truth) = synthesize(&sc, &m, &scene, false, 1, false, Cancel::NEVER).unwrap();
    assert!(truth.paths[0][0].iter().all(|t| t.kind != PathKind::Wall));
}

#[test]
fn second_order_between_two_parallel_walls() {
    // Walls y = 24 and y = −9: Tx → top → bottom → Rx unfolds to the Rx seen through the
    // images y ↦ 2·24 − y, then y ↦ 2·(−9) − y... the hand value: Tx's images.
    let (sc, m) = setup();
    let mut scene = bare_scene();
    scene.walls = vec![
        Wall {
            a_m: [-100.0, 24.0],
            b_m: [100.0, 24.0],
            gamma: -0.6,
        },
        Wall {
            a_m: [-100.0, -9.0],
            b_m: [100.0, -9.0],
            gamma: 0.5,
        },
    ];
    let (_, truth) = synthesize(&sc, &m, &scene, false, 1, false, Cancel::NEVER).unwrap();
    for p in 0..m.link_count() {
        let (tx, rx) = m.network.link_nodes(p);
        // Tx in the top wall: 48 − y; then in the bottom: −18 − (48 − y) = y − 66.
        let via_top_first = Vec2::new(tx.x, tx.y - 66.0);
        // Tx in the bottom: −18 − y; then in the top: 48 − (−18 − y) = y + 66.
        let via_bottom_first = Vec2::new(tx.x, tx.y + 66.0);
        let mut got: Vec<Real> = truth.paths[0][p]
            .iter()
            .filter(|t| t.kind == PathKind::WallWall)
            .map(|t| t.delay_s)
            .collect();
        got.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let mut want = vec![
            dist(via_top_first, rx) / SPEED_OF_LIGHT,
            dist(via_bottom_first, rx) / SPEED_OF_LIGHT,
        ];
        want.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(got.len(), 2, "link {p}");
        for (g, w) in got.iter().zip(&want) {
            assert!(rel(*g, *w) < 1e-14);
        }
    }
}

#[test]
fn shadowing_exactly_when_the_walker_is_on_the_los() {
    let (sc, m) = setup();
    let mut scene = bare_scene();
    // Link 0: Tx (0, 0) → Rx (−5, 12); cross its middle perpendicularly at 1 m/s.
    let mid = Vec2::new(-2.5, 6.0);
    let n = Vec2::new(12.0, 5.0) / 13.0;
    let a = mid - n * 2.0;
    let b = mid + n * 2.0;
    scene.walk = Walk {
        waypoints_m: vec![[a.x, a.y], [b.x, b.y]],
        speed_mps: 1.0,
        turn_radius_m: 0.0,
    };
    scene.dt_s = 0.04;
    scene.duration_s = Some(4.0);
    let (_, truth) = synthesize(&sc, &m, &scene, true, 1, false, Cancel::NEVER).unwrap();
    let (tx, rx) = m.network.link_nodes(0);
    let lambda = SPEED_OF_LIGHT / sc.radio.carrier_hz;
    let k = lambda / (4.0 * PI * dist(tx, rx));
    let friis =
        dbm_to_watt(37.0) * m.patterns[0].gain_toward((rx - tx) / 13.0) * 6.309573444801933 * k * k;
    let mut count = 0;
    for (s, &t) in truth.t_s.iter().enumerate() {
        let on = (t - 2.0).abs() < 0.3;
        count += on as usize;
        assert_eq!(truth.shadowed[s][0], on, "t = {t}");
        for p in 1..m.link_count() {
            assert!(!truth.shadowed[s][p]);
        }
        let los = truth.paths[s][0][0];
        let want = if on {
            friis * db_to_linear(-15.0)
        } else {
            friis
        };
        assert!(rel(los.power_w, want) < 1e-12, "t = {t}");
    }
    assert_eq!(count, 15); // t = 1.72 … 2.28
}

#[test]
fn noise_variance_is_n_times_pn() {
    let (sc, m) = setup();
    let scene = bare_scene();
    let want = scene.subcarriers as Real * m.noise_power_w;
    for seed in [1, 2, 3] {
        for with_person in [false, true] {
            let (clean, _) =
                synthesize(&sc, &m, &scene, with_person, seed, false, Cancel::NEVER).unwrap();
            let (noisy, _) =
                synthesize(&sc, &m, &scene, with_person, seed, true, Cancel::NEVER).unwrap();
            let nv = noisy.noise_var.as_ref().unwrap();
            for (p, &nvp) in nv.iter().enumerate() {
                assert!(rel(nvp, want) < 1e-15);
                let mut sum = 0.0;
                let mut count = 0usize;
                let mut re2 = 0.0;
                for s in 0..noisy.snapshot_count() {
                    for (a, b) in noisy.response(s, p).iter().zip(clean.response(s, p)) {
                        let d = *a - *b;
                        sum += abs2(d);
                        re2 += d.re * d.re;
                        count += 1;
                    }
                }
                // |w|² is exponential: the mean's standard error is σ²/√M; Re² has mean σ²/2
                // and standard error σ²/√(2M).
                let mean = sum / count as Real;
                let se = want / sqrt(count as Real);
                assert!((mean - want).abs() < 4.0 * se, "{mean} vs {want}");
                let re_mean = re2 / count as Real;
                assert!((re_mean - want / 2.0).abs() < 4.0 * want / sqrt(2.0 * count as Real));
            }
        }
    }
}

#[test]
fn dynamic_range_raises_the_noise_floor() {
    let (sc, m) = setup();
    let mut scene = bare_scene();
    scene.dynamic_range_db = Some(30.0);
    let (rec, truth) = synthesize(&sc, &m, &scene, true, 1, false, Cancel::NEVER).unwrap();
    let nv = rec.noise_var.as_ref().unwrap();
    for p in 0..m.link_count() {
        let strongest = truth
            .paths
            .iter()
            .flat_map(|s| s[p].iter().map(|t| t.power_w))
            .fold(0.0, Real::max);
        let floor = scene.subcarriers as Real * strongest * 1e-3;
        assert!(floor > scene.subcarriers as Real * m.noise_power_w);
        assert!(rel(nv[p], floor) < 1e-12);
    }
}

#[test]
fn deterministic_per_seed() {
    let (sc, m) = setup();
    let scene = bare_scene();
    let a = simulate_recording(&sc, &m, &scene, true, 7).unwrap();
    let b = simulate_recording(&sc, &m, &scene, true, 7).unwrap();
    assert_eq!(a, b);
    let c = simulate_recording(&sc, &m, &scene, true, 8).unwrap();
    assert_ne!(a.0.samples, c.0.samples);
    assert_eq!(a.1.states, c.1.states);
    // The calibration recording draws its noise from another stream.
    let (e, te) = simulate_recording(&sc, &m, &scene, false, 7).unwrap();
    let (ec, _) = synthesize(&sc, &m, &scene, false, 7, false, Cancel::NEVER).unwrap();
    let (pc, _) = synthesize(&sc, &m, &scene, true, 7, false, Cancel::NEVER).unwrap();
    let noise_e: Vec<Complex> = e
        .samples
        .iter()
        .zip(&ec.samples)
        .map(|(x, y)| x - y)
        .collect();
    let noise_p: Vec<Complex> =
        a.0.samples
            .iter()
            .zip(&pc.samples)
            .map(|(x, y)| x - y)
            .collect();
    assert_ne!(noise_e[0], noise_p[0]);
    assert!(te.states.is_empty());
    assert_eq!(te.t_s.len(), e.t_s.len());
}

#[test]
fn body_fluctuation_has_unit_mean_power_and_the_set_correlation() {
    // One centre, no walls: H at the middle bin is α·g, |α| from the truth (radius 0: the
    // centre is the walker). Mean |g|² = 1, lag-1 correlation ρ.
    let (sc, m) = setup();
    let mut scene = bare_scene();
    scene.body.centres = 1;
    scene.body.radius_m = 0.0;
    scene.body.correlation = 0.5;
    scene.duration_s = Some(4000.0 * DEFAULT_DT_S);
    scene.subcarriers = 2;
    let (with, truth) = synthesize(&sc, &m, &scene, true, 11, false, Cancel::NEVER).unwrap();
    let (without, _) = synthesize(&sc, &m, &scene, false, 11, false, Cancel::NEVER).unwrap();
    // Link 2 (Rx (−6, −8)): the walk along y = 4 never shadows its LoS.
    let p = 2;
    let g: Vec<Complex> = (0..with.snapshot_count())
        .map(|s| {
            let b = truth.paths[s][p][1];
            assert_eq!(b.kind, PathKind::Body);
            let h = with.response(s, p)[0] - without.response(s, p)[0];
            let f0 = -0.5 * sc.radio.bandwidth_hz / 2.0;
            h / (cis_neg((sc.radio.carrier_hz + f0) * b.delay_s) * sqrt(b.power_w))
        })
        .collect();
    let n = g.len() as Real;
    let mean = g.iter().map(|z| abs2(*z)).sum::<Real>() / n;
    // AR(1) with ρ = 0.5: effective sample size ≈ n(1 − ρ²)/(1 + ρ²) = 0.6 n.
    assert!((mean - 1.0).abs() < 4.0 / sqrt(0.6 * n), "{mean}");
    let lag: Complex = g.windows(2).map(|w| w[1] * w[0].conj()).sum::<Complex>() / n;
    assert!((lag.re - 0.5).abs() < 4.0 / sqrt(n), "{}", lag.re);
}

#[test]
fn body_centres_on_the_circle_turning_with_the_heading() {
    let c = Vec2::new(3.0, -1.0);
    let head = [cos(0.7), sin(0.7)];
    for k in 0..6 {
        let p = body_centre(c, head, k, 6, 0.2);
        assert!((dist(c, p) - 0.2).abs() < 1e-15);
        let ang = atan2(p.y - c.y, p.x - c.x);
        let want = 0.7 + 2.0 * PI * k as Real / 6.0;
        let d = (ang - want) / (2.0 * PI);
        assert!((d - round(d)).abs() < 1e-12);
    }
}

#[test]
fn walk_speed_continuity_and_curvature() {
    let w = ChannelScene::hangar().walk;
    let path = w.compile().unwrap();
    let dur = path.duration_s();
    // 46 m of polyline, each of three right-angle corners cut by (2 − π/2)·2.5 m.
    let len = 46.0 - 3.0 * (2.0 - PI / 2.0) * 2.5;
    assert!(rel(dur, len / 1.4) < 1e-12);
    assert!((25.0..35.0).contains(&dur));
    let h = 1e-3;
    let mut t = 0.0;
    while t + h < dur {
        let a = path.state_at(t);
        let b = path.state_at(t + h);
        assert!(rel(sqrt(a[2] * a[2] + a[3] * a[3]), 1.4) < 1e-12);
        let step = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]));
        // A chord of an arc of 1.4 mm at radius ≥ 2.5 m: within 1e-7 relative of the arc.
        assert!(
            step <= 1.4 * h * (1.0 + 1e-9) && step >= 1.4 * h * (1.0 - 1e-6),
            "t = {t}"
        );
        t += 0.0173;
    }
    // The first corner (16, 4) is an arc of centre (13.5, 6.5), radius 2.5, from s = 11.5 m.
    let arc = 2.5 * PI / 2.0;
    for i in 1..10 {
        let s = 11.5 + arc * i as Real / 10.0;
        let st = path.state_at(s / 1.4);
        assert!((dist(Vec2::new(st[0], st[1]), Vec2::new(13.5, 6.5)) - 2.5).abs() < 1e-12);
        // Curvature: heading change per metre.
        let st2 = path.state_at((s + 0.01) / 1.4);
        let turn = atan2(st2[3], st2[2]) - atan2(st[3], st[2]);
        assert!(rel(turn / 0.01, 1.0 / 2.5) < 1e-9);
    }
    // Stops at the end.
    let end = path.state_at(dur + 1.0);
    assert_eq!(end, [4.0, 8.0, 0.0, 0.0]);
    // Inside the area, more than 1 m from every node.
    let sc = sensors2019();
    let mut t = 0.0;
    while t <= dur {
        let st = path.state_at(t);
        assert!((-7.5..=30.0).contains(&st[0]) && (-10.0..=26.0).contains(&st[1]));
        let p = Vec2::new(st[0], st[1]);
        for n in sc
            .transmitters
            .iter()
            .map(|n| n.position_m)
            .chain(sc.receivers.iter().map(|n| n.position_m))
        {
            assert!(dist(p, v(n)) > 1.0);
        }
        t += 0.05;
    }
}

#[test]
fn short_segments_clamp_the_radius() {
    let w = Walk {
        waypoints_m: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
        speed_mps: 1.0,
        turn_radius_m: 2.5,
    };
    // Tangent length clamped to half the shorter segment: radius 0.5.
    let want = 0.5 + 0.5 + 0.5 * PI / 2.0;
    assert!(rel(w.length_m().unwrap(), want) < 1e-12);
    let mid = w.state_at(0.5 + 0.25 * PI / 2.0).unwrap();
    assert!((dist(Vec2::new(mid[0], mid[1]), Vec2::new(0.5, 0.5)) - 0.5).abs() < 1e-12);
}

#[test]
fn hangar_scene_has_every_path_kind() {
    let (sc, m) = setup();
    let mut scene = ChannelScene::hangar();
    scene.duration_s = Some(0.0);
    let (rec, truth) = simulate_recording(&sc, &m, &scene, true, 1).unwrap();
    assert_eq!(rec.snapshot_count(), 1);
    assert_eq!(rec.links, vec![[0, 0], [0, 1], [0, 2], [0, 3]]);
    let kinds: Vec<PathKind> = truth.paths[0].iter().flatten().map(|t| t.kind).collect();
    for k in [
        PathKind::Los,
        PathKind::Wall,
        PathKind::Scatterer,
        PathKind::Body,
        PathKind::BodyWall,
    ] {
        assert!(kinds.contains(&k), "{k:?}");
    }
    assert!(rec
        .samples
        .iter()
        .all(|z| z.re.is_finite() && z.im.is_finite()));
}

#[test]
fn validation_names_the_field() {
    let (sc, m) = setup();
    let mut scene = bare_scene();
    scene.walls = vec![Wall {
        a_m: [0.0, 1.0],
        b_m: [1.0, 1.0],
        gamma: 1.5,
    }];
    let e = simulate_recording(&sc, &m, &scene, true, 1).unwrap_err();
    assert_eq!(e.field(), Some("scene.walls[0].gamma"));
    let mut scene = bare_scene();
    scene.body.correlation = 1.0;
    let e = scene.validate().unwrap_err();
    assert_eq!(e.field(), Some("scene.body.correlation"));
    let mut scene = bare_scene();
    scene.walk.speed_mps = 0.0;
    assert_eq!(
        scene.validate().unwrap_err().field(),
        Some("scene.walk.speed_mps")
    );
    // Size cap before allocating: 4 links × 241 bins × 1e5 s / 2.048 ms ≫ 64 Mi.
    let mut scene = bare_scene();
    scene.duration_s = Some(1e5);
    match simulate_recording(&sc, &m, &scene, true, 1).unwrap_err() {
        Error::SizeLimit { field, max, .. } => {
            assert_eq!(field, "scene.duration_s");
            assert_eq!(max, MAX_CHANNEL_SAMPLES / (4 * 241));
        }
        e => panic!("{e:?}"),
    }
}

#[test]
fn json_round_trips_and_truth_has_times_and_states() {
    let scene = ChannelScene::hangar();
    let text = serde_json::to_string(&scene).unwrap();
    let back: ChannelScene = serde_json::from_str(&text).unwrap();
    assert_eq!(back, scene);
    // Defaults fill what is left out; unknown fields are refused.
    let minimal = r#"{"walk": {"waypoints_m": [[0, 0], [1, 0]], "speed_mps": 1.0}}"#;
    let s: ChannelScene = serde_json::from_str(minimal).unwrap();
    assert_eq!(s.subcarriers, 241);
    assert_eq!(s.body, Body::default());
    assert!(s.second_order && s.double_reflections);
    assert!(serde_json::from_str::<ChannelScene>(
        r#"{"walk": {"waypoints_m": [[0, 0], [1, 0]], "speed_mps": 1.0}, "wals": []}"#
    )
    .is_err());

    let (sc, m) = setup();
    let (_, truth) = simulate_recording(&sc, &m, &bare_scene(), true, 1).unwrap();
    // That it reads as `formats::Truth` (`track --truth`) is tested in `formats` (a layer
    // above): `channel_truth_reads_as_truth`.
    let json = serde_json::to_string(&truth).unwrap();
    let value: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(value["t_s"].as_array().map(Vec::len), Some(truth.t_s.len()));
    assert_eq!(
        value["states"].as_array().map(Vec::len),
        Some(truth.states.len())
    );
    let back: ChannelTruth = serde_json::from_str(&json).unwrap();
    assert_eq!(back, truth);
}

#[test]
fn body_wall_delays_are_the_image_method() {
    let (sc, m) = setup();
    let mut scene = bare_scene();
    let c = 24.0;
    scene.walls = vec![Wall {
        a_m: [-8.0, c],
        b_m: [30.0, c],
        gamma: -0.6,
    }];
    let (_, truth) = synthesize(&sc, &m, &scene, true, 1, false, Cancel::NEVER).unwrap();
    let st = truth.states[3];
    let r = Vec2::new(st[0], st[1]);
    let mirror = |p: Vec2| Vec2::new(p.x, 2.0 * c - p.y);
    for p in 0..m.link_count() {
        let (tx, rx) = m.network.link_nodes(p);
        let mut got: Vec<(Real, Real)> = truth.paths[3][p]
            .iter()
            .filter(|t| t.kind == PathKind::BodyWall)
            .map(|t| (t.delay_s, t.power_w))
            .collect();
        got.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
        let (d1, d2) = (dist(mirror(tx), r), dist(r, rx));
        let (e1, e2) = (dist(tx, r), dist(r, mirror(rx)));
        let mut want = vec![(d1 + d2) / SPEED_OF_LIGHT, (e1 + e2) / SPEED_OF_LIGHT];
        want.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(got.len(), 2, "link {p}");
        for (g, w) in got.iter().zip(&want) {
            assert!(rel(g.0, *w) < 1e-14);
        }
        // Tx → walker → wall → Rx: the radar equation with the Rx's image, × Γ².
        let via_rx = if rel(got[0].0, (e1 + e2) / SPEED_OF_LIGHT) < 1e-14 {
            got[0].1
        } else {
            got[1].1
        };
        let model_like = m.snr_from_geometry(p, m.patterns[0].gain_toward((r - tx) / e1), e1, e2)
            * m.noise_power_w
            * 0.36;
        assert!(rel(via_rx, model_like) < 1e-12);
    }
}

#[test]
#[ignore = "the full 30 s hangar recording (≈ 15 k snapshots × 4 links, 0.23 GB, 6 s in debug); run in release by scripts/reproduce.sh"]
fn full_hangar_recording() {
    let (sc, m) = setup();
    let scene = ChannelScene::hangar();
    let (rec, truth) = simulate_recording(&sc, &m, &scene, true, 1).unwrap();
    let dur = scene.walk.duration_s().unwrap();
    assert_eq!(rec.snapshot_count(), (dur / DEFAULT_DT_S) as usize + 1);
    assert_eq!(truth.states.len(), rec.snapshot_count());
    assert!(rec
        .samples
        .iter()
        .all(|z| z.re.is_finite() && z.im.is_finite()));
    // The walk crosses LoS paths somewhere: some snapshot is shadowed.
    assert!(truth.shadowed.iter().flatten().any(|&s| s));
}

/// Issue 37 item 4: a scene of 4096 scatterers grew the truth by every static path of every
/// link and snapshot (a 278 MB `truth.json` in 2 s of walk, 3 GB of memory in 11 s). Refused
/// by name before anything is computed when the static paths alone exceed a cap (the truth's
/// path entries, or the path × subcarrier work); a shorter walk of the same scene is
/// simulated.
#[test]
fn the_truth_and_the_work_are_capped_by_name() {
    let (sc, m) = setup();
    let mut scene = bare_scene();
    scene.subcarriers = 16;
    scene.scatterers = (0..4096)
        .map(|i| PointScatterer {
            position_m: [1.0 + (i % 64) as Real * 0.25, 1.0 + (i / 64) as Real * 0.1],
            rcs_m2: 0.01,
        })
        .collect();
    scene.dt_s = 0.004;
    let refused =
        |scene: &ChannelScene| match synthesize(&sc, &m, scene, true, 1, true, Cancel::NEVER) {
            Ok(_) => panic!("accepted"),
            Err(e) => e.to_string(),
        };
    // 501 snapshots × 4 links × ≥ 4097 paths: refused before the first snapshot.
    scene.duration_s = Some(2.0);
    let text = refused(&scene);
    assert!(
        text.starts_with("scene.duration_s: the truth would hold more than 1048576 true paths"),
        "{text}"
    );
    assert!(text.contains("in 501 of 501 snapshots"), "{text}");
    // 40 snapshots fit (≈ 655 000 paths).
    scene.duration_s = Some(39.0 * 0.004);
    let (_, truth) = synthesize(&sc, &m, &scene, true, 1, true, Cancel::NEVER).unwrap();
    let entries: usize = truth.paths.iter().flatten().map(Vec::len).sum();
    assert!(
        entries > 600_000 && entries <= limits::MAX_TRUTH_PATHS,
        "{entries}"
    );
    // The work: 600 scatterers on 32 768 subcarriers for 400 snapshots (52·10⁶ samples, under
    // their cap; 0.96·10⁶ paths, under the truth's) is 3.2·10¹⁰ path × bin products > 2³⁴.
    scene.scatterers.truncate(600);
    scene.subcarriers = 32_768;
    scene.duration_s = Some(399.0 * 0.004);
    let text = refused(&scene);
    assert!(
        text.starts_with("scene.duration_s: more than 17179869184 path × subcarrier products"),
        "{text}"
    );
}

/// Issue 37 item 13: the simulator asks its cancel callback once per snapshot (Ctrl-C took
/// effect only after the whole simulation).
#[test]
fn the_simulator_asks_to_cancel_per_snapshot() {
    use core::sync::atomic::{AtomicUsize, Ordering};
    let (sc, m) = setup();
    let scene = bare_scene();
    for at in [1, 4, usize::MAX] {
        let n = AtomicUsize::new(0);
        let stop = || n.fetch_add(1, Ordering::SeqCst) + 1 >= at;
        let got = synthesize(&sc, &m, &scene, true, 1, true, Cancel::when(&stop));
        let asked = n.load(Ordering::SeqCst);
        if at == usize::MAX {
            assert_eq!(asked, got.unwrap().0.t_s.len());
        } else {
            assert!(matches!(got, Err(Error::Cancelled)));
            assert_eq!(asked, at);
        }
    }
}
