//! The tracking API in the browser: `App.simulate_track` and its `Track`, the worker-facing
//! `MonteCarloJob` (chunked = one go = the core's `run_sequential`; spec check 5) and the
//! plotters chart on a canvas. Bad input throws the core's message.

use js_sys::{Array, Function, JSON};
use serde_json::{json, Value};
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::*;

use scatterloc::track::ConstantVelocity;
use scatterloc::track::{paper_initial_covariance, TrackScenario, PAPER_INTENSITY};
use scatterloc::track::{run_sequential, MonteCarloConfig};
use scatterloc::wasm::{self, MonteCarloJob};
use scatterloc::{scenario::presets, Model};

use super::{err, get, num, ok, sensors};

/// The `trajectory` of a settings object: `kind` with the prior mean `[x0, y0, vx, vy]` (m,
/// m/s; `custom` only).
fn trajectory(kind: &str, [x0, y0, vx, vy]: [f64; 4]) -> Value {
    json!({ "kind": kind, "x0_m": x0, "y0_m": y0, "vx_mps": vx, "vy_mps": vy })
}

/// `App.simulate_track`'s settings object (JSON text): trajectory II, T = 0.1 s, 100 steps,
/// seed 7, the EKF (1000 particles if `pf`), with the fields of `set` instead.
fn track_settings(set: Value) -> String {
    let mut v = json!({
        "trajectory": trajectory("II", [0.0; 4]),
        "dt_s": 0.1,
        "steps": 100,
        "seed": 7,
        "filter": "ekf",
        "particles": 1000,
    });
    for (key, x) in set.as_object().unwrap() {
        v[key] = x.clone();
    }
    v.to_string()
}

/// `MonteCarloJob`'s settings object (JSON text) of trajectory `kind`, seed 11.
fn study(kind: &str, dt_s: f64, steps: usize, trajectories: usize, noise_runs: usize) -> String {
    json!({
        "trajectory": trajectory(kind, [0.0; 4]),
        "dt_s": dt_s,
        "steps": steps,
        "trajectories": trajectories,
        "noise_runs": noise_runs,
        "seed": 11,
    })
    .to_string()
}

fn len(v: &JsValue) -> u32 {
    Array::from(v).length()
}

fn stringify(v: &JsValue) -> String {
    JSON::stringify(v).unwrap().as_string().unwrap()
}

/// The run has `steps + 1` entries in every series, no measurement at t₀, one iso-delay
/// ellipse per link after; the same seed gives the same run, another seed another one.
#[wasm_bindgen_test]
fn simulate_track_is_deterministic_and_complete() {
    let app = sensors();
    let track = ok(app.simulate_track(&track_settings(json!({}))));
    assert_eq!(track.entries(), 101);
    let d = ok(track.data());
    for key in [
        "t_s",
        "truth",
        "estimates",
        "ellipses",
        "sigma_m",
        "error_m",
        "nis",
        "measurements",
    ] {
        assert_eq!(len(&get(&d, key)), 101, "{key}");
    }
    assert!(get(&d, "failed_at").is_null());
    let meas = Array::from(&get(&d, "measurements"));
    assert_eq!(len(&meas.get(0)), 0);
    assert_eq!(len(&meas.get(1)), 4);
    let truth0 = Array::from(&Array::from(&get(&d, "truth")).get(0));
    let (x, y) = (
        truth0.get(0).as_f64().unwrap(),
        truth0.get(1).as_f64().unwrap(),
    );
    assert!((x + 4.5).hypot(y + 2.0) < 2.0, "II starts near (−4.5, −2)");
    let est = Array::from(&Array::from(&get(&d, "estimates")).get(0));
    assert_eq!(
        est.get(0).as_f64(),
        Some(-4.5),
        "the EKF starts at the prior mean"
    );
    assert_eq!(est.length(), 4);
    // P(t₀) = diag(0.1, 0.1, …): σ = √0.2 m; the filter settles to the cm scale.
    let sig = Array::from(&get(&d, "sigma_m"));
    assert!((sig.get(0).as_f64().unwrap() - 0.2_f64.sqrt()).abs() < 1e-12);
    assert!(sig.get(100).as_f64().unwrap() < 0.05);

    let again = ok(app.simulate_track(&track_settings(json!({}))));
    assert_eq!(stringify(&ok(again.data())), stringify(&d));
    let other = ok(app.simulate_track(&track_settings(json!({ "seed": 8 }))));
    assert_ne!(stringify(&ok(other.data())), stringify(&d));

    // A frame is snapshot-shaped: links with ellipse, outline and arc; the estimate as `fix`.
    let f = ok(track.frame(50));
    assert_eq!(num(&f, "step"), 50.0);
    assert!((num(&f, "t_s") - 5.0).abs() < 1e-12);
    let links = Array::from(&get(&f, "links"));
    assert_eq!(links.length(), 4);
    for l in links.iter() {
        assert!(num(&get(&l, "ellipse"), "a") > 0.0);
        assert_eq!(len(&get(&l, "outline")), 160);
    }
    let fix = get(&f, "fix");
    assert!(num(&get(&fix, "ellipse"), "a") > 0.0);
    assert!(num(&fix, "error_m") < num(&f, "view_radius_m"));
    assert!(get(&fix, "error_label").as_string().is_some());
    assert_eq!(len(&get(&ok(track.frame(0)), "links")), 0);
    assert!(err(track.frame(101)).contains("steps[101]"));
}

/// A drawn trajectory: the prior mean is the drawn start and velocity.
#[wasm_bindgen_test]
fn custom_track_starts_where_drawn() {
    let app = sensors();
    let v = ok(wasm::drag_velocity(2.0, 3.0, 12.0, -2.0, 10.0));
    assert_eq!(v, vec![1.0, -0.5]);
    let t = ok(app.simulate_track(&track_settings(json!({
        "trajectory": trajectory("custom", [2.0, 3.0, v[0], v[1]]),
        "dt_s": 0.05,
        "steps": 40,
        "seed": 1,
    }))));
    assert_eq!(t.entries(), 41);
    let e = Array::from(&Array::from(&get(&ok(t.data()), "estimates")).get(0));
    let e: Vec<f64> = e.iter().map(|x| x.as_f64().unwrap()).collect();
    assert_eq!(e, vec![2.0, 3.0, 1.0, -0.5]);
    assert_eq!(ok(wasm::track_steps(10.0, 0.1)), 100);
    assert_eq!(ok(wasm::track_steps(10.0, 2.048e-3)), 4883);
}

/// Bad input to the tracking API throws the core's message naming the field.
#[wasm_bindgen_test]
fn tracking_errors_are_exceptions() {
    let app = sensors();
    let sim = |kind: &str, vx: f64, dt: f64, steps: usize| {
        app.simulate_track(&track_settings(json!({
            "trajectory": trajectory(kind, [1.0, 2.0, vx, 0.5]),
            "dt_s": dt,
            "steps": steps,
            "seed": 1,
        })))
        .map(|_| ())
    };
    let filter = |name: &str, particles: usize, steps: usize| {
        app.simulate_track(&track_settings(json!({
            "trajectory": trajectory("I", [0.0; 4]),
            "steps": steps,
            "seed": 1,
            "filter": name,
            "particles": particles,
        })))
        .map(|_| ())
    };
    for (m, field) in [
        (err(sim("IV", 1.0, 0.1, 100)), "trajectory \"IV\""),
        (err(sim("custom", f64::NAN, 0.1, 100)), "vx"),
        (err(sim("I", 1.0, 0.0, 100)), "dt_s"),
        (err(sim("I", 1.0, f64::INFINITY, 100)), "dt_s"),
        (err(sim("I", 1.0, 0.1, 0)), "steps"),
        (err(sim("I", 1.0, 0.1, 10_001)), "steps: 10001 is outside"),
        (
            err(wasm::drag_velocity(0.0, 0.0, 1.0, 1.0, 0.0)),
            "duration_s",
        ),
        (err(wasm::drag_velocity(0.0, f64::NAN, 1.0, 1.0, 1.0)), "y0"),
        (err(wasm::track_steps(1e9, 1e-3)), "steps"),
        (err(wasm::track_steps(10.0, -1.0)), "dt_s"),
        (
            err(filter("kf", 1000, 100)),
            "filter: unknown filter \"kf\"",
        ),
        (err(filter("pf", 0, 100)), "particles: 0"),
        (err(filter("pf", 2_000_000, 100)), "particles"),
        (err(filter("pf", 5000, 10_000)), "particles × steps"),
    ] {
        assert!(m.contains(field), "message {m:?} should name {field}");
    }
}

fn job(
    kind: &str,
    steps: usize,
    trajectories: usize,
    noise: usize,
) -> Result<MonteCarloJob, wasm_bindgen::JsError> {
    let scenario = ok(wasm::preset_json("sensors2019"));
    MonteCarloJob::new(&scenario, &study(kind, 0.1, steps, trajectories, noise))
}

/// The native model and study of [`job`]`("II", …)`.
fn native_study(steps: usize, trajectories: usize, noise: usize) -> (Model, MonteCarloConfig) {
    let cfg = MonteCarloConfig {
        motion: ConstantVelocity::new(0.1, PAPER_INTENSITY),
        steps,
        mean_state: TrackScenario::II.mean_state(),
        initial_covariance: paper_initial_covariance(),
        trajectories,
        noise_runs: noise,
        seed: 11,
        oracle_noise: false,
    };
    (Model::new(&presets::sensors2019()).unwrap(), cfg)
}

fn parse(s: &str) -> Value {
    serde_json::from_str(s).expect("result_json is JSON")
}

/// Chunk by chunk equals one go equals the core's `run_sequential` (what the CLI runs), to
/// the bit; ε_PCRLB(t₀) = √(0.1 + 0.1) = 0.4472 m (spec check 5).
#[wasm_bindgen_test]
fn monte_carlo_job_chunked_equals_one_go_and_core() {
    let (steps, trajectories, noise) = (30, 40, 2);
    let mut a = ok(job("II", steps, trajectories, noise));
    assert_eq!((a.chunk_count(), a.runs(), a.chunks_done()), (3, 80, 0));
    assert!(err(a.result_json()).contains("runs"), "nothing has run yet");
    assert!(!ok(a.run_chunks(1)));
    let partial = parse(&ok(a.result_json()));
    assert_eq!(partial["done"], Value::Bool(false));
    assert_eq!(partial["runs"], 32);
    while !ok(a.run_chunks(1)) {}
    assert!(a.is_done() && ok(a.run_chunks(5)));
    let mut b = ok(job("II", steps, trajectories, noise));
    assert!(ok(b.run_chunks(100)));
    let (ra, rb) = (ok(a.result_json()), ok(b.result_json()));
    assert_eq!(ra, rb);
    let r = parse(&ra);
    assert_eq!(r["runs"], 80);
    assert_eq!(r["failed_runs"], 0);
    assert_eq!(r["done"], Value::Bool(true));

    let (model, cfg) = native_study(steps, trajectories, noise);
    let native = run_sequential(&model, &cfg, |_, _| true).unwrap();
    let floats = |v: &Value| -> Vec<Option<f64>> {
        v.as_array().unwrap().iter().map(Value::as_f64).collect()
    };
    let some = |v: &[f64]| v.iter().map(|x| Some(*x)).collect::<Vec<_>>();
    assert_eq!(floats(&r["t_s"]), some(&native.t_s));
    assert_eq!(floats(&r["rmse_ekf_m"]), some(&native.rmse_m));
    assert_eq!(floats(&r["rmse_pcrlb_m"]), native.rmse_pcrlb_m);
    assert_eq!(floats(&r["nees"]), some(&native.nees));
    let p0 = r["rmse_pcrlb_m"][0].as_f64().unwrap();
    assert!((p0 - 0.4472).abs() < 5e-5, "check 5: {p0}");
    assert_eq!(r["rmse_ekf_m"].as_array().unwrap().len(), steps + 1);
}

/// Bad counts and inputs are exceptions with the core's message; nothing traps.
#[wasm_bindgen_test]
fn monte_carlo_job_rejects_bad_input() {
    let e = |r: Result<MonteCarloJob, wasm_bindgen::JsError>| err(r.map(|_| ()));
    for (m, field) in [
        (e(job("I", 100, 0, 1)), "runs: 0"),
        (e(job("I", 100, 10, 0)), "noise_runs: 0"),
        (e(job("I", 0, 10, 1)), "steps: 0"),
        (e(job("I", 20_000, 10, 1)), "steps: 20000"),
        (e(job("I", 100, 20_000_000, 1)), "runs"),
        (e(job("V", 100, 10, 1)), "trajectory"),
        (
            e(MonteCarloJob::new("{", &study("I", 0.1, 10, 1, 1))),
            "invalid JSON",
        ),
        (
            e(MonteCarloJob::new(
                &ok(wasm::preset_json("sensors2019")),
                &study("I", -0.1, 10, 1, 1),
            )),
            "dt_s",
        ),
    ] {
        assert!(m.contains(field), "message {m:?} should name {field}");
    }
}

/// The plotters chart lands on a canvas in both series' colours and reports two curves; empty
/// input draws axes only; malformed JSON throws.
#[wasm_bindgen_test]
fn chart_draws_both_curves_on_a_canvas() {
    let mut j = ok(job("I", 40, 16, 1));
    ok(j.run_chunks(1));
    let result = ok(j.result_json());
    let make = Function::new_no_args(
        "const c = document.createElement('canvas'); c.width = 1000; c.height = 620; return c;",
    );
    let canvas = make.call0(&JsValue::NULL).unwrap();
    let html = canvas.clone().dyn_into().unwrap();
    let n = ok(wasm::draw_tracking_chart(
        html,
        &result,
        "RMSE",
        "16 runs",
        "Scenario I",
    ));
    assert_eq!(n, 2);
    // Pixels close to the EKF blue (0, 114, 178) and the PCRLB vermillion (213, 94, 0).
    let count = Function::new_with_args(
        "c, r, g, b",
        "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; let n = 0; \
         for (let i = 0; i < d.length; i += 4) \
           if (Math.abs(d[i] - r) + Math.abs(d[i + 1] - g) + Math.abs(d[i + 2] - b) < 40) n++; \
         return n;",
    );
    let px = |rgb: [f64; 3]| {
        let args = Array::of4(&canvas, &rgb[0].into(), &rgb[1].into(), &rgb[2].into());
        count
            .apply(&JsValue::NULL, &args)
            .unwrap()
            .as_f64()
            .unwrap()
    };
    let (blue, red) = (px([0.0, 114.0, 178.0]), px([213.0, 94.0, 0.0]));
    assert!(
        blue > 200.0 && red > 200.0,
        "curve pixels: EKF {blue}, PCRLB {red}"
    );
    let empty = canvas.clone().dyn_into().unwrap();
    assert_eq!(ok(wasm::draw_tracking_chart(empty, "", "RMSE", "", "–")), 0);
    // Degenerate canvas sizes draw what fits; nothing traps.
    let sized = Function::new_with_args(
        "w, h",
        "const c = document.createElement('canvas'); c.width = w; c.height = h; return c;",
    );
    for (w, h) in [(0, 0), (1, 1), (40, 2000), (300, 3)] {
        let tiny = sized.call2(&JsValue::NULL, &w.into(), &h.into()).unwrap();
        ok(wasm::draw_tracking_chart(
            tiny.dyn_into().unwrap(),
            &result,
            "RMSE",
            "",
            "I",
        ));
    }
    let bad = canvas.dyn_into().unwrap();
    assert!(
        err(wasm::draw_tracking_chart(bad, "{\"t_s\": [1", "", "", "")).contains("invalid JSON")
    );
}

/// The UKF and the particle filter animate like the EKF: the same truth and delays for one
/// seed, their own estimates, a 1σ ellipse at every step, and `filter`/`particles` in the data.
#[wasm_bindgen_test]
fn simulate_track_runs_every_filter_on_the_same_data() {
    let app = sensors();
    let run = |name: &str| {
        let t =
            ok(app.simulate_track(&track_settings(json!({ "filter": name, "particles": 500 }))));
        parse(&stringify(&ok(t.data())))
    };
    let (ekf, ukf, pf) = (run("ekf"), run("ukf"), run("pf"));
    for (name, d) in [("ekf", &ekf), ("ukf", &ukf), ("pf", &pf)] {
        assert_eq!(d["filter"], name);
        assert_eq!(d["truth"], ekf["truth"], "{name}");
        assert_eq!(d["measurements"], ekf["measurements"], "{name}");
        assert!(d["failed_at"].is_null(), "{name}");
        let ellipses = d["ellipses"].as_array().unwrap();
        assert!(
            ellipses.iter().all(|e| !e.is_null()),
            "{name}: a 1σ ellipse per step"
        );
        // Every filter settles to the cm scale (σ √(Pxx+Pyy) at the end below 5 cm).
        assert!(d["sigma_m"][100].as_f64().unwrap() < 0.05, "{name}");
    }
    assert_eq!(
        (&pf["particles"], &ekf["particles"]),
        (&Value::from(500), &Value::Null)
    );
    assert_ne!(ukf["estimates"], ekf["estimates"]);
    assert_ne!(pf["estimates"], ekf["estimates"]);
}

/// Several filters in one job: each filter's curves equal the core's chunks
/// ([`run_filter_chunk`], what the CLI's `montecarlo --filters` runs) to the bit; the particle
/// filter runs only the leading chunks its budget allows; the top level is the EKF's. Bad
/// filter lists throw, and so does a change after the first chunk.
#[wasm_bindgen_test]
fn monte_carlo_job_runs_several_filters() {
    use scatterloc::track::{finish, run_filter_chunk, FilterKind, PfConfig, StudySums};
    let (steps, trajectories) = (20, 40);
    let mut j = ok(job("II", steps, trajectories, 1));
    // 2 chunks' worth of PF runs: 32 runs × 20 steps × 300 particles = 192 000 particle-steps.
    ok(j.set_filters("ekf, ukf,pf", 300, 200_000));
    assert_eq!(j.chunk_count(), 3 + 3 + 2);
    let mut first = true;
    while !ok(j.run_chunks(1)) {
        if first {
            first = false;
            assert!(err(j.set_filters("ekf", 300, 1)).contains("started"));
        }
    }
    let text = ok(j.result_json());
    let r = parse(&text);
    assert_eq!(r["done"], Value::Bool(true));
    // The chart draws one curve per filter and the PCRLB.
    let make = Function::new_with_args(
        "w, h",
        "const c = document.createElement('canvas'); c.width = w; c.height = h; return c;",
    );
    let canvas = make
        .call2(&JsValue::NULL, &600.into(), &400.into())
        .unwrap();
    let n = ok(wasm::draw_tracking_chart(
        canvas.dyn_into().unwrap(),
        &text,
        "RMSE",
        "",
        "II",
    ));
    assert_eq!(n, 4);
    assert_eq!(
        (r["particles"].as_u64(), r["particle_budget"].as_u64()),
        (Some(300), Some(200_000))
    );
    let (model, cfg) = native_study(steps, trajectories, 1);
    let pf = FilterKind::Pf(PfConfig {
        particles: 300,
        roughening: None,
        regularized: true,
    });
    for (name, kind, chunks, planned) in [
        ("ekf", FilterKind::Ekf, 3, 40),
        ("ukf", FilterKind::Ukf(Default::default()), 3, 40),
        ("pf", pf, 2, 32),
    ] {
        let mut sums = StudySums::new(steps);
        for c in 0..chunks {
            sums.add(&run_filter_chunk(&model, &cfg, kind, c).unwrap());
        }
        let native = finish(&cfg, &sums).unwrap();
        let f = &r["filters"][name];
        assert_eq!(f["runs"].as_u64(), Some(native.runs as u64), "{name}");
        assert_eq!(
            (f["chunk_count"].as_u64(), f["runs_planned"].as_u64()),
            (Some(chunks as u64), Some(planned))
        );
        let v: Vec<f64> = f["rmse_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(v, native.rmse_m, "{name}");
        let v: Vec<f64> = f["nees"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(v, native.nees, "{name}");
    }
    assert_eq!(r["rmse_ekf_m"], r["filters"]["ekf"]["rmse_m"]);

    // Without the EKF the top level is the first filter's; a budget below one chunk still
    // runs one chunk.
    let mut j = ok(job("II", steps, trajectories, 1));
    ok(j.set_filters("pf", 300, 1));
    assert_eq!(j.chunk_count(), 1);
    assert!(ok(j.run_chunks(5)));
    let r = parse(&ok(j.result_json()));
    assert_eq!(r["rmse_ekf_m"], r["filters"]["pf"]["rmse_m"]);
    assert_eq!(r["filters"]["pf"]["runs_planned"], 16);

    for (list, particles, msg) in [
        ("ekf,kf", 100, "filters[1]: unknown filter \"kf\""),
        ("ekf,ekf", 100, "filters[1]"),
        ("", 100, "filters[0]: unknown filter"),
        ("pf", 0, "particles: 0"),
        ("ukf,pf", 2_000_000, "particles"),
    ] {
        let mut j = ok(job("II", steps, trajectories, 1));
        let m = err(j.set_filters(list, particles, 1_000_000));
        assert!(m.contains(msg), "{list}: {m}");
    }
}
