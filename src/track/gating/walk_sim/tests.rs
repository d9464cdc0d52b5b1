use super::*;
use crate::scenario::presets;

fn model() -> Model {
    Model::new(&presets::sensors2019()).unwrap()
}

#[test]
fn a_short_walk_has_its_steps_start_and_truth() {
    let m = model();
    let bw = presets::sensors2019().radio.bandwidth_hz;
    let req = WalkRequest {
        duration_s: 1.0,
        calibration_snapshots: 3,
        ..WalkRequest::default()
    };
    let w = req.simulate(&m, bw).unwrap();
    assert_eq!(w.raw_steps.len(), 10);
    assert_eq!(
        (w.t_s.len(), w.states.len(), w.resolved.len()),
        (10, 10, 10)
    );
    assert_eq!(w.calibration.len(), 3);
    assert!(w.initial_snapshot.is_some() && w.initial_state.is_none());
    assert!((w.t_s[9] - 1.0).abs() < 1e-12);
    // The snapshots after t₀ do not depend on the start.
    let t = WalkRequest {
        start_from_truth: true,
        ..req.clone()
    }
    .simulate(&m, bw)
    .unwrap();
    assert_eq!(t.raw_steps, w.raw_steps);
    assert!(t.initial_snapshot.is_none() && t.initial_covariance.is_some());
    assert_eq!(t.initial_state, Some(LoopPath::default().state_at(0.0)));
}

#[test]
fn bad_settings_name_their_field() {
    let m = model();
    let field = |req: WalkRequest| {
        let e = req.check(&m, 40e6).unwrap_err();
        alloc::string::String::from(e.field().unwrap())
    };
    let d = WalkRequest::default();
    let cases: [(WalkRequest, &str); 6] = [
        (
            WalkRequest {
                dt_s: 0.0,
                ..d.clone()
            },
            "dt_s",
        ),
        (
            WalkRequest {
                process_noise: -1.0,
                ..d.clone()
            },
            "process_noise",
        ),
        (
            WalkRequest {
                duration_s: 0.0,
                ..d.clone()
            },
            "duration_s",
        ),
        (
            WalkRequest {
                calibration_snapshots: 0,
                ..d.clone()
            },
            "calibration_snapshots",
        ),
        (
            WalkRequest {
                false_alarms: 1e3,
                ..d.clone()
            },
            "false_alarms",
        ),
        (
            WalkRequest {
                dt_s: 1e-4,
                false_alarms: 100.0,
                ..d.clone()
            },
            "walk_estimates",
        ),
    ];
    for (req, want) in cases {
        assert_eq!(field(req), want);
    }
    assert_eq!(d.check(&m, 40e6).unwrap(), 600);
}
