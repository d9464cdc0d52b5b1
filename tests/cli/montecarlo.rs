//! End-to-end tests of `scatterloc montecarlo` (issue 3 §2): the fast profile of spec §9.5 with
//! its JSON curves and figure ([S] Fig. 3), thread-count independence, three panels for all
//! trajectories, and Ctrl-C leaving no files behind.
#![cfg(not(target_arch = "wasm32"))]

use crate::common;

use std::process::Command;

use serde_json::json;

use common::cli::{fails, floats, interrupted, ok_json_line, read_json, TempDir, BIN, FAST};

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

// Issue 24, "Long work": in-run cancellation, the cost cap, per-filter failures.

/// A full mesh of `k` transmitters × `l` receivers on the sensors2019 radio (the mesh of
/// `tests/common/tracking.rs`) as a scenario file in `dir`: `k·l` links.
fn mesh_scenario(dir: &TempDir, k: usize, l: usize) -> String {
    use scatterloc::scenario::{presets, Receiver, Transmitter};
    let mut s = presets::sensors2019();
    let tx = s.transmitters[0].clone();
    s.transmitters = (0..k)
        .map(|i| Transmitter {
            name: format!("T{i}"),
            height_m: 0.0,
            position_m: [3.0 * i as f64 - 2.0, -1.0 + 0.5 * i as f64],
            ..tx.clone()
        })
        .collect();
    let rx = s.receivers[0].clone();
    s.receivers = (0..l)
        .map(|i| Receiver {
            name: format!("R{i}"),
            height_m: 0.0,
            position_m: [-6.0 + 4.5 * i as f64, if i % 2 == 0 { 12.0 } else { -8.0 }],
            ..rx.clone()
        })
        .collect();
    let v = serde_json::to_value(&s).unwrap();
    dir.write(&format!("mesh{k}x{l}.json"), &v)
}

/// Ctrl-C inside one long run (issue 24): a particle filter of 10⁶ particles at the paper step
/// (4883 steps of ≈ 60 ms each, one run of minutes; before, cancellation waited for the run to
/// end) stops with exit status 130 and writes nothing. The 60 s wait of `interrupted` is for
/// liveness only.
#[test]
fn ctrl_c_stops_a_particle_filter_inside_its_run() {
    let dir = TempDir::new();
    let js = dir.path("pf.json");
    let out = interrupted(
        Command::new(BIN).args([
            "montecarlo",
            "--trajectory",
            "I",
            "--filters",
            "pf",
            "--particles",
            "1000000",
            "--runs",
            "1",
            "--noise-runs",
            "1",
            "--threads",
            "1",
            "--json",
            &js,
        ]),
        "montecarlo --filters pf --particles 1000000",
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(out.stdout.is_empty());
    assert!(err.contains("cancelled"), "{err}");
    assert!(dir.files().is_empty(), "{:?}", dir.files());
}

/// The cost cap (issue 24): EKF + UKF on a 64 × 64-node full mesh (4096 links; a UKF step
/// factorises a 4096 × 4096 matrix, ≈ 16 s) at the default 5000 × 50 runs is refused before it
/// starts, with the predicted time and the flags to change; nothing is written.
#[test]
fn montecarlo_refuses_a_64_by_64_mesh_ukf_study_with_its_predicted_time() {
    let dir = TempDir::new();
    let scenario = mesh_scenario(&dir, 64, 64);
    let js = dir.path("mc.json");
    let err = fails(
        &[
            "montecarlo",
            "--scenario",
            &scenario,
            "--filters",
            "ekf,ukf",
            "--json",
            &js,
        ],
        &[
            "montecarlo: the work is predicted to take",
            "days of CPU time",
            "over the cap of 24.0 h",
            "--runs",
            "--max-cpu-hours",
        ],
    );
    assert!(!dir.files().contains(&"mc.json".to_string()), "{err}");
    // The cap is the flag's: one run of 0.1 s at T = 0.1 s (one UKF step, ≈ 16 s predicted)
    // passes a cap of 1 h … but is refused under 10 s.
    fails(
        &[
            "montecarlo",
            "--scenario",
            &scenario,
            "--trajectory",
            "I",
            "--filters",
            "ukf",
            "--runs",
            "1",
            "--noise-runs",
            "1",
            "--dt",
            "0.1",
            "--duration",
            "0.1",
            "--max-cpu-hours",
            "0.002",
        ],
        &["over the cap of 7 s (--max-cpu-hours 0.002)"],
    );
    fails(
        &["montecarlo", "--max-cpu-hours", "0"],
        &["--max-cpu-hours: 0 is outside the allowed range"],
    );
}

/// `track` with the UKF and the PF on a 4096-link mesh (≈ 16 s and ≈ 13 s per step predicted)
/// is refused over the cap with the predicted time (a file may hold 10⁶ steps).
#[test]
fn track_refuses_ukf_and_pf_on_4096_links_over_the_cap() {
    let dir = TempDir::new();
    let scenario = mesh_scenario(&dir, 64, 64);
    let row = vec![serde_json::Value::Null; 4096];
    let m = json!({
        "dt_s": 0.1, "process_noise": 0.01,
        "initial_state": [4, 1, 1.39, 0.25],
        "initial_covariance": [[0.1,0,0,0],[0,0.1,0,0],[0,0,0.01,0],[0,0,0,0.01]],
        "sigma_s": 3.5e-11,
        "steps": vec![row; 5],
    });
    let mpath = dir.write("m.json", &m);
    for filter in ["ukf", "pf"] {
        fails(
            &[
                "track",
                "--scenario",
                &scenario,
                "--measurements",
                &mpath,
                "--filter",
                filter,
                "--max-cpu-hours",
                "0.01",
            ],
            &[
                "track: the work is predicted to take",
                "over the cap of 36 s",
                "--max-cpu-hours",
            ],
        );
    }
}

/// Every run of one filter fails (issue 24): `--particles 1` (inside its documented range
/// 1 … 10⁶) collapses the particle filter's covariance in every run. With `--filters ekf,pf` the
/// EKF's curves are kept, the PF is reported as failed in all its runs with the first cause and
/// the flag, in the JSON and on stderr, and the exit status is 0; with the PF alone there is no
/// result: exit status 2, a named error.
#[test]
fn a_filter_that_fails_every_run_is_reported_on_its_own() {
    let dir = TempDir::new();
    let js = dir.path("mc.json");
    let base = [
        "montecarlo",
        "--trajectory",
        "I",
        "--runs",
        "16",
        "--noise-runs",
        "1",
        "--dt",
        "0.1",
        "--duration",
        "1",
        "--particles",
        "1",
    ];
    let mut args = base.to_vec();
    args.extend(["--filters", "ekf,pf", "--json", &js]);
    let out = common::cli::run(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("warning: scenario I: --particles: every run of the PF failed (16 of 16)"),
        "{err}"
    );
    let v = read_json(&js);
    assert_eq!(v["runs"], 16, "the EKF's runs");
    assert_eq!(v["rmse_ekf_m"].as_array().unwrap().len(), 11);
    assert_eq!(v["filters"]["ekf"]["failed_runs"], 0);
    let pf = &v["filters"]["pf"];
    assert_eq!(
        (pf["runs"].as_u64(), pf["failed_runs"].as_u64()),
        (Some(0), Some(16))
    );
    assert!(pf.get("rmse_m").is_none());
    let e = pf["error"].as_str().unwrap();
    assert!(
        e.starts_with("--particles: every run of the PF failed (16 of 16); the first: "),
        "{e}"
    );
    // The PF alone: nothing to report.
    let mut alone = base.to_vec();
    alone.extend(["--filters", "pf"]);
    fails(
        &alone,
        &["--particles: every run of the PF failed (16 of 16); the first: "],
    );
}

/// The UKF's α outside Wan & van der Merwe's 10⁻⁴ … 1 is a named error naming the flag and
/// the range (it used to fail every run with `ukf.covariance`).
#[test]
fn ukf_alpha_outside_its_range_names_the_flag() {
    for a in ["1e-300", "2"] {
        fails(
            &[
                "montecarlo",
                "--filters",
                "ukf",
                "--ukf-alpha",
                a,
                "--runs",
                "16",
            ],
            &[&format!(
                "--ukf-alpha: {a} is out of range (1e-4 to 1, Wan & van der Merwe)"
            )],
        );
    }
}
