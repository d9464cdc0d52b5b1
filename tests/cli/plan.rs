//! End-to-end tests of `scatterloc plan` (issue 14, CLI part): a small plan on sensors2019 whose
//! `plan.json` improves the objective and holds a scenario every command loads, bounds and
//! spacing kept, allowed polygons kept, determinism per seed, bad input named by its flag (exit
//! 2, nothing written), the before/after figure as SVG and PNG, and Ctrl-C (exit 130, nothing
//! written).
#![cfg(not(target_arch = "wasm32"))]

use crate::common;

use std::process::Command;

use serde_json::Value;

use common::cli::{fails, interrupted, ok_json, ok_json_line, read_json, run, TempDir, BIN};
use scatterloc::present::format_length_m;
use scatterloc::scenario::presets;

/// The sensors2019 area as `--roi`: the whole scenario area.
const WHOLE_AREA: &str = "-7.5,30,-10,26";

/// The preset as a scenario file in `dir`.
fn preset_file(dir: &TempDir) -> String {
    dir.write_text("s.json", &presets::sensors2019().to_json())
}

/// `plan` on `scenario` with `extra` flags and the small, fast settings (grid 16).
fn plan_args<'a>(scenario: &'a str, out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["plan", "--scenario", scenario, "--out", out, "--grid", "16"];
    args.extend_from_slice(extra);
    args
}

/// Every node of a plan.json scenario: (name, is transmitter, [x, y]).
fn nodes(doc: &Value) -> Vec<(String, bool, [f64; 2])> {
    let s = &doc["scenario"];
    let list = |key: &str, tx: bool| {
        s[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|n| {
                let p = &n["position_m"];
                (
                    n["name"].as_str().unwrap().to_string(),
                    tx,
                    [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()],
                )
            })
            .collect::<Vec<_>>()
    };
    let mut all = list("transmitters", true);
    all.extend(list("receivers", false));
    all
}

fn inside(p: [f64; 2], r: [f64; 4]) -> bool {
    (r[0]..=r[1]).contains(&p[0]) && (r[2]..=r[3]).contains(&p[1])
}

#[test]
fn small_plan_moves_receivers_improves_p90_and_writes_a_loadable_scenario() {
    let dir = TempDir::new();
    let s = preset_file(&dir);
    let out = dir.path("plan.json");
    let args = plan_args(
        &s,
        &out,
        &[
            "--move",
            "rx",
            "--objective",
            "p90",
            "--roi",
            WHOLE_AREA,
            "--budget",
            "400",
        ],
    );
    let summary = ok_json_line(&args);
    assert_eq!(summary["out"], out.as_str());
    assert!(summary["figure"].is_null());
    assert_eq!(summary["objective"], "p90");
    let doc = read_json(&out);
    let obj = &doc["objective"];
    assert_eq!(obj["kind"], "p90");
    assert_eq!(obj["grid"], 16);
    assert_eq!(obj["maximised"], false);
    let (before, after) = (
        obj["before"].as_f64().unwrap(),
        obj["after"].as_f64().unwrap(),
    );
    assert!(after <= before, "after {after} > before {before}");
    assert!(
        after < before,
        "400 evaluations should improve p90 ({before} m)"
    );
    assert_eq!(summary["before"], obj["before"]);
    assert_eq!(summary["after"], obj["after"]);
    assert_eq!(doc["seed"], 1);
    let evaluations = doc["evaluations"].as_u64().unwrap();
    assert!((1..=400 + 64).contains(&evaluations), "{evaluations}");
    let history = doc["history"].as_array().unwrap();
    assert!(!history.is_empty());
    let mut last = 0;
    for h in history {
        let e = h["evaluations"].as_u64().unwrap();
        assert!(e > last && e <= evaluations, "{history:?}");
        last = e;
        assert!(h["best"].as_f64().unwrap() > 0.0);
    }
    assert_eq!(
        doc["moved"],
        serde_json::json!(["Rx1", "Rx2", "Rx3", "Rx4"])
    );

    // Only receivers moved, each inside the bounds (the scenario area); the transmitter stayed.
    let base = presets::sensors2019();
    let planned = nodes(&doc);
    for (name, tx, p) in &planned {
        assert!(inside(*p, [-7.5, 30.0, -10.0, 26.0]), "{name} at {p:?}");
        if *tx {
            let t = base.transmitters.iter().find(|t| &t.name == name).unwrap();
            assert_eq!(*p, t.position_m, "{name} moved");
        }
    }
    assert_eq!(doc["scenario"]["transmitters"], {
        let v: Value = serde_json::from_str(&base.to_json()).unwrap();
        v["transmitters"].clone()
    });
    // Each path runs from the base position to the planned one.
    let paths = doc["paths"].as_array().unwrap();
    assert_eq!(paths.len(), 4);
    for path in paths {
        let name = path["name"].as_str().unwrap();
        assert_eq!(path["transmitter"], false);
        let points = path["points"].as_array().unwrap();
        let xy = |v: &Value| [v[0].as_f64().unwrap(), v[1].as_f64().unwrap()];
        let r = base.receivers.iter().find(|r| r.name == name).unwrap();
        assert_eq!(xy(&points[0]), r.position_m, "{name}");
        let end = planned.iter().find(|(n, _, _)| n == name).unwrap().2;
        assert_eq!(xy(points.last().unwrap()), end, "{name}");
    }

    // The scenario loads with the other commands.
    let planned_scenario = dir.write("planned.json", &doc["scenario"]);
    let map = dir.path("map.json");
    let m = ok_json_line(&[
        "crlb-map",
        "--scenario",
        &planned_scenario,
        "--out",
        &map,
        "--nx",
        "8",
        "--ny",
        "8",
    ]);
    assert_eq!(m["unbounded_cells"], 0);
    let c = ok_json(&["crlb", "--scenario", &planned_scenario, "--at", "10,5"]);
    assert!(c["rmse_bound_m"].as_f64().unwrap() > 0.0);
}

#[test]
fn bounds_and_min_spacing_are_kept() {
    let dir = TempDir::new();
    let s = preset_file(&dir);
    let out = dir.path("plan.json");
    let bounds = [0.0, 12.0, 0.0, 12.0];
    let args = plan_args(
        &s,
        &out,
        &[
            "--move",
            "rx",
            "--objective",
            "mean",
            "--roi",
            "0,20,0,20",
            "--bounds",
            "0,12,0,12",
            "--min-spacing",
            "2",
            "--budget",
            "400",
        ],
    );
    ok_json_line(&args);
    let doc = read_json(&out);
    let all = nodes(&doc);
    for (name, tx, p) in &all {
        if !tx {
            assert!(inside(*p, bounds), "{name} at {p:?} outside {bounds:?}");
        }
    }
    for (i, (a, _, p)) in all.iter().enumerate() {
        for (b, _, q) in &all[i + 1..] {
            let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
            assert!(d >= 2.0 - 1e-9, "{a} and {b} are {d} m apart");
        }
    }
    assert!(doc["objective"]["after"].as_f64().is_some());
}

#[test]
fn allowed_polygons_are_kept() {
    let dir = TempDir::new();
    let s = preset_file(&dir);
    let out = dir.path("plan.json");
    // Two rooms: moved nodes must end in one of them.
    let rooms = [[0.0, 8.0, 14.0, 22.0], [18.0, 28.0, -8.0, 2.0]];
    let polygons: Vec<Vec<[f64; 2]>> = rooms
        .iter()
        .map(|r| vec![[r[0], r[2]], [r[1], r[2]], [r[1], r[3]], [r[0], r[3]]])
        .collect();
    let allowed = dir.write("rooms.json", &serde_json::json!(polygons));
    let args = plan_args(
        &s,
        &out,
        &[
            "--move",
            "Rx2, Rx4",
            "--objective",
            "coverage:0.05",
            "--roi",
            "0,25,-5,20",
            "--allowed",
            &allowed,
            "--budget",
            "300",
        ],
    );
    let summary = ok_json_line(&args);
    assert_eq!(summary["objective"], "coverage:0.05");
    let doc = read_json(&out);
    assert_eq!(doc["objective"]["kind"], "coverage");
    assert_eq!(doc["objective"]["maximised"], true);
    let before = doc["objective"]["before"].as_f64().unwrap();
    let after = doc["objective"]["after"].as_f64().unwrap();
    // The base layout lies outside the rooms (infeasible), so `after` need not beat `before`.
    assert!((0.0..=1.0).contains(&before) && (0.0..=1.0).contains(&after));
    assert_eq!(doc["moved"], serde_json::json!(["Rx2", "Rx4"]));
    let base = presets::sensors2019();
    for (name, _, p) in nodes(&doc) {
        if name == "Rx2" || name == "Rx4" {
            assert!(
                rooms.iter().any(|r| inside(p, *r)),
                "{name} at {p:?} in no room"
            );
        } else {
            let fixed = base
                .transmitters
                .iter()
                .map(|t| (&t.name, t.position_m))
                .chain(base.receivers.iter().map(|r| (&r.name, r.position_m)))
                .find(|(n, _)| **n == name)
                .unwrap()
                .1;
            assert_eq!(p, fixed, "{name} moved");
        }
    }
}

#[test]
fn tx_boresight_moves_and_turns_the_transmitter_only() {
    let dir = TempDir::new();
    let s = preset_file(&dir);
    let out = dir.path("plan.json");
    let args = plan_args(
        &s,
        &out,
        &[
            "--move",
            "tx-boresight",
            "--objective",
            "max",
            "--roi",
            "0,20,0,20",
            "--budget",
            "200",
        ],
    );
    ok_json_line(&args);
    let doc = read_json(&out);
    assert_eq!(doc["moved"], serde_json::json!(["Tx"]));
    assert_eq!(doc["paths"][0]["transmitter"], true);
    let base: Value = serde_json::from_str(&presets::sensors2019().to_json()).unwrap();
    assert_eq!(doc["scenario"]["receivers"], base["receivers"]);
    let after = doc["objective"]["after"].as_f64().unwrap();
    assert!(after <= doc["objective"]["before"].as_f64().unwrap());
    let boresight = doc["scenario"]["transmitters"][0]["pattern"]["boresight_deg"]
        .as_f64()
        .unwrap();
    assert!((0.0..360.0).contains(&boresight), "{boresight}");
}

#[test]
fn same_seed_gives_identical_bytes_and_another_seed_another_history() {
    let dir = TempDir::new();
    let s = preset_file(&dir);
    let run_seed = |name: &str, seed: &str| {
        let out = dir.path(name);
        let args = plan_args(
            &s,
            &out,
            &[
                "--move",
                "rx",
                "--objective",
                "p90",
                "--roi",
                WHOLE_AREA,
                "--budget",
                "300",
                "--seed",
                seed,
            ],
        );
        ok_json_line(&args);
        std::fs::read(&out).unwrap()
    };
    let a = run_seed("a.json", "7");
    let b = run_seed("b.json", "7");
    assert_eq!(a, b, "same seed, different plan.json");
    let c = run_seed("c.json", "8");
    let history = |bytes: &[u8]| serde_json::from_slice::<Value>(bytes).unwrap()["history"].clone();
    assert_ne!(
        history(&a),
        history(&c),
        "seeds 7 and 8 gave the same history"
    );
    assert_eq!(serde_json::from_slice::<Value>(&c).unwrap()["seed"], 8);
    // --preset is the same scenario as the preset's file.
    let out = dir.path("preset.json");
    ok_json_line(&[
        "plan",
        "--preset",
        "sensors2019",
        "--out",
        &out,
        "--grid",
        "16",
        "--move",
        "rx",
        "--objective",
        "p90",
        "--roi",
        WHOLE_AREA,
        "--budget",
        "300",
        "--seed",
        "7",
    ]);
    assert_eq!(std::fs::read(&out).unwrap(), a);
}

#[test]
fn bad_input_exits_2_naming_the_flag_and_writes_nothing() {
    let dir = TempDir::new();
    let s = preset_file(&dir);
    let out = dir.path("plan.json");
    let flat = dir.write("flat.json", &serde_json::json!([[[0, 0], [1, 0], [2, 0]]]));
    let two = dir.write("two.json", &serde_json::json!([[[0, 0], [1, 1]]]));
    let broken = dir.write_text("broken.json", "[[[0, 0], [1, 0], [1, 1]]");
    let not_pairs = dir.write("pairs.json", &serde_json::json!([[0, 0]]));
    let far = dir.write(
        "far.json",
        &serde_json::json!([[[100, 100], [110, 100], [110, 110]]]),
    );
    let fig = dir.path("f.pdf");
    let before = dir.files();
    let base = [
        "--move",
        "rx",
        "--objective",
        "p90",
        "--roi",
        "0,10,0,10",
        "--budget",
        "50",
    ];
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        // ROI outside the scenario area (core field `roi`).
        (
            vec!["--roi", "-20,30,-10,26"],
            vec!["--roi", "must lie inside the scenario area"],
        ),
        (vec!["--roi", "5,1,0,10"], vec!["--roi", "roi.x", "minimum"]),
        // Malformed rectangles.
        (vec!["--roi", "0,10,0"], vec!["--roi", "X0,X1,Y0,Y1"]),
        (vec!["--roi", "0,10,0,y"], vec!["--roi", "X0,X1,Y0,Y1"]),
        (vec!["--roi", "0,10,0,10,5"], vec!["--roi", "X0,X1,Y0,Y1"]),
        (vec!["--bounds", "1,2,3"], vec!["--bounds", "X0,X1,Y0,Y1"]),
        (vec!["--bounds", "5,2,0,4"], vec!["--bounds", "bounds.x"]),
        // No movable node, unknown node name.
        (vec!["--move", ","], vec!["--move", "no node to move"]),
        (vec!["--move", "Rx9"], vec!["--move", "unknown node", "Rx9"]),
        (vec!["--move", "Rx1,Nope"], vec!["--move", "Nope"]),
        // Infeasible spacing: fixed nodes too close, too many moved nodes for the bounds.
        (
            vec!["--move", "Rx1", "--min-spacing", "15"],
            vec!["--min-spacing", "fixed nodes", "Tx", "Rx2"],
        ),
        (
            vec!["--min-spacing", "30", "--bounds", "0,10,0,10"],
            vec!["--min-spacing", "4 moved nodes"],
        ),
        (vec!["--min-spacing", "-1"], vec!["--min-spacing"]),
        (vec!["--min-spacing", "x"], vec!["--min-spacing"]),
        // Bad objectives.
        (vec!["--objective", "p95"], vec!["--objective", "'p95'"]),
        (vec!["--objective", "coverage:x"], vec!["--objective"]),
        (
            vec!["--objective", "coverage:-1"],
            vec!["--objective", "threshold"],
        ),
        // Bad polygons files.
        (
            vec!["--allowed", &flat],
            vec!["--allowed", "allowed[0]", "no area"],
        ),
        (
            vec!["--allowed", &two],
            vec!["--allowed", "allowed[0]", "2 vertices", "3 to 1000"],
        ),
        (vec!["--allowed", &broken], vec!["--allowed", "broken.json"]),
        (
            vec!["--allowed", &not_pairs],
            vec!["--allowed", "pairs.json"],
        ),
        (
            vec!["--allowed", &far],
            vec!["--min-spacing / --allowed", "no layout"],
        ),
        (
            vec!["--allowed", "/nonexistent/rooms.json"],
            vec!["--allowed", "cannot read"],
        ),
        // Limits.
        (vec!["--grid", "513"], vec!["--grid", "2..=512"]),
        (vec!["--grid", "1"], vec!["--grid", "2..=512"]),
        (vec!["--budget", "0"], vec!["--budget", "1..=1000000"]),
        (vec!["--budget", "1000001"], vec!["--budget"]),
        (vec!["--seed", "-1"], vec!["--seed"]),
        // Output paths and formats.
        (vec!["--figure", &fig], vec!["--figure", ".pdf"]),
        (
            vec!["--preset", "sensors2019"],
            vec!["--preset / --scenario"],
        ),
    ];
    for (extra, needles) in &cases {
        let mut args = plan_args(&s, &out, &base);
        // A later flag replaces an earlier one's value: drop the base flags the case gives.
        for flag in extra.iter().filter(|a| a.starts_with("--")) {
            if let Some(k) = args.iter().position(|a| a == flag) {
                args.drain(k..k + 2);
            }
        }
        args.extend(extra.iter().copied());
        fails(&args, needles);
    }
    fails(
        &["plan", "--scenario", &s, "--out", &dir.path("p.txt")],
        &["required"],
    );
    fails(
        &plan_args(&s, &dir.path("p.txt"), &base),
        &["--out", ".txt"],
    );
    let mut missing = plan_args(&s, &out, &base);
    missing.drain(7..9); // --move rx
    fails(&missing, &["--move", "required"]);
    assert_eq!(dir.files(), before, "bad input wrote files");
}

/// Minimal well-formedness of an SVG document: every element opened is closed in order.
fn assert_well_formed(svg: &str) {
    let mut stack: Vec<String> = Vec::new();
    let mut rest = svg;
    while let Some(start) = rest.find('<') {
        let end = rest[start..].find('>').expect("unclosed tag") + start;
        let tag = &rest[start + 1..end];
        rest = &rest[end + 1..];
        if tag.starts_with('?') || tag.starts_with('!') {
            continue;
        }
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(
                stack.pop().as_deref(),
                Some(name.trim()),
                "mismatched </{name}>"
            );
        } else if !tag.ends_with('/') {
            let name = tag.split_whitespace().next().unwrap_or_default();
            stack.push(name.to_string());
        }
    }
    assert!(stack.is_empty(), "unclosed elements {stack:?}");
}

#[test]
fn figure_as_svg_and_png() {
    let dir = TempDir::new();
    let s = preset_file(&dir);
    let (out, svg) = (dir.path("plan.json"), dir.path("plan.svg"));
    let base = [
        "--move",
        "rx",
        "--objective",
        "p90",
        "--roi",
        "0,20,0,20",
        "--budget",
        "200",
    ];
    let mut args = plan_args(&s, &out, &base);
    args.extend(["--figure", &svg]);
    let summary = ok_json_line(&args);
    assert_eq!(summary["figure"], svg.as_str());
    let doc = read_json(&out);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg"), "{}", &text[..40]);
    assert!(text.trim_end().ends_with("</svg>"));
    assert_well_formed(&text);
    for want in [
        "Network plan",
        "before: p90 ",
        "after: p90 ",
        "Tx",
        "Rx1",
        "Rx4",
        "ROI",
        "x (m)",
        "1 cm",
        "#FF7F0E", // the paths' colour
        "<polyline",
        "<circle",
    ] {
        assert!(text.contains(want), "SVG lacks {want}");
    }
    // One colour bar: its label appears once; both captions carry the objective values.
    assert_eq!(text.matches("RMSE bound").count(), 1);
    for (which, key) in [("before", "before"), ("after", "after")] {
        let v = doc["objective"][key].as_f64().unwrap();
        let caption = format!("{which}: p90 {}", format_length_m(v, 3));
        assert!(text.contains(&caption), "SVG lacks {caption}");
    }

    let png = dir.path("plan.PNG");
    let out2 = dir.path("plan2.json");
    let mut args = plan_args(&s, &out2, &base);
    args.extend(["--figure", &png]);
    ok_json_line(&args);
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&bytes[12..16], b"IHDR");
    let be = |k: usize| u32::from_be_bytes(bytes[k..k + 4].try_into().unwrap());
    let (w, h) = (be(16), be(20));
    assert_eq!(w, 1600);
    assert!((500..=1200).contains(&h), "{h}");
    assert!(bytes.len() > 50_000, "{} bytes", bytes.len());
    // The figure does not change plan.json.
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&out2).unwrap());
}

#[test]
fn help_lists_plan() {
    let help = String::from_utf8(run(&["help"]).stdout).unwrap();
    assert!(help.contains("scatterloc plan"), "{help}");
    let text = String::from_utf8(run(&["plan", "--help"]).stdout).unwrap();
    for want in [
        "--move <rx|tx|all|tx-boresight|NAME[,NAME..]>",
        "--objective <mean|p90|max|coverage:T>",
        "--roi <X0,X1,Y0,Y1>",
        "--allowed <FILE>",
        "[default: 10000]",
        "[default: 64]",
        "§3",
    ] {
        assert!(text.contains(want), "plan --help lacks {want}: {text}");
    }
}

#[test]
fn ctrl_c_stops_without_writing_files() {
    let dir = TempDir::new();
    let s = preset_file(&dir);
    let (out, fig) = (dir.path("c.json"), dir.path("c.png"));
    let out = interrupted(
        Command::new(BIN).args(plan_args(
            &s,
            &out,
            &[
                "--move",
                "rx",
                "--objective",
                "p90",
                "--roi",
                WHOLE_AREA,
                "--budget",
                "1000000",
                "--figure",
                &fig,
            ],
        )),
        "plan",
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(out.stdout.is_empty());
    assert_eq!(err.trim().lines().count(), 1, "{err:?}");
    assert!(err.contains("cancelled"), "{err}");
    assert_eq!(dir.files(), ["s.json"], "files written");
}
