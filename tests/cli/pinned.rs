//! Issue 23's guard: the CLI's outputs do not change when its use cases move into the library.
//! A fixed set of commands (every command family: presets, CRLB, maps, tracking with gating,
//! the Monte Carlo study with one and several filters, whole and sharded + merged, the bound
//! alone, the multi-target Table II and ROC, whole and sharded + merged) is run and every
//! output — stdout and each file written, JSON and SVG — is compared with the outputs the
//! binary of commit 3026b0e (before the move) wrote for the same commands, stored in
//! `tests/golden/cli_pinned.json`. JSON must keep every key and value (floats to 1e-12
//! relative; new keys may be added); the run-time keys (wall times, ns per step) are only
//! required to be present. SVG figures must be identical.
//!
//! The reference was regenerated in issue 26, whose changes to these outputs were all meant:
//! the figures' curve palette became the colour-blind-safe Okabe–Ito one, the PF is regularised
//! (its curves and the multi-filter legend with the failed counts), the map SVG embeds the map
//! as one PNG image, and the transcendental functions are the `libm` crate's on every platform
//! (last-bit changes: the PF's NEES at 1.4e-12 relative, the exact sums' expansions of the part
//! files). Issue 24 had made part files format version 2 (a digest of their sums). Issue 38
//! changed two figures on purpose (only their entries were replaced): the filters' curves of
//! `montecarlo-filters` and `montecarlo-merge` differ in line style (EKF solid, UKF dotted, PF
//! dashed), and the merged figure's legend is drawn smaller so that it fits its panel (it was
//! cut at the plot's left edge).
//!
//! To regenerate the reference with another binary (only when an output is meant to change):
//! `SCATTERLOC_PIN_WRITE=/path/to/scatterloc cargo test --test cli pinned::`.

use std::collections::BTreeMap;
use std::process::Command;

use serde_json::Value;

use crate::common::cli::{TempDir, BIN};

/// Keys whose values are run times or this CPU's kernel path: present, not compared.
const TIMING_KEYS: [&str; 6] = [
    "kernel",
    "wall_time_s",
    "ns_per_ekf_step",
    "wall_ns_per_ekf_step",
    "compute_ms",
    "write_ms",
];
const GOLDEN: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/golden/cli_pinned.json");

/// One command: its name, its arguments (`{dir}` is the scratch directory), the files it writes
/// (compared too) and whether its stdout is compared (a ROC summary table holds its wall time).
struct Step {
    name: &'static str,
    args: &'static [&'static str],
    files: &'static [&'static str],
    stdout: bool,
}

fn steps() -> Vec<Step> {
    let s = |name, args, files, stdout| Step {
        name,
        args,
        files,
        stdout,
    };
    vec![
        s("preset", &["preset", "sensors2019"], &[], true),
        s(
            "crlb",
            &["crlb", "--scenario", "{dir}/s.json", "--at", "5,4"],
            &[],
            true,
        ),
        s(
            "crlb-map-json",
            &[
                "crlb-map",
                "--scenario",
                "{dir}/s.json",
                "--nx",
                "9",
                "--ny",
                "7",
                "--out",
                "{dir}/map.json",
            ],
            &["map.json"],
            true,
        ),
        s(
            "crlb-map-svg",
            &[
                "crlb-map",
                "--scenario",
                "{dir}/s.json",
                "--nx",
                "12",
                "--ny",
                "10",
                "--out",
                "{dir}/map.svg",
            ],
            &["map.svg"],
            true,
        ),
        s(
            "simulate-walk",
            &[
                "simulate-walk",
                "--scenario",
                "{dir}/s.json",
                "--out-dir",
                "{dir}/walk",
                "--duration",
                "2",
                "--seed",
                "2",
            ],
            &[
                "walk/calibration_snapshots.json",
                "walk/measurements.json",
                "walk/truth.json",
            ],
            true,
        ),
        s(
            "calibrate",
            &[
                "calibrate",
                "--scenario",
                "{dir}/s.json",
                "--snapshots",
                "{dir}/walk/calibration_snapshots.json",
                "--out",
                "{dir}/cal.json",
            ],
            &["cal.json"],
            true,
        ),
        s(
            "track-gated",
            &[
                "track",
                "--scenario",
                "{dir}/s.json",
                "--measurements",
                "{dir}/walk/measurements.json",
                "--calibration",
                "{dir}/cal.json",
                "--association",
                "gated",
                "--out",
                "{dir}/track.svg",
                "--truth",
                "{dir}/walk/truth.json",
            ],
            &["track.svg"],
            true,
        ),
        s(
            "track-gated-stdout",
            &[
                "track",
                "--scenario",
                "{dir}/s.json",
                "--measurements",
                "{dir}/walk/measurements.json",
                "--calibration",
                "{dir}/cal.json",
                "--association",
                "gated",
            ],
            &[],
            true,
        ),
        s(
            "montecarlo-ekf",
            &[
                "montecarlo",
                "--trajectory",
                "II",
                "--seed",
                "3",
                "--runs",
                "32",
                "--noise-runs",
                "2",
                "--dt",
                "0.1",
                "--duration",
                "1",
                "--threads",
                "1",
            ],
            &[],
            true,
        ),
        s(
            "montecarlo-ekf-files",
            &[
                "montecarlo",
                "--trajectory",
                "all",
                "--seed",
                "4",
                "--runs",
                "16",
                "--noise-runs",
                "2",
                "--dt",
                "0.1",
                "--duration",
                "1",
                "--threads",
                "1",
                "--json",
                "{dir}/mc.json",
                "--out",
                "{dir}/mc.svg",
            ],
            &["mc.json", "mc.svg"],
            true,
        ),
        s(
            "montecarlo-filters",
            &[
                "montecarlo",
                "--filters",
                "ekf,ukf,pf",
                "--particles",
                "300",
                "--trajectory",
                "I",
                "--runs",
                "16",
                "--noise-runs",
                "1",
                "--dt",
                "0.1",
                "--duration",
                "0.5",
                "--threads",
                "1",
                "--json",
                "{dir}/mcf.json",
                "--out",
                "{dir}/mcf.svg",
            ],
            &["mcf.json", "mcf.svg"],
            true,
        ),
        s(
            "montecarlo-ukf-alone",
            &[
                "montecarlo",
                "--filters",
                "ukf",
                "--trajectory",
                "III",
                "--runs",
                "16",
                "--noise-runs",
                "1",
                "--dt",
                "0.1",
                "--duration",
                "0.5",
                "--threads",
                "1",
            ],
            &[],
            true,
        ),
        s(
            "montecarlo-shard-0",
            &[
                "montecarlo",
                "--filters",
                "ekf,ukf",
                "--trajectory",
                "all",
                "--runs",
                "40",
                "--noise-runs",
                "1",
                "--dt",
                "0.1",
                "--duration",
                "0.5",
                "--threads",
                "1",
                "--shard",
                "0/2",
                "--json",
                "{dir}/p0.json",
            ],
            &["p0.json"],
            true,
        ),
        s(
            "montecarlo-shard-1",
            &[
                "montecarlo",
                "--filters",
                "ekf,ukf",
                "--trajectory",
                "all",
                "--runs",
                "40",
                "--noise-runs",
                "1",
                "--dt",
                "0.1",
                "--duration",
                "0.5",
                "--threads",
                "1",
                "--shard",
                "1/2",
                "--json",
                "{dir}/p1.json",
            ],
            &["p1.json"],
            true,
        ),
        s(
            "montecarlo-merge",
            &[
                "merge",
                "--json",
                "{dir}/merged.json",
                "--out",
                "{dir}/merged.svg",
                "{dir}/p1.json",
                "{dir}/p0.json",
            ],
            &["merged.json", "merged.svg"],
            true,
        ),
        s(
            "montecarlo-ekf-shard-0",
            &[
                "montecarlo",
                "--trajectory",
                "II",
                "--runs",
                "40",
                "--noise-runs",
                "1",
                "--dt",
                "0.1",
                "--duration",
                "0.5",
                "--threads",
                "1",
                "--shard",
                "0/3",
                "--json",
                "{dir}/e0.json",
            ],
            &["e0.json"],
            true,
        ),
        s(
            "pcrlb-nominal",
            &[
                "pcrlb",
                "--nominal",
                "--trajectory",
                "II",
                "--dt",
                "0.1",
                "--duration",
                "2",
            ],
            &[],
            true,
        ),
        s(
            "pcrlb-mc",
            &[
                "pcrlb",
                "--trajectory",
                "all",
                "--runs",
                "32",
                "--dt",
                "0.1",
                "--duration",
                "1",
                "--threads",
                "1",
                "--json",
                "{dir}/pc.json",
                "--out",
                "{dir}/pc.svg",
            ],
            &["pc.json", "pc.svg"],
            true,
        ),
        s(
            "mtl-table2",
            &["mtl", "table2", "--draws", "20", "--seed", "1"],
            &[],
            true,
        ),
        s(
            "mtl-roc",
            &[
                "mtl",
                "roc",
                "--experiment",
                "vb",
                "--realizations",
                "3",
                "--threads",
                "1",
                "--json",
                "{dir}/roc.json",
                "--out",
                "{dir}/roc.svg",
            ],
            &["roc.json", "roc.svg"],
            false,
        ),
        s(
            "mtl-roc-shard-0",
            &[
                "mtl",
                "roc",
                "--experiment",
                "vc",
                "--realizations",
                "3",
                "--threads",
                "1",
                "--shard",
                "0/2",
                "--json",
                "{dir}/r0.json",
            ],
            &["r0.json"],
            true,
        ),
        s(
            "mtl-roc-shard-1",
            &[
                "mtl",
                "roc",
                "--experiment",
                "vc",
                "--realizations",
                "3",
                "--threads",
                "1",
                "--shard",
                "1/2",
                "--json",
                "{dir}/r1.json",
            ],
            &["r1.json"],
            true,
        ),
        s(
            "mtl-roc-merge",
            &[
                "merge",
                "--json",
                "{dir}/rm.json",
                "{dir}/r0.json",
                "{dir}/r1.json",
            ],
            &["rm.json"],
            false,
        ),
    ]
}

/// Runs every step with `bin` in a fresh directory: `{step: {"stdout": .., "files": {..}}}`
/// with the directory's path replaced by `{dir}`.
fn run_all(bin: &str) -> BTreeMap<String, Value> {
    let dir = TempDir::new();
    let root = dir.0.to_string_lossy().into_owned();
    let mut out = BTreeMap::new();
    for step in steps() {
        let args: Vec<String> = step
            .args
            .iter()
            .map(|a| a.replace("{dir}", &root))
            .collect();
        let o = Command::new(bin).args(&args).output().unwrap();
        assert!(
            o.status.success(),
            "{}: {}",
            step.name,
            String::from_utf8_lossy(&o.stderr)
        );
        let stdout = String::from_utf8(o.stdout).unwrap().replace(&root, "{dir}");
        if step.name == "preset" {
            std::fs::write(dir.path("s.json"), &stdout).unwrap();
        }
        let mut files = serde_json::Map::new();
        for f in step.files {
            let text = std::fs::read_to_string(dir.path(f)).unwrap();
            files.insert(f.to_string(), Value::String(text.replace(&root, "{dir}")));
        }
        let stdout = if step.stdout {
            Value::String(stdout)
        } else {
            Value::Null
        };
        out.insert(
            step.name.to_string(),
            serde_json::json!({"stdout": stdout, "files": files}),
        );
    }
    out
}

/// Compares `got` with `want` below `path`: every key of `want` present with an equal value
/// (numbers to 1e-12 relative, timing keys only present); errors collected in `bad`.
fn compare(want: &Value, got: &Value, path: &str, bad: &mut Vec<String>) {
    match (want, got) {
        (Value::Object(a), Value::Object(b)) => {
            for (k, v) in a {
                let at = format!("{path}.{k}");
                match b.get(k) {
                    None => bad.push(format!("{at}: missing")),
                    Some(_) if TIMING_KEYS.contains(&k.as_str()) => {}
                    Some(w) => compare(v, w, &at, bad),
                }
            }
        }
        (Value::Array(a), Value::Array(b)) => {
            if a.len() != b.len() {
                bad.push(format!("{path}: {} entries, not {}", b.len(), a.len()));
                return;
            }
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                compare(x, y, &format!("{path}[{i}]"), bad);
            }
        }
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            if (x - y).abs() > 1e-12 * x.abs().max(y.abs()) {
                bad.push(format!("{path}: {y}, not {x}"));
            }
        }
        _ if want == got => {}
        _ => bad.push(format!("{path}: {got}, not {want}")),
    }
}

/// An output's text: JSON (one document, or one per line) compared as values, anything else
/// (SVG, text tables) exactly.
fn compare_text(want: &str, got: &str, path: &str, bad: &mut Vec<String>) {
    let parse = |t: &str| -> Option<Vec<Value>> {
        if let Ok(v) = serde_json::from_str::<Value>(t) {
            return Some(vec![v]);
        }
        t.lines().map(|l| serde_json::from_str(l).ok()).collect()
    };
    match (parse(want), parse(got)) {
        (Some(a), Some(b)) if !want.trim().is_empty() => {
            compare(&Value::Array(a), &Value::Array(b), path, bad)
        }
        _ if want == got => {}
        _ => bad.push(format!(
            "{path}: text differs ({} vs {} bytes)",
            got.len(),
            want.len()
        )),
    }
}

#[test]
fn cli_outputs_are_those_of_the_binary_before_the_move() {
    if let Ok(bin) = std::env::var("SCATTERLOC_PIN_WRITE") {
        let all = run_all(&bin);
        std::fs::write(GOLDEN, serde_json::to_string_pretty(&all).unwrap()).unwrap();
        panic!("wrote {GOLDEN} with {bin}; rerun without SCATTERLOC_PIN_WRITE to compare");
    }
    let golden: BTreeMap<String, Value> =
        serde_json::from_str(&std::fs::read_to_string(GOLDEN).unwrap()).unwrap();
    let now = run_all(BIN);
    assert_eq!(
        golden.keys().collect::<Vec<_>>(),
        now.keys().collect::<Vec<_>>()
    );
    let mut bad = Vec::new();
    let mut compared = 0;
    for (name, want) in &golden {
        let got = &now[name];
        if let (Some(w), Some(g)) = (want["stdout"].as_str(), got["stdout"].as_str()) {
            compare_text(w, g, &format!("{name}.stdout"), &mut bad);
            compared += 1;
        }
        for (f, w) in want["files"].as_object().unwrap() {
            let g = got["files"][f].as_str().unwrap_or("");
            compare_text(w.as_str().unwrap(), g, &format!("{name}.{f}"), &mut bad);
            compared += 1;
        }
    }
    assert!(compared >= 40, "only {compared} outputs compared");
    assert!(
        bad.is_empty(),
        "{} differences:\n{}",
        bad.len(),
        bad.join("\n")
    );
}
