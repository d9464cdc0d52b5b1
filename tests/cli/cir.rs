//! `cir simulate|estimate|track` (issues 25, 36): the chain from a signal-level recording to a
//! track, each stage's files readable by the next and by the delay-level commands (`calibrate`,
//! `track`); the track's accuracy on the simulated hangar walk against its truth with the
//! default statics (background subtraction, C9), with a recording of the empty area, with a
//! recursive background learnt from the walk itself and with `--calibration-range`; `--statics
//! clusters` (C7); receivers without a common clock (C10: `synchronized = false`, delays
//! relative to each link's direct path); the track's segments (C11) and the front end's report
//! (`front_end`, `alignment`, `bounds`); named errors for bad recordings and flags (exit 2,
//! nothing written), and Ctrl-C (exit 130, nothing written).
//!
//! Measured numbers in the doc comments: the debug CLI of 2026-12-06 (HEAD 3122a44).

use std::process::Command;

use serde_json::{json, Value};

use crate::common::cli::{
    fails, fails_output, interrupted, ok_json, ok_json_line, read_json, TempDir, BIN,
};
use crate::nees::position_nees;

/// Writes the sensors2019 scenario into `dir`; returns its path.
pub(crate) fn scenario(dir: &TempDir) -> String {
    dir.write_text(
        "s.json",
        &String::from_utf8(
            Command::new(BIN)
                .args(["preset", "sensors2019"])
                .output()
                .unwrap()
                .stdout,
        )
        .unwrap(),
    )
}

/// Simulates `seconds` of the walk at `dt` into `dir/name` (the hangar, or the scene file
/// `scene`), with `calibration` seconds of the empty area; returns the output directory.
fn simulate_into(
    dir: &TempDir,
    scenario: &str,
    name: &str,
    scene: Option<&str>,
    [seconds, dt, calibration, seed]: [&str; 4],
) -> String {
    let out = dir.path(name);
    let mut args = vec![
        "cir",
        "simulate",
        "--scenario",
        scenario,
        "--out-dir",
        &out,
        "--duration",
        seconds,
        "--dt",
        dt,
        "--calibration-duration",
        calibration,
        "--seed",
        seed,
    ];
    if let Some(s) = scene {
        args.extend_from_slice(&["--scene", s]);
    }
    let summary = ok_json_line(&args);
    assert_eq!(summary["links"], 4);
    assert_eq!(summary["subcarriers"], 241);
    out
}

/// Simulates `seconds` of the hangar walk at `dt` into `dir` (plus a scenario file), with
/// 0.4 s of the empty area.
pub(crate) fn simulate(dir: &TempDir, seconds: &str, dt: &str, seed: &str) -> (String, String) {
    let scenario = scenario(dir);
    let out = simulate_into(dir, &scenario, "sim", None, [seconds, dt, "0.4", seed]);
    (scenario, out)
}

/// `cir track` of `sim/recording.npz` with `extra` flags and the truth: its summary and
/// TRACK.json, checked for the invariants every track keeps ([`check_track`]).
fn track(dir: &TempDir, scenario: &str, sim: &str, extra: &[&str]) -> (Value, Value) {
    let out = dir.path("track.json");
    let rec = format!("{sim}/recording.npz");
    let truth = format!("{sim}/truth.json");
    let mut args = vec![
        "cir",
        "track",
        "--scenario",
        scenario,
        "--cir",
        &rec,
        "--truth",
        &truth,
        "--out",
        &out,
    ];
    args.extend_from_slice(extra);
    let s = ok_json_line(&args);
    let t = read_json(&out);
    check_track(&s, &t);
    (s, t)
}

/// What every TRACK.json keeps: one entry per snapshot; the segments (C11) in time order, not
/// overlapping, each ended with a named reason; a state (and covariance) exactly inside them;
/// `start` the first segment's; the summary's statics, delay reference and segment count those
/// of `front_end`; `front_end.bounds` over every link-snapshot.
fn check_track(summary: &Value, t: &Value) {
    let n = t["t_s"].as_array().unwrap().len();
    for k in [
        "states",
        "covariances",
        "links_used",
        "delays_used_s",
        "choices",
    ] {
        assert_eq!(t[k].as_array().unwrap().len(), n, "{k}");
    }
    let segments = t["segments"].as_array().unwrap();
    let mut inside = vec![false; n];
    let mut after = None;
    for (i, s) in segments.iter().enumerate() {
        let (first, last) = (
            s["first"].as_u64().unwrap() as usize,
            s["last"].as_u64().unwrap() as usize,
        );
        assert!(first <= last && last < n, "segment {i}: {s}");
        assert!(after.is_none_or(|a| first > a), "segment {i} overlaps: {s}");
        after = Some(last);
        let end = s["end"].as_str().unwrap();
        assert!(
            ["innovation", "misses", "outside_area", "end"].contains(&end),
            "{end}"
        );
        // Only the last segment can end with the recording.
        assert!(end != "end" || i + 1 == segments.len(), "segment {i}: {s}");
        let confirmed = s["confirmed_at"].as_u64().unwrap() as usize;
        assert!((first..=last).contains(&confirmed), "segment {i}: {s}");
        assert_eq!(s["start"]["snapshot"].as_u64().unwrap() as usize, first);
        assert_eq!(s["t_first_s"], t["t_s"][first]);
        assert_eq!(s["t_last_s"], t["t_s"][last]);
        inside[first..=last].iter_mut().for_each(|x| *x = true);
    }
    for (k, &inside) in inside.iter().enumerate() {
        assert_eq!(!t["states"][k].is_null(), inside, "states[{k}]");
        assert_eq!(!t["covariances"][k].is_null(), inside, "covariances[{k}]");
    }
    match segments.first() {
        Some(s) => assert_eq!(t["start"], s["start"]),
        None => assert!(t["start"].is_null()),
    }
    let fe = &t["front_end"];
    assert_eq!(summary["segments"], segments.len());
    assert_eq!(summary["statics"], fe["statics"]);
    assert_eq!(summary["delay_reference"], fe["delay_reference"]);
    let links = fe["links"].as_array().unwrap().len();
    assert_eq!(links, 4);
    assert_eq!(fe["bounds"]["link_snapshots"], n * links);
}

/// The median and 90 % point of a summary's error.
fn median_p90(s: &Value) -> (f64, f64) {
    let e = &s["error"];
    (
        e["median_m"].as_f64().unwrap(),
        e["p90_m"].as_f64().unwrap(),
    )
}

/// The fraction of all snapshots with a state within 1 m of the truth (0 without a track).
fn within_1m(s: &Value, snapshots: usize) -> f64 {
    let e = &s["error"];
    match (e["count"].as_f64(), e["fraction_below_1m"].as_f64()) {
        (Some(n), Some(f)) => n * f / snapshots as f64,
        _ => 0.0,
    }
}

/// The whole chain with the default statics (background subtraction, C9, against the empty
/// area's recording) on 6 s of the hangar walk with turns (walls, scatterers, double
/// reflections, shadowing) at 20 ms, on three seeds: the track's median error stays below
/// 0.5 m and its 90 % point below 1 m (measured, seeds 1–3: median 0.115, 0.112, 0.134 m,
/// 90 % 0.212, 0.261, 0.215 m; seed 2 first confirms a ghost near the wall for 0.4 s, whose
/// segment ends by `innovation`, and restarts on the walker; see docs/reproduction.md for the
/// full 30 s walk); the files and figures are written; TRACK.json reports the statics per link.
#[test]
fn the_chain_tracks_the_simulated_walk_on_several_seeds() {
    for seed in ["1", "2", "3"] {
        let dir = TempDir::new();
        let (scenario, sim) = simulate(&dir, "6", "0.02", seed);
        let (fig, delays) = (dir.path("f.svg"), dir.path("d.png"));
        let cal = format!("{sim}/calibration.npz");
        let (s, t) = track(
            &dir,
            &scenario,
            &sim,
            &[
                "--calibration",
                &cal,
                "--figure",
                &fig,
                "--delays-figure",
                &delays,
            ],
        );
        assert_eq!(t["t_s"].as_array().unwrap().len(), 301, "one per snapshot");
        let (median, p90) = median_p90(&s);
        eprintln!("seed {seed}: {}", s["error"]);
        assert!(median < 0.5 && p90 < 1.0, "seed {seed}: {}", s["error"]);
        // The defaults: background subtraction, absolute delays (the recording has no
        // `synchronized` flag), the tracker's settings echoed.
        assert_eq!(s["statics"], "background");
        assert_eq!(s["delay_reference"], "absolute");
        assert!(!t["segments"].as_array().unwrap().is_empty());
        assert_eq!(t["association"], "gated");
        assert_eq!(t["extent_sigma_m"], 0.2);
        assert_eq!(t["front_end"]["background_time_s"], 10.0);
        // Every link's background is the mean of the 21 empty snapshots (0.4 s at 20 ms), and
        // the background's own paths (LoS, wall, scatterers) are the static clusters.
        for l in t["front_end"]["links"].as_array().unwrap() {
            assert_eq!(l["empty_snapshots"], 21, "{l}");
            assert_eq!(l["background"], true, "{l}");
            assert!(l["los_delay_s"].is_null(), "absolute delays: {l}");
        }
        assert_eq!(t["calibration"]["snapshot_count"], 21);
        for l in t["calibration"]["links"].as_array().unwrap() {
            assert!(!l["clusters"].as_array().unwrap().is_empty(), "{l}");
        }
        let svg = std::fs::read_to_string(&fig).unwrap();
        assert!(svg.contains("90 %"), "the CDF's 90 % point is marked");
        assert!(std::fs::metadata(&delays).unwrap().len() > 10_000);
    }
}

/// Without `--calibration` the background is learnt from the walk itself (recursive mean, C9
/// step 1; the walker is in the first snapshot): on the same 6 s of the hangar walk at 20 ms the
/// track's median error stays below 0.5 m (measured, seeds 1–3: median 0.165, 0.131, 0.229 m,
/// 90 % 0.353, 0.268, 0.925 m; seed 3 loses and restarts the track five times). `--background-
/// time` sets the time constant (2 s, seed 1: median 0.161 m).
#[test]
fn track_without_calibration_learns_the_background() {
    for seed in ["1", "2", "3"] {
        let dir = TempDir::new();
        let (scenario, sim) = simulate(&dir, "6", "0.02", seed);
        let (s, t) = track(&dir, &scenario, &sim, &[]);
        let (median, _) = median_p90(&s);
        eprintln!("seed {seed}, recursive background: {}", s["error"]);
        assert!(median < 0.5, "seed {seed}: {}", s["error"]);
        assert!(
            s["error"]["count"].as_u64().unwrap() >= 240,
            "a state at 80 % of the snapshots: {}",
            s["error"]
        );
        assert_eq!(s["statics"], "background");
        for l in t["front_end"]["links"].as_array().unwrap() {
            assert_eq!(l["empty_snapshots"], 0, "recursive: {l}");
            assert_eq!(l["background"], true, "{l}");
        }
        if seed == "1" {
            let (s, t) = track(&dir, &scenario, &sim, &["--background-time", "2"]);
            assert_eq!(t["front_end"]["background_time_s"], 2.0);
            assert!(median_p90(&s).0 < 0.5, "{}", s["error"]);
        }
    }
}

/// `--statics clusters` (C7: every full response estimated, the empty area's clusters gated)
/// writes the same documents as the default: the same fields in TRACK.json and EST.json, its
/// statics named; it needs a recording of the empty area (exit 2 naming `--calibration`). On
/// this 2 s walk it tracks far worse than the default (measured, seed 1: median 3.90 m against
/// 0.17 m: the person's echo lies within 1/B of the direct path on two links at the start).
#[test]
fn statics_clusters_writes_the_same_documents() {
    let dir = TempDir::new();
    let (scenario, sim) = simulate(&dir, "2", "0.02", "1");
    let (rec, cal) = (
        format!("{sim}/recording.npz"),
        format!("{sim}/calibration.npz"),
    );
    let estimate = |statics: &str| {
        let out = dir.path(&format!("est-{statics}.json"));
        let s = ok_json_line(&[
            "cir",
            "estimate",
            "--scenario",
            &scenario,
            "--cir",
            &rec,
            "--calibration",
            &cal,
            "--statics",
            statics,
            "--out",
            &out,
        ]);
        assert_eq!(s["statics"], statics);
        (s, read_json(&out))
    };
    let keys = |v: &Value| {
        let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
        k.sort();
        k
    };
    let (sb, eb) = estimate("background");
    let (sc, ec) = estimate("clusters");
    assert_eq!(keys(&sb), keys(&sc));
    assert_eq!(keys(&eb), keys(&ec));
    for k in ["front_end", "calibration"] {
        assert_eq!(keys(&eb[k]), keys(&ec[k]), "{k}");
    }
    assert_eq!(
        keys(&eb["front_end"]["links"][0]),
        keys(&ec["front_end"]["links"][0])
    );
    assert_eq!(ec["front_end"]["statics"], "clusters");
    for (e, background) in [(&eb, true), (&ec, false)] {
        for l in e["front_end"]["links"].as_array().unwrap() {
            assert_eq!(l["background"], background, "{l}");
            assert_eq!(l["empty_snapshots"], 21, "{l}");
        }
        let alignment = e["alignment"].as_array().unwrap();
        assert_eq!(alignment.len(), 101);
        for row in alignment {
            let row = row.as_array().unwrap();
            assert_eq!(row.len(), 4);
            // Aligned to the background (absolute delays: no shift, unit gain), or none made.
            for a in row {
                if background {
                    assert_eq!(a["delay_s"], 0.0, "{a}");
                    assert_eq!(a["gain"], json!([1.0, 0.0]), "{a}");
                } else {
                    assert!(a.is_null(), "{a}");
                }
            }
        }
    }
    let (s, tc) = track(
        &dir,
        &scenario,
        &sim,
        &["--calibration", &cal, "--statics", "clusters"],
    );
    eprintln!("clusters: {}", s["error"]);
    assert_eq!(s["statics"], "clusters");
    let (s, tb) = track(&dir, &scenario, &sim, &["--calibration", &cal]);
    eprintln!("background: {}", s["error"]);
    assert_eq!(keys(&tb), keys(&tc));
    for k in ["front_end", "calibration"] {
        assert_eq!(keys(&tb[k]), keys(&tc[k]), "{k}");
    }
    if let (Some(a), Some(b)) = (tb["segments"].get(0), tc["segments"].get(0)) {
        assert_eq!(keys(a), keys(b));
    }
    // Clusters need the empty area; a bad name is clap's error. Exit 2, nothing written.
    let out = dir.path("o.json");
    for cmd in ["estimate", "track"] {
        let base = [
            "cir",
            cmd,
            "--scenario",
            &scenario,
            "--cir",
            &rec,
            "--out",
            &out,
        ];
        let fail = |extra: &[&str], needles: &[&str]| fails(&[&base[..], extra].concat(), needles);
        let line = fail(&["--statics", "clusters"], &["--calibration"]);
        assert!(line.contains("empty area"), "{line}");
        fail(&["--statics", "x"], &["--statics", "'x'"]);
        fail(&["--delay-reference", "x"], &["--delay-reference", "'x'"]);
        fail(&["--background-time", "0"], &["--background-time"]);
    }
    assert!(!std::path::Path::new(&out).exists());
}

/// `--calibration-range T0,T1`: the recording's snapshots in that range are the empty area
/// (here the walk's first 0.1 s: 6 snapshots); not together with `--calibration`, and a range
/// without snapshots, reversed or malformed, is exit 2 naming `--calibration-range`.
#[test]
fn calibration_range_takes_the_empty_area_from_the_recording() {
    let dir = TempDir::new();
    let (scenario, sim) = simulate(&dir, "1", "0.02", "7");
    let (rec, cal) = (
        format!("{sim}/recording.npz"),
        format!("{sim}/calibration.npz"),
    );
    let out = dir.path("est.json");
    let s = ok_json_line(&[
        "cir",
        "estimate",
        "--scenario",
        &scenario,
        "--cir",
        &rec,
        "--calibration-range",
        "0,0.11",
        "--out",
        &out,
    ]);
    assert_eq!(s["snapshots"], 51);
    let e = read_json(&out);
    for l in e["front_end"]["links"].as_array().unwrap() {
        assert_eq!(l["empty_snapshots"], 6, "{l}");
        assert_eq!(l["background"], true, "{l}");
    }
    assert_eq!(e["calibration"]["snapshot_count"], 6);
    std::fs::remove_file(&out).unwrap();
    for cmd in ["estimate", "track"] {
        let base = [
            "cir",
            cmd,
            "--scenario",
            &scenario,
            "--cir",
            &rec,
            "--out",
            &out,
        ];
        let fail = |extra: &[&str], needles: &[&str]| fails(&[&base[..], extra].concat(), needles);
        let line = fail(
            &["--calibration", &cal, "--calibration-range", "0,0.1"],
            &["--calibration-range", "not both"],
        );
        assert!(line.contains("calibration recording"), "{line}");
        fail(
            &["--calibration-range", "10,11"],
            &["--calibration-range", "no snapshot"],
        );
        fail(
            &["--calibration-range", "1,0"],
            &["--calibration-range", "t1 >= t0"],
        );
        fail(
            &["--calibration-range", "1"],
            &["--calibration-range", "T0,T1"],
        );
    }
    assert!(!std::path::Path::new(&out).exists());
}

/// The hangar scene of `cir simulate` with receivers without a common clock: every snapshot
/// and link with a timing offset uniform over ±100 ns (25/B) and a random carrier phase (the
/// example of docs/recording.md, "The simulator's scene").
fn free_running_scene() -> Value {
    json!({
        "walls": [{"a_m": [-8.0, 24.0], "b_m": [30.0, 24.0], "gamma": -0.6}],
        "scatterers": [
            {"position_m": [20.0, 14.0], "rcs_m2": 5.0},
            {"position_m": [4.0, -8.0], "rcs_m2": 3.0}
        ],
        "walk": {
            "waypoints_m": [[2.0, 4.0], [16.0, 4.0], [16.0, 16.0], [4.0, 16.0], [4.0, 8.0]],
            "speed_mps": 1.4,
            "turn_radius_m": 2.5
        },
        "clock": {"timing_offset_s": 100e-9, "carrier_phase": true}
    })
}

/// Receivers without a common clock (C10) end to end, on 10 s of the hangar walk at 50 ms with
/// 1 s of the empty area, three seeds: `cir simulate --scene` with a `clock` writes recordings
/// whose `synchronized` is false and the offsets it drew in truth.json; `cir track` then takes
/// delays relative to each link's direct path by itself (`"delay_reference": "los"`) and tracks
/// (measured, seeds 1–3: median 0.143, 0.142, 0.135 m, 90 % 0.360, 0.283, 0.350 m, 197, 200 and
/// 192 of 201 snapshots within 1 m); the same recording read with `--delay-reference absolute`
/// does not (no track on seeds 1 and 2, seed 3 13.4 m off for 11 snapshots; none within 1 m).
/// EST.json's alignment follows the drawn offsets up to each link's constant (the background's
/// own offset; measured, seed 1: within 1.03 ns).
#[test]
fn receivers_without_a_common_clock_track_relative_to_the_direct_path() {
    let dir = TempDir::new();
    let scenario = scenario(&dir);
    let scene = dir.write("scene.json", &free_running_scene());
    for seed in ["1", "2", "3"] {
        let sim = simulate_into(
            &dir,
            &scenario,
            &format!("sim{seed}"),
            Some(&scene),
            ["10", "0.05", "1", seed],
        );
        let read = |name: &str| {
            let bytes = std::fs::read(format!("{sim}/{name}")).unwrap();
            scatterloc::npz::read_recording(&bytes).unwrap()
        };
        assert_eq!(read("recording.npz").synchronized, Some(false));
        assert_eq!(read("calibration.npz").synchronized, Some(false));
        let truth = read_json(&format!("{sim}/truth.json"));
        let clock = truth["clock"].as_array().unwrap();
        assert_eq!(clock.len(), 201);
        let offsets: Vec<f64> = clock
            .iter()
            .flat_map(|s| s.as_array().unwrap().iter())
            .map(|c| c["delay_s"].as_f64().unwrap())
            .collect();
        assert_eq!(offsets.len(), 201 * 4);
        assert!(offsets.iter().all(|d| d.abs() <= 100e-9));
        assert!(offsets.iter().any(|d| d.abs() > 50e-9));

        let cal = format!("{sim}/calibration.npz");
        let (s, t) = track(&dir, &scenario, &sim, &["--calibration", &cal]);
        eprintln!("seed {seed}, los: {}", s["error"]);
        assert_eq!(s["delay_reference"], "los");
        assert_eq!(t["front_end"]["delay_reference"], "los");
        // The direct path's delay in the background's time base, per link.
        for l in t["front_end"]["links"].as_array().unwrap() {
            assert!(l["los_delay_s"].as_f64().unwrap() > 0.0, "{l}");
            assert!(l["los_sigma_s"].as_f64().unwrap() > 0.0, "{l}");
        }
        let (median, _) = median_p90(&s);
        let los = within_1m(&s, 201);
        assert!(median < 0.5 && los > 0.8, "seed {seed}: {}", s["error"]);

        let (s, _) = track(
            &dir,
            &scenario,
            &sim,
            &["--calibration", &cal, "--delay-reference", "absolute"],
        );
        eprintln!("seed {seed}, absolute: {}", s["error"]);
        assert_eq!(s["delay_reference"], "absolute");
        let absolute = within_1m(&s, 201);
        assert!(absolute < 0.1, "seed {seed}: {absolute} {}", s["error"]);

        if seed == "1" {
            let out = dir.path("est.json");
            ok_json_line(&[
                "cir",
                "estimate",
                "--scenario",
                &scenario,
                "--cir",
                &format!("{sim}/recording.npz"),
                "--calibration",
                &cal,
                "--out",
                &out,
            ]);
            let e = read_json(&out);
            assert_eq!(e["front_end"]["delay_reference"], "los");
            let span = 241.0 / 120e6;
            for p in 0..4 {
                // δ̂ − δ, folded into the unambiguous span, is the link's constant.
                let d: Vec<f64> = (0..201)
                    .map(|k| {
                        let x = e["alignment"][k][p]["delay_s"].as_f64().unwrap()
                            - clock[k][p]["delay_s"].as_f64().unwrap();
                        x - span * (x / span).round()
                    })
                    .collect();
                let mean = d.iter().sum::<f64>() / d.len() as f64;
                let worst = d.iter().map(|x| (x - mean).abs()).fold(0.0, f64::max);
                assert!(worst < 2e-9, "link {p}: {worst:e} s");
            }
        }
    }
}

/// `cir estimate` writes the forms the delay-level commands read: `calibrate --snapshots` and
/// `track --measurements` run on them, and the raw estimates carry the estimator's σ; EST.json
/// reports how the estimates were made (`front_end` with its `bounds` over every
/// link-snapshot, the alignment per snapshot and link, the static clusters).
#[test]
fn estimate_writes_what_calibrate_and_track_read() {
    let dir = TempDir::new();
    let (scenario, sim) = simulate(&dir, "1", "0.02", "4");
    let (est, snaps, meas) = (
        dir.path("est.json"),
        dir.path("snaps.json"),
        dir.path("m.json"),
    );
    let s = ok_json_line(&[
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
        "--snapshots",
        &snaps,
        "--measurements",
        &meas,
    ]);
    assert_eq!(s["snapshots"], 51);
    assert_eq!(s["statics"], "background");
    assert_eq!(s["delay_reference"], "absolute");
    let e = read_json(&est);
    assert_eq!(e["format"], "scatterloc-estimates");
    // The front end: every link-snapshot counted, the bounds it reached no more than that.
    let fe = &e["front_end"];
    assert_eq!(s["bounds"], fe["bounds"]);
    let b = &fe["bounds"];
    assert_eq!(b["link_snapshots"], 51 * 4);
    for k in ["path_budget", "sweeps"] {
        assert!(b[k].as_u64().unwrap() <= 51 * 4, "{k}: {b}");
    }
    assert!(b["max_passes"].as_u64().unwrap() >= 1, "{b}");
    assert_eq!(fe["max_paths"], e["max_paths"]);
    assert_eq!(fe["p_fa"], e["p_fa"]);
    assert_eq!(e["alignment"].as_array().unwrap().len(), 51);
    assert_eq!(e["calibration"]["links"].as_array().unwrap().len(), 4);
    // The residual of the background holds the walker: a path in every snapshot.
    let estimates = e["estimates"].as_array().unwrap();
    assert!(estimates
        .iter()
        .all(|s| s.as_array().unwrap().iter().any(|l| !l[0].is_null())));
    let p = &e["estimates"][0]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| !l[0].is_null())
        .unwrap()[0];
    for k in ["delay_s", "amplitude", "sigma_s", "track", "confirmed"] {
        assert!(!p[k].is_null(), "{k} in {p}");
    }
    // Each estimate's σ is C4 at its fitted SNR or the joint bound: positive, below 1 ns.
    let sig = p["sigma_s"].as_f64().unwrap();
    assert!(sig > 0.0 && sig < 1e-9, "{sig}");
    let m = read_json(&meas);
    let raw = &m["raw_steps"][0]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| !l[0].is_null())
        .unwrap()[0];
    assert_eq!(
        raw.as_array().unwrap().len(),
        3,
        "[delay, amplitude, sigma]: {raw}"
    );
    let cal = ok_json(&["calibrate", "--scenario", &scenario, "--snapshots", &snaps]);
    assert_eq!(cal["links"].as_array().unwrap().len(), 4);
    let out = Command::new(BIN)
        .args(["track", "--scenario", &scenario, "--measurements", &meas])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let tr: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(tr["states"].as_array().unwrap().len(), 50);
}

/// Bad recordings and flags: exit 2, one line naming the flag (and the array), nothing written.
#[test]
fn bad_recordings_and_flags_are_named_errors() {
    let dir = TempDir::new();
    let (scenario, sim) = simulate(&dir, "0.2", "0.02", "5");
    let rec = format!("{sim}/recording.npz");
    let junk = dir.write_text("junk.npz", "not a zip file at all");
    let out = dir.path("o.json");
    // `cir estimate` of `recording` on `scenario` with `extra` flags fails naming `needles`.
    let estimate = |scenario: &str, recording: &str, extra: &[&str], needles: &[&str]| {
        let mut args = vec![
            "cir",
            "estimate",
            "--scenario",
            scenario,
            "--cir",
            recording,
            "--out",
            &out,
        ];
        args.extend_from_slice(extra);
        fails(&args, needles);
    };
    estimate(&scenario, &junk, &[], &["--cir"]);
    estimate(
        &scenario,
        &dir.path("missing.npz"),
        &[],
        &["--cir", "cannot read"],
    );
    estimate(&scenario, &junk, &["--calibration", &rec], &["--cir"]);
    estimate(
        &scenario,
        &rec,
        &["--calibration", &junk],
        &["--calibration"],
    );
    estimate(&scenario, &rec, &["--pfa", "2"], &["--pfa", "0 < pfa < 1"]);
    estimate(&scenario, &rec, &["--max-paths", "0"], &["--max-paths"]);
    // A scenario with two receivers: the recording's links (0, 2) and (0, 3) are not in it.
    let mut small = read_json(&scenario);
    small["receivers"].as_array_mut().unwrap().truncate(2);
    let small = dir.write("small.json", &small);
    estimate(
        &small,
        &rec,
        &[],
        &["--cir", "links[2]", "not one of the scenario's 2 links"],
    );
    fails(
        &[
            "cir",
            "simulate",
            "--scenario",
            &scenario,
            "--out-dir",
            &dir.path("w"),
            "--walk",
            "1,2",
        ],
        &["--walk", "at least 2"],
    );
    // A scene's clock out of range names its field.
    let mut scene = free_running_scene();
    scene["clock"]["timing_offset_s"] = json!(1.0);
    let scene = dir.write("scene.json", &scene);
    fails(
        &[
            "cir",
            "simulate",
            "--scenario",
            &scenario,
            "--out-dir",
            &dir.path("w"),
            "--scene",
            &scene,
        ],
        &["scene.clock.timing_offset_s"],
    );
    assert!(!std::path::Path::new(&dir.path("w")).exists());
    fails(
        &[
            "cir",
            "track",
            "--scenario",
            &scenario,
            "--calibration",
            &rec,
            "--cir",
            &rec,
            "--out",
            &dir.path("t.txt"),
        ],
        &["--out", ".txt"],
    );
    assert!(!std::path::Path::new(&out).exists());
}

/// Ctrl-C during the estimation of a long recording: exit 130, nothing written.
#[test]
fn ctrl_c_stops_cir_track_and_writes_nothing() {
    let dir = TempDir::new();
    let (scenario, sim) = simulate(&dir, "10", "0.002048", "6");
    let track = dir.path("track.json");
    let out = interrupted(
        Command::new(BIN).args([
            "cir",
            "track",
            "--scenario",
            &scenario,
            "--calibration",
            &format!("{sim}/calibration.npz"),
            "--cir",
            &format!("{sim}/recording.npz"),
            "--out",
            &track,
            "--threads",
            "1",
        ]),
        "cir track",
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(!std::path::Path::new(&track).exists());
}

/// Issue 37 item 6: a recording whose members each declare 10⁹ bytes (under the 1.06·10⁹ cap)
/// but hold a few kB, read under a 1.5 GB address-space limit: a named error at the first
/// member (exit 2), not an abort. Before, the reader reserved every member's declared size
/// up front and the second reservation aborted the process (exit 134).
#[test]
fn declared_sizes_are_not_reserved_up_front() {
    let dir = TempDir::new();
    let (scenario, sim) = simulate(&dir, "0.1", "0.02", "5");
    let mut z = std::fs::read(format!("{sim}/recording.npz")).unwrap();
    let size = 1_000_000_000u32.to_le_bytes();
    let mut patched = 0;
    for i in 0..z.len().saturating_sub(30) {
        match &z[i..i + 4] {
            b"PK\x03\x04" => z[i + 22..i + 26].copy_from_slice(&size),
            b"PK\x01\x02" => z[i + 24..i + 28].copy_from_slice(&size),
            _ => continue,
        }
        patched += 1;
    }
    assert!(patched >= 8, "{patched} headers");
    let rec = dir.path("forged.npz");
    std::fs::write(&rec, &z).unwrap();
    let out = dir.path("o.json");
    let script = format!(
        "ulimit -v 1500000 && exec '{BIN}' cir estimate --threads 1 --scenario '{scenario}' \
         --cir '{rec}' --out '{out}'"
    );
    let run = Command::new("bash").args(["-c", &script]).output().unwrap();
    fails_output(
        &[&script],
        &run,
        &["--cir", "fewer than its declared 1000000000"],
    );
    assert!(!std::path::Path::new(&out).exists());
}

/// Issue 38 §11: the reported covariance of a channel track is consistent with its error. On
/// 15 s of the hangar walk at 50 ms (the page's Simulate) with the empty area's recording and
/// the default estimator σ widened by the 0.2 m body extent, seeds 1–12: each seed's mean
/// position NEES (2 degrees of freedom) against its two-sided 95 % band
/// `χ²_{2n}(0.025 | 0.975)/n` with `n = N/τ` independent samples (`τ` the NEES series'
/// integrated autocorrelation time: the extent's offset holds over several snapshots); at most 2
/// of 12 seeds outside (with 12 consistent seeds, 3 or more outside has probability 2 %).
/// Ghost states (> 2 m from the truth: an association failure, not a covariance question) are
/// left out and counted: at most 1 % of the states.
///
/// Measured (release CLI, 2026-12-06): without the extent's consider term (the filter's own
/// covariance) the seeds' means were 5.1–6.5, every seed outside its band; with it 1.35–2.10
/// (pooled 1.77: conservative, the term takes the offset as constant where the simulated body
/// decorrelates with ρ = 0.9 per snapshot), seed 12 (1.35) below its band [1.43, 2.66], the
/// others inside; seed 9 starts on a ghost 20 m away for 12 snapshots (0.3 % of the states).
#[test]
fn track_nees_is_in_its_band_over_seeds() {
    let dir = TempDir::new();
    let scenario = scenario(&dir);
    let (mut outside, mut ghosts, mut states) = (Vec::new(), 0, 0);
    for seed in 1..=12 {
        let name = format!("sim{seed}");
        let sim = simulate_into(
            &dir,
            &scenario,
            &name,
            None,
            ["15", "0.05", "1", &seed.to_string()],
        );
        let cal = format!("{sim}/calibration.npz");
        let (_, t) = track(&dir, &scenario, &sim, &["--calibration", &cal]);
        let truth = read_json(&format!("{sim}/truth.json"));
        let n = position_nees(&t, &truth);
        ghosts += n.ghosts;
        states += n.samples + n.ghosts;
        assert!(
            n.samples > 200,
            "seed {seed}: the track holds {} of 301 snapshots near the truth",
            n.samples
        );
        eprintln!(
            "seed {seed}: mean NEES {:.2} of {} states ({:.0} independent), band [{:.2}, {:.2}], {} ghost states",
            n.mean, n.samples, n.independent, n.band.0, n.band.1, n.ghosts
        );
        if !n.inside() {
            outside.push((seed, n.mean, n.band));
        }
    }
    assert!(
        outside.len() <= 2,
        "seeds outside their 95 % band: {outside:?}"
    );
    assert!(ghosts * 100 <= states, "{ghosts} ghost states of {states}");
}
