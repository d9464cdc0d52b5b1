//! End-to-end tests of the trackers on the command line (issue 15): `track --filter ekf|ukf|pf`
//! (same output shape, the UKF close to the EKF on an easy path, raw_steps refused), and
//! `montecarlo --filters` (every filter's curves, the EKF's equal to the single-filter run's,
//! determinism, bad flags named, two shards merged equal to the unsharded run, Ctrl-C).
#![cfg(not(target_arch = "wasm32"))]

use crate::common;

use scatterloc::{scenario::presets, Model, Vec2};
use serde_json::{json, Value};

use std::process::Command;

use common::cli::{fails, floats, interrupted, ok_json, ok_json_line, read_json, TempDir, BIN};

/// A straight path from (4, 1) at (1.4, 0.25) m/s sampled every 0.1 s.
fn truth(n: usize) -> Vec2 {
    Vec2::new(4.0, 1.0) + (n as f64 * 0.1) * Vec2::new(1.4, 0.25)
}

/// Noise-free delays of 20 steps (link 1 missing at step 10), fixed σ.
fn measurements() -> Value {
    let model = Model::new(&presets::sensors2019()).unwrap();
    let steps: Vec<Value> = (1..=20)
        .map(|n| {
            let d = model.network.delays(truth(n));
            let row: Vec<Value> = d
                .iter()
                .enumerate()
                .map(|(p, d)| {
                    if (n, p) == (10, 1) {
                        Value::Null
                    } else {
                        json!(d)
                    }
                })
                .collect();
            json!(row)
        })
        .collect();
    json!({
        "dt_s": 0.1, "process_noise": 0.01, "initial_state": [4.1, 0.95, 1.4, 0.25],
        "initial_covariance": [[0.01, 0, 0, 0], [0, 0.01, 0, 0], [0, 0, 0.01, 0], [0, 0, 0, 0.01]],
        "sigma_s": 3e-11,
        "steps": steps,
    })
}

/// Scenario and measurements files in `dir`.
fn files(dir: &TempDir) -> (String, String) {
    let s = dir.write(
        "s.json",
        &serde_json::from_str(&presets::sensors2019().to_json()).unwrap(),
    );
    (s, dir.write("m.json", &measurements()))
}

fn keys(v: &Value) -> Vec<String> {
    v.as_object().unwrap().keys().cloned().collect()
}

#[test]
fn track_runs_every_filter_with_the_same_output_shape() {
    let dir = TempDir::new();
    let (s, m) = files(&dir);
    let base = ["track", "--scenario", &s, "--measurements", &m];
    let ekf = ok_json_line(&base);
    let explicit = ok_json_line(&[&base[..], &["--filter", "ekf"]].concat());
    assert_eq!(ekf, explicit, "--filter ekf is the default");
    let ukf = ok_json_line(&[&base[..], &["--filter", "ukf"]].concat());
    let pf = ok_json_line(
        &[
            &base[..],
            &["--filter", "pf", "--particles", "2000", "--seed", "3"],
        ]
        .concat(),
    );
    for v in [&ukf, &pf] {
        assert_eq!(keys(v), keys(&ekf));
        assert_eq!(v["t_s"], ekf["t_s"]);
        assert_eq!(v["links_used"], ekf["links_used"]);
        assert_eq!(v["states"].as_array().unwrap().len(), 20);
        for k in 0..20 {
            assert!(floats(&v["states"][k]).iter().all(|x| x.is_finite()));
            for row in v["covariances"][k].as_array().unwrap() {
                assert!(floats(row).iter().all(|x| x.is_finite()));
            }
        }
    }
    // Easy case: the UKF within 1 mm of the EKF at every step, and on the path at the end.
    for k in 0..20 {
        let (a, b) = (floats(&ekf["states"][k]), floats(&ukf["states"][k]));
        let d = Vec2::new(a[0] - b[0], a[1] - b[1]).norm();
        assert!(d < 1e-3, "step {k}: {d}");
    }
    let x = floats(&pf["states"][19]);
    let err = (Vec2::new(x[0], x[1]) - truth(20)).norm();
    assert!(err < 0.05, "pf error {err}");
    // Same seed, same particles; the seed matters.
    let again = ok_json_line(
        &[
            &base[..],
            &["--filter", "pf", "--particles", "2000", "--seed", "3"],
        ]
        .concat(),
    );
    assert_eq!(pf, again);
    let other = ok_json_line(
        &[
            &base[..],
            &["--filter", "pf", "--particles", "2000", "--seed", "4"],
        ]
        .concat(),
    );
    assert_ne!(pf["states"], other["states"]);
}

#[test]
fn track_rejects_bad_filter_flags_naming_them() {
    let dir = TempDir::new();
    let (s, m) = files(&dir);
    let base = ["track", "--scenario", &s, "--measurements", &m];
    let cases: [(&[&str], &[&str]); 8] = [
        (&["--filter", "kf"], &["--filter"]),
        (&["--filter", "pf", "--particles", "0"], &["--particles"]),
        (
            &["--filter", "pf", "--particles", "1000001"],
            &["--particles"],
        ),
        (&["--filter", "ukf", "--ukf-alpha", "0"], &["--ukf-alpha"]),
        (&["--filter", "ukf", "--ukf-kappa", "-4"], &["--ukf-kappa"]),
        (&["--particles", "10"], &["--particles", "pf"]),
        (&["--filter", "ukf", "--seed", "2"], &["--seed"]),
        (
            &["--filter", "pf", "--ukf-beta", "1"],
            &["--ukf-beta", "ukf"],
        ),
    ];
    for (extra, needles) in cases {
        fails(&[&base[..], extra].concat(), needles);
    }
    // raw_steps: gated with any filter (issue 23; tests/gating.rs tracks the §9.6 stand-in).
    let mut raw = measurements();
    let o = raw.as_object_mut().unwrap();
    o.remove("steps");
    o.insert("raw_steps".into(), json!([[[[1e-8, 1.0]], [], [], []]]));
    let r = dir.write("raw.json", &raw);
    for filter in ["ukf", "pf"] {
        let v = ok_json(&[
            "track",
            "--scenario",
            &s,
            "--measurements",
            &r,
            "--filter",
            filter,
        ]);
        assert_eq!(v["links_used"], json!([1]), "{filter}: {v}");
    }
}

/// A tiny study: scenario I, 16 trajectories × 2 noise runs, 20 steps.
const TINY: [&str; 10] = [
    "montecarlo",
    "--trajectory",
    "I",
    "--runs",
    "16",
    "--noise-runs",
    "2",
    "--dt",
    "0.1",
    "--duration",
];

fn tiny(extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = TINY.iter().map(|s| s.to_string()).collect();
    a.push("2".into());
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn refs(a: &[String]) -> Vec<&str> {
    a.iter().map(|s| s.as_str()).collect()
}

/// The document without its timing fields.
fn untimed(mut v: Value) -> Value {
    let o = v.as_object_mut().unwrap();
    for k in ["wall_time_s", "ns_per_ekf_step", "wall_ns_per_ekf_step"] {
        o.remove(k);
    }
    v
}

#[test]
fn montecarlo_runs_every_filter_on_the_same_data() {
    let three = tiny(&["--filters", "ekf,ukf,pf", "--particles", "200"]);
    let v = ok_json(&refs(&three));
    let single = ok_json(&refs(&tiny(&[])));
    assert!(single.get("filters").is_none(), "ekf alone: no 'filters'");
    let f = &v["filters"];
    assert_eq!(keys(f).len(), 3);
    for name in ["ekf", "ukf", "pf"] {
        let c = &f[name];
        assert_eq!(c["rmse_m"].as_array().unwrap().len(), 21, "{name}");
        assert_eq!(c["nees"].as_array().unwrap().len(), 21, "{name}");
        assert_eq!(
            c["runs"].as_u64().unwrap() + c["failed_runs"].as_u64().unwrap(),
            32
        );
    }
    // Every counted filter's curves are finite.
    for name in ["ekf", "ukf"] {
        assert!(floats(&f[name]["rmse_m"]).iter().all(|x| x.is_finite()));
        assert_eq!(f[name]["runs"], 32);
    }
    if f["pf"]["runs"].as_u64().unwrap() > 0 {
        assert!(floats(&f["pf"]["rmse_m"]).iter().all(|x| x.is_finite()));
    }
    // The EKF's curve is the single-filter run's, bitwise (and kept at the top level).
    let bits = |v: &Value| -> Vec<u64> { floats(v).iter().map(|x| x.to_bits()).collect() };
    assert_eq!(bits(&f["ekf"]["rmse_m"]), bits(&single["rmse_ekf_m"]));
    assert_eq!(bits(&f["ekf"]["nees"]), bits(&single["nees"]));
    assert_eq!(v["rmse_ekf_m"], single["rmse_ekf_m"]);
    assert_eq!(v["rmse_pcrlb_m"], single["rmse_pcrlb_m"]);
    assert_eq!(v["t_s"], single["t_s"]);
    // The UKF within 10 % of the EKF on this easy study.
    let (e, u) = (floats(&f["ekf"]["rmse_m"]), floats(&f["ukf"]["rmse_m"]));
    assert!(
        (u[20] - e[20]).abs() < 0.1 * e[20],
        "{} vs {}",
        u[20],
        e[20]
    );
    // Determinism: same seed, same results.
    assert_eq!(untimed(ok_json(&refs(&three))), untimed(v));
}

#[test]
fn montecarlo_multi_filter_files_and_figure() {
    let dir = TempDir::new();
    let (js, svg) = (dir.path("mc.json"), dir.path("fig.svg"));
    let a = tiny(&[
        "--filters",
        "ukf,ekf",
        "--ukf-alpha",
        "0.5",
        "--json",
        &js,
        "--out",
        &svg,
    ]);
    let summary = ok_json_line(&refs(&a));
    assert_eq!(summary["trajectory"], "I");
    let v = read_json(&js);
    assert_eq!(keys(&v["filters"]).len(), 2);
    // In the order asked.
    let raw = std::fs::read_to_string(&js).unwrap();
    assert!(raw.find("\"ukf\":{").unwrap() < raw.find("\"ekf\":{").unwrap());
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("Scenario I"));
    for label in ["UKF RMSE", "EKF RMSE", "UKF, EKF vs posterior CRLB"] {
        assert!(text.contains(label), "{label}");
    }
    // Each legend label gives the filter's failed runs; the legend says what "failed" means.
    for (name, f) in [("EKF", "ekf"), ("UKF", "ukf")] {
        let d = &v["filters"][f];
        let n = d["runs"].as_u64().unwrap() + d["failed_runs"].as_u64().unwrap();
        let label = format!("{name} RMSE ({}/{n} failed)", d["failed_runs"]);
        assert!(text.contains(&label), "{label}");
    }
    assert!(text.contains(scatterloc::study::FAILED_NOTE));
    // ukf alone: no EKF curve at the top level.
    let u = ok_json(&refs(&tiny(&["--filters", "ukf"])));
    assert!(u.get("rmse_ekf_m").is_none() && u.get("nees").is_none());
    assert_eq!(keys(&u["filters"]), ["ukf"]);
}

#[test]
fn montecarlo_rejects_bad_filter_flags_naming_them() {
    let cases: [(&[&str], &[&str]); 7] = [
        (&["--filters", "ekf,kf"], &["--filters", "kf"]),
        (&["--filters", ""], &["--filters"]),
        (&["--filters", "ekf,ekf"], &["--filters", "twice"]),
        (&["--filters", "pf", "--particles", "0"], &["--particles"]),
        (&["--filters", "ukf", "--ukf-beta", "11"], &["--ukf-beta"]),
        (&["--particles", "100"], &["--particles", "pf"]),
        (
            &["--filters", "pf", "--roughening", "-1"],
            &["--roughening"],
        ),
    ];
    for (extra, needles) in cases {
        fails(&refs(&tiny(extra)), needles);
    }
}

#[test]
fn montecarlo_filters_sharded_and_merged_equal_the_whole_run() {
    let dir = TempDir::new();
    // 40 trajectories: 3 chunks of 16, split 2 + 1.
    let study = [
        "montecarlo",
        "--trajectory",
        "I",
        "--runs",
        "40",
        "--noise-runs",
        "2",
        "--dt",
        "0.1",
        "--duration",
        "1",
        "--filters",
        "ukf,pf,ekf",
        "--particles",
        "100",
        "--roughening",
        "0.2",
    ];
    let whole = dir.path("whole.json");
    ok_json_line(&[&study[..], &["--json", &whole]].concat());
    let (p0, p1, merged) = (dir.path("p0.json"), dir.path("p1.json"), dir.path("m.json"));
    ok_json_line(&[&study[..], &["--shard", "0/2", "--json", &p0]].concat());
    ok_json_line(&[&study[..], &["--shard", "1/2", "--json", &p1]].concat());
    let part = read_json(&p0);
    assert_eq!(
        part["config"]["filters"]["names"],
        json!(["ukf", "pf", "ekf"])
    );
    assert_eq!(part["sums"].as_array().unwrap().len(), 3);
    ok_json_line(&["merge", "--json", &merged, &p1, &p0]);
    let (a, b) = (untimed(read_json(&whole)), untimed(read_json(&merged)));
    assert!(a.get("filters").is_some());
    assert_eq!(a, b, "merged parts equal the unsharded run");
}

#[test]
fn montecarlo_filters_ctrl_c_stops_without_writing_files() {
    let dir = TempDir::new();
    let js = dir.path("c.json");
    let out = interrupted(
        Command::new(BIN)
            .args(["montecarlo", "--trajectory", "I", "--runs", "5000000"])
            .args(["--noise-runs", "1", "--dt", "0.1", "--filters", "ukf,pf"])
            .args(["--particles", "100", "--json", &js]),
        "montecarlo",
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(out.stdout.is_empty());
    assert!(err.contains("cancelled"), "{err}");
    assert!(dir.files().is_empty(), "{:?}", dir.files());
}

/// Issue 24: the UKF from a wide prior. At its cap diag(1e4) (σ = 100 m) it tracks like the EKF
/// on the same data (within 1 cm of it from step 10 on; `ukf::MAX_PRIOR_VARIANCE` has the
/// measurements behind the cap); wider priors that the EKF takes (its information form, up to
/// diag(1e12)) are refused for the UKF with a named error on the file's `initial_covariance`
/// and the range, not `ukf.covariance` in every step.
#[test]
fn ukf_wide_prior_tracks_like_the_ekf_or_is_refused_by_name() {
    let dir = TempDir::new();
    let s = dir.write(
        "s.json",
        &serde_json::from_str(&presets::sensors2019().to_json()).unwrap(),
    );
    let with_prior = |v: f64, name: &str| {
        let mut m = measurements();
        m["initial_covariance"] = json!([[v, 0, 0, 0], [0, v, 0, 0], [0, 0, v, 0], [0, 0, 0, v]]);
        dir.write(name, &m)
    };
    let wide = with_prior(1e4, "wide.json");
    let base = ["track", "--scenario", &s, "--measurements", &wide];
    let ekf = ok_json_line(&base);
    let ukf = ok_json_line(&[&base[..], &["--filter", "ukf"]].concat());
    for k in 10..20 {
        let (a, b) = (floats(&ekf["states"][k]), floats(&ukf["states"][k]));
        let d = Vec2::new(a[0] - b[0], a[1] - b[1]).norm();
        assert!(d < 0.01, "step {k}: UKF {d} m from the EKF");
        let t = truth(k + 1);
        assert!(Vec2::new(b[0] - t.x, b[1] - t.y).norm() < 0.05, "step {k}");
    }
    for (v, text) in [(1e6, "1000000"), (1e12, "1000000000000")] {
        let widest = with_prior(v, "widest.json");
        ok_json_line(&["track", "--scenario", &s, "--measurements", &widest]);
        fails(
            &[
                "track",
                "--scenario",
                &s,
                "--measurements",
                &widest,
                "--filter",
                "ukf",
            ],
            &[
                &format!("initial_covariance[0][0]: {text} is out of range"),
                "at most 1e4 for the UKF; the EKF takes up to 1e12",
            ],
        );
    }
}
