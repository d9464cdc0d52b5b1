//! End-to-end tests of the `scatterloc` binary: every subcommand's JSON, the figure files and the
//! "exit 2 + one stderr line naming the field" contract for bad input.
#![cfg(not(target_arch = "wasm32"))]

use std::path::Path;
use std::process::Command;

use scatterloc::localize::{crlb_at, Grid};
use scatterloc::scenario::Area;
use scatterloc::{scenario::presets, Model, Scenario, Vec2};
use serde_json::{json, Value};

use crate::common;

use common::cli::{fails, ok_json, run, TempDir, BIN};
use common::within_rel;

fn preset_file(dir: &TempDir, name: &str) -> String {
    let out = run(&["preset", name]);
    assert!(out.status.success());
    dir.write_text(
        &format!("{name}.json"),
        &String::from_utf8(out.stdout).unwrap(),
    )
}

fn sensors_value() -> Value {
    serde_json::from_str(&presets::sensors2019().to_json()).unwrap()
}

#[test]
fn presets_round_trip() {
    let dir = TempDir::new();
    for name in ["sensors2019", "iclgnss2019"] {
        let path = preset_file(&dir, name);
        let s = Scenario::from_json(&std::fs::read_to_string(path).unwrap()).unwrap();
        assert_eq!(s, presets::preset(name).unwrap());
    }
    fails(&["preset", "nope"], &["nope", "sensors2019"]);
    fails(&["preset"], &["preset"]);
}

#[test]
fn crlb_matches_spec_check_7() {
    let dir = TempDir::new();
    let s = preset_file(&dir, "sensors2019");
    let v = ok_json(&["crlb", "--scenario", &s, "--at", "10,0"]);
    assert_eq!(v["bounded"], json!(true));
    assert_eq!(v["position_m"], json!([10.0, 0.0]));
    let rmse = v["rmse_bound_m"].as_f64().unwrap();
    assert!(within_rel(rmse, 0.00792, 1e-3), "{rmse}");
    let (sx, sy) = (
        v["sigma_x_m"].as_f64().unwrap(),
        v["sigma_y_m"].as_f64().unwrap(),
    );
    assert!(within_rel((sx * sx + sy * sy).sqrt(), rmse, 1e-12));
    let f = &v["fim_per_m2"];
    assert_eq!(f[0][1], f[1][0]);
    let links = v["links"].as_array().unwrap();
    let want = [
        ("Rx1", 33.51),
        ("Rx2", 39.18),
        ("Rx3", 34.13),
        ("Rx4", 43.16),
    ];
    assert_eq!(links.len(), 4);
    for (l, (rx, snr)) in links.iter().zip(want) {
        assert_eq!(l["tx"], "Tx");
        assert_eq!(l["rx"], rx);
        let got = l["snr_db"].as_f64().unwrap();
        assert!((got - snr).abs() <= 0.01, "{rx}: {got}");
        assert!(l["sigma_delay_s"].as_f64().unwrap() > 0.0);
    }
    let e = &v["ellipse_1sigma"];
    assert!(e["semi_major_m"].as_f64().unwrap() >= e["semi_minor_m"].as_f64().unwrap());
    for (at, cm) in [("4,1", 0.426), ("20,10", 4.864), ("0,20", 17.69)] {
        let v = ok_json(&["crlb", "--scenario", &s, "--at", at]);
        let got = v["rmse_bound_m"].as_f64().unwrap() * 100.0;
        assert!(within_rel(got, cm, 1e-3), "{at}: {got} cm");
    }
}

fn one_link_scenario(dir: &TempDir) -> String {
    let mut v = sensors_value();
    v["receivers"] = json!([{"name": "Rx", "position_m": [10.0, 0.0], "gain_dbi": 8.0}]);
    dir.write_text("one.json", &v.to_string())
}

#[test]
fn crlb_unbounded_gives_nulls() {
    let dir = TempDir::new();
    let s = one_link_scenario(&dir);
    let out = run(&["crlb", "--scenario", &s, "--at", "3,4"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(!text.to_lowercase().contains("nan") && !text.contains("inf"));
    let v: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["bounded"], json!(false));
    for k in ["sigma_x_m", "sigma_y_m", "rmse_bound_m", "ellipse_1sigma"] {
        assert!(v[k].is_null(), "{k}");
    }
    assert!(v["fim_per_m2"][0][0].as_f64().unwrap() > 0.0);
    assert_eq!(v["links"].as_array().unwrap().len(), 1);
}

#[test]
fn crlb_map_json_matches_core() {
    let dir = TempDir::new();
    let s = preset_file(&dir, "sensors2019");
    let out = dir.path("map.json");
    let args = [
        "crlb-map",
        "--scenario",
        &s,
        "--out",
        &out,
        "--nx",
        "16",
        "--ny",
        "12",
        "--x-min",
        "-2",
        "--y-max=14",
    ];
    let summary = ok_json(&args);
    assert_eq!(summary["nx"], 16);
    assert_eq!(summary["ny"], 12);
    assert_eq!(summary["format"], "json");
    assert_eq!(summary["unbounded_cells"], 0);
    assert!(summary["compute_ms"].as_f64().is_some());
    let paths: Vec<&str> = scatterloc::native::map_paths()
        .iter()
        .map(|p| p.name())
        .collect();
    assert!(
        paths.contains(&summary["kernel"].as_str().unwrap()),
        "{} not among {paths:?}",
        summary["kernel"]
    );
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let (xs, ys, rows) = (
        doc["x_m"].as_array().unwrap(),
        doc["y_m"].as_array().unwrap(),
        doc["rmse_bound_m"].as_array().unwrap(),
    );
    assert_eq!((xs.len(), ys.len(), rows.len()), (16, 12, 12));
    let area = Area {
        x: [-2.0, 30.0],
        y: [-10.0, 14.0],
    };
    let grid = Grid::new(area, 16, 12).unwrap();
    let model = Model::new(&presets::sensors2019()).unwrap();
    for (j, row) in rows.iter().enumerate() {
        let row = row.as_array().unwrap();
        assert_eq!(row.len(), 16);
        for (i, cell) in row.iter().enumerate() {
            let (x, y) = (grid.x(i), grid.y(j));
            assert_eq!(xs[i].as_f64().unwrap(), x);
            assert_eq!(ys[j].as_f64().unwrap(), y);
            let want = crlb_at(&model, Vec2::new(x, y)).bound.unwrap().rmse_m;
            let got = cell.as_f64().unwrap();
            assert!(within_rel(got, want, 1e-12), "({i},{j}): {got} vs {want}");
        }
    }
    let min = summary["min_m"].as_f64().unwrap();
    assert!(rows
        .iter()
        .flat_map(|r| r.as_array().unwrap())
        .all(|c| c.as_f64().unwrap() >= min));
}

#[test]
fn crlb_map_json_unbounded_cells_are_null() {
    let dir = TempDir::new();
    let s = one_link_scenario(&dir);
    let out = dir.path("one_map.json");
    let summary = ok_json(&[
        "crlb-map",
        "--scenario",
        &s,
        "--out",
        &out,
        "--nx",
        "4",
        "--ny",
        "3",
    ]);
    assert_eq!(summary["unbounded_cells"], 12);
    assert!(summary["min_m"].is_null() && summary["max_m"].is_null());
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let rows = doc["rmse_bound_m"].as_array().unwrap();
    assert!(rows
        .iter()
        .all(|r| r.as_array().unwrap().iter().all(Value::is_null)));
}

#[test]
fn crlb_map_svg_has_the_figure() {
    let dir = TempDir::new();
    let s = preset_file(&dir, "sensors2019");
    let out = dir.path("map.svg");
    let summary = ok_json(&[
        "crlb-map",
        "--scenario",
        &s,
        "--out",
        &out,
        "--nx",
        "64",
        "--ny",
        "64",
    ]);
    assert_eq!(summary["format"], "svg");
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..40]);
    assert!(svg.trim_end().ends_with("</svg>"));
    for name in [
        "Tx",
        "Rx1",
        "Rx2",
        "Rx3",
        "Rx4",
        "sensors2019",
        "x (m)",
        "y (m)",
        "1 cm",
    ] {
        assert!(svg.contains(name), "missing {name}");
    }
    // The map is one embedded PNG of 64 × 64 pixels (one per cell, the top row the highest y),
    // each the colour of the core's bound at that cell on the figure's scale (the finite range).
    let png = crate::svg::embedded_png("crlb-map svg", &svg);
    let img = image::load_from_memory_with_format(&png, image::ImageFormat::Png)
        .unwrap()
        .to_rgb8();
    assert_eq!((img.width(), img.height()), (64, 64));
    let sc = presets::sensors2019();
    let model = Model::new(&sc).unwrap();
    let grid = Grid::new(sc.area_m, 64, 64).unwrap();
    let mut v = vec![0.0; grid.len()];
    scatterloc::localize::crlb_map(&model, &grid, &mut v).unwrap();
    let scale = scatterloc::present::LogScale::spanning(&v).unwrap();
    for j in 0..64 {
        for i in 0..64 {
            let p = img.get_pixel(i as u32, 63 - j as u32).0;
            assert_eq!(p, scale.color(v[j * 64 + i]), "cell ({i}, {j})");
        }
    }
    // No rectangle per cell any more: the colour bar's runs and the labels' boxes only.
    let rects = svg.matches("<rect").count();
    assert!(rects < 1000, "{rects} rectangles");
}

fn png_size(path: &Path) -> (u32, u32, usize) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&bytes[12..16], b"IHDR");
    let be = |k: usize| u32::from_be_bytes([bytes[k], bytes[k + 1], bytes[k + 2], bytes[k + 3]]);
    (be(16), be(20), bytes.len())
}

#[test]
fn crlb_map_png_is_a_png() {
    let dir = TempDir::new();
    let s = preset_file(&dir, "sensors2019");
    let out = dir.path("map.png");
    let summary = ok_json(&[
        "crlb-map",
        "--scenario",
        &s,
        "--out",
        &out,
        "--nx",
        "96",
        "--ny",
        "96",
    ]);
    assert_eq!(summary["format"], "png");
    let (w, h, len) = png_size(Path::new(&out));
    assert_eq!(w, 1000);
    assert!((600..=1200).contains(&h), "{h}");
    assert!(len > 30_000, "{len} bytes");
    let out2 = dir.path("small.PNG");
    let args = [
        "crlb-map",
        "--scenario",
        &s,
        "--out",
        &out2,
        "--nx",
        "8",
        "--ny",
        "8",
        "--width",
        "600",
        "--height",
        "500",
    ];
    ok_json(&args);
    assert_eq!(png_size(Path::new(&out2)).0, 600);
    assert_eq!(png_size(Path::new(&out2)).1, 500);
}

#[test]
fn crlb_map_bad_arguments() {
    let dir = TempDir::new();
    let s = preset_file(&dir, "sensors2019");
    let out = dir.path("m.json");
    fails(
        &["crlb-map", "--scenario", &s, "--out", &dir.path("m.txt")],
        &["--out", ".txt"],
    );
    fails(
        &["crlb-map", "--scenario", &s, "--out", &out, "--nx", "1"],
        &["--nx"],
    );
    fails(
        &["crlb-map", "--scenario", &s, "--out", &out, "--ny", "-3"],
        &["--ny"],
    );
    fails(
        &["crlb-map", "--scenario", &s, "--out", &out, "--x-min", "40"],
        &["--x-min", "40"],
    );
    fails(
        &[
            "crlb-map",
            "--scenario",
            &s,
            "--out",
            &out,
            "--y-max",
            "nan",
        ],
        &["--y-max"],
    );
    fails(&["crlb-map", "--scenario", &s], &["--out"]);
    fails(
        &[
            "crlb-map",
            "--scenario",
            &s,
            "--out",
            &out,
            "--nx",
            "4096",
            "--ny",
            "4096",
        ],
        &["--nx", "--ny"],
    );
    fails(
        &[
            "crlb-map",
            "--scenario",
            &s,
            "--out",
            &dir.path("no/such/dir/m.png"),
        ],
        &["--out", "cannot write"],
    );
    assert!(!Path::new(&out).exists());
}

/// Writes a delays file for `truth` with noise-free delays from the core, dropping `missing`.
fn delays_file(dir: &TempDir, truth: Vec2, missing: &[usize], extra: Value) -> String {
    let model = Model::new(&presets::sensors2019()).unwrap();
    let delays: Vec<Value> = model
        .network
        .delays(truth)
        .iter()
        .enumerate()
        .map(|(p, d)| {
            if missing.contains(&p) {
                Value::Null
            } else {
                json!(d)
            }
        })
        .collect();
    let mut v = json!({"delays_s": delays, "sigma_s": model.sigma_delays(truth)});
    for (k, x) in extra.as_object().unwrap() {
        v[k] = x.clone();
    }
    dir.write_text(&format!("d{}.json", missing.len()), &v.to_string())
}

fn assert_fix(v: &Value, truth: Vec2, links: u64) {
    let p = &v["position_m"];
    let err = Vec2::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap()) - truth;
    assert!(err.norm() < 1e-6, "{v}");
    assert_eq!(v["links_used"], links);
    assert_eq!(v["converged"], true);
    assert!(v["termination"].is_string());
    assert!(v["cost"].as_f64().unwrap() >= 0.0);
}

#[test]
fn locate_noise_free() {
    let dir = TempDir::new();
    let s = preset_file(&dir, "sensors2019");
    for truth in [
        Vec2::new(4.0, 1.0),
        Vec2::new(12.3, -2.7),
        Vec2::new(-4.0, 20.5),
    ] {
        let d = delays_file(&dir, truth, &[], json!({}));
        let v = ok_json(&["locate", "--scenario", &s, "--delays", &d]);
        assert_fix(&v, truth, 4);
        assert!(v["covariance_m2"][0][0].as_f64().unwrap() > 0.0);
    }
    let truth = Vec2::new(4.0, 1.0);
    let d = delays_file(
        &dir,
        truth,
        &[],
        json!({"initial_m": [6.0, -1.0], "sigma_s": 3e-11}),
    );
    let v = ok_json(&["locate", "--scenario", &s, "--delays", &d]);
    assert_fix(&v, truth, 4);
    assert_eq!(v["start_m"], json!([6.0, -1.0]));
}

#[test]
fn locate_with_missing_links() {
    let dir = TempDir::new();
    let s = preset_file(&dir, "sensors2019");
    let truth = Vec2::new(8.0, 3.0);
    let d = delays_file(&dir, truth, &[2], json!({}));
    assert_fix(
        &ok_json(&["locate", "--scenario", &s, "--delays", &d]),
        truth,
        3,
    );
    let d = delays_file(&dir, truth, &[0, 3], json!({}));
    fails(&["locate", "--scenario", &s, "--delays", &d], &["delays_s"]);
}

#[test]
fn locate_bad_delays_files() {
    let dir = TempDir::new();
    let s = preset_file(&dir, "sensors2019");
    let cases = [
        (
            r#"{"delays_s": [1e-7, 1e-7, 1e-7, 1e-7], "sigma_s": 1e-10, "inital_m": [0, 0]}"#,
            "inital_m",
        ),
        (
            r#"{"delays_s": [1e-7, 1e-7, 1e-7], "sigma_s": 1e-10}"#,
            "delays_s",
        ),
        (
            r#"{"delays_s": [1e-7, 1e-7, 1e-7, 1e-7], "sigma_s": -1}"#,
            "sigma_s",
        ),
        (
            r#"{"delays_s": [1e-7, 1e-7, 1e-7, 1e-7], "sigma_s": [1e-10, 0, 1e-10, 1e-10]}"#,
            "sigma_s[1]",
        ),
        (
            r#"{"delays_s": [1e-7, 1e-7, 1e-7, 1e-7], "sigma_s": "x"}"#,
            "sigma_s",
        ),
        (
            r#"{"delays_s": [1e-7, 1e999, 1e-7, 1e-7], "sigma_s": 1e-10}"#,
            "delays_s[1]",
        ),
        (r#"{"sigma_s": 1e-10}"#, "delays_s"),
        (r#"[1, 2"#, "invalid JSON"),
    ];
    for (text, field) in cases {
        let d = dir.write_text("bad_delays.json", text);
        fails(
            &["locate", "--scenario", &s, "--delays", &d],
            &["--delays", field],
        );
    }
    fails(&["locate", "--scenario", &s], &["--delays"]);
    fails(
        &[
            "locate",
            "--scenario",
            &s,
            "--delays",
            &dir.path("missing.json"),
        ],
        &["--delays", "cannot read"],
    );
}

#[test]
fn broken_scenario_files_name_the_field() {
    let dir = TempDir::new();
    let base = sensors_value();
    let edit = |f: &dyn Fn(&mut Value)| {
        let mut v = base.clone();
        f(&mut v);
        serde_json::to_string_pretty(&v).unwrap()
    };
    let mut typo = base.clone();
    let rx = typo.as_object_mut().unwrap().remove("receivers").unwrap();
    typo["recievers"] = rx;
    let cases: Vec<(String, Vec<&str>)> = vec![
        ("{\"name\": \"x\",".into(), vec!["invalid JSON"]),
        ("".into(), vec!["invalid JSON"]),
        (typo.to_string(), vec!["recievers"]),
        (
            edit(&|v| v["radio"]["bandwidth_hz"] = json!(-1.0)),
            vec!["radio.bandwidth_hz"],
        ),
        (
            edit(&|v| v["receivers"][1]["name"] = json!("Rx1")),
            vec!["duplicate", "Rx1"],
        ),
        (
            edit(&|v| v["links"] = json!([["Tx", "Rx1"], ["Tx", "Rx9"]])),
            vec!["links[1][1]", "Rx9"],
        ),
        (
            edit(&|v| v["area_m"]["x"] = json!([30.0, -7.5])),
            vec!["area_m.x"],
        ),
        (
            edit(&|v| v["target"]["rcs_m2"] = json!(0.0)),
            vec!["target.rcs_m2"],
        ),
        (edit(&|v| v["receivers"] = json!([])), vec!["receivers"]),
        (
            edit(&|v| v["radio"]["bandwidth_hz"] = json!(123456789.0))
                .replace("123456789.0", "1e999"),
            vec!["radio.bandwidth_hz"],
        ),
        (
            edit(&|v| v["receivers"][2]["position_m"][1] = json!(123456789.0))
                .replace("123456789.0", "-1e999"),
            vec!["receivers[2].position_m[1]"],
        ),
    ];
    for (i, (text, needles)) in cases.iter().enumerate() {
        let path = dir.write_text(&format!("bad{i}.json"), text);
        let mut n = needles.clone();
        n.push("--scenario");
        fails(&["crlb", "--scenario", &path, "--at", "1,2"], &n);
        fails(
            &[
                "crlb-map",
                "--scenario",
                &path,
                "--out",
                &dir.path("x.json"),
            ],
            &n,
        );
    }
}

#[test]
fn bad_command_lines() {
    let dir = TempDir::new();
    let s = preset_file(&dir, "sensors2019");
    for at in ["1", "a,b", "1,2,3", "nan,1", "1,inf", ""] {
        fails(&["crlb", "--scenario", &s, "--at", at], &["--at", "X,Y"]);
    }
    fails(&["crlb", "--scenario", &s], &["--at"]);
    fails(&["crlb", "--scenario", &s, "--at"], &["--at"]);
    fails(&["crlb", "--at", "1,2"], &["--scenario"]);
    fails(
        &["crlb", "--scenario", &s, "--at", "1,2", "--at", "3,4"],
        &["--at"],
    );
    fails(
        &["crlb", "--scenario", &s, "--at", "1,2", "--bogus", "1"],
        &["--bogus"],
    );
    fails(
        &["crlb", "--scenario", &s, "--at", "1,2", "extra"],
        &["extra"],
    );
    fails(
        &["crlb", "--scenario", &dir.path("nope.json"), "--at", "1,2"],
        &["--scenario: cannot read", "nope.json"],
    );
    fails(&["frobnicate"], &["frobnicate"]);
    fails(&["--frobnicate"], &["--frobnicate"]);
    fails(&[], &["subcommand"]);
}

#[test]
fn help_and_version() {
    for args in [&["help"][..], &["--help"], &["-h"], &["crlb", "--help"]] {
        let out = run(args);
        assert!(out.status.success());
        let text = String::from_utf8(out.stdout).unwrap();
        for cmd in ["preset", "crlb --scenario", "crlb-map", "locate"] {
            // `crlb --help`'s usage line lists its optional flags first (`--free-z`, `--height`).
            let usage = cmd == "crlb --scenario" && text.contains("crlb [OPTIONS] --scenario");
            assert!(text.contains(cmd) || usage, "{args:?}: {cmd}");
        }
    }
    let out = run(&["--version"]);
    assert!(out.status.success());
    assert!(String::from_utf8(out.stdout)
        .unwrap()
        .starts_with("scatterloc "));
}

#[test]
fn scenario_from_stdin() {
    use std::io::Write;
    let mut child = Command::new(BIN)
        .args(["crlb", "--scenario", "-", "--at", "10,0"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(presets::sensors2019().to_json().as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(within_rel(
        v["rmse_bound_m"].as_f64().unwrap(),
        0.00792,
        1e-3
    ));
}

#[test]
fn version_flag() {
    for flag in ["--version", "-V"] {
        let out = run(&[flag]);
        assert_eq!(out.status.code(), Some(0));
        let text = String::from_utf8(out.stdout).unwrap();
        assert_eq!(text, format!("scatterloc {}\n", env!("CARGO_PKG_VERSION")));
    }
}

#[test]
fn completions_for_bash_zsh_fish() {
    for shell in ["bash", "zsh", "fish"] {
        let out = run(&["completions", shell]);
        assert_eq!(out.status.code(), Some(0), "{shell}");
        let script = String::from_utf8(out.stdout).unwrap();
        assert!(script.len() > 500, "{shell}: {script}");
        for word in [
            "scatterloc",
            "crlb-map",
            "simulate-walk",
            "montecarlo",
            "plan",
            "mtl",
            "scenario",
        ] {
            assert!(script.contains(word), "{shell} script lacks {word}");
        }
    }
    fails(&["completions", "tcsh"], &["tcsh", "bash, zsh or fish"]);
    fails(&["completions"], &["completions"]);
}

#[test]
fn typos_get_a_suggestion_on_one_line() {
    fails(
        &["montecarol"],
        &[
            "unknown subcommand 'montecarol'",
            "did you mean 'montecarlo'?",
        ],
    );
    fails(
        &["mtl", "locat"],
        &["mtl", "'locat'", "did you mean 'locate'?"],
    );
    fails(
        &["mtl"],
        &["mtl: missing subcommand", "locate, table2 or roc"],
    );
    fails(
        &["montecarlo", "--runz", "3"],
        &["unexpected argument '--runz'", "did you mean '--runs'?"],
    );
    fails(
        &["track", "--scenari", "s.json"],
        &["'--scenari'", "did you mean '--scenario'?"],
    );
    fails(
        &[
            "track",
            "--scenario",
            "s.json",
            "--measurements",
            "m.json",
            "--association",
            "gatd",
        ],
        &["--association", "'gatd'", "did you mean 'gated'?"],
    );
}

#[test]
fn every_command_has_help_citing_the_spec() {
    let commands: [&[&str]; 15] = [
        &["preset"],
        &["crlb"],
        &["crlb-map"],
        &["locate"],
        &["track"],
        &["calibrate"],
        &["simulate-walk"],
        &["montecarlo"],
        &["pcrlb"],
        &["plan"],
        &["mtl"],
        &["mtl", "locate"],
        &["mtl", "table2"],
        &["mtl", "roc"],
        &["merge"],
    ];
    for cmd in commands {
        for how in ["--help", "-h"] {
            let mut args = cmd.to_vec();
            args.push(how);
            let out = run(&args);
            assert_eq!(out.status.code(), Some(0), "{args:?}");
            assert!(out.stderr.is_empty(), "{args:?}");
            let text = String::from_utf8(out.stdout).unwrap();
            assert!(
                text.contains("spec") && text.contains('§'),
                "{args:?}: {text}"
            );
            assert!(
                text.contains(&format!("scatterloc {}", cmd.join(" "))),
                "{args:?}"
            );
        }
        // `help COMMAND` is the long help, as `COMMAND --help`.
        let mut args = vec!["help"];
        args.extend(cmd);
        let out = run(&args);
        assert_eq!(out.status.code(), Some(0), "{args:?}");
        let mut long = cmd.to_vec();
        long.push("--help");
        assert_eq!(out.stdout, run(&long).stdout, "{args:?}");
    }
    // Flags name their unit and default.
    let text = String::from_utf8(run(&["montecarlo", "--help"]).stdout).unwrap();
    for want in [
        "--runs <N>",
        "[default: 5000]",
        "--dt <T>",
        "s [default: 2.048e-3",
    ] {
        assert!(
            text.contains(want),
            "montecarlo --help lacks {want}: {text}"
        );
    }
}

/// Issue 12 item 4: output paths. A symbolic link, a FIFO or a device at an output path is
/// refused with a named error and left as it was (an atomic rename would replace it and never
/// write its target); an empty path and an `--out-dir` naming a file exit 2; a regular file is
/// still replaced.
#[cfg(unix)]
#[test]
fn output_paths_that_are_not_regular_files_are_refused_and_kept() {
    let dir = TempDir::new();
    let scenario = dir.write_text("s.json", &presets::sensors2019().to_json());
    let target = dir.write_text("target.json", "keep me");
    let link = dir.path("link.json");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let map = |out: &str| {
        [
            "crlb-map",
            "--scenario",
            &scenario,
            "--out",
            out,
            "--nx",
            "4",
            "--ny",
            "4",
        ]
        .map(String::from)
    };
    let args = map(&link);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    fails(&args, &["--out", "link.json", "symbolic link", "refusing"]);
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep me");

    let fifo = dir.path("fifo.json");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        let args = map(&fifo);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        fails(&args, &["--out", "fifo.json", "not a regular file"]);
        assert!(!std::fs::symlink_metadata(&fifo).unwrap().is_file());
    }
    // A device (the issue's case: run as root, `calibrate --out /dev/full` replaced the node).
    let walk = dir.path("walk");
    let w = [
        "simulate-walk",
        "--scenario",
        &scenario,
        "--out-dir",
        &walk,
        "--duration",
        "1",
    ];
    assert!(run(&[&w[..], &["--calibration-snapshots", "5"]].concat())
        .status
        .success());
    let snaps = format!("{walk}/calibration_snapshots.json");
    fails(
        &[
            "calibrate",
            "--scenario",
            &scenario,
            "--snapshots",
            &snaps,
            "--out",
            "/dev/null",
        ],
        &["--out", "/dev/null", "a device, not a regular file"],
    );
    assert!(!std::fs::metadata("/dev/null").unwrap().is_file());

    let args = map("");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    fails(&args, &["--out"]);
    let file = dir.write_text("afile", "x");
    for (out_dir, needle) in [(file.as_str(), "not a directory"), ("", "empty")] {
        fails(
            &[
                "simulate-walk",
                "--scenario",
                &scenario,
                "--out-dir",
                out_dir,
                "--duration",
                "1",
            ],
            &["--out-dir", needle],
        );
    }
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
    // A regular file is replaced, atomically, as before.
    let regular = dir.write_text("map.json", "old");
    let args = map(&regular);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    assert!(run(&args).status.success());
    assert!(std::fs::read_to_string(&regular)
        .unwrap()
        .contains("rmse_bound_m"));
}

/// Issue 12 item 11: a scenario with a UTF-8 byte-order mark (as some editors write it) is read
/// like the same file without one.
#[test]
fn a_utf8_bom_scenario_is_accepted() {
    let dir = TempDir::new();
    let text = presets::sensors2019().to_json();
    let plain = dir.write_text("plain.json", &text);
    let bom = dir.write_text("bom.json", &format!("\u{feff}{text}"));
    let a = ok_json(&["crlb", "--scenario", &plain, "--at", "3,4"]);
    let b = ok_json(&["crlb", "--scenario", &bom, "--at", "3,4"]);
    assert_eq!(a, b);
}
