//! The page's objects (run with `wasm-pack test`): the key sets, nesting and `null`s the page
//! (www/*.js) reads are pinned here, for representative inputs including unbounded, missing and
//! non-finite values. (The structs were checked equal, value for value, to the `json!` builders
//! they replaced before those were deleted.)

use serde::Serialize;
use serde_json::Value;
use wasm_bindgen_test::*;

use super::*;
use crate::error::Error;
use crate::localize::crlb_at;
use crate::present::{linear_ticks, scale_bar, simulate_snapshot, track_estimate};
use crate::present::{mtl_view, MtlScene};
use crate::present::{track_frame, track_mean_state, LogScale};
use crate::scenario::presets::{iclgnss2019, sensors2019};
use crate::track::{finish, paper_initial_covariance, run_chunk, simulate_track};
use crate::track::{ConstantVelocity, MonteCarloConfig, StudySums, PAPER_INTENSITY};
use crate::track::{FilterKind, PfConfig};

wasm_bindgen_test_configure!(run_in_browser);

/// `v` as a value; the JSON text `to_js` parses reads back as the same value.
fn value<T: Serialize>(v: &T) -> Value {
    let value = serde_json::to_value(v).unwrap();
    let text: Value =
        serde_json::from_str(&to_json(v).unwrap_or_else(|_| panic!("to_json"))).unwrap();
    assert_eq!(text, value);
    value
}

/// The sorted keys of an object.
fn keys(v: &Value) -> Vec<&str> {
    let mut k: Vec<&str> = v
        .as_object()
        .unwrap_or_else(|| panic!("not an object: {v}"))
        .keys()
        .map(String::as_str)
        .collect();
    k.sort_unstable();
    k
}

const ELLIPSE: [&str; 5] = ["a", "angle", "b", "cx", "cy"];
const CRLB: [&str; 10] = [
    "bounded",
    "ellipse",
    "rmse_label",
    "rmse_m",
    "sigma_x_label",
    "sigma_x_m",
    "sigma_y_label",
    "sigma_y_m",
    "x",
    "y",
];
const LINK: [&str; 9] = [
    "arc",
    "delay_s",
    "ellipse",
    "name",
    "outline",
    "range_sigma_label",
    "rx",
    "sigma_s",
    "tx",
];

fn sessions() -> Vec<Session> {
    let mut beamed = Session::new(iclgnss2019()).unwrap();
    beamed
        .edit(|s| s.set_tx_pattern_kind(0, "parabolic", 30.0, 60.0, 20.0))
        .unwrap();
    vec![
        Session::new(sensors2019()).unwrap(),
        Session::new(iclgnss2019()).unwrap(),
        beamed,
    ]
}

#[wasm_bindgen_test]
fn crlb_bounded_unbounded_and_nan() {
    let model = Session::new(sensors2019()).unwrap().model().clone();
    let bounded = crlb_at(&model, Vec2::new(10.0, 0.0));
    assert!(bounded.bound.is_some());
    let unbounded = CrlbPoint {
        bound: None,
        ..bounded
    };
    let mut nan = bounded;
    nan.bound.as_mut().unwrap().sigma_x_m = f64::NAN;
    nan.position.y = f64::INFINITY;
    let b = value(&CrlbJs::new(&bounded));
    let u = value(&CrlbJs::new(&unbounded));
    let n = value(&CrlbJs::new(&nan));
    assert_eq!(keys(&b), CRLB);
    assert_eq!(keys(&u), CRLB);
    assert_eq!(keys(&b["ellipse"]), ELLIPSE);
    assert_eq!(
        (u["ellipse"].clone(), u["rmse_m"].clone()),
        (Value::Null, Value::Null)
    );
    assert_eq!(
        (n["sigma_x_m"].clone(), n["y"].clone()),
        (Value::Null, Value::Null)
    );
}

#[wasm_bindgen_test]
fn nodes() {
    for s in sessions() {
        let v = value(&NodesJs::new(&s));
        assert_eq!(keys(&v), ["links", "receivers", "transmitters"]);
        assert_eq!(keys(&v["transmitters"][0]), ["boresight", "name", "x", "y"]);
        assert_eq!(keys(&v["receivers"][0]), ["name", "x", "y"]);
        assert_eq!(v["links"][0].as_array().unwrap().len(), 2);
    }
    let all = sessions();
    let plain = value(&NodesJs::new(&all[1]));
    let beamed = value(&NodesJs::new(&all[2]));
    assert!(plain["transmitters"][0]["boresight"].is_null());
    assert!(beamed["transmitters"][0]["boresight"].is_array());
}

#[wasm_bindgen_test]
fn snapshot_with_and_without_fix() {
    for s in sessions() {
        let (sc, model) = (s.scenario(), s.model());
        for (truth, seed) in [(Vec2::new(4.0, 1.0), 7), (Vec2::new(20.0, 10.0), 3)] {
            let sim = simulate_snapshot(model, &sc.area_m, truth, seed);
            let v = value(&SnapshotJs::new(&sim, sc));
            assert_eq!(
                keys(&v),
                [
                    "crlb",
                    "fix",
                    "fix_error",
                    "links",
                    "seed",
                    "truth",
                    "view_radius_m"
                ]
            );
            assert_eq!(keys(&v["truth"]), ["x", "y"]);
            assert_eq!(keys(&v["links"][0]), LINK);
            assert_eq!(keys(&v["crlb"]), CRLB);
            assert_eq!(
                keys(&v["fix"]),
                [
                    "converged",
                    "cost",
                    "ellipse",
                    "error_label",
                    "error_m",
                    "iterations",
                    "termination",
                    "x",
                    "y"
                ]
            );
            assert!(v["fix_error"].is_null());

            // No fix, a link without an ellipse, non-finite numbers.
            let mut bad = sim.clone();
            bad.fix = Err(Error::NonFinite { field: "x".into() });
            bad.links[0].ellipse = None;
            bad.links[0].outline.clear();
            bad.links[0].arc.clear();
            bad.links[1].delay_s = f64::NAN;
            bad.view_radius_m = f64::INFINITY;
            let v = value(&SnapshotJs::new(&bad, sc));
            assert!(v["fix"].is_null() && v["fix_error"].is_string());
            assert!(v["links"][0]["ellipse"].is_null() && v["view_radius_m"].is_null());
            assert_eq!(v["links"][0]["outline"], Value::Array(vec![]));
        }
    }
}

#[wasm_bindgen_test]
fn track_frame_estimate_and_data() {
    for s in sessions() {
        let model = s.model();
        let motion = ConstantVelocity::validated(0.1, PAPER_INTENSITY).unwrap();
        for kind in ["I", "III"] {
            let mean = track_mean_state(kind, Vec2::new(0.0, 0.0), Vec2::new(0.0, 0.0)).unwrap();
            let p0 = paper_initial_covariance();
            let mut run =
                simulate_track(model, &motion, &mean, &p0, 6, 5, Default::default()).unwrap();
            for n in [0, 1, 6] {
                let f = track_frame(model, &run, n).unwrap();
                let v = value(&FrameJs::new(&f, s.scenario()));
                assert_eq!(
                    keys(&v),
                    [
                        "crlb",
                        "fix",
                        "fix_error",
                        "links",
                        "step",
                        "t_s",
                        "truth",
                        "view_radius_m"
                    ]
                );
                assert_eq!(keys(&v["truth"]), ["vx", "vy", "x", "y"]);
                assert!(v["fix_error"].is_null());
                if n > 0 {
                    assert_eq!(keys(&v["links"][0]), LINK);
                }
                let e = track_estimate(&run, n).unwrap();
                let v = value(&EstimateJs::new(&e));
                assert_eq!(
                    keys(&v),
                    [
                        "ellipse",
                        "error_label",
                        "error_m",
                        "nis",
                        "sigma_label",
                        "sigma_m",
                        "vx",
                        "vy",
                        "x",
                        "y"
                    ]
                );
                assert_eq!(keys(&v["ellipse"]), ELLIPSE);
            }
            for failed_at in [None, Some(4)] {
                run.failed_at = failed_at;
                run.delays_s[2][0] = 0.0; // below the line-of-sight delay: no ellipse
                let est: Vec<_> = (0..run.estimates.len())
                    .map(|n| track_estimate(&run, n).unwrap())
                    .collect();
                let pf = FilterKind::Pf(PfConfig {
                    particles: 300,
                    roughening: None,
                    regularized: true,
                });
                let v = value(&TrackDataJs::new(kind, pf, 5, 6, &run, &est, model));
                assert_eq!(
                    keys(&v),
                    [
                        "dt_s",
                        "ellipses",
                        "error_m",
                        "estimates",
                        "failed_at",
                        "filter",
                        "kind",
                        "measurements",
                        "nis",
                        "particles",
                        "seed",
                        "sigma_m",
                        "steps",
                        "t_s",
                        "truth"
                    ]
                );
                assert!(v["measurements"][2][0].is_null());
                assert_eq!(
                    (&v["filter"], &v["particles"]),
                    (&Value::from("pf"), &Value::from(300))
                );
                assert_eq!(v["measurements"][0], Value::Array(vec![]));
            }
        }
    }
}

#[wasm_bindgen_test]
fn monte_carlo_progress_and_result() {
    let model = Session::new(sensors2019()).unwrap().model().clone();
    let cfg = MonteCarloConfig {
        motion: ConstantVelocity::validated(0.1, PAPER_INTENSITY).unwrap(),
        steps: 8,
        mean_state: track_mean_state("II", Vec2::new(0.0, 0.0), Vec2::new(0.0, 0.0)).unwrap(),
        initial_covariance: paper_initial_covariance(),
        trajectories: 20,
        noise_runs: 2,
        seed: 4,
        oracle_noise: false,
    };
    let mut sums = StudySums::new(cfg.steps);
    for chunk in 0..cfg.chunk_count() {
        sums.add(&run_chunk(&model, &cfg, chunk).unwrap());
        let mut r = finish(&cfg, &sums).unwrap();
        r.rmse_pcrlb_m[0] = None;
        r.nees[1] = f64::NAN;
        let ekf = FilterCurvesJs {
            name: "ekf",
            rmse_m: &r.rmse_m,
            nees: &r.nees,
            runs: r.runs,
            failed_runs: r.failed_runs,
            chunks_done: chunk + 1,
            chunk_count: cfg.chunk_count(),
            runs_planned: cfg.runs(),
        };
        let v = value(&MonteCarloJs::new(
            &r,
            &cfg,
            StudyProgressJs {
                trajectories_done: sums.trajectories,
                chunks_done: chunk + 1,
                chunk_count: cfg.chunk_count(),
                filters: vec![ekf],
                particles: None,
                particle_budget: None,
                failed_filters: Vec::new(),
            },
        ));
        assert_eq!(
            keys(&v),
            [
                "chunk_count",
                "chunks_done",
                "done",
                "dt_s",
                "failed_runs",
                "filters",
                "nees",
                "noise_runs",
                "particle_budget",
                "particles",
                "rmse_ekf_m",
                "rmse_pcrlb_m",
                "runs",
                "seed",
                "steps",
                "t_s",
                "trajectories",
                "trajectories_done"
            ]
        );
        assert_eq!(v["done"], Value::Bool(chunk + 1 == cfg.chunk_count()));
        assert!(v["rmse_pcrlb_m"][0].is_null() && v["nees"][1].is_null());
        assert_eq!(
            keys(&v["filters"]["ekf"]),
            [
                "chunk_count",
                "chunks_done",
                "failed_runs",
                "nees",
                "rmse_m",
                "runs",
                "runs_planned"
            ]
        );
        assert_eq!(v["filters"]["ekf"]["rmse_m"], v["rmse_ekf_m"]);
        assert!(v["particles"].is_null() && v["particle_budget"].is_null());
    }
}

#[wasm_bindgen_test]
fn ticks_and_scale_bar() {
    for (min, max, labels) in [(1e-3, 2.0, usize::MAX), (4e-3, 0.17, 3), (-1.0, 1.0, 5)] {
        let ticks = LogScale::new(min, max)
            .map(|s| s.ticks(labels))
            .unwrap_or_default();
        let js = ColorbarTickJs::all(&ticks);
        let v = value(&js);
        assert_eq!(v.as_array().unwrap().is_empty(), min < 0.0);
        for t in v.as_array().unwrap() {
            assert_eq!(keys(t), ["frac", "label", "value_m"]);
        }
    }
    for (lo, hi, n) in [(-3.0, 17.0, 6), (0.0, 0.002, 5), (1.0, 1.0, 4)] {
        let ticks = linear_ticks(lo, hi, n);
        let v = value(&ticks);
        assert!(lo == hi || !v.as_array().unwrap().is_empty());
        for t in v.as_array().unwrap() {
            assert_eq!(keys(t), ["label", "value"]);
        }
    }
    for len in [0.37, 12.0, -1.0, f64::NAN] {
        let bar = scale_bar(len);
        let js = bar.as_ref().map(ScaleBarJs::new);
        let v = value(&js);
        if bar.is_some() {
            assert_eq!(keys(&v), ["label", "length_m"]);
        } else {
            assert!(v.is_null());
        }
    }
}

#[wasm_bindgen_test]
fn mtl_view_with_compute_ms() {
    let view = mtl_view(&MtlScene::vb()).unwrap();
    let v = value(&MtlViewJs {
        view: &view,
        compute_ms: 12.5,
    });
    assert_eq!(
        keys(&v),
        [
            "compute_ms",
            "detected",
            "hypotheses",
            "metrics",
            "model",
            "mpcs",
            "seeds",
            "segments",
            "stages",
            "targets",
            "trps"
        ]
    );
}
