//! End-to-end tests of `scatterloc montecarlo` (issue 3 §2): the fast profile of spec §9.5 with
//! its JSON curves and figure ([S] Fig. 3), thread-count independence, three panels for all
//! trajectories, and Ctrl-C leaving no files behind.
#![cfg(not(target_arch = "wasm32"))]

use crate::common;

use std::process::Command;

use serde_json::json;

use common::cli::{floats, interrupted, ok_json_line, read_json, TempDir, BIN, FAST};

#[test]
fn montecarlo_fast_profile_writes_curves_and_figure() {
    let dir = TempDir::new();
    let (js, svg) = (dir.path("mc.json"), dir.path("fig.svg"));
    let mut args = vec![
        "montecarlo",
        "--trajectory",
        "I",
        "--json",
        &js,
        "--out",
        &svg,
    ];
    args.extend(FAST);
    let summary = ok_json_line(&args);
    assert_eq!(summary["trajectory"], "I");
    assert_eq!(summary["at"].as_array().unwrap().len(), 4);
    assert!(summary["ns_per_ekf_step"].as_f64().unwrap() > 0.0);
    let v = read_json(&js);
    for key in ["t_s", "rmse_ekf_m", "rmse_pcrlb_m", "nees"] {
        assert_eq!(v[key].as_array().unwrap().len(), 101, "{key}");
    }
    assert!((floats(&v["t_s"])[100] - 10.0).abs() < 1e-9);
    // Check 5: both start at √0.2 = 0.4472 m (the EKF within Monte Carlo error).
    assert!((v["rmse_pcrlb_m"][0].as_f64().unwrap() - 0.2f64.sqrt()).abs() < 1e-12);
    let e0 = v["rmse_ekf_m"][0].as_f64().unwrap();
    assert!((0.33..0.56).contains(&e0), "{e0}");
    assert_eq!(
        (v["runs"].as_u64(), v["trajectories"].as_u64()),
        (Some(128), Some(64))
    );
    assert_eq!(
        (v["noise_runs"].as_u64(), v["seed"].as_u64()),
        (Some(2), Some(1))
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("Scenario I"));
    assert_eq!(
        dir.files(),
        ["fig.svg", "mc.json"],
        "no temporary files left"
    );
}

#[test]
fn montecarlo_curves_do_not_depend_on_the_thread_count() {
    let dir = TempDir::new();
    let curves = |threads: &str| {
        let path = dir.path(&format!("t{threads}.json"));
        let mut args = vec![
            "montecarlo",
            "--trajectory",
            "II",
            "--threads",
            threads,
            "--json",
            &path,
        ];
        args.extend(FAST);
        ok_json_line(&args);
        let text = std::fs::read_to_string(&path).unwrap();
        // The curves come first; wall time and the thread count after "runs".
        text[..text.find(",\"runs\":").unwrap()].to_string()
    };
    let one = curves("1");
    assert!(one.starts_with("{\"t_s\":[") && one.contains("\"nees\":["));
    assert_eq!(one, curves("2"));
}

#[test]
fn montecarlo_all_draws_three_panels() {
    let dir = TempDir::new();
    let (js, png) = (dir.path("all.json"), dir.path("fig3.png"));
    let v = ok_json_line(&[
        "montecarlo",
        "--runs",
        "16",
        "--noise-runs",
        "1",
        "--dt",
        "0.1",
        "--duration",
        "2",
        "--json",
        &js,
        "--out",
        &png,
    ]);
    assert_eq!(v["scenarios"].as_array().unwrap().len(), 3);
    assert_eq!(v["out"], json!(png));
    let doc = read_json(&js);
    let names: Vec<&str> = doc["scenarios"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["trajectory"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["I", "II", "III"]);
    assert_eq!(doc["scenarios"][2]["t_s"].as_array().unwrap().len(), 21);
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    assert_eq!(width, 3 * 620);
}

#[test]
fn ctrl_c_stops_without_writing_files() {
    let dir = TempDir::new();
    let (js, png) = (dir.path("c.json"), dir.path("c.png"));
    let out = interrupted(
        Command::new(BIN)
            .args([
                "montecarlo",
                "--trajectory",
                "I",
                "--runs",
                "5000000",
                "--noise-runs",
                "1",
            ])
            .args(["--dt", "0.1", "--json", &js, "--out", &png]),
        "montecarlo",
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(out.stdout.is_empty());
    assert_eq!(err.trim().lines().count(), 1, "{err:?}");
    assert!(err.contains("cancelled"), "{err}");
    assert!(dir.files().is_empty(), "{:?}", dir.files());
}
