//! End-to-end tests of the `track` and `pcrlb` subcommands of the `scatterloc` binary (issue 3
//! §3): the EKF over a measurement file (spec §6) with gaps and bad input, the nominal PCRLB
//! (§8, check 9) and the Monte Carlo bound, and bad study flags. `montecarlo`: cli/montecarlo.rs.
#![cfg(not(target_arch = "wasm32"))]

use crate::common;

use scatterloc::{scenario::presets, Model, Vec2};
use serde_json::{json, Value};

use common::cli::{fails, floats, ok_json_line, read_json, run, TempDir};

/// A straight path from (4, 1) at (1.4, 0.25) m/s sampled every 0.1 s.
fn truth(n: usize) -> Vec2 {
    Vec2::new(4.0, 1.0) + (n as f64 * 0.1) * Vec2::new(1.4, 0.25)
}

/// A measurements file with noise-free delays from the core for steps 1..=50; link 1 is
/// missing at step 20 and every link at step 30.
fn measurements(extra: Value) -> Value {
    let model = Model::new(&presets::sensors2019()).unwrap();
    let steps: Vec<Value> = (1..=50)
        .map(|n| {
            let d = model.network.delays(truth(n));
            let row: Vec<Value> = d
                .iter()
                .enumerate()
                .map(|(p, d)| match (n, p) {
                    (30, _) | (20, 1) => Value::Null,
                    _ => json!(d),
                })
                .collect();
            json!(row)
        })
        .collect();
    let mut m = json!({
        "dt_s": 0.1, "process_noise": 0.01, "initial_state": [4.3, 0.8, 1.3, 0.3],
        "initial_covariance": [[0.1, 0, 0, 0], [0, 0.1, 0, 0], [0, 0, 0.01, 0], [0, 0, 0, 0.01]],
        "steps": steps,
    });
    for (k, v) in extra.as_object().unwrap() {
        m[k] = v.clone();
    }
    m
}

fn scenario(dir: &TempDir) -> String {
    dir.write(
        "s.json",
        &serde_json::from_str(&presets::sensors2019().to_json()).unwrap(),
    )
}

#[test]
fn track_follows_a_straight_path_through_gaps() {
    let dir = TempDir::new();
    let s = scenario(&dir);
    for extra in [json!({}), json!({"sigma_s": 3e-11})] {
        let m = dir.write("m.json", &measurements(extra));
        let v = ok_json_line(&["track", "--scenario", &s, "--measurements", &m]);
        let states = v["states"].as_array().unwrap();
        assert_eq!(states.len(), 50);
        assert_eq!(v["covariances"].as_array().unwrap().len(), 50);
        assert!((floats(&v["t_s"])[49] - 5.0).abs() < 1e-12);
        let err = |k: usize| {
            let x = floats(&states[k]);
            (Vec2::new(x[0], x[1]) - truth(k + 1)).norm()
        };
        assert!(
            err(0) < 0.3 && err(9) < 1e-3 && err(49) < 1e-6,
            "{}",
            err(49)
        );
        let used: Vec<u64> = v["links_used"]
            .as_array()
            .unwrap()
            .iter()
            .map(|u| u.as_u64().unwrap())
            .collect();
        assert_eq!((used[0], used[19], used[29]), (4, 3, 0));
        // All links missing: predict only (x ← A x, trace of P grows) and no NIS.
        assert_eq!(v["nis"][29], Value::Null);
        assert!(v["nis"][28].as_f64().unwrap() >= 0.0);
        let (a, b) = (floats(&states[28]), floats(&states[29]));
        assert!((b[0] - (a[0] + 0.1 * a[2])).abs() < 1e-12 && b[2] == a[2]);
        let trace = |k: usize| {
            (0..4)
                .map(|i| v["covariances"][k][i][i].as_f64().unwrap())
                .sum::<f64>()
        };
        assert!(trace(29) > trace(28) && trace(30) < trace(29));
    }
}

#[test]
fn track_rejects_bad_input_naming_the_field() {
    let dir = TempDir::new();
    let s = scenario(&dir);
    let good = measurements(json!({}));
    let mut cases: Vec<(String, &str)> = vec![
        (
            good.to_string().replacen("[4.3,", "[1e999,", 1),
            "initial_state",
        ),
        (measurements(json!({"dt_s": 0.0})).to_string(), "dt_s"),
        (
            measurements(json!({"process_noise": -1.0})).to_string(),
            "process_noise",
        ),
        (
            measurements(json!({"sigma_s": [1e-11, 0, 1e-11, 1e-11]})).to_string(),
            "sigma_s[1]",
        ),
        (
            measurements(json!({"sigma_s": [1e-11]})).to_string(),
            "sigma_s",
        ),
        (measurements(json!({"colour": 1})).to_string(), "colour"),
    ];
    let mut m = good.clone();
    m["initial_covariance"][1][1] = json!(-0.1);
    cases.push((m.to_string(), "initial_covariance"));
    let mut m = good.clone();
    m["steps"][3] = json!([1e-7, 1e-7]);
    cases.push((m.to_string(), "steps[3]"));
    // A delay that is not a propagation delay is named by step and link (issue 12, item 7).
    for bad in [json!(-4.5e-8), json!(0.0), json!(1e308)] {
        let mut m = good.clone();
        m["steps"][2][1] = bad;
        cases.push((m.to_string(), "steps[2][1]: "));
    }
    let mut m = good.clone();
    m.as_object_mut().unwrap().remove("steps");
    cases.push((m.to_string(), "steps"));
    for (text, field) in cases {
        let path = dir.path("bad.json");
        std::fs::write(&path, text).unwrap();
        fails(
            &["track", "--scenario", &s, "--measurements", &path],
            &[field, "--measurements"],
        );
    }
    fails(&["track", "--scenario", &s], &["--measurements"]);
}

#[test]
fn pcrlb_nominal_reproduces_check_9() {
    let dir = TempDir::new();
    let js = dir.path("p.json");
    let v = ok_json_line(&[
        "pcrlb",
        "--trajectory",
        "II",
        "--nominal",
        "--dt",
        "0.1",
        "--json",
        &js,
    ]);
    let doc = read_json(&js);
    assert_eq!(
        (doc["nominal"].clone(), doc["trajectory"].clone()),
        (json!(true), json!("II"))
    );
    let rmse = floats(&doc["rmse_pcrlb_m"]);
    assert_eq!(rmse.len(), 101);
    assert!((rmse[0] - 0.2f64.sqrt()).abs() < 1e-12);
    for (k, cm) in [2.9315, 3.1668, 2.2581, 1.7823].iter().enumerate() {
        let at = &v["at"][k];
        assert_eq!(at["t_s"].as_f64().unwrap(), [1.0, 2.0, 5.0, 10.0][k]);
        let got = at["rmse_pcrlb_m"].as_f64().unwrap() * 100.0;
        assert!((got / cm - 1.0).abs() < 1e-3, "{got} cm vs {cm}");
        assert_eq!(
            at["rmse_pcrlb_m"].as_f64(),
            Some(rmse[[10, 20, 50, 100][k]])
        );
    }
    // Without --json the curve goes to stdout.
    let out = ok_json_line(&["pcrlb", "--trajectory", "II", "--nominal", "--dt", "0.1"]);
    assert_eq!(out["rmse_pcrlb_m"], doc["rmse_pcrlb_m"]);
}

#[test]
fn pcrlb_monte_carlo_is_the_bound_of_montecarlo() {
    // E[F̃] depends on the truth trajectories only, not on the noise runs (spec §8).
    let common = ["--trajectory", "III", "--runs", "32", "--seed", "5"];
    let common = [&common[..], &["--dt", "0.1"]].concat();
    let p = ok_json_line(&[&["pcrlb"][..], &common[..]].concat());
    let mut args = vec!["montecarlo", "--noise-runs", "3"];
    args.extend(&common);
    let m = ok_json_line(&args);
    assert_eq!(p["nominal"], json!(false));
    // Without --json and --out both print their whole curves.
    assert_eq!(p["rmse_pcrlb_m"].as_array().unwrap().len(), 101);
    assert_eq!(p["rmse_pcrlb_m"], m["rmse_pcrlb_m"]);
    assert_eq!(m["rmse_ekf_m"].as_array().unwrap().len(), 101);
}

#[test]
fn studies_reject_bad_flags() {
    let dir = TempDir::new();
    let bad_dir = dir.path("missing/x.png");
    let cases: [(&[&str], &str); 14] = [
        (&["montecarlo", "--trajectory", "IV"], "--trajectory"),
        (&["montecarlo", "--runs", "0"], "--runs"),
        (
            &["montecarlo", "--runs", "100000", "--noise-runs", "200"],
            "--runs",
        ),
        (&["montecarlo", "--noise-runs", "0"], "--noise-runs"),
        (&["montecarlo", "--runs", "ten"], "--runs"),
        (&["montecarlo", "--dt", "0"], "--dt"),
        (&["montecarlo", "--duration", "-1"], "--duration"),
        (
            &["montecarlo", "--dt", "1e-6", "--duration", "10"],
            "--duration",
        ),
        (&["montecarlo", "--threads", "1000"], "--threads"),
        (&["montecarlo", "--json", "out.txt"], "--json"),
        (&["montecarlo", "--out", &bad_dir], "--out"),
        (&["montecarlo", "--oracle-noise=yes"], "--oracle-noise"),
        (&["pcrlb", "--nominal", "--seed", "3"], "--seed"),
        (&["pcrlb", "--preset", "nope"], "--preset"),
    ];
    for (args, needle) in cases {
        fails(args, &[needle]);
    }
    assert!(dir.files().is_empty());
    let help = String::from_utf8(run(&["help"]).stdout).unwrap();
    assert!(["track --scenario", "montecarlo", "pcrlb --nominal"]
        .iter()
        .all(|w| help.contains(w)));
}
