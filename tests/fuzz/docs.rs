//! The valid documents every kind starts from: the presets, the examples of `docs/cli.md`, and
//! files the CLI itself writes (`simulate-walk`, `calibrate`), generated once per test process.

use std::sync::OnceLock;

use serde_json::{json, Value};

use scatterloc::math::Vec2;
use scatterloc::mtl::empirical::EmpiricalTable;
use scatterloc::mtl::polygon::Rect;
use scatterloc::present::MtlScene;
use scatterloc::scenario::presets;
use scatterloc::{measure, Model};

use super::check::{run_cli, CaseDir};

fn parse(text: &str) -> Value {
    serde_json::from_str(text).expect("valid base document")
}

/// The L4 preset (4 links), used by every CLI kind as its scenario file.
pub fn sensors_text() -> String {
    presets::sensors2019().to_json()
}

/// Scenario documents: both presets, and a variant with an explicit link list, an explicit noise
/// power, a processing gain and an omni Tx.
pub fn scenarios() -> Vec<Value> {
    let a = parse(&presets::sensors2019().to_json());
    let b = parse(&presets::iclgnss2019().to_json());
    let mut c = a.clone();
    c["radio"] = json!({"carrier_hz": 2.4e9, "bandwidth_hz": 2e7, "noise_power_dbm": -90.0,
                        "processing_gain_db": 10.0});
    c["transmitters"][0]["pattern"] = json!({"kind": "omni"});
    c["links"] = json!([["Tx", "Rx1"], ["Tx", "Rx3"], ["Tx", "Rx4"]]);
    vec![a, b, c]
}

/// Delays files of `locate` on the L4 preset: the docs/cli.md example, and noise-free delays at
/// (10, 5) with per-link σ and no start.
pub fn delays() -> Vec<Value> {
    let model = Model::new(&presets::sensors2019()).expect("preset");
    let at = Vec2::new(10.0, 5.0);
    let d: Vec<f64> = model.network.delays(at);
    vec![
        json!({"delays_s": [4.5e-8, null, 4.9e-8, 5.1e-8], "sigma_s": 3.5e-11, "initial_m": [3, 2]}),
        json!({"delays_s": d, "sigma_s": model.sigma_delays(at)}),
    ]
}

/// Measurements files (`steps` form) of `track` on the L4 preset: five noise-free steps of a
/// walk from (4, 1) at (1.39, 0.25) m/s, with a fixed σ, and without (σ from the link budget).
pub fn measurements() -> Vec<Value> {
    let model = Model::new(&presets::sensors2019()).expect("preset");
    let steps: Vec<Vec<Option<f64>>> = (1..=5)
        .map(|k| {
            let t = 0.1 * k as f64;
            let d = model
                .network
                .delays(Vec2::new(4.0 + 1.39 * t, 1.0 + 0.25 * t));
            d.into_iter()
                .enumerate()
                .map(|(p, x)| (p != 1 || k != 3).then_some(x))
                .collect()
        })
        .collect();
    let p0 = json!([
        [0.1, 0, 0, 0],
        [0, 0.1, 0, 0],
        [0, 0, 0.01, 0],
        [0, 0, 0, 0.01]
    ]);
    let a = json!({"dt_s": 0.1, "process_noise": 0.01, "initial_state": [4, 1, 1.39, 0.25],
                   "initial_covariance": p0, "sigma_s": 3.5e-11, "steps": steps});
    let mut b = a.clone();
    b.as_object_mut().expect("object").remove("sigma_s");
    vec![a, b]
}

/// Files written by the CLI for the raw-estimate chain: `simulate-walk` (1 s at 0.1 s, 20
/// calibration snapshots; both start forms) and `calibrate` on its snapshots.
pub struct Walk {
    /// `measurements.json` with `initial_snapshot`, trimmed to 4 raw steps.
    pub raw_snapshot_start: Value,
    /// `measurements.json` of `--start truth`, trimmed to 4 raw steps.
    pub raw_truth_start: Value,
    /// `calibration_snapshots.json`.
    pub snapshots: Value,
    /// `calibrate`'s output on them.
    pub calibration: Value,
}

pub fn walk() -> &'static Walk {
    static WALK: OnceLock<Walk> = OnceLock::new();
    WALK.get_or_init(|| {
        let dir = CaseDir::new("walk");
        let scen = dir.write("s.json", &sensors_text());
        let read = |p: std::path::PathBuf| parse(&std::fs::read_to_string(p).expect("read"));
        let mut out = vec![];
        for start in ["snapshot", "truth"] {
            let d = dir.0.join(start).to_string_lossy().into_owned();
            let args: Vec<String> = [
                "simulate-walk",
                "--scenario",
                &scen,
                "--out-dir",
                &d,
                "--duration",
                "1",
                "--calibration-snapshots",
                "20",
                "--start",
                start,
            ]
            .iter()
            .map(|s| s.to_string())
            .collect();
            let r = run_cli(&args);
            assert_eq!(r.code, Some(0), "simulate-walk: {}", r.stderr);
            let mut m = read(dir.0.join(start).join("measurements.json"));
            m["raw_steps"]
                .as_array_mut()
                .expect("raw_steps")
                .truncate(4);
            out.push(m);
        }
        let snaps_path = dir.0.join("snapshot").join("calibration_snapshots.json");
        let snapshots = read(snaps_path.clone());
        let r = run_cli(&[
            "calibrate".into(),
            "--scenario".into(),
            scen.clone(),
            "--snapshots".into(),
            snaps_path.to_string_lossy().into_owned(),
        ]);
        assert_eq!(r.code, Some(0), "calibrate: {}", r.stderr);
        let truth_start = out.pop().expect("two");
        Walk {
            raw_snapshot_start: out.pop().expect("two"),
            raw_truth_start: truth_start,
            snapshots,
            calibration: parse(&r.stdout),
        }
    })
}

/// The network of docs/cli.md (3 TX, 3 RX, region [0, 10]², cσ 0.1).
pub fn network() -> Value {
    json!({"tx": [[5, 10], [0.67, 2.5], [9.33, 2.5]], "rx": [[9.33, 7.5], [0.67, 7.5], [5, 0]],
           "region": {"min_m": [0, 0], "max_m": [10, 10]}, "c_sigma_m": 0.1})
}

/// Ranges files for [`network`]: the docs/cli.md example, and the noise-free bistatic ranges of
/// two targets at (3, 4) and (7, 5.5) plus one clutter range per TRP.
pub fn ranges() -> Vec<Value> {
    let n = network();
    let pts = |k: &str| -> Vec<Vec2> {
        n[k].as_array()
            .expect("nodes")
            .iter()
            .map(|p| Vec2::new(p[0].as_f64().expect("x"), p[1].as_f64().expect("y")))
            .collect()
    };
    let (tx, rx) = (pts("tx"), pts("rx"));
    let targets = [Vec2::new(3.0, 4.0), Vec2::new(7.0, 5.5)];
    let mut lists = vec![];
    for m in 0..tx.len() * rx.len() {
        let (u, v) = (tx[m % tx.len()], rx[m / tx.len()]);
        let mut l: Vec<f64> = targets
            .iter()
            .map(|t| (t - u).norm() + (t - v).norm())
            .collect();
        l.push(11.0 + 0.7 * m as f64);
        lists.push(l);
    }
    vec![
        json!({"ranges_m": [[10.3, 14.2], [7.9], [], [12.0, 8.8], [9.1], [11.7], [6.4, 20.5],
                            [10.0], [13.3]]}),
        json!({ "ranges_m": lists }),
    ]
}

/// A small empirical table for [`network`]: 4 × 4 cells over the region, 30 disc scenes.
pub fn empirical_table() -> &'static Value {
    static TABLE: OnceLock<Value> = OnceLock::new();
    TABLE.get_or_init(|| {
        let r = Rect::new(Vec2::new(0.0, 0.0), Vec2::new(10.0, 10.0)).expect("rect");
        let mut t = EmpiricalTable::new(&r, 4, 4, 3, 3).expect("table");
        let tx = [
            Vec2::new(5.0, 10.0),
            Vec2::new(0.67, 2.5),
            Vec2::new(9.33, 2.5),
        ];
        let rx = [
            Vec2::new(9.33, 7.5),
            Vec2::new(0.67, 7.5),
            Vec2::new(5.0, 0.0),
        ];
        t.train_discs(&tx, &rx, 0.03, 0.6, 30, &mut measure::rng(1, 0))
            .expect("train");
        serde_json::to_value(&t).expect("table JSON")
    })
}

/// Multi-target requests (`mtl::input::LocateRequest`: network, ranges, model) for each model.
pub fn mtl_requests() -> Vec<Value> {
    let models = [
        json!({"kind": "icb"}),
        json!({"kind": "icb", "p_u": 0.271}),
        json!({"kind": "ppp", "lambda": 0.03, "diameter_m": 0.6, "p_d": 0.9, "exact": false}),
        json!({"kind": "ppp", "exact": true}),
        json!({"kind": "empirical", "p_d": 0.9, "training":
               {"lambda": 0.03, "diameter_m": 0.6, "cells": 4, "scenes": 20, "seed": 1}}),
    ];
    let mut out = vec![];
    for (i, m) in models.into_iter().enumerate() {
        out.push(json!({"network": network(), "ranges": ranges()[i % 2], "model": m}));
    }
    out
}

/// Page scenes of the multi-target view: the V-B scene and an i.c.b variant.
pub fn mtl_scenes() -> Vec<Value> {
    let a = parse(&MtlScene::vb().to_json());
    let mut b = a.clone();
    b["model"] = json!({"kind": "icb", "p_los": 0.9});
    b["r_max"] = json!(30.0);
    vec![a, b]
}
