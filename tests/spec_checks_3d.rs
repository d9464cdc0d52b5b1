#![cfg(not(target_arch = "wasm32"))]
//! The checks of `shared/spec/delay-localization.md` §0 extended to rooms in 3-D (issue 40 §2):
//! nodes at heights `z_n`, the target in the horizontal plane at `z_t`. Every expected number comes
//! from an independent reference written here with explicit 3-D vectors `[x, y, z]` (no call into
//! `measure`), from central finite differences with their error bound, or from a hand computation
//! stated next to it. With every height 0 (or every height equal to the target's) the outputs are
//! the planar model's, bitwise.

use scatterloc::channel::{simulate_recording, ChannelScene, PathKind, Walk};
use scatterloc::localize::{self, crlb_at, crlb_map, crlb_map_scalar, DelayMeasurements, Grid};
use scatterloc::localize::{LmConfig, SINGULAR_RCOND};
use scatterloc::math::{Real, Vec2, PI, SPEED_OF_LIGHT};
use scatterloc::measure::{self, Model};
use scatterloc::mtl::input::NetworkInput;
use scatterloc::native::{crlb_map_on, map_paths};
use scatterloc::scenario::{parse_json, presets, Scenario};
use scatterloc::Error;

mod common;

use common::rel_close;

const C: Real = SPEED_OF_LIGHT;

type P3 = [Real; 3];

fn sub(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn len(a: P3) -> Real {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// A deterministic pseudo-random number in [0, 1) (splitmix64), no crate needed.
fn unit(state: &mut u64) -> Real {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as Real / (1u64 << 53) as Real
}

/// The node positions in 3-D: `(transmitters, receivers)` as `[x, y, z]`.
fn nodes_3d(s: &Scenario) -> (Vec<P3>, Vec<P3>) {
    (
        s.transmitters
            .iter()
            .map(|t| [t.position_m[0], t.position_m[1], t.height_m])
            .collect(),
        s.receivers
            .iter()
            .map(|r| [r.position_m[0], r.position_m[1], r.height_m])
            .collect(),
    )
}

/// A room scenario from JSON (the schema path users take): 6 m × 4 m, one Tx and `rx.len()`
/// receivers, the target plane at `target_z`.
fn room(tx: [Real; 3], rx: &[[Real; 3]], target_z: Real) -> Scenario {
    let rxs: Vec<String> = rx
        .iter()
        .enumerate()
        .map(|(i, p)| {
            format!(
                r#"{{"name":"Rx{i}","position_m":[{},{}],"height_m":{},"gain_dbi":3}}"#,
                p[0], p[1], p[2]
            )
        })
        .collect();
    let json = format!(
        r#"{{"name":"room","radio":{{"carrier_hz":6.5e9,"bandwidth_hz":5e8,"noise_figure_db":7}},
        "transmitters":[{{"name":"Tx","position_m":[{},{}],"height_m":{},"power_dbm":14,"gain_dbi":3}}],
        "receivers":[{}],"target":{{"rcs_m2":1.0,"height_m":{target_z}}},
        "area_m":{{"x":[0,6],"y":[0,4]}}}}"#,
        tx[0],
        tx[1],
        tx[2],
        rxs.join(",")
    );
    Scenario::from_json(&json).expect("valid room")
}

/// The typical room of the docs: Tx at the west wall, three receivers at the other walls, all at
/// the ceiling (2.8 m), the walker's body centre at 1.0 m.
fn ceiling_room() -> Scenario {
    room(
        [0.0, 2.0, 2.8],
        &[[6.0, 2.0, 2.8], [3.0, 4.0, 2.8], [3.0, 0.0, 2.8]],
        1.0,
    )
}

/// Random scenarios with random heights (nodes 0–3 m, target plane 0.5–1.5 m) and a beam on
/// some transmitters: the sensors2019 radio, 1–3 Tx, 2–4 Rx in a 20 m square.
fn random_3d(seed: u64) -> Scenario {
    let mut st = seed.wrapping_mul(7919).wrapping_add(17);
    let mut s = presets::sensors2019();
    let ntx = 1 + (unit(&mut st) * 3.0) as usize;
    let nrx = 2 + (unit(&mut st) * 3.0) as usize;
    let proto_tx = s.transmitters[0].clone();
    let proto_rx = s.receivers[0].clone();
    s.transmitters = (0..ntx)
        .map(|i| {
            let mut t = proto_tx.clone();
            t.name = format!("T{i}");
            t.position_m = [unit(&mut st) * 20.0, unit(&mut st) * 20.0];
            t.height_m = unit(&mut st) * 3.0;
            if i % 2 == 1 {
                t.pattern = scatterloc::scenario::Pattern::Omni;
            }
            t
        })
        .collect();
    s.receivers = (0..nrx)
        .map(|i| {
            let mut r = proto_rx.clone();
            r.name = format!("R{i}");
            r.position_m = [unit(&mut st) * 20.0, unit(&mut st) * 20.0];
            r.height_m = unit(&mut st) * 3.0;
            r
        })
        .collect();
    s.links = scatterloc::scenario::LinkSpec::All;
    s.target.height_m = 0.5 + unit(&mut st);
    s.area_m = scatterloc::scenario::Area {
        x: [0.0, 20.0],
        y: [0.0, 20.0],
    };
    s.validate().expect("random scenario valid");
    s
}

/// Points of a scenario's area on an offset grid.
fn points(s: &Scenario, n: usize) -> Vec<Vec2> {
    let a = s.area_m;
    let mut out = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let x = a.x[0] + (i as Real + 0.371) * (a.x[1] - a.x[0]) / n as Real;
            let y = a.y[0] + (j as Real + 0.613) * (a.y[1] - a.y[0]) / n as Real;
            out.push(Vec2::new(x, y));
        }
    }
    out
}

/// The independent reference of (E1) in 3-D: `(‖r − t‖ + ‖r − rx‖)/c` with `r = [x, y, z_t]`.
fn ref_delay(t: P3, rx: P3, r: Vec2, zt: Real) -> Real {
    let r3 = [r.x, r.y, zt];
    (len(sub(r3, t)) + len(sub(r3, rx))) / C
}

/// The independent reference of (E3) in 3-D: the (x, y) part of the 3-D unit vectors node → r,
/// over c.
fn ref_gradient(t: P3, rx: P3, r: Vec2, zt: Real) -> Vec2 {
    let r3 = [r.x, r.y, zt];
    let (a, b) = (sub(r3, t), sub(r3, rx));
    let (la, lb) = (len(a), len(b));
    Vec2::new(a[0] / la + b[0] / lb, a[1] / la + b[1] / lb) / C
}

// ---------------------------------------------------------------------------------------------
// Schema: heights are optional, named in errors, and absent from planar files.
// ---------------------------------------------------------------------------------------------

#[test]
fn heights_default_to_zero_and_planar_files_serialise_unchanged() {
    for name in presets::PRESET_NAMES {
        let s = presets::preset(name).unwrap();
        let json = s.to_json();
        assert!(!json.contains("height_m"), "{name}: {json}");
        assert_eq!(Scenario::from_json(&json).unwrap(), s);
        assert!(Model::new(&s).unwrap().network.is_planar());
    }
    let s = ceiling_room();
    assert_eq!(s.transmitters[0].height_m, 2.8);
    assert_eq!(s.target.height_m, 1.0);
    let back = Scenario::from_json(&s.to_json()).unwrap();
    assert_eq!(back, s);
    let m = Model::new(&s).unwrap();
    assert!(!m.network.is_planar());
    // dz = z_node − z_target.
    assert_eq!(m.network.transmitters_dz, vec![2.8 - 1.0]);
    assert_eq!(m.network.receivers_dz, vec![2.8 - 1.0; 3]);
}

#[test]
fn bad_heights_are_named_errors() {
    let mut s = ceiling_room();
    s.receivers[1].height_m = 1e8;
    match s.validate() {
        Err(Error::OutOfRange { field, .. }) => assert_eq!(field, "receivers[1].height_m"),
        other => panic!("{other:?}"),
    }
    let mut s = ceiling_room();
    s.transmitters[0].height_m = Real::NAN;
    let e = s.validate().unwrap_err().to_string();
    assert!(e.contains("transmitters[0].height_m"), "{e}");
    let mut s = ceiling_room();
    s.target.height_m = Real::INFINITY;
    let e = s.validate().unwrap_err().to_string();
    assert!(e.contains("target.height_m"), "{e}");
    let json = ceiling_room()
        .to_json()
        .replace("\"height_m\": 1.0", "\"height_m\": \"1\"");
    let e = Scenario::from_json(&json).unwrap_err().to_string();
    assert!(e.contains("target.height_m"), "{e}");
}

#[test]
fn the_multi_target_layer_refuses_heights_by_name() {
    let e = parse_json::<NetworkInput>(r#"{"tx":[[0,0,1]],"rx":[[1,1]]}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("tx"), "{e}");
    let e = parse_json::<NetworkInput>(r#"{"tx":[[0,0]],"rx":[[1,1]],"height_m":1}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("height_m"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// Heights all 0, or all equal to the target's: the planar model, bitwise.
// ---------------------------------------------------------------------------------------------

#[test]
fn zero_heights_give_the_planar_outputs_bitwise() {
    for name in ["sensors2019", "iclgnss2019"] {
        let s = presets::preset(name).unwrap();
        let m = Model::new(&s).unwrap();
        // Every node lifted to the target's plane at 1.2 m: dz = 0 exactly, the same model.
        let mut lifted = s.clone();
        lifted.target.height_m = 1.2;
        lifted
            .transmitters
            .iter_mut()
            .for_each(|t| t.height_m = 1.2);
        lifted.receivers.iter_mut().for_each(|r| r.height_m = 1.2);
        let ml = Model::new(&lifted).unwrap();
        assert_eq!(ml, m, "{name}: lifted model");
        let net = &m.network;
        for r in points(&s, 9) {
            for p in 0..net.link_count() {
                let (tx, rx) = net.link_nodes(p);
                // The planar formulas (E1, E3) as they were before heights existed.
                let d2 = ((r - tx).norm() + (r - rx).norm()) / C;
                let j2 = (measure::unit_from(tx, r).0 + measure::unit_from(rx, r).0) / C;
                assert_eq!(net.delay(p, r).to_bits(), d2.to_bits());
                assert_eq!(
                    net.delay(p, r).to_bits(),
                    measure::bistatic_delay(tx, rx, r).to_bits()
                );
                let j = net.jacobian_row(p, r);
                assert_eq!(
                    (j.x.to_bits(), j.y.to_bits()),
                    (j2.x.to_bits(), j2.y.to_bits())
                );
                assert_eq!(net.los_delay(p).to_bits(), ((rx - tx).norm() / C).to_bits());
            }
            let a = crlb_at(&m, r);
            let b = crlb_at(&ml, r);
            assert_eq!(a.rmse_m().to_bits(), b.rmse_m().to_bits());
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Check 1 in 3-D (E1): delays against the independent 3-D reference.
// ---------------------------------------------------------------------------------------------

#[test]
fn delays_match_the_independent_3d_reference() {
    let mut checked = 0;
    for seed in 0..40 {
        let s = random_3d(seed);
        let m = Model::new(&s).unwrap();
        let (txs, rxs) = nodes_3d(&s);
        let zt = s.target.height_m;
        for r in points(&s, 7) {
            for p in 0..m.link_count() {
                let l = m.network.links[p];
                let want = ref_delay(txs[l.tx], rxs[l.rx], r, zt);
                rel_close(
                    "3-D delay",
                    m.network.delay(p, r),
                    want,
                    4.0 * Real::EPSILON,
                );
                // The LoS delay uses the nodes' own heights.
                let los = len(sub(rxs[l.rx], txs[l.tx])) / C;
                rel_close(
                    "3-D LoS delay",
                    m.network.los_delay(p),
                    los,
                    4.0 * Real::EPSILON,
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 5_000, "{checked}");
}

// ---------------------------------------------------------------------------------------------
// Check 3 in 3-D (E3): the Jacobian against the reference and against central differences.
// ---------------------------------------------------------------------------------------------

#[test]
fn jacobian_matches_reference_and_central_differences_in_3d() {
    let h = 1e-5; // m
    let (mut checked, mut worst) = (0, 0.0 as Real);
    for seed in 0..40 {
        let s = random_3d(seed);
        let m = Model::new(&s).unwrap();
        let net = &m.network;
        let (txs, rxs) = nodes_3d(&s);
        let zt = s.target.height_m;
        for r in points(&s, 9) {
            for p in 0..net.link_count() {
                let l = net.links[p];
                let j = net.jacobian_row(p, r);
                let want = ref_gradient(txs[l.tx], rxs[l.rx], r, zt);
                assert!(
                    (j - want).norm() <= 8.0 * Real::EPSILON * (2.0 / C),
                    "seed {seed} link {p} at {r:?}: {j:?} vs {want:?}"
                );
                // ‖row‖ ≤ 2/c (each term is the horizontal part of a unit vector).
                assert!(j.norm() <= 2.0 / C * (1.0 + 1e-15));
                // Central differences of the range (m per m). Error bound: truncation
                // h²/6·|ρ'''| with |ρ'''| ≤ Σ 3/d_n², rounding 2·4ε·ρ/(2h).
                let rng = |q: Vec2| C * net.delay(p, q);
                let fd = Vec2::new(
                    (rng(r + Vec2::new(h, 0.0)) - rng(r - Vec2::new(h, 0.0))) / (2.0 * h),
                    (rng(r + Vec2::new(0.0, h)) - rng(r - Vec2::new(0.0, h))) / (2.0 * h),
                );
                let r3 = [r.x, r.y, zt];
                let (dt, dr) = (len(sub(r3, txs[l.tx])), len(sub(r3, rxs[l.rx])));
                let bound = h * h / 6.0 * (3.0 / (dt * dt) + 3.0 / (dr * dr))
                    + 8.0 * Real::EPSILON * rng(r) / (2.0 * h);
                let g = C * j;
                let err = (fd - g).norm();
                assert!(
                    err <= bound.max(1e-8 * g.norm()) * 1.5,
                    "seed {seed} link {p} at {r:?}: FD {fd:?} vs {g:?}, err {err:e}, bound {bound:e}"
                );
                if g.norm() > 0.05 {
                    worst = worst.max(err / g.norm());
                }
                checked += 1;
            }
        }
    }
    println!("3-D Jacobian vs central differences (h = 1e-5 m): {checked} rows, worst relative {worst:.2e}");
    assert!(checked > 10_000, "{checked}");
}

#[test]
fn gradient_is_zero_straight_below_a_node_but_the_range_is_not() {
    // A target right under the ceiling Tx: horizontal gradient of its term is 0, its distance
    // is the height difference.
    let s = room([3.0, 2.0, 2.8], &[[3.0, 2.0, 2.8], [6.0, 2.0, 2.8]], 1.0);
    let m = Model::new(&s).unwrap();
    let r = Vec2::new(3.0, 2.0);
    assert_eq!(m.network.jacobian_row(0, r), Vec2::zeros());
    rel_close(
        "range below the nodes",
        C * m.network.delay(0, r),
        2.0 * 1.8,
        1e-15,
    );
    assert!(m.snr(0, r).is_finite() && m.snr(0, r) > 0.0);
}

// ---------------------------------------------------------------------------------------------
// CRLB (E8) in 3-D against the inverse FIM computed independently.
// ---------------------------------------------------------------------------------------------

#[test]
fn crlb_matches_independent_inverse_fim_in_3d() {
    // Omni antennas so that the reference needs no pattern: SNR = P G_t G_r σ c² /
    // ((4π)³ f² d_t² d_r² P_n) with 3-D distances floored at 1 m, F = Σ 8π²β²SNR/c²·g gᵀ.
    let s = ceiling_room();
    let m = Model::new(&s).unwrap();
    let (txs, rxs) = nodes_3d(&s);
    let zt = s.target.height_m;
    let kb = 1.380649e-23;
    let pn = kb * 290.0 * s.radio.bandwidth_hz * 10f64.powf(7.0 / 10.0);
    let beta2 = s.radio.bandwidth_hz * s.radio.bandwidth_hz / 12.0;
    let f = s.radio.carrier_hz;
    let ptx = 10f64.powf((14.0 - 30.0) / 10.0);
    let (gt, gr) = (10f64.powf(0.3), 10f64.powf(0.3));
    let mut checked = 0;
    for r in points(&s, 12) {
        let r3 = [r.x, r.y, zt];
        let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
        for l in &m.network.links {
            let (dt, dr) = (len(sub(r3, txs[l.tx])), len(sub(r3, rxs[l.rx])));
            let (ft, fr) = (dt.max(1.0), dr.max(1.0));
            let snr =
                ptx * gt * gr * 1.0 * C * C / ((4.0 * PI).powi(3) * f * f * ft * ft * fr * fr * pn);
            let g = ref_gradient(txs[l.tx], rxs[l.rx], r, zt) * C;
            let w = 8.0 * PI * PI * beta2 * snr / (C * C);
            a += w * g.x * g.x;
            b += w * g.x * g.y;
            c += w * g.y * g.y;
        }
        let det = a * c - b * b;
        let point = crlb_at(&m, r);
        if det <= 1e3 * SINGULAR_RCOND * (a + c) * (a + c) {
            continue;
        }
        let want = ((a + c) / det).sqrt();
        let bound = point.bound.expect("regular");
        rel_close("3-D CRLB rmse", bound.rmse_m, want, 1e-10);
        rel_close("3-D CRLB σx", bound.sigma_x_m, (c / det).sqrt(), 1e-10);
        rel_close("3-D CRLB σy", bound.sigma_y_m, (a / det).sqrt(), 1e-10);
        checked += 1;
    }
    assert!(checked > 100, "{checked}");
}

// ---------------------------------------------------------------------------------------------
// The map kernel with heights: SIMD = scalar bitwise, every exact native path too, = crlb_at.
// ---------------------------------------------------------------------------------------------

#[test]
fn map_kernel_equals_scalar_with_heights() {
    let mut bounded = 0;
    for seed in 0..24 {
        let s = random_3d(seed);
        let m = Model::new(&s).unwrap();
        let grid = Grid::new(s.area_m, 37, 29).unwrap();
        let mut simd = vec![Real::NAN; grid.len()];
        let mut scalar = vec![Real::NAN; grid.len()];
        crlb_map(&m, &grid, &mut simd).unwrap();
        crlb_map_scalar(&m, &grid, &mut scalar).unwrap();
        for (i, (a, b)) in simd.iter().zip(&scalar).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "seed {seed} cell {i}: {a} vs {b}");
        }
        for path in map_paths()
            .into_iter()
            .filter(|p| !p.name().contains("fast"))
        {
            let mut out = vec![Real::NAN; grid.len()];
            crlb_map_on(path, &m, &grid, &mut out).unwrap();
            for (i, (a, b)) in out.iter().zip(&scalar).enumerate() {
                assert_eq!(a.to_bits(), b.to_bits(), "{path:?} seed {seed} cell {i}");
            }
        }
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                let v = simd[j * grid.nx + i];
                let p = crlb_at(&m, Vec2::new(grid.x(i), grid.y(j)));
                let f = p.fisher_per_m2;
                let (tr, det) = (f[(0, 0)] + f[(1, 1)], f.determinant());
                if let (Some(b), true) = (p.bound, v.is_finite()) {
                    let tol = 1e-12 + 64.0 * tr * tr / det * Real::EPSILON;
                    assert!(
                        (v - b.rmse_m).abs() <= tol * b.rmse_m,
                        "seed {seed} ({i},{j})"
                    );
                    bounded += 1;
                }
            }
        }
    }
    assert!(bounded > 10_000, "{bounded}");
}

// ---------------------------------------------------------------------------------------------
// Check 8 in 3-D: LM from noise-free 3-D delays converges to the truth.
// ---------------------------------------------------------------------------------------------

#[test]
fn lm_converges_to_truth_from_noise_free_3d_delays() {
    let cfg = LmConfig::default();
    let offsets = [
        [3.0, 0.0],
        [0.0, -3.0],
        [2.0, 2.0],
        [-2.1, 2.1],
        [-1.0, -2.5],
    ];
    let mut cases = 0;
    for s in [ceiling_room(), random_3d(3), random_3d(11)] {
        let m = Model::new(&s).unwrap();
        for t in points(&s, 4) {
            let delays: Vec<Option<Real>> = m.network.delays(t).into_iter().map(Some).collect();
            let sigmas = m.sigma_delays(t);
            let meas = DelayMeasurements {
                delays_s: &delays,
                sigmas_s: &sigmas,
            };
            for o in offsets {
                let start = t + Vec2::new(o[0], o[1]);
                let rep =
                    localize::locate(&m.network, &meas, &cfg, Some(start), &s.area_m).unwrap();
                let err = (rep.position - t).norm();
                // A start across a baseline may fall into the mirror minimum of a two-receiver
                // layout; the ceiling room (three receivers around the walker) must always
                // converge.
                if s.name == "room" || err <= 1e-6 {
                    assert!(
                        err <= 1e-6 && rep.termination.converged(),
                        "{}: truth {t:?} start {start:?}: error {err}",
                        s.name
                    );
                    cases += 1;
                }
            }
        }
    }
    assert!(cases >= 80, "{cases}");
}

// ---------------------------------------------------------------------------------------------
// The issue's example: a ceiling node (2.8 m) over a walker (body centre 1.0 m).
// ---------------------------------------------------------------------------------------------

#[test]
fn ceiling_nodes_give_the_hand_computed_bistatic_range() {
    // Tx at (0, 2, 2.8), Rx0 at (6, 2, 2.8), target plane 1.0 m: dz = 1.8 m, dz² = 3.24 m².
    let m = Model::new(&ceiling_room()).unwrap();
    let range = |x: Real, y: Real| C * m.network.delay(0, Vec2::new(x, y));
    // (3, 2): 2·√(3² + 3.24) = 2·√12.24.
    rel_close(
        "range at (3, 2)",
        range(3.0, 2.0),
        2.0 * 12.24f64.sqrt(),
        1e-15,
    );
    // (1, 1): √(1 + 1 + 3.24) + √(25 + 1 + 3.24).
    rel_close(
        "range at (1, 1)",
        range(1.0, 1.0),
        5.24f64.sqrt() + 29.24f64.sqrt(),
        1e-15,
    );
    // (5, 3.5): √(25 + 2.25 + 3.24) + √(1 + 2.25 + 3.24).
    rel_close(
        "range at (5, 3.5)",
        range(5.0, 3.5),
        30.49f64.sqrt() + 6.49f64.sqrt(),
        1e-15,
    );
    // (0.5, 0.5): √(0.25 + 2.25 + 3.24) + √(30.25 + 2.25 + 3.24).
    rel_close(
        "range at (0.5, 0.5)",
        range(0.5, 0.5),
        5.74f64.sqrt() + 35.74f64.sqrt(),
        1e-15,
    );
    // The planar model there: 6, √2 + √26, … — the bias at (3, 2) is 2√12.24 − 6 = 0.9971 m.
    rel_close("bias at (3, 2)", range(3.0, 2.0) - 6.0, 0.997_142_3, 1e-7);
}

/// Bias of the planar model over the room (0.1 m grid, cell centres) for one link:
/// `(max, rms, min)` of `ρ_3D − ρ_2D`, m.
fn planar_bias(s: &Scenario, p: usize) -> (Real, Real, Real) {
    let m = Model::new(s).unwrap();
    let (tx, rx) = m.network.link_nodes(p);
    let (mut max, mut sum2, mut min, mut n) = (0.0 as Real, 0.0, Real::INFINITY, 0);
    for j in 0..40 {
        for i in 0..60 {
            let r = Vec2::new(0.05 + 0.1 * i as Real, 0.05 + 0.1 * j as Real);
            let b = C * m.network.delay(p, r) - measure::bistatic_range(tx, rx, r);
            max = max.max(b);
            min = min.min(b);
            sum2 += b * b;
            n += 1;
        }
    }
    (max, (sum2 / n as Real).sqrt(), min)
}

#[test]
fn the_planar_models_bias_in_a_typical_room() {
    // 6 m × 4 m, body centre at 1.0 m. Layouts: both nodes at the ceiling (2.8 m) on opposite
    // walls; the Tx at the ceiling and the Rx at body height; both on a shelf at 1.5 m; both on
    // the floor-standing 1.0 m (no bias).
    let cases: [(&str, [Real; 3], [Real; 3]); 4] = [
        ("Tx 2.8 m, Rx 2.8 m", [0.0, 2.0, 2.8], [6.0, 2.0, 2.8]),
        ("Tx 2.8 m, Rx 1.0 m", [0.0, 2.0, 2.8], [6.0, 2.0, 1.0]),
        ("Tx 1.5 m, Rx 1.5 m", [0.0, 2.0, 1.5], [6.0, 2.0, 1.5]),
        ("Tx 1.0 m, Rx 1.0 m", [0.0, 2.0, 1.0], [6.0, 2.0, 1.0]),
    ];
    println!("| layout (target plane 1.0 m) | max bias [m] | RMS bias [m] | min bias [m] |");
    for (name, tx, rx) in cases {
        let s = room(tx, &[rx], 1.0);
        let (max, rms, min) = planar_bias(&s, 0);
        // (A planar layout leaves ±1e-16 of rounding: printed as 0.)
        let show = |v: Real| if v.abs() < 1e-12 { 0.0 } else { v };
        let (max, rms, min) = (show(max), show(rms), show(min));
        println!("| {name} | {max:.3} | {rms:.3} | {min:.3} |");
        if tx[2] == 1.0 && rx[2] == 1.0 {
            // Only the rounding of c·(ρ/c) is left.
            assert!(max == 0.0 && min == 0.0, "{max} {min}");
        } else {
            // The bias is at most |dz_t| + |dz_r| (a node's term grows by at most |dz|).
            assert!(max <= (tx[2] - 1.0).abs() + (rx[2] - 1.0).abs() + 1e-12);
            assert!(min > 0.0 && rms <= max);
        }
    }
    // Ceiling layout by hand. Largest next to the Tx, at the cell centre (0.05, 1.95):
    // √(0.05² + 0.05² + 1.8²) − √(0.05² + 0.05²) + √(5.95² + 0.05² + 1.8²) − √(5.95² + 0.05²).
    let s = room([0.0, 2.0, 2.8], &[[6.0, 2.0, 2.8]], 1.0);
    let (max, _, min) = planar_bias(&s, 0);
    let want_max = 3.245f64.sqrt() - 0.005f64.sqrt() + (35.405f64 + 3.24).sqrt() - 35.405f64.sqrt();
    rel_close("max bias (hand)", max, want_max, 1e-12);
    // Smallest in the middle of a long wall, at (2.95, 0.05) (or its mirror images):
    // √(2.95² + 1.95² + 1.8²) − √(2.95² + 1.95²) + √(3.05² + 1.95² + 1.8²) − √(3.05² + 1.95²).
    let want_min =
        (12.505f64 + 3.24).sqrt() - 12.505f64.sqrt() + (13.105f64 + 3.24).sqrt() - 13.105f64.sqrt();
    rel_close("min bias (hand)", min, want_min, 1e-12);
}

#[test]
fn localisation_error_of_the_planar_model_in_the_ceiling_room() {
    // Noise-free 3-D delays localised with the planar model (every height 0): the position
    // error a 2-D model makes in the ceiling room. Printed for docs/rooms-3d.md.
    let s3 = ceiling_room();
    let m3 = Model::new(&s3).unwrap();
    let mut s2 = s3.clone();
    s2.target.height_m = 0.0;
    s2.transmitters.iter_mut().for_each(|t| t.height_m = 0.0);
    s2.receivers.iter_mut().for_each(|r| r.height_m = 0.0);
    let m2 = Model::new(&s2).unwrap();
    let cfg = LmConfig::default();
    let (mut max, mut sum2, mut n, mut fails) = (0.0 as Real, 0.0, 0, 0);
    for j in 0..8 {
        for i in 0..12 {
            let t = Vec2::new(0.25 + 0.5 * i as Real, 0.25 + 0.5 * j as Real);
            let delays: Vec<Option<Real>> = m3.network.delays(t).into_iter().map(Some).collect();
            let sigmas = vec![1e-10; delays.len()];
            let meas = DelayMeasurements {
                delays_s: &delays,
                sigmas_s: &sigmas,
            };
            // The 3-D model recovers the truth; the planar one is biased.
            let r3 = localize::locate(&m3.network, &meas, &cfg, Some(t), &s3.area_m).unwrap();
            assert!((r3.position - t).norm() <= 1e-6, "3-D fix at {t:?}");
            match localize::locate(&m2.network, &meas, &cfg, Some(t), &s2.area_m) {
                Ok(r2) if r2.position.iter().all(|v| v.is_finite()) => {
                    let e = (r2.position - t).norm();
                    max = max.max(e);
                    sum2 += e * e;
                    n += 1;
                }
                _ => fails += 1,
            }
        }
    }
    let rms = (sum2 / n as Real).sqrt();
    println!(
        "planar model on 3-D delays, ceiling room (3 links, 96 points on a 0.5 m grid): \
         position error max {max:.3} m, RMS {rms:.3} m, {fails} fixes failed"
    );
    assert!(n >= 90 && max > 0.1, "n {n} max {max}");
}

// ---------------------------------------------------------------------------------------------
// Iso-delay curves in the target's plane.
// ---------------------------------------------------------------------------------------------

#[test]
fn iso_delay_curve_is_exact_in_3d_and_the_ellipse_in_2d() {
    let s = ceiling_room();
    let m = Model::new(&s).unwrap();
    let truth = Vec2::new(2.0, 1.3);
    for p in 0..m.link_count() {
        let tau = m.network.delay(p, truth);
        let curve = m.network.iso_delay_curve(p, tau, 160);
        assert_eq!(curve.len(), 160);
        for q in &curve {
            rel_close("point on the 3-D curve", m.network.delay(p, *q), tau, 1e-13);
        }
        let arc = m.network.iso_delay_arc_near(p, tau, truth, 0.2, 48);
        assert_eq!(arc.len(), 48);
        assert!(arc.iter().any(|q| (q - truth).norm() < 0.02));
        for q in &arc {
            rel_close("point on the 3-D arc", m.network.delay(p, *q), tau, 1e-13);
        }
        // The planar ellipse with the same delay misses the truth by the bias (an approximation
        // only).
        let e = m.network.iso_delay_ellipse(p, tau).unwrap();
        assert!(e.semi_major > C * tau / 2.0 - 1e-9);
    }
    // Planar: the curve lies on the ellipse.
    let sp = presets::sensors2019();
    let mp = Model::new(&sp).unwrap();
    let t = Vec2::new(4.0, 1.0);
    let tau = mp.network.delay(0, t);
    let (tx, rx) = mp.network.link_nodes(0);
    for q in mp.network.iso_delay_curve(0, tau, 64) {
        rel_close(
            "curve on the ellipse",
            (q - tx).norm() + (q - rx).norm(),
            C * tau,
            1e-13,
        );
    }
    assert!(mp.network.iso_delay_curve(0, Real::NAN, 64).is_empty());
    assert!(mp.network.iso_delay_curve(0, 0.0, 64).is_empty());
}

// ---------------------------------------------------------------------------------------------
// The channel simulator with heights: LoS, wall and body paths have 3-D lengths.
// ---------------------------------------------------------------------------------------------

#[test]
fn channel_simulator_uses_3d_path_lengths() {
    let s = ceiling_room();
    let m = Model::new(&s).unwrap();
    let mut scene = ChannelScene::hangar();
    scene.scatterers.clear();
    scene.walls = vec![
        wall([-0.5, -0.5], [6.5, -0.5]),
        wall([6.5, -0.5], [6.5, 4.5]),
        wall([6.5, 4.5], [-0.5, 4.5]),
        wall([-0.5, 4.5], [-0.5, -0.5]),
    ];
    scene.walk = Walk {
        waypoints_m: vec![[1.0, 1.0], [5.0, 3.0]],
        speed_mps: 1.0,
        turn_radius_m: 0.5,
    };
    scene.duration_s = Some(5.0 * scene.dt_s);
    let (_, truth) = simulate_recording(&s, &m, &scene, true, 7).unwrap();
    let (txs, rxs) = nodes_3d(&s);
    let zt = s.target.height_m;
    let mut walls_checked = 0;
    for (n, links) in truth.paths.iter().enumerate() {
        let st = truth.states[n];
        let c = Vec2::new(st[0], st[1]);
        for (p, paths) in links.iter().enumerate() {
            let l = m.network.links[p];
            let (t, r) = (txs[l.tx], rxs[l.rx]);
            // Wall images of the Rx in 3-D (a vertical wall keeps z).
            let images: Vec<Real> = scene
                .walls
                .iter()
                .map(|w| len(sub(mirror(w, r), t)) / C)
                .collect();
            for path in paths {
                match path.kind {
                    PathKind::Los => rel_close("LoS", path.delay_s, len(sub(r, t)) / C, 1e-14),
                    PathKind::Body => {
                        rel_close("body", path.delay_s, ref_delay(t, r, c, zt), 1e-14)
                    }
                    PathKind::Wall => {
                        assert!(
                            images.iter().any(|d| (d - path.delay_s).abs() <= 1e-14 * d),
                            "wall path {} not an image path",
                            path.delay_s
                        );
                        walls_checked += 1;
                    }
                    _ => {}
                }
            }
        }
    }
    assert!(walls_checked > 0);
}

fn wall(a: [Real; 2], b: [Real; 2]) -> scatterloc::channel::Wall {
    scatterloc::channel::Wall {
        a_m: a,
        b_m: b,
        gamma: -0.5,
    }
}

/// The mirror image of `p` in the vertical plane through the wall (z unchanged).
fn mirror(w: &scatterloc::channel::Wall, p: P3) -> P3 {
    let (ax, ay) = (w.a_m[0], w.a_m[1]);
    let (dx, dy) = (w.b_m[0] - ax, w.b_m[1] - ay);
    let t = ((p[0] - ax) * dx + (p[1] - ay) * dy) / (dx * dx + dy * dy);
    let (fx, fy) = (ax + t * dx, ay + t * dy);
    [2.0 * fx - p[0], 2.0 * fy - p[1], p[2]]
}

// ---------------------------------------------------------------------------------------------
// The three filters and the PCRLB see the 3-D model.
// ---------------------------------------------------------------------------------------------

#[test]
fn filters_predict_and_track_with_3d_delays() {
    use scatterloc::math::{Mat4, Vec4};
    use scatterloc::track::{
        nominal_pcrlb_rmse, ConstantVelocity, Filter, FilterKind, MeasurementNoise, PfConfig,
        Tracker, UkfParams,
    };
    let s = ceiling_room();
    let m = Model::new(&s).unwrap();
    let (txs, rxs) = nodes_3d(&s);
    let zt = s.target.height_m;
    let motion = ConstantVelocity::new(0.1, 0.01);
    let kinds = [
        FilterKind::Ekf,
        FilterKind::Ukf(UkfParams::default()),
        FilterKind::Pf(PfConfig::bootstrap(4000)),
    ];
    for kind in kinds {
        // Predicted delays at a tight prior around (2, 1.3): the 3-D reference (the EKF
        // exactly; the UKF and PF to their spread's second order / sampling error, far below
        // the ≈ 1 m planar bias).
        let x0 = Vec4::new(2.0, 1.3, 0.5, 0.2);
        let p0 = Mat4::from_diagonal(&Vec4::new(1e-6, 1e-6, 1e-4, 1e-4));
        let f = Tracker::new(kind, x0, p0, measure::rng(5, 1)).unwrap();
        let pred = f
            .predicted_delays(&m, MeasurementNoise::AtPrediction)
            .unwrap();
        for (p, d) in pred.iter().enumerate() {
            let l = m.network.links[p];
            let want = ref_delay(txs[l.tx], rxs[l.rx], Vec2::new(2.0, 1.3), zt);
            let tol = if matches!(kind, FilterKind::Ekf) {
                1e-15
            } else {
                1e-4
            };
            assert!(
                (C * (d.delay_s - want)).abs() <= tol * C * want,
                "{}: link {p}: {} vs {want}",
                kind.name(),
                d.delay_s
            );
        }
        // Tracking a straight walk from noise-free 3-D delays: the filter stays on the truth.
        let mut f = Tracker::new(
            kind,
            Vec4::new(1.0, 1.0, 0.8, 0.4),
            Mat4::from_diagonal(&Vec4::new(0.01, 0.01, 0.01, 0.01)),
            measure::rng(5, 2),
        )
        .unwrap();
        let mut err = 0.0;
        for n in 1..=40 {
            let t = Vec2::new(1.0 + 0.08 * n as Real, 1.0 + 0.04 * n as Real);
            let z: Vec<Option<Real>> = m.network.delays(t).into_iter().map(Some).collect();
            f.step(&motion, &m, &z, MeasurementNoise::AtPrediction)
                .unwrap();
            err = (f.position() - t).norm();
        }
        println!(
            "{}: position error after 40 noise-free 3-D steps {err:.2e} m",
            kind.name()
        );
        assert!(err < 0.02, "{}: error {err} m", kind.name());
    }
    // The PCRLB along the walk uses the 3-D Fisher information: with heights it differs from
    // the planar room's (longer distances, other directions).
    let p0 = Mat4::from_diagonal(&Vec4::new(0.1, 0.1, 0.01, 0.01));
    let x0 = Vec4::new(1.0, 1.0, 0.8, 0.4);
    let b3 = nominal_pcrlb_rmse(&m, &motion, &x0, &p0, 30).unwrap();
    let mut s2 = s.clone();
    s2.target.height_m = 0.0;
    s2.transmitters.iter_mut().for_each(|t| t.height_m = 0.0);
    s2.receivers.iter_mut().for_each(|r| r.height_m = 0.0);
    let b2 = nominal_pcrlb_rmse(&Model::new(&s2).unwrap(), &motion, &x0, &p0, 30).unwrap();
    let (l3, l2) = (b3.last().unwrap().unwrap(), b2.last().unwrap().unwrap());
    println!("PCRLB after 3 s: 3-D room {l3:.3e} m, planar room {l2:.3e} m");
    assert!(l3.is_finite() && (l3 - l2).abs() > 1e-3 * l2);
}

// ---------------------------------------------------------------------------------------------
// A fix and a bound with a free height (the target's z unknown).
// ---------------------------------------------------------------------------------------------

#[path = "spec_checks_3d/free_z.rs"]
mod free_z;
