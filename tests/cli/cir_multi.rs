//! `cir simulate` with a further walker and `cir track --targets auto` (issue 41 §2): the
//! scene's `others` simulated and written to truth.json; the multi-target track of the
//! recording is the library's ([`scatterloc::study::cir_track_multi`] on the front end's
//! estimates) bit for bit, and so is its score against the walkers' truth; named errors for
//! the flags of one mode given in the other.

use scatterloc::channel::{ChannelScene, SimulationRequest};
use scatterloc::error::Cancel;
use scatterloc::scenario::presets;
use scatterloc::study::{
    cir_track_multi, estimate_recording, recording_multi_settings, score_multi, walkers_truth,
    ChannelRequest, Sequential, RECORDING_EXTENT_SIGMA_M,
};
use scatterloc::Model;
use serde_json::Value;

use crate::common::cli::{fails, ok_json_line, read_json, TempDir};

/// `cir simulate` of the crossing scene, seed `seed`, into `dir/sim`: the scenario's path
/// and the output directory.
fn simulate(dir: &TempDir, seed: &str) -> (String, String) {
    let scenario = crate::cir::scenario(dir);
    let scene = dir.write("scene.json", &crate::crossing::crossing_scene());
    let out = dir.path("sim");
    let s = ok_json_line(&[
        "cir",
        "simulate",
        "--scenario",
        &scenario,
        "--scene",
        &scene,
        "--out-dir",
        &out,
        "--seed",
        seed,
    ]);
    assert_eq!(s["links"], 4);
    (scenario, out)
}

/// `cir simulate` writes the further walker: truth.json's `others` holds its state per
/// snapshot (the library's simulation of the same request, bit for bit), scene.json keeps
/// it; `states` is the main walker's.
#[test]
fn simulate_writes_the_further_walkers() {
    let dir = TempDir::new();
    let (_, sim) = simulate(&dir, "4");
    let truth = read_json(&format!("{sim}/truth.json"));
    let scenario = presets::preset("sensors2019").unwrap();
    let model = Model::new(&scenario).unwrap();
    let scene: ChannelScene = serde_json::from_value(crate::crossing::crossing_scene()).unwrap();
    let lib = SimulationRequest {
        scene: Some(scene.clone()),
        seed: 4,
        ..SimulationRequest::default()
    }
    .run(&scenario, &model, Cancel::NEVER)
    .unwrap();
    assert_eq!(truth, serde_json::to_value(lib.truth_file()).unwrap());
    let others = truth["others"].as_array().unwrap();
    assert_eq!(others.len(), 1);
    let n = truth["t_s"].as_array().unwrap().len();
    assert_eq!(others[0].as_array().unwrap().len(), n);
    // Both walkers start where their walks do.
    assert_eq!(truth["states"][0][0], 13.0);
    assert_eq!(others[0][0][0], 12.09);
    let written: ChannelScene =
        serde_json::from_value(read_json(&format!("{sim}/scene.json"))).unwrap();
    assert_eq!(written, scene);
}

/// `cir track --targets auto` of seed 1 with the truth: TRACK.json is the library's track
/// and score of the same recording, bit for bit, plus the settings it used; the summary
/// names the method, the labels and the score.
#[test]
fn track_targets_auto_is_the_library_track() {
    let dir = TempDir::new();
    let (scenario_path, sim) = simulate(&dir, "1");
    let out = dir.path("track.json");
    let rec = format!("{sim}/recording.npz");
    let cal = format!("{sim}/calibration.npz");
    let truth_path = format!("{sim}/truth.json");
    let s = ok_json_line(&[
        "cir",
        "track",
        "--targets",
        "auto",
        "--scenario",
        &scenario_path,
        "--cir",
        &rec,
        "--calibration",
        &cal,
        "--truth",
        &truth_path,
        "--out",
        &out,
    ]);
    let doc = read_json(&out);
    // The library on the same recording (simulated again: `cir simulate` is the library's).
    let scenario = presets::preset("sensors2019").unwrap();
    let model = Model::new(&scenario).unwrap();
    let sim = SimulationRequest {
        scene: Some(serde_json::from_value(crate::crossing::crossing_scene()).unwrap()),
        seed: 1,
        ..SimulationRequest::default()
    }
    .run(&scenario, &model, Cancel::NEVER)
    .unwrap();
    let req = ChannelRequest::default();
    let (statics, est) = estimate_recording(
        &model,
        scenario.radio.bandwidth_hz,
        &sim.recording,
        Some(&sim.calibration),
        &req.front_end(sim.recording.synchronized),
        &mut Sequential::new(),
        &|_| {},
    )
    .unwrap();
    let track = cir_track_multi(
        &model,
        &scenario.area_m,
        &statics.calibration,
        &est,
        &recording_multi_settings(model.link_count()),
        req.process_noise,
        RECORDING_EXTENT_SIGMA_M,
        Cancel::NEVER,
    )
    .unwrap();
    let truth = walkers_truth(&sim.truth.t_s, &sim.truth.states, &sim.others).unwrap();
    let score = score_multi(&track, &truth, 1.0).unwrap();
    let mut want = serde_json::to_value(&track).unwrap();
    want["score"] = serde_json::to_value(&score).unwrap();
    want["extent_sigma_m"] = RECORDING_EXTENT_SIGMA_M.into();
    want["statics"] = "background".into();
    want["delay_reference"] = "absolute".into();
    assert_eq!(doc, want);
    assert_eq!(doc["method"], "pmb");
    assert_eq!(doc["settings"]["detection_probability"], 0.7);
    assert_eq!(s["method"], "pmb");
    assert_eq!(s["labels"], doc["tracks"].as_array().unwrap().len());
    assert_eq!(s["score"]["switches"], score.switches);
    assert_eq!(s["score"]["mean_gospa_m"], score.mean_gospa_m);
    assert_eq!(s["snapshots"], sim.truth.t_s.len());
    // Both walkers are tracked: at least two labels, two targets in most scans.
    let two = doc["targets"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|t| t.as_array().unwrap().len() == 2)
        .count();
    assert!(2 * two > sim.truth.t_s.len(), "two targets in {two} scans");

    // The flags set the settings: --method gnn with P_D and clutter of the delay-level
    // defaults.
    let gnn = dir.path("gnn.json");
    ok_json_line(&[
        "cir",
        "track",
        "--targets",
        "auto",
        "--method",
        "gnn",
        "--detection-probability",
        "0.9",
        "--clutter",
        "5",
        "--clutter-window-ns",
        "60",
        "--birth-rate",
        "0.02",
        "--extent-sigma-m",
        "0.25",
        "--scenario",
        &scenario_path,
        "--cir",
        &rec,
        "--calibration",
        &cal,
        "--out",
        &gnn,
    ]);
    let g = read_json(&gnn);
    assert_eq!(g["method"], "gnn");
    let set: &Value = &g["settings"];
    assert_eq!(set["detection_probability"], 0.9);
    assert_eq!(set["clutter"], 5.0);
    // ns → s as `track --targets auto` converts it.
    assert_eq!(set["clutter_window_s"], 60.0 * 1e-9);
    assert_eq!(set["birth_rate"], 0.02);
    assert_eq!(g["extent_sigma_m"], 0.25);
    assert!(g.get("score").is_none());
}

/// The flags of one mode in the other are named errors (exit 2, nothing written).
#[test]
fn flags_of_the_other_mode_are_named() {
    let dir = TempDir::new();
    let scenario = crate::cir::scenario(&dir);
    let (rec, out) = (dir.path("missing.npz"), dir.path("o.json"));
    let base = [
        "cir",
        "track",
        "--scenario",
        &scenario,
        "--cir",
        &rec,
        "--out",
        &out,
    ];
    let with = |extra: &[&str], needles: &[&str]| {
        let mut a = base.to_vec();
        a.extend_from_slice(extra);
        fails(&a, needles);
    };
    with(&["--method", "gnn"], &["--method", "--targets auto"]);
    with(&["--clutter", "3"], &["--clutter", "--targets auto"]);
    with(&["--gospa-c", "2"], &["--gospa-c", "--targets auto"]);
    with(
        &["--targets", "auto", "--filter", "ukf"],
        &["--filter", "not with --targets auto"],
    );
    with(
        &["--targets", "auto", "--seed", "3"],
        &["--seed", "not with --targets auto"],
    );
    with(
        &["--targets", "auto", "--gospa-c", "2"],
        &["--gospa-c", "--truth"],
    );
    with(
        &["--targets", "auto", "--detection-probability", "1.5"],
        &["--detection-probability"],
    );
    assert!(!std::path::Path::new(&out).exists());
}
