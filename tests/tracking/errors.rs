#![cfg(not(target_arch = "wasm32"))]
//! Tracking, bad inputs of the motion model and the Monte Carlo configuration (named errors,
//! validated by every driver before any work) and cancellation of the Monte Carlo drivers.
//! (Split from the former `tracking.rs`.)

use crate::common;

use std::sync::atomic::{AtomicBool, Ordering};

use common::sensors_model as model;
use common::tracking::{study, FAST_STEP_S};
use scatterloc::math::{Real, Vec4};
use scatterloc::native::run_parallel;
use scatterloc::track::ConstantVelocity;
use scatterloc::track::{paper_initial_covariance, TrackScenario, PAPER_INTENSITY};
use scatterloc::track::{
    run_pcrlb_sequential, run_sequential, MonteCarloConfig, MAX_RUNS, MAX_STEPS,
};
use scatterloc::Error;

#[test]
fn motion_and_study_bad_inputs_are_named_errors() {
    // Δt in 1e-6 ..= 3600 s and q in (0, 1e6] (docs/cli.md, "Limits"; issue 12 item 8: 1e308
    // reached the filter and failed as "ekf.covariance").
    let out = |field: &str, value: Real, allowed: &'static str| Error::OutOfRange {
        field: field.into(),
        value,
        allowed,
    };
    for dt in [0.0, -0.1, 1e-7, 3601.0, 1e308] {
        assert_eq!(
            ConstantVelocity::validated(dt, 0.01).unwrap_err(),
            out("dt_s", dt, "1e-6 to 3600 s")
        );
    }
    assert_eq!(
        ConstantVelocity::validated(Real::NAN, 0.01).unwrap_err(),
        Error::NonFinite {
            field: "dt_s".into()
        }
    );
    for q in [0.0, -1.0, 1.1e6, 1e308] {
        assert_eq!(
            ConstantVelocity::validated(0.1, q).unwrap_err(),
            out("process_noise", q, "0 < q <= 1e6 m²/s³")
        );
    }
    assert!(ConstantVelocity::validated(1e-6, 1e6).is_ok());
    assert!(ConstantVelocity::validated(3600.0, 1e-300).is_ok());
    assert!(ConstantVelocity::validated(0.1, 0.01).is_ok());

    let ok = study(TrackScenario::I, FAST_STEP_S, 10, 2);
    assert!(ok.validate().is_ok());
    let size = |field: &'static str, value: usize, max: usize| Error::SizeLimit {
        field,
        value,
        min: 1,
        max,
    };
    let cases: Vec<(MonteCarloConfig, Error)> = vec![
        (
            MonteCarloConfig {
                trajectories: 0,
                ..ok
            },
            size("runs", 0, MAX_RUNS),
        ),
        (
            MonteCarloConfig {
                trajectories: MAX_RUNS + 1,
                ..ok
            },
            size("runs", MAX_RUNS + 1, MAX_RUNS),
        ),
        (
            MonteCarloConfig {
                noise_runs: 0,
                ..ok
            },
            size("noise_runs", 0, MAX_RUNS),
        ),
        (
            MonteCarloConfig {
                trajectories: 5000,
                noise_runs: 2001,
                ..ok
            },
            size("runs*noise_runs", 5000 * 2001, MAX_RUNS),
        ),
        (
            MonteCarloConfig { steps: 0, ..ok },
            size("steps", 0, MAX_STEPS),
        ),
        (
            MonteCarloConfig {
                steps: MAX_STEPS + 1,
                ..ok
            },
            size("steps", MAX_STEPS + 1, MAX_STEPS),
        ),
        (
            MonteCarloConfig {
                motion: ConstantVelocity::new(0.0, PAPER_INTENSITY),
                ..ok
            },
            out("dt_s", 0.0, "1e-6 to 3600 s"),
        ),
        (
            MonteCarloConfig {
                motion: ConstantVelocity::new(0.1, -1.0),
                ..ok
            },
            out("process_noise", -1.0, "0 < q <= 1e6 m²/s³"),
        ),
        (
            MonteCarloConfig {
                mean_state: Vec4::new(0.0, Real::NAN, 0.0, 0.0),
                ..ok
            },
            Error::NonFinite {
                field: "initial_state".into(),
            },
        ),
        (
            MonteCarloConfig {
                initial_covariance: -paper_initial_covariance(),
                ..ok
            },
            Error::NotPositiveDefinite {
                field: "initial_covariance".into(),
            },
        ),
    ];
    let model = model();
    let never = AtomicBool::new(false);
    for (cfg, want) in cases {
        assert_eq!(cfg.validate().unwrap_err(), want);
        // Every driver validates before doing any work.
        assert_eq!(run_sequential(&model, &cfg, |_, _| true).unwrap_err(), want);
        // The PCRLB-only driver ignores `noise_runs` (it runs no filter).
        if let Err(e) = (MonteCarloConfig {
            noise_runs: 1,
            ..cfg
        })
        .validate()
        {
            assert_eq!(
                run_pcrlb_sequential(&model, &cfg, |_, _| true).unwrap_err(),
                e
            );
        }
        assert_eq!(
            run_parallel(&model, &cfg, 1, &never, |_, _| {}).unwrap_err(),
            want
        );
    }
}

/// A cancel request stops every driver with `Error::Cancelled`: a flag already set, a flag set
/// from the progress callback after the first wave, and `on_chunk` returning `false`.
#[test]
fn cancel_stops_with_cancelled() {
    let model = model();
    let cfg = MonteCarloConfig {
        steps: 5,
        ..study(TrackScenario::I, FAST_STEP_S, 200, 1)
    };
    let set = AtomicBool::new(true);
    assert_eq!(
        run_parallel(&model, &cfg, 2, &set, |_, _| {}).unwrap_err(),
        Error::Cancelled
    );
    let flag = AtomicBool::new(false);
    let mut calls = 0;
    let r = run_parallel(&model, &cfg, 1, &flag, |done, total| {
        calls += 1;
        assert!(done < total, "cancelled before the end");
        flag.store(true, Ordering::Relaxed);
    });
    assert_eq!(r.unwrap_err(), Error::Cancelled);
    assert_eq!(calls, 1);
    let mut chunks = Vec::new();
    let r = run_sequential(&model, &cfg, |done, total| {
        chunks.push((done, total));
        done < 3
    });
    assert_eq!(r.unwrap_err(), Error::Cancelled);
    assert_eq!(chunks, vec![(1, 13), (2, 13), (3, 13)]); // ⌈200/16⌉ = 13 chunks
    assert_eq!(
        run_pcrlb_sequential(&model, &cfg, |_, _| false).unwrap_err(),
        Error::Cancelled
    );
}
