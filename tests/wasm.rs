//! Core and page-API tests inside headless Chromium (`wasm-pack test --headless --chrome`):
//! the spec's numbers hold in wasm too, and the JS-facing API fills typed arrays, never lets NaN
//! through and turns bad input into exceptions with the core's message.
#![cfg(target_arch = "wasm32")]

use js_sys::{Float64Array, Reflect, Uint8ClampedArray};
use wasm_bindgen::{JsCast, JsError, JsValue};
use wasm_bindgen_test::*;

use scatterloc::localize::{crlb_at, Grid};
use scatterloc::localize::{locate, DelayMeasurements, LmConfig};
use scatterloc::wasm::{self, App};
use scatterloc::{scenario::presets, Model, Vec2};

wasm_bindgen_test_configure!(run_in_browser);

/// The tracking API: tracks, the worker's Monte Carlo job, the chart.
#[path = "wasm/tracking.rs"]
mod tracking;

/// The multi-target view API (`mtl_view_of`).
#[path = "wasm/mtl.rs"]
mod mtl;

/// SVG text checks shared with the other figure-export tests.
#[path = "common/svg.rs"]
mod svg;

/// "Save figure": the SVG figures of the map and the tracking chart.
#[path = "wasm/export.rs"]
mod export;

/// A dropped `.npz` channel recording (`read_recording_summary`).
#[path = "wasm/recording.rs"]
mod recording;

/// The channel view's settings table (`channel_settings`).
#[path = "wasm/channel_settings.rs"]
mod channel_settings;

/// The channel view's Replay (`ChannelReplay`): the CLI's live lines, the batch run's states.
#[path = "wasm/replay.rs"]
mod replay;

/// Several people in the tracking view (`track_people`, `draw_people_chart`): the core's use case.
#[path = "wasm/multi.rs"]
mod multi;

/// Issue 42 §1: the bound with Doppler at a point (`App.doppler_at`) and the maps with Doppler
/// as figures (`App.map_svg`'s `doppler`).
#[path = "wasm/doppler.rs"]
mod doppler;

fn message(e: JsError) -> String {
    let v: JsValue = e.into();
    v.dyn_into::<js_sys::Error>()
        .map(|e| String::from(e.message()))
        .unwrap_or_else(|v| format!("{v:?}"))
}

fn ok<T>(r: Result<T, JsError>) -> T {
    r.unwrap_or_else(|e| panic!("unexpected error: {}", message(e)))
}

fn err<T>(r: Result<T, JsError>) -> String {
    match r {
        Ok(_) => panic!("expected an error"),
        Err(e) => message(e),
    }
}

fn get(obj: &JsValue, key: &str) -> JsValue {
    Reflect::get(obj, &JsValue::from_str(key)).expect("property")
}

fn num(obj: &JsValue, key: &str) -> f64 {
    get(obj, key)
        .as_f64()
        .unwrap_or_else(|| panic!("{key} is not a number"))
}

fn sensors() -> App {
    ok(App::from_preset("sensors2019"))
}

/// `App.compute_map_in`'s settings object (JSON text, as the page's `JSON.stringify`: a
/// non-finite number is `null`) of window `w` on an `nx × ny` grid.
fn map_window(w: [f64; 4], nx: usize, ny: usize) -> String {
    serde_json::json!({ "window": w, "nx": nx, "ny": ny }).to_string()
}

/// Spec §0 check 7: layout L4 CRLB RMSE at four points, within 0.1 %.
#[wasm_bindgen_test]
fn spec_check_7_l4_crlb_rmse() {
    let model = Model::new(&presets::sensors2019()).unwrap();
    for (x, y, cm) in [
        (10.0, 0.0, 0.792),
        (4.0, 1.0, 0.426),
        (20.0, 10.0, 4.864),
        (0.0, 20.0, 17.69),
    ] {
        let rmse = crlb_at(&model, Vec2::new(x, y)).bound.unwrap().rmse_m;
        let rel = (rmse / (cm / 100.0) - 1.0).abs();
        assert!(rel < 1e-3, "({x}, {y}): {rmse} m vs {cm} cm (rel {rel:e})");
    }
}

/// Spec §0 check 8 (first half): noise-free delays, LM converges to the truth within 1e-6 m,
/// from a start 3 m off and from the grid-search start.
#[wasm_bindgen_test]
fn noise_free_lm_fix_hits_truth() {
    let s = presets::sensors2019();
    let model = Model::new(&s).unwrap();
    for truth in [
        Vec2::new(4.0, 1.0),
        Vec2::new(10.0, 0.0),
        Vec2::new(-3.0, 7.5),
    ] {
        let delays: Vec<Option<f64>> = model.network.delays(truth).into_iter().map(Some).collect();
        let sigmas = model.sigma_delays(truth);
        let m = DelayMeasurements {
            delays_s: &delays,
            sigmas_s: &sigmas,
        };
        for start in [Some(truth + Vec2::new(2.1, -2.1)), None] {
            let rep = locate(&model.network, &m, &LmConfig::default(), start, &s.area_m).unwrap();
            let miss = (rep.position - truth).norm();
            assert!(
                miss < 1e-6,
                "truth {truth:?} start {start:?}: miss {miss} m"
            );
            assert!(rep.termination.converged());
        }
    }
}

/// The map lands in the caller's Float64Array, finite where bounded; a cell equals `crlb_at` at
/// its centre; the colouring fills 4 bytes per cell and reports its scale.
#[wasm_bindgen_test]
fn map_fills_float64array_and_matches_point_queries() {
    let app = sensors();
    let (nx, ny) = (64, 48);
    let out = Float64Array::new_with_length((nx * ny) as u32);
    let ms = ok(app.compute_map(nx, ny, &out));
    assert!(ms.is_finite() && ms >= 0.0);
    let v = out.to_vec();
    assert!(
        v.iter().all(|x| x.is_finite() && *x > 0.0),
        "L4 map is bounded everywhere"
    );
    for (i, j) in [(0, 0), (17, 9), (63, 47), (40, 30)] {
        let c = ok(app.cell_center(nx, ny, i, j));
        let cell = v[j * nx + i];
        let point = ok(app.crlb_at(c[0], c[1]));
        assert_eq!(get(&point, "bounded"), JsValue::TRUE);
        let rmse = num(&point, "rmse_m");
        assert!(
            (cell / rmse - 1.0).abs() < 1e-12,
            "cell ({i},{j}) {cell} vs crlb_at {rmse}"
        );
        assert_eq!(ok(app.rmse_at(c[0], c[1])), rmse);
        let e = get(&point, "ellipse");
        assert!(num(&e, "a") >= num(&e, "b") && num(&e, "b") > 0.0);
    }
    // The same cell centres as the core's grid.
    let g = Grid::new(presets::sensors2019().area_m, nx, ny).unwrap();
    assert_eq!(ok(app.cell_center(nx, ny, 5, 7)), vec![g.x(5), g.y(7)]);

    let rgba = Uint8ClampedArray::new_with_length((4 * nx * ny) as u32);
    let range = ok(wasm::render_map_rgba(&out, &rgba));
    let (lo, hi) = (range[0], range[1]);
    assert!(v.iter().all(|x| *x >= lo && *x <= hi));
    assert_eq!(lo, v.iter().copied().fold(f64::INFINITY, f64::min));
    let px = rgba.to_vec();
    assert!(px.chunks_exact(4).all(|p| p[3] == 255));
    assert!(
        px.chunks_exact(4).any(|p| p[..3] != px[..3]),
        "not a flat image"
    );
}

/// The page's zoom and pan (issue 16 §3): the map of a window is computed in that window at full
/// resolution, not cropped from the area's map. Every cell equals the core's map over the grid of
/// the window bit for bit and `crlb_at` at its centre, including a window reaching past the area.
/// A window that is not a finite, non-empty rectangle is a named error.
#[wasm_bindgen_test]
fn map_of_a_window_is_the_core_map_of_that_window() {
    use scatterloc::localize::crlb_map;
    use scatterloc::scenario::Area;
    let app = sensors();
    let s = presets::sensors2019();
    let m = Model::new(&s).unwrap();
    let (nx, ny) = (40, 30);
    for w in [
        [2.5, 4.0, -1.0, 0.125],
        [25.0, 45.0, 20.0, 35.0],
        [-7.5, 30.0, -10.0, 26.0],
    ] {
        let out = Float64Array::new_with_length((nx * ny) as u32);
        ok(app.compute_map_in(&map_window(w, nx, ny), &out));
        let grid = Grid::new(
            Area {
                x: [w[0], w[1]],
                y: [w[2], w[3]],
            },
            nx,
            ny,
        )
        .unwrap();
        let mut want = vec![0.0; grid.len()];
        crlb_map(&m, &grid, &mut want).unwrap();
        let got = out.to_vec();
        assert!(
            got.iter()
                .zip(&want)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "window {w:?}"
        );
        for (i, j) in [(0, 0), (nx - 1, ny - 1), (13, 21)] {
            let rmse = ok(app.rmse_at(grid.x(i), grid.y(j)));
            assert!(
                (got[j * nx + i] / rmse - 1.0).abs() < 1e-12,
                "window {w:?} cell ({i},{j})"
            );
        }
    }
    // The whole area as a window is the area's map.
    let (a, b) = (
        Float64Array::new_with_length(64),
        Float64Array::new_with_length(64),
    );
    ok(app.compute_map(8, 8, &a));
    ok(app.compute_map_in(&map_window([-7.5, 30.0, -10.0, 26.0], 8, 8), &b));
    assert_eq!(a.to_vec(), b.to_vec());
    let buf = Float64Array::new_with_length(64);
    for (m, field) in [
        (
            err(app.compute_map_in(&map_window([1.0, 1.0, 0.0, 1.0], 8, 8), &buf)),
            "window.x",
        ),
        (
            err(app.compute_map_in(&map_window([0.0, 1.0, f64::NAN, 1.0], 8, 8), &buf)),
            "settings: invalid JSON: window[2]",
        ),
        (
            err(app.compute_map_in(&map_window([0.0, 1.0, 2.0, 1.0], 8, 8), &buf)),
            "window.y",
        ),
        (
            err(app.compute_map_in(&map_window([0.0, f64::INFINITY, 0.0, 1.0], 8, 8), &buf)),
            "settings: invalid JSON: window[1]",
        ),
        (
            err(app.compute_map_in(&map_window([0.0, 1.0, 0.0, 1.0], 1, 8), &buf)),
            "nx",
        ),
    ] {
        assert!(m.contains(field), "message {m:?} should name {field}");
    }
}

/// Issue 39: the bindings that took many positional numbers take one settings object (JSON text,
/// read into a serde struct): an unknown, missing or mistyped field is an exception naming the
/// field (never a trap, never a silent default), for each of `App.compute_map_in`,
/// `App.simulate_track`, `MonteCarloJob` and `map_data_text`.
#[wasm_bindgen_test]
fn settings_objects_name_a_bad_field() {
    use serde_json::{json, Value};
    /// `base` with `key` set to `value` (`None` removes it; a `.` goes one level down).
    fn with(base: &Value, key: &str, value: Option<Value>) -> String {
        let mut v = base.clone();
        let (obj, key) = match key.split_once('.') {
            Some((outer, inner)) => (&mut v[outer], inner),
            None => (&mut v, key),
        };
        let obj = obj.as_object_mut().unwrap();
        match value {
            Some(value) => obj.insert(key.into(), value),
            None => obj.remove(key),
        };
        v.to_string()
    }
    let cases = [
        ("extra", Some(json!(1)), "unknown field `extra`"),
        ("nx", None, "missing field `nx`"),
        ("nx", Some(json!(-1)), "nx: invalid value"),
        ("nx", Some(json!(8.5)), "nx: invalid type"),
        ("window", Some(json!([0, 1, 0])), "window: invalid length 3"),
        (
            "window",
            Some(json!([0, 1, 0, "1"])),
            "window[3]: invalid type",
        ),
    ];
    let app = sensors();
    let buf = Float64Array::new_with_length(64);
    let map = json!({ "window": [0.0, 1.0, 0.0, 1.0], "nx": 8, "ny": 8 });
    ok(app.compute_map_in(&map.to_string(), &buf));
    for (key, value, want) in cases.clone() {
        let m = err(app.compute_map_in(&with(&map, key, value), &buf));
        assert!(
            m.starts_with("settings: invalid JSON: ") && m.contains(want),
            "{key}: {m}"
        );
    }
    assert!(
        err(app.compute_map_in("[0, 1, 0, 1, 8, 8]", &buf)).starts_with("settings: invalid JSON")
    );
    assert!(err(app.compute_map_in("", &buf)).starts_with("settings: invalid JSON"));

    let mut data = map.clone();
    data["scenario"] = json!("L4");
    data["format"] = json!("csv");
    let values = vec![1.0; 64];
    assert!(ok(wasm::map_data_text(&values, &data.to_string())).starts_with("x_m,y_m,rmse_m\n"));
    for (key, value, want) in cases {
        let m = err(wasm::map_data_text(&values, &with(&data, key, value)));
        assert!(
            m.starts_with("map_data_text: invalid JSON: ") && m.contains(want),
            "{key}: {m}"
        );
    }
    let m = err(wasm::map_data_text(
        &values,
        &with(&data, "format", Some(json!(1))),
    ));
    assert!(m.contains("format: invalid type"), "{m}");

    let trajectory = json!({ "kind": "II", "x0_m": 0, "y0_m": 0, "vx_mps": 0, "vy_mps": 0 });
    let track = json!({
        "trajectory": trajectory, "dt_s": 0.1, "steps": 10, "seed": 7, "filter": "ekf",
        "particles": 1000,
    });
    ok(app.simulate_track(&track.to_string()));
    let scenario = ok(wasm::preset_json("sensors2019"));
    let study = json!({
        "trajectory": trajectory, "dt_s": 0.1, "steps": 10, "trajectories": 16,
        "noise_runs": 1, "seed": 7,
    });
    ok(wasm::MonteCarloJob::new(&scenario, &study.to_string()));
    for (key, value, want) in [
        ("x0", Some(json!(1)), "unknown field `x0`"),
        ("steps", None, "missing field `steps`"),
        (
            "dt_s",
            Some(Value::from(f64::NAN)),
            "dt_s: invalid type: null",
        ),
        ("dt_s", Some(json!("0.1")), "dt_s: invalid type: string"),
        ("steps", Some(json!(-1)), "steps: invalid value"),
        ("seed", Some(json!(1u64 << 32)), "seed: invalid value"),
        (
            "trajectory.x0",
            Some(json!(0)),
            "trajectory.x0: unknown field `x0`",
        ),
        (
            "trajectory.vy_mps",
            None,
            "trajectory: missing field `vy_mps`",
        ),
        (
            "trajectory.kind",
            Some(json!(2)),
            "trajectory.kind: invalid type",
        ),
    ] {
        let m = err(app.simulate_track(&with(&track, key, value.clone())));
        assert!(
            m.starts_with("settings: invalid JSON: ") && m.contains(want),
            "track {key}: {m}"
        );
        let m = err(wasm::MonteCarloJob::new(&scenario, &with(&study, key, value)).map(|_| ()));
        assert!(
            m.starts_with("settings: invalid JSON: ") && m.contains(want),
            "study {key}: {m}"
        );
    }
    for (key, value, want) in [
        ("filter", Some(json!(["ekf"])), "filter: invalid type"),
        ("particles", Some(json!(1.5)), "particles: invalid type"),
        (
            "trajectories",
            Some(json!(1)),
            "unknown field `trajectories`",
        ),
    ] {
        let m = err(app.simulate_track(&with(&track, key, value)));
        assert!(m.contains(want), "track {key}: {m}");
    }
    for (key, value, want) in [
        ("noise_runs", Some(json!("1")), "noise_runs: invalid type"),
        ("filter", Some(json!("ekf")), "unknown field `filter`"),
    ] {
        let m = err(wasm::MonteCarloJob::new(&scenario, &with(&study, key, value)).map(|_| ()));
        assert!(m.contains(want), "study {key}: {m}");
    }
}

/// The page's map kernel (SIMD on simd128) equals the scalar reference bit for bit, and the page's
/// map is the core's. Against the native map (values printed by a native run of the same grid)
/// it agrees to 1e-14 relative, not bitwise: the model's setup (dB → linear, the pattern's
/// Chebyshev fit) calls `exp`, `cos`, `acos`, which are glibc's natively and Rust's libm port in
/// wasm and may differ in the last bit; given the same model, the kernel is bitwise the same.
#[wasm_bindgen_test]
fn wasm_map_kernel_is_bitwise_its_scalar_reference_and_matches_native() {
    use scatterloc::localize::{crlb_map, crlb_map_scalar};
    let s = presets::sensors2019();
    let m = Model::new(&s).unwrap();
    let grid = Grid::new(s.area_m, 53, 41).unwrap();
    let (mut simd, mut scalar) = (vec![0.0; grid.len()], vec![0.0; grid.len()]);
    crlb_map(&m, &grid, &mut simd).unwrap();
    crlb_map_scalar(&m, &grid, &mut scalar).unwrap();
    assert!(simd
        .iter()
        .zip(&scalar)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    let out = Float64Array::new_with_length(grid.len() as u32);
    ok(sensors().compute_map(53, 41, &out));
    assert!(out
        .to_vec()
        .iter()
        .zip(&simd)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    for (i, j, native) in [
        (0, 0, 2.931801628719025e-1),
        (26, 20, 1.2473021277619423e-2),
        (52, 40, 4.0748922097223345e-1),
        (10, 30, 1.0229857713553472e-1),
    ] {
        let v = simd[j * 53 + i];
        assert!(
            (v / native - 1.0).abs() < 1e-14,
            "cell ({i},{j}): {v:e} vs native {native:e}"
        );
    }
}

/// Unbounded cells are Infinity in the typed array; point queries say `bounded: false` with
/// nulls (never NaN).
#[wasm_bindgen_test]
fn unbounded_is_infinity_and_null() {
    let mut app = sensors();
    for _ in 0..3 {
        ok(app.remove_receiver(1));
    }
    assert_eq!(app.link_count(), 1);
    let out = Float64Array::new_with_length(16 * 16);
    ok(app.compute_map(16, 16, &out));
    assert!(out.to_vec().iter().all(|x| *x == f64::INFINITY));
    let p = ok(app.crlb_at(3.0, 4.0));
    assert_eq!(get(&p, "bounded"), JsValue::FALSE);
    assert!(get(&p, "rmse_m").is_null() && get(&p, "ellipse").is_null());
    assert_eq!(ok(app.rmse_at(3.0, 4.0)), f64::INFINITY);
    let rgba = Uint8ClampedArray::new_with_length(4 * 16 * 16);
    let range = ok(wasm::render_map_rgba(&out, &rgba));
    assert_eq!(range, vec![f64::INFINITY, f64::INFINITY]);
    // One link is too few for a fix: a message, not a trap.
    let f = ok(app.simulate_fix(3.0, 4.0, 1));
    assert!(get(&f, "fix").is_null());
    let why = get(&f, "fix_error").as_string().unwrap();
    assert!(why.contains("at least 3"), "{why}");
}

/// Bad input crosses as an exception with the core's message naming the field; the state is
/// unchanged afterwards.
#[wasm_bindgen_test]
fn errors_are_exceptions_naming_the_field() {
    let good = ok(wasm::preset_json("sensors2019"));
    let m = err(App::new(
        &good.replace("\"bandwidth_hz\": 120000000.0", "\"bandwidth_hz\": -5.0"),
    ));
    assert!(m.contains("radio.bandwidth_hz"), "{m}");
    let m = err(App::new(&good.replace("\"carrier_hz\"", "\"carrier_ghz\"")));
    assert!(m.contains("carrier_ghz"), "{m}");
    let m = err(App::new("{ \"name\": \"broken\", "));
    assert!(m.starts_with("invalid JSON"), "{m}");
    assert!(err(App::from_preset("nope")).contains("unknown preset"));

    let mut app = sensors();
    let before = app.scenario_json();
    for (m, field) in [
        (err(app.set_bandwidth_hz(-1.0)), "radio.bandwidth_hz"),
        (err(app.set_carrier_hz(f64::NAN)), "radio.carrier_hz"),
        (err(app.set_rcs_m2(0.0)), "target.rcs_m2"),
        (err(app.set_noise_figure_db(500.0)), "radio.noise_figure_db"),
        (
            err(app.set_tx_pattern(0, "parabolic", 0.0, -3.0, 20.0)),
            "beamwidth_deg",
        ),
        (
            err(app.set_tx_pattern(0, "cardioid", 0.0, 70.0, 20.0)),
            "pattern.kind",
        ),
        (err(app.move_receiver(9, 1.0, 1.0)), "receivers[9]"),
        (
            err(app.move_transmitter(0, f64::INFINITY, 1.0)),
            "transmitters[0].position_m",
        ),
        (err(app.remove_transmitter(0)), "transmitters"),
        (err(app.crlb_at(f64::NAN, 0.0)), "x"),
        (
            err(app.compute_map(1, 64, &Float64Array::new_with_length(64))),
            "nx",
        ),
        (
            err(app.compute_map(8, 8, &Float64Array::new_with_length(10))),
            "map buffer",
        ),
        (err(app.set_scenario_json("[]")), "invalid JSON"),
    ] {
        assert!(m.contains(field), "message {m:?} should name {field}");
    }
    assert_eq!(
        app.scenario_json(),
        before,
        "rejected edits leave the scenario unchanged"
    );
}

/// Node editing: unique generated names, moves land in the exported JSON.
#[wasm_bindgen_test]
fn node_editing_round_trips_through_json() {
    let mut app = sensors();
    assert_eq!(ok(app.add_receiver(3.0, 4.0)), 4);
    assert_eq!(ok(app.add_transmitter(-1.0, 2.0)), 1);
    ok(app.move_receiver(0, 1.5, -2.25));
    assert_eq!(app.link_count(), 10);
    let s = scatterloc::Scenario::from_json(&app.scenario_json()).unwrap();
    assert_eq!(s.receivers[4].name, "Rx5");
    assert_eq!(s.transmitters[1].name, "Tx1");
    assert_eq!(s.receivers[0].position_m, [1.5, -2.25]);
    ok(app.remove_receiver(0));
    assert_eq!(ok(app.add_receiver(0.0, 0.5)), 4);
    let s = scatterloc::Scenario::from_json(&app.scenario_json()).unwrap();
    assert_eq!(s.receivers[4].name, "Rx1", "smallest free name is reused");
}

/// A simulated snapshot: one iso-delay ellipse per link, a converged LM fix near the truth with
/// a 1σ ellipse, and the CRLB ellipse at the truth.
#[wasm_bindgen_test]
fn simulated_fix_has_ellipses_and_lands_near_truth() {
    let app = sensors();
    let f = ok(app.simulate_fix(6.0, 4.0, 7));
    let links = js_sys::Array::from(&get(&f, "links"));
    assert_eq!(links.length(), 4);
    for l in links.iter() {
        let e = get(&l, "ellipse");
        assert!(num(&e, "a") > num(&e, "b"));
        assert!(num(&l, "sigma_s") > 0.0 && num(&l, "delay_s") > 0.0);
    }
    // The inset arcs pass through the view window around the truth.
    let radius = num(&f, "view_radius_m");
    for l in links.iter() {
        let arc = js_sys::Array::from(&get(&l, "arc"));
        assert_eq!(arc.length(), 48);
        let mid = js_sys::Array::from(&arc.get(24));
        let (dx, dy) = (
            mid.get(0).as_f64().unwrap() - 6.0,
            mid.get(1).as_f64().unwrap() - 4.0,
        );
        assert!((dx * dx + dy * dy).sqrt() < 2.0 * radius);
        assert_eq!(js_sys::Array::from(&get(&l, "outline")).length(), 160);
    }
    let fix = get(&f, "fix");
    assert_eq!(get(&fix, "converged"), JsValue::TRUE);
    let crlb = get(&f, "crlb");
    let rmse = num(&crlb, "rmse_m");
    assert!(num(&fix, "error_m") < 6.0 * rmse, "fix within a few σ");
    assert!(num(&get(&fix, "ellipse"), "a") > 0.0);
    assert!(num(&get(&crlb, "ellipse"), "a") > 0.0);
    assert!(num(&f, "view_radius_m") >= num(&get(&crlb, "ellipse"), "a"));
    // Same seed, same snapshot.
    let again = ok(app.simulate_fix(6.0, 4.0, 7));
    assert_eq!(num(&get(&again, "fix"), "x"), num(&fix, "x"));
}

/// Presentation helpers come from the core.
#[wasm_bindgen_test]
fn labels_and_ticks() {
    assert_eq!(wasm::format_length(0.004258, 3), "4.26 mm");
    assert_eq!(wasm::format_length(f64::INFINITY, 3), "\u{221e}");
    let t = js_sys::Array::from(&ok(wasm::colorbar_ticks(0.003, 0.5, None)));
    assert_eq!(get(&t.get(1), "label").as_string().unwrap(), "1 cm");
    assert_eq!(
        js_sys::Array::from(&ok(wasm::colorbar_ticks(f64::NAN, 1.0, None))).length(),
        0
    );
    // The page's colour bar uses the figures' algorithm: same values and labels, thinned alike.
    for max_labels in [2, 3, 8] {
        let page = js_sys::Array::from(&ok(wasm::colorbar_ticks(1e-4, 3.0, Some(max_labels))));
        let figure = scatterloc::present::colorbar_ticks(1e-4, 3.0, max_labels);
        assert_eq!(page.length() as usize, figure.len());
        for (i, t) in figure.iter().enumerate() {
            let p = page.get(i as u32);
            assert_eq!(get(&p, "label").as_string().unwrap(), t.label);
            assert_eq!(num(&p, "value_m"), t.value);
        }
    }
    assert_eq!(wasm::colorbar_rgba(16).len(), 64);
    let bar = ok(wasm::scale_bar(0.03));
    assert_eq!(num(&bar, "length_m"), 0.02);
}

/// Axis ticks stay few and readable for any span and any requested count (issue 12): a span
/// below the spacing of doubles with a huge count used to overflow the core's `i64` tick
/// indices (a panic in this debug build; labels like ±9223372036854775808 in release).
#[wasm_bindgen_test]
fn axis_ticks_are_bounded() {
    for (lo, hi, n) in [
        (1e3, 1e3 + 1e-13, 100_000),
        (1e3, 1e3 + 1e-13, usize::MAX),
        (-1e7, 1e7, 1_000_000),
        (-1e7, -1e7 + 1e-3, 100_000),
        (-1e308, 1e308, 10),
        (0.0, 10.0, 0),
    ] {
        let t = js_sys::Array::from(&ok(wasm::axis_ticks(lo, hi, n)));
        assert!(
            t.length() as usize <= 2 * wasm::MAX_AXIS_TICKS + 2,
            "{lo} {hi} {n}"
        );
        for v in t.iter() {
            let label = get(&v, "label").as_string().unwrap();
            assert!(
                !label.contains("922337203685477") && label.len() <= 24,
                "{lo} {hi} {n}: {label}"
            );
            let x = num(&v, "value");
            assert!(
                x >= lo - (hi - lo) && x <= hi + (hi - lo),
                "{lo} {hi} {n}: {x}"
            );
        }
    }
}

/// Spec check 12 and the calibration stage in wasm: 1 − erfc(3/√2) = 0.9973, and a calibrated
/// link gates its static paths and keeps the echo (spec §4).
#[wasm_bindgen_test]
fn gating_in_wasm() {
    use scatterloc::track::gating::default_channel;
    use scatterloc::track::gating::{select, AssociationRule, Choice};
    use scatterloc::track::gating::{Calibration, ClusterConfig};
    let p = 1.0 - scatterloc::math::erfc(3.0 / 2f64.sqrt());
    assert!((p - 0.9973).abs() < 5e-5, "{p}");
    let model = Model::new(&presets::sensors2019()).unwrap();
    let ch = default_channel(120e6, 0.0);
    let mut rng = scatterloc::measure::rng(5, 0);
    let cfg = ClusterConfig::for_bandwidth(120e6).unwrap();
    let cal = Calibration::from_snapshots(
        &ch.calibration_snapshots(&model, 200, &mut rng),
        model.link_count(),
        &cfg,
    )
    .unwrap();
    assert!(cal.links.iter().all(|l| l.clusters.len() == 2));
    let r = Vec2::new(20.0, 6.0);
    let snap = ch.snapshot(&model, Some(r), &mut rng);
    let s = select(&cal, &snap, None, AssociationRule::Spec).unwrap();
    for p in 0..model.link_count() {
        let tau = model.network.delay(p, r);
        assert_eq!(s.choices[p], Choice::Single, "link {p}");
        assert!((s.delays[p].unwrap() - tau).abs() < 6.0 * model.sigma_delay(p, r));
    }
}

/// The planner in the browser (issue 14, check 4): the short plan of the native test
/// `plans_depend_on_the_seed_only` (tests/library/planning.rs) through the page's binding gives the same
/// bits; progress is reported per generation, a `false` from the callback cancels, and bad
/// requests are named errors.
#[wasm_bindgen_test]
fn plan_in_wasm_equals_native_and_cancels() {
    use js_sys::Function;
    let scenario = ok(wasm::preset_json("sensors2019"));
    let request = r#"{"move": "Rx2", "objective": "mean", "roi": [-7.5, 30.0, -10.0, 26.0],
        "grid": 8, "budget": 300, "seed": 7}"#;
    let calls = Function::new_with_args(
        "p",
        "globalThis.__planCalls = (globalThis.__planCalls || 0) + 1; return true;",
    );
    let plan = ok(wasm::plan_network(&scenario, request, &calls));
    let rx2 = get(&get(&get(&plan, "scenario"), "receivers"), "1");
    let pos = get(&rx2, "position_m");
    let bits = [num(&pos, "0").to_bits(), num(&pos, "1").to_bits()];
    // tests/library/planning.rs DETERMINISM_RX2_BITS.
    assert_eq!(bits, [0x4021_e4d3_ec16_58ec, 0x4037_c8ac_686a_6934]);
    assert_eq!(num(&plan, "evaluations"), 300.0);
    let calls_made = num(&js_sys::global().into(), "__planCalls");
    assert!(calls_made >= 10.0, "{calls_made} progress calls");
    let objective = get(&plan, "objective");
    assert!(num(&objective, "after") <= num(&objective, "before"));
    let stop = Function::new_with_args("p", "return false;");
    let m = err(wasm::plan_network(&scenario, request, &stop));
    assert!(m.contains("cancelled"), "{m}");
    for (bad, field) in [
        (
            r#"{"move": "Nobody", "objective": "mean", "roi": [0, 1, 0, 1]}"#,
            "Nobody",
        ),
        (
            r#"{"move": "rx", "objective": "p95", "roi": [0, 1, 0, 1]}"#,
            "objective",
        ),
        (
            r#"{"move": "rx", "objective": "mean", "roi": [0, 100, 0, 1]}"#,
            "roi",
        ),
        (r#"{"move": "rx", "objective": "mean"}"#, "roi"),
    ] {
        let m = err(wasm::plan_network(&scenario, bad, &calls));
        assert!(m.contains(field), "{bad}: {m}");
    }
}

/// The limits the page range-checks its own inputs against are the core's (one definition): the
/// URL's track step and the Plan panel's budget and default budget.
#[wasm_bindgen_test]
fn page_field_ranges_are_the_cores() {
    let track: serde_json::Value = serde_json::from_str(&wasm::track_field_ranges()).unwrap();
    assert_eq!(
        track,
        serde_json::json!({ "step": [0, wasm::MAX_TRACK_STEPS] })
    );
    let plan: serde_json::Value = serde_json::from_str(&wasm::plan_field_ranges()).unwrap();
    assert_eq!(
        plan,
        serde_json::json!({
            "budget": [1, scatterloc::plan::MAX_PLAN_BUDGET],
            "default_budget": scatterloc::present::DEFAULT_PLAN_BUDGET,
        })
    );
}
