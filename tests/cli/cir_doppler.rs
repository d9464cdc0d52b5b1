//! `cir simulate` with the scene's CPI and `cir estimate --cpi-snapshots` (issue 42 §2, §5): the
//! recording's bursts and the paths' range rates in EST.json equal the library's (the same
//! simulation and `estimate_recording` with `cpi_snapshots`) bit for bit, the detections' JSON
//! lines carry the Doppler `f̂_D = −ṙ/λ`, and bad CPI flags are named errors (exit 2, nothing
//! written).

use scatterloc::channel::{ChannelScene, SceneCpi, SimulationRequest};
use scatterloc::error::Cancel;
use scatterloc::scenario::presets;
use scatterloc::study::{estimate_recording, ChannelRequest, Sequential};
use scatterloc::Model;
use serde_json::Value;

use crate::common::cli::{fails, ok_json_line, read_json, TempDir};

/// The hangar's first leg, 1 s, each 0.1 s scan a CPI of 8 snapshots 2.048 ms apart.
fn scene() -> ChannelScene {
    let mut s = ChannelScene::hangar();
    s.walk.waypoints_m = vec![[2.0, 4.0], [14.0, 7.0]];
    s.dt_s = 0.1;
    s.duration_s = Some(1.0);
    s.cpi = Some(SceneCpi {
        snapshots: 8,
        spacing_s: 2.048e-3,
    });
    s
}

#[test]
fn cir_estimate_reads_range_rates_over_cpis() {
    let dir = TempDir::new();
    let scenario = crate::cir::scenario(&dir);
    let scene_path = dir.write("scene.json", &serde_json::to_value(scene()).unwrap());
    let sim = dir.path("sim");
    ok_json_line(&[
        "cir",
        "simulate",
        "--scenario",
        &scenario,
        "--scene",
        &scene_path,
        "--out-dir",
        &sim,
        "--seed",
        "3",
    ]);
    let (rec, cal) = (
        format!("{sim}/recording.npz"),
        format!("{sim}/calibration.npz"),
    );
    let out = dir.path("est.json");
    let det = dir.path("det.jsonl");
    ok_json_line(&[
        "cir",
        "estimate",
        "--scenario",
        &scenario,
        "--cir",
        &rec,
        "--calibration",
        &cal,
        "--cpi-snapshots",
        "8",
        "--out",
        &out,
        "--detections-out",
        &det,
    ]);
    let est = read_json(&out);
    // The library's simulation and estimation of the same request.
    let s = presets::preset("sensors2019").unwrap();
    let model = Model::new(&s).unwrap();
    let lib = SimulationRequest {
        scene: Some(scene()),
        seed: 3,
        ..SimulationRequest::default()
    }
    .run(&s, &model, Cancel::NEVER)
    .unwrap();
    assert_eq!(lib.recording.t_s.len(), 11 * 8);
    let req = ChannelRequest {
        cpi_snapshots: Some(8),
        ..ChannelRequest::default()
    };
    let (_, want) = estimate_recording(
        &model,
        s.radio.bandwidth_hz,
        &lib.recording,
        Some(&lib.calibration),
        &req.front_end(lib.recording.synchronized),
        &mut Sequential::new(),
        &|_| {},
    )
    .unwrap();
    let t: Vec<f64> = serde_json::from_value(est["t_s"].clone()).unwrap();
    assert_eq!(t, want.t_s);
    assert_eq!(t.len(), 11);
    let mut rated = 0;
    for (k, scan) in want.paths.iter().enumerate() {
        for (p, list) in scan.iter().enumerate() {
            let got = est["estimates"][k][p].as_array().unwrap();
            assert_eq!(got.len(), list.len());
            for (g, w) in got.iter().zip(list) {
                assert_eq!(g["delay_s"].as_f64().unwrap(), w.estimate.delay_s);
                match w.estimate.range_rate {
                    Some(r) => {
                        rated += 1;
                        let pair: [f64; 2] =
                            serde_json::from_value(g["range_rate_mps"].clone()).unwrap();
                        assert_eq!(pair, [r.range_rate_mps, r.sigma_mps]);
                    }
                    None => assert!(g.get("range_rate_mps").is_none()),
                }
            }
        }
    }
    assert!(rated > 40, "{rated}");
    // Detections: each line with the Doppler of its paths, −ṙ/λ.
    let lambda = scatterloc::math::SPEED_OF_LIGHT / s.radio.carrier_hz;
    let text = std::fs::read_to_string(&det).unwrap();
    let mut lines = 0;
    for line in text.lines() {
        let v: Value = serde_json::from_str(line).unwrap();
        let Some(d) = v.get("doppler") else { continue };
        let d: Vec<f64> = serde_json::from_value(d.clone()).unwrap();
        assert_eq!(d.len(), v["delay"].as_array().unwrap().len());
        lines += 1;
        for f in d {
            assert!((f * lambda).abs() < 10.0, "{f} Hz");
        }
    }
    assert!(lines > 20, "{lines}");
    // Bad CPI flags: named, exit 2, nothing written.
    let bad = dir.path("bad.json");
    let base = [
        "cir",
        "estimate",
        "--scenario",
        &scenario,
        "--cir",
        &rec,
        "--calibration",
        &cal,
        "--out",
        &bad,
    ];
    fails(
        &[&base[..], &["--cpi-snapshots", "7"]].concat(),
        &["cpi", "7"],
    );
    fails(
        &[
            &base[..],
            &["--cpi-snapshots", "8", "--range-rate-floor", "-1"],
        ]
        .concat(),
        &["--range-rate-floor"],
    );
    assert!(!std::path::Path::new(&bad).exists());
}
