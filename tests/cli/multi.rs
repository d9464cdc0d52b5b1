//! `track --targets auto` and `simulate-walk --walkers`/`--path` (issue 41): the CLI prints the
//! library's documents (study::track_multi, score_multi, simulate_people) bit for bit, and
//! refuses bad input with one named line.

use crate::common::cli::{fails, ok_json, ok_json_line, read_json, TempDir};
use scatterloc::error::Cancel;
use scatterloc::formats::Measurements;
use scatterloc::study::{
    score_multi, simulate_people, track_multi, walk_region, MultiSettings, MultiTruth, Walkers,
};
use scatterloc::track::multi::{people_layout, MultiKind};
use scatterloc::Model;
use serde_json::{json, Value};

fn people_scenario(dir: &TempDir) -> String {
    dir.write(
        "people.json",
        &serde_json::to_value(people_layout()).unwrap(),
    )
}

#[test]
fn walkers_and_their_multi_target_track_are_the_librarys() {
    let dir = TempDir::new();
    let s = people_scenario(&dir);
    let out = dir.path("walk");
    for seed in ["3", "4"] {
        let summary = ok_json(&[
            "simulate-walk",
            "--scenario",
            &s,
            "--out-dir",
            &out,
            "--walkers",
            "3",
            "--seed",
            seed,
        ]);
        assert_eq!(summary["steps"], json!(101));
        // The files are the library's.
        let scenario = people_layout();
        let model = Model::new(&scenario).unwrap();
        let region = walk_region(&scenario.area_m);
        let (m, truth) = simulate_people(
            &model,
            &region,
            3,
            101,
            0.1,
            0.5,
            &MultiSettings::default(),
            seed.parse().unwrap(),
        )
        .unwrap();
        let meas_path = format!("{out}/measurements.json");
        let truth_path = format!("{out}/truth.json");
        assert_eq!(read_json(&meas_path), serde_json::to_value(&m).unwrap());
        assert_eq!(
            read_json(&truth_path),
            serde_json::to_value(&truth).unwrap()
        );
        for (method, kind) in [("pmb", MultiKind::Pmb), ("gnn", MultiKind::Gnn)] {
            let doc = ok_json_line(&[
                "track",
                "--scenario",
                &s,
                "--measurements",
                &meas_path,
                "--targets",
                "auto",
                "--method",
                method,
                "--truth",
                &truth_path,
            ]);
            let settings = MultiSettings {
                method: kind,
                ..MultiSettings::default()
            };
            let lib =
                track_multi(&model, &scenario.area_m, &m, None, &settings, Cancel::NEVER).unwrap();
            let score = score_multi(&lib, &truth, 1.0).unwrap();
            let mut want = serde_json::to_value(&lib).unwrap();
            want["score"] = serde_json::to_value(&score).unwrap();
            assert_eq!(doc, want, "{method} seed {seed}");
            // Three walkers found and kept to the end, labels kept.
            let tracks = doc["tracks"].as_array().unwrap();
            let to_end = tracks.iter().filter(|t| t["end"] == "end_of_data").count();
            assert_eq!(to_end, 3, "{method} seed {seed}: {tracks:?}");
            assert!(doc["score"]["mean_gospa_m"].as_f64().unwrap() < 0.1);
        }
    }
}

#[test]
fn drawn_paths_are_walked_end_to_end_and_bad_ones_are_refused() {
    let dir = TempDir::new();
    let s = people_scenario(&dir);
    let out = dir.path("drawn");
    let paths = [[1.0, 2.0, 8.5, 7.25], [-0.5, 6.0, 9.0, 1.5]];
    let flags: Vec<String> = paths
        .iter()
        .map(|p| format!("{},{},{},{}", p[0], p[1], p[2], p[3]))
        .collect();
    let summary = ok_json(&[
        "simulate-walk",
        "--scenario",
        &s,
        "--out-dir",
        &out,
        "--path",
        &flags[0],
        "--path",
        &flags[1],
        "--seed",
        "4",
    ]);
    assert_eq!(summary["walkers"], json!(2));
    assert_eq!(summary["steps"], json!(101));
    let truth = read_json(&format!("{out}/truth.json"));
    let targets = truth["targets"].as_array().unwrap();
    assert_eq!(targets.len(), 101);
    for (k, ends) in [(0, [0, 1]), (100, [2, 3])] {
        let scan = targets[k].as_array().unwrap();
        assert_eq!(scan.len(), 2);
        for (i, p) in paths.iter().enumerate() {
            assert_eq!(scan[i]["label"], json!(i));
            for (c, e) in ends.iter().enumerate() {
                let x = scan[i]["state"][c].as_f64().unwrap();
                assert!(
                    (x - p[*e]).abs() <= 1e-12,
                    "scan {k} walker {i}: {x} vs {}",
                    p[*e]
                );
            }
        }
    }
    // The files are the library's for the same paths and seed.
    let scenario = people_layout();
    let model = Model::new(&scenario).unwrap();
    let drawn: Vec<_> = paths.iter().map(|p| ([p[0], p[1]], [p[2], p[3]])).collect();
    let (m, t) = simulate_people(
        &model,
        &walk_region(&scenario.area_m),
        Walkers::Drawn(drawn),
        101,
        0.1,
        0.5,
        &MultiSettings::default(),
        4,
    )
    .unwrap();
    assert_eq!(truth, serde_json::to_value(&t).unwrap());
    assert_eq!(
        read_json(&format!("{out}/measurements.json")),
        serde_json::to_value(&m).unwrap()
    );
    // --walkers equal to the paths is accepted; a different one, six paths, three numbers
    // and a far coordinate are refused, naming the flag.
    let base = ["simulate-walk", "--scenario", &s, "--out-dir", &out];
    let args = |extra: &[&str]| -> Vec<String> {
        base.iter().chain(extra).map(|x| x.to_string()).collect()
    };
    let a = args(&["--walkers", "1", "--path", &flags[0]]);
    ok_json(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let refused = |extra: &[&str], needles: &[&str]| {
        let a = args(extra);
        fails(&a.iter().map(String::as_str).collect::<Vec<_>>(), needles);
    };
    refused(
        &["--walkers", "3", "--path", &flags[0], "--path", &flags[1]],
        &["--walkers 3", "2 --path"],
    );
    let six: Vec<&str> = (0..6).flat_map(|_| ["--path", "1,2,3,4"]).collect();
    refused(&six, &["--path", "paths", "6", "1..=5"]);
    refused(&["--path", "1,2,3"], &["--path", "x0,y0,x1,y1"]);
    refused(&["--path", "1,2,3,nan"], &["--path", "x0,y0,x1,y1"]);
    refused(
        &["--path", "1,2,3,1e9"],
        &["--path", "paths[0].y1", "out of range"],
    );
}

#[test]
fn the_settings_flags_reach_the_document() {
    let dir = TempDir::new();
    let s = people_scenario(&dir);
    let out = dir.path("walk");
    ok_json(&[
        "simulate-walk",
        "--scenario",
        &s,
        "--out-dir",
        &out,
        "--walkers",
        "2",
        "--seed",
        "9",
        "--false-alarms",
        "2",
        "--detection-probability",
        "0.95",
        "--duration",
        "3",
    ]);
    let meas_path = format!("{out}/measurements.json");
    let m: Measurements = serde_json::from_value(read_json(&meas_path)).unwrap();
    assert_eq!(m.raw_steps.as_ref().unwrap().len(), 30);
    let doc = ok_json_line(&[
        "track",
        "--scenario",
        &s,
        "--measurements",
        &meas_path,
        "--targets",
        "auto",
        "--detection-probability",
        "0.95",
        "--clutter",
        "2",
        "--clutter-window-ns",
        "60",
        "--birth-rate",
        "0.05",
    ]);
    assert_eq!(doc["settings"]["detection_probability"], json!(0.95));
    assert_eq!(doc["settings"]["clutter"], json!(2.0));
    assert_eq!(doc["settings"]["birth_rate"], json!(0.05));
    assert_eq!(doc["targets"].as_array().unwrap().len(), 31);
    let truth: MultiTruth =
        serde_json::from_value(read_json(&format!("{out}/truth.json"))).unwrap();
    assert_eq!(truth.targets[0].len(), 2);
}

#[test]
fn bad_multi_target_input_is_named() {
    let dir = TempDir::new();
    let s = people_scenario(&dir);
    let out = dir.path("walk");
    ok_json(&[
        "simulate-walk",
        "--scenario",
        &s,
        "--out-dir",
        &out,
        "--walkers",
        "2",
        "--duration",
        "1",
    ]);
    let meas = format!("{out}/measurements.json");
    let truth = format!("{out}/truth.json");
    let base = ["track", "--scenario", &s, "--measurements", &meas];
    let with = |extra: &[&str]| -> Vec<String> {
        base.iter().chain(extra).map(|x| x.to_string()).collect()
    };
    let run = |extra: &[&str], needles: &[&str]| {
        let a = with(extra);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        fails(&a, needles);
    };
    run(&["--method", "gnn"], &["--method", "--targets auto"]);
    run(
        &["--targets", "auto", "--filter", "ukf"],
        &["--filter", "not with --targets auto"],
    );
    run(&["--targets", "auto", "--method", "jpda"], &["--method"]);
    run(
        &["--targets", "auto", "--detection-probability", "1.5"],
        &["detection-probability"],
    );
    run(&["--targets", "auto", "--clutter", "-1"], &["clutter"]);
    run(
        &["--targets", "auto", "--gospa-c", "2"],
        &["--gospa-c", "--truth"],
    );
    run(&["--targets", "some"], &["--targets"]);
    // Inconsistent target counts: a scan with one list too few.
    let mut m = read_json(&meas);
    m["raw_steps"][3].as_array_mut().unwrap().pop();
    let bad = dir.write("bad.json", &m);
    fails(
        &[
            "track",
            "--scenario",
            &s,
            "--measurements",
            &bad,
            "--targets",
            "auto",
        ],
        &["raw_steps[3]", "one per link"],
    );
    // A plain steps file has no unlabelled delays to track several targets from.
    let plain = dir.write(
        "plain.json",
        &json!({"dt_s": 0.1, "process_noise": 0.1, "initial_state": [1, 2, 0, 0],
                "initial_covariance": [[0.1,0,0,0],[0,0.1,0,0],[0,0,0.01,0],[0,0,0,0.01]],
                "steps": [[3.0e-8, null, null, null, null, null, null, null]]}),
    );
    fails(
        &[
            "track",
            "--scenario",
            &s,
            "--measurements",
            &plain,
            "--targets",
            "auto",
        ],
        &["raw_steps"],
    );
    // Thousands of clutter delays on a link: the cap, named.
    let mut flood = read_json(&meas);
    flood["raw_steps"][0][0] = Value::Array(vec![json!([5e-8, 1.0]); 5000]);
    let f = dir.write("flood.json", &flood);
    fails(
        &[
            "track",
            "--scenario",
            &s,
            "--measurements",
            &f,
            "--targets",
            "auto",
        ],
        &["detections per link", "1024"],
    );
    // A truth of the wrong shape.
    let t = dir.write(
        "t.json",
        &json!({"t_s": [0.0], "targets": [[{"label": 0}]]}),
    );
    fails(
        &[
            "track",
            "--scenario",
            &s,
            "--measurements",
            &meas,
            "--targets",
            "auto",
            "--truth",
            &t,
        ],
        &["truth"],
    );
    let _ = truth;
    // simulate-walk's walkers are capped.
    fails(
        &[
            "simulate-walk",
            "--scenario",
            &s,
            "--out-dir",
            &dir.path("w2"),
            "--walkers",
            "9",
        ],
        &["walkers", "5"],
    );
    fails(
        &[
            "simulate-walk",
            "--scenario",
            &s,
            "--out-dir",
            &dir.path("w3"),
            "--detection-probability",
            "0.5",
        ],
        &["--detection-probability", "--walkers"],
    );
}

#[test]
fn montecarlo_targets_sharded_merges_to_the_whole_run() {
    let dir = TempDir::new();
    let whole = dir.path("whole.json");
    let args = [
        "montecarlo",
        "--targets",
        "2",
        "--runs",
        "3",
        "--duration",
        "2",
        "--seed",
        "5",
    ];
    let table = crate::common::cli::run(&[&args[..], &["--json", &whole]].concat());
    assert!(
        table.status.success(),
        "{}",
        String::from_utf8_lossy(&table.stderr)
    );
    let mut parts = Vec::new();
    for i in 0..2 {
        let p = dir.path(&format!("part{i}.json"));
        let shard = format!("{i}/2");
        let out =
            crate::common::cli::run(&[&args[..], &["--shard", &shard, "--json", &p]].concat());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(read_json(&p)["study"], json!("multi-target"));
        parts.push(p);
    }
    let merged = dir.path("merged.json");
    let out = crate::common::cli::run(&["merge", &parts[0], &parts[1], "--json", &merged]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (mut a, mut b) = (read_json(&whole), read_json(&merged));
    for d in [&mut a, &mut b] {
        let o = d.as_object_mut().unwrap();
        o.remove("wall_time_s");
        o.remove("threads");
    }
    assert_eq!(a, b);
    // The document is the library's study of the same configuration.
    let cfg: scatterloc::study::MultiStudyConfig =
        serde_json::from_value(a["config"].clone()).unwrap();
    let sums = scatterloc::study::MultiStudy::run_range(
        &cfg,
        0..3,
        &mut scatterloc::study::Sequential::new(),
        &mut |_, _| {},
    )
    .unwrap();
    let doc = serde_json::to_value(scatterloc::study::multi_study_doc(&cfg, &sums)).unwrap();
    for (k, v) in doc.as_object().unwrap() {
        assert_eq!(&a[k], v, "{k}");
    }
    assert_eq!(a["methods"][0]["method"], json!("pmb"));
    assert_eq!(a["t_s"].as_array().unwrap().len(), 20);
    // Named errors.
    fails(
        &["montecarlo", "--targets", "9", "--runs", "2"],
        &["walkers", "5"],
    );
    fails(
        &["montecarlo", "--targets", "2", "--filters", "ekf,ukf"],
        &["--filters", "not with --targets"],
    );
    fails(
        &["montecarlo", "--targets", "2", "--runs", "0"],
        &["--runs"],
    );
}
