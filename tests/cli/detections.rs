//! Detections in and out (issue 40 §3, docs/detections.md): `cir estimate --detections-out`
//! then `track --detections` gives the same track, byte for byte, as `cir estimate
//! --measurements` then `track --measurements` on a simulated recording; the same detections as
//! bistatic ranges in metres give the same track (to the rounding of range / c); the flags'
//! usage errors and a bad line name the flag, the file, the line and the field (exit 2,
//! nothing written).

use std::io::Write;
use std::process::{Command, Stdio};

use serde_json::Value;

use crate::cir::simulate;
use crate::common::cli::{fails, ok_json_line, run, TempDir, BIN};

/// `track` with `args`: its stdout (exit 0).
fn track(args: &[&str]) -> String {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn detections_out_then_track_is_the_measurements_track() {
    let dir = TempDir::new();
    let (scenario, sim) = simulate(&dir, "1", "0.02", "4");
    let (est, meas, det) = (
        dir.path("est.json"),
        dir.path("m.json"),
        dir.path("d.jsonl"),
    );
    ok_json_line(&[
        "cir",
        "estimate",
        "--scenario",
        &scenario,
        "--cir",
        &format!("{sim}/recording.npz"),
        "--calibration",
        &format!("{sim}/calibration.npz"),
        "--out",
        &est,
        "--measurements",
        &meas,
        "--detections-out",
        &det,
    ]);
    // One line per snapshot and recorded link: 51 × 4, each with delay, snr and sigma.
    let text = std::fs::read_to_string(&det).unwrap();
    let lines: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 51 * 4);
    assert!(text.ends_with('\n'));
    let e: Value = serde_json::from_str(&std::fs::read_to_string(&est).unwrap()).unwrap();
    for (i, l) in lines.iter().enumerate() {
        let (s, p) = (i / 4, i % 4);
        assert_eq!(l["timestamp"], e["t_s"][s]);
        assert_eq!((l["tx"].clone(), l["rx"].clone()), (0.into(), p.into()));
        assert_eq!(l["unit"], "s");
        // The same delays, σ and SNR as EST.json's estimates, to the last bit.
        let paths = e["estimates"][s][p].as_array().unwrap();
        assert_eq!(l["delay"].as_array().unwrap().len(), paths.len());
        for (k, path) in paths.iter().enumerate() {
            assert_eq!(l["delay"][k], path["delay_s"]);
            assert_eq!(l["sigma"][k], path["sigma_s"]);
            assert_eq!(l["snr"][k], path["snr_db"]);
        }
    }
    let by_measurements = track(&["track", "--scenario", &scenario, "--measurements", &meas]);
    let by_detections = track(&["track", "--scenario", &scenario, "--detections", &det]);
    assert_eq!(by_measurements, by_detections);
    let t: Value = serde_json::from_str(&by_detections).unwrap();
    assert_eq!(t["states"].as_array().unwrap().len(), 50);
    // From standard input too.
    let mut child = Command::new(BIN)
        .args(["track", "--scenario", &scenario, "--detections", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(text.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    assert_eq!(String::from_utf8(out.stdout).unwrap(), by_detections);
    // The same detections as bistatic ranges in metres (link as [tx, rx], a comment, blank
    // lines): the same track to the rounding of range / c.
    let c = 299_792_458.0;
    let mut metres = String::from("# bistatic ranges, m\n\n");
    for l in &lines {
        let m = |v: &Value| -> Vec<f64> {
            v.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap() * c)
                .collect()
        };
        let doc = serde_json::json!({
            "timestamp": l["timestamp"], "link": [l["tx"], l["rx"]], "unit": "m",
            "delay": m(&l["delay"]), "sigma": m(&l["sigma"]), "snr": l["snr"],
        });
        metres.push_str(&format!("{doc}\n\n"));
    }
    let dm = dir.write_text("m.jsonl", &metres);
    let in_metres = track(&["track", "--scenario", &scenario, "--detections", &dm]);
    let tm: Value = serde_json::from_str(&in_metres).unwrap();
    let (a, b) = (
        t["states"].as_array().unwrap(),
        tm["states"].as_array().unwrap(),
    );
    assert_eq!(a.len(), b.len());
    let mut worst: f64 = 0.0;
    for (x, y) in a.iter().zip(b) {
        for i in 0..4 {
            worst = worst.max((x[i].as_f64().unwrap() - y[i].as_f64().unwrap()).abs());
        }
    }
    assert!(worst < 1e-6, "{worst}");
    assert_eq!(t["choices"], tm["choices"]);
}

#[test]
fn detections_flags_and_bad_lines_are_named_errors() {
    let dir = TempDir::new();
    let out = run(&["preset", "sensors2019"]);
    let scenario = dir.write_text("s.json", &String::from_utf8(out.stdout).unwrap());
    let good = "{\"timestamp\": 0, \"tx\": 0, \"rx\": 0, \"delay\": [4e-8]}\n\
                {\"timestamp\": 0.1, \"tx\": 0, \"rx\": 0, \"delay\": [4.1e-8]}\n";
    let d = dir.write_text("d.jsonl", good);
    let m = dir.write_text("m.json", "{}");
    fails(
        &["track", "--scenario", &scenario],
        &["--measurements/--detections: give one of them"],
    );
    fails(
        &[
            "track",
            "--scenario",
            &scenario,
            "--measurements",
            &m,
            "--detections",
            &d,
        ],
        &["--measurements/--detections: give one of them, not both"],
    );
    fails(
        &[
            "track",
            "--scenario",
            &scenario,
            "--measurements",
            &m,
            "--process-noise",
            "1",
        ],
        &["--process-noise: only with --detections"],
    );
    fails(
        &[
            "track",
            "--scenario",
            &scenario,
            "--detections",
            &d,
            "--process-noise",
            "-1",
        ],
        &["--process-noise"],
    );
    let bad = dir.write_text(
        "bad.jsonl",
        &format!("{good}{{\"timestamp\": 0.2, \"tx\": 0, \"rx\": 1, \"delay\": [1e-8, 2e-8], \"snr\": [3]}}\n"),
    );
    fails(
        &["track", "--scenario", &scenario, "--detections", &bad],
        &[&format!(
            "--detections {bad}: line 3: snr: 1 values, expected 2 (one per delay)"
        )],
    );
    let unknown = dir.write_text(
        "unknown.jsonl",
        &format!("{good}{{\"timestamp\": 0.2, \"tx\": 0, \"rx\": 9, \"delay\": []}}\n"),
    );
    fails(
        &["track", "--scenario", &scenario, "--detections", &unknown],
        &["line 3: link: [0, 9] (tx, rx) is not a link of the scenario"],
    );
    let uneven = dir.write_text(
        "uneven.jsonl",
        &format!("{good}{{\"timestamp\": 0.5, \"tx\": 0, \"rx\": 1, \"delay\": []}}\n"),
    );
    fails(
        &["track", "--scenario", &scenario, "--detections", &uneven],
        &["line 2: timestamp: frame 1 comes 0.1 s after the previous one, the mean spacing is 0.25 s"],
    );
    // The first frame starts the track by an LM fix: one link with a delay is too few.
    fails(
        &["track", "--scenario", &scenario, "--detections", &d],
        &[&format!(
            "--detections {d}: initial_snapshot: delays_s: 1 link(s) carry a measurement, at \
             least 3 are needed"
        )],
    );
    // `cir estimate --detections-out`: a clash with another output is named before any work.
    fails(
        &[
            "cir",
            "estimate",
            "--scenario",
            &scenario,
            "--cir",
            "none.npz",
            "--out",
            &dir.path("e.json"),
            "--detections-out",
            &dir.path("e.json"),
        ],
        &["--detections-out"],
    );
    assert!(!std::path::Path::new(&dir.path("e.json")).exists());
}

#[test]
fn help_lists_the_detections_flags() {
    let top = String::from_utf8(run(&["--help"]).stdout).unwrap();
    assert!(top.contains("--detections D.jsonl"), "{top}");
    assert!(top.contains("--detections-out D.jsonl"), "{top}");
    let t = String::from_utf8(run(&["track", "--help"]).stdout).unwrap();
    assert!(t.contains("--detections <D.jsonl>") && t.contains("--process-noise <Q>"));
    let e = String::from_utf8(run(&["cir", "estimate", "--help"]).stdout).unwrap();
    assert!(e.contains("--detections-out <D.jsonl>"));
}
