use super::*;
use crate::scenario::presets::sensors2019;
use crate::track::{paper_initial_covariance, TrackScenario, PAPER_INTENSITY};

/// Scenario I, 0.1 s for 10 s: the track settles to the CRLB scale (< 5 cm error after
/// 1 s, where ε_PCRLB ≈ 0.46–1.4 cm, check 9) and the run is reproducible from its seed.
#[test]
fn scenario_i_track_converges_and_is_deterministic() {
    let model = Model::new(&sensors2019()).unwrap();
    let motion = ConstantVelocity::new(0.1, PAPER_INTENSITY);
    let s = TrackScenario::I;
    let a = simulate_track(
        &model,
        &motion,
        &s.mean_state(),
        &paper_initial_covariance(),
        100,
        5,
    )
    .unwrap();
    let b = simulate_track(
        &model,
        &motion,
        &s.mean_state(),
        &paper_initial_covariance(),
        100,
        5,
    )
    .unwrap();
    assert_eq!(a, b);
    assert_eq!(a.truth.len(), 101);
    assert!(a.failed_at.is_none());
    for n in 10..=100 {
        let e = (a.estimates[n] - a.truth[n]).fixed_rows::<2>(0).norm();
        assert!(e < 0.05, "step {n}: error {e} m");
    }
    assert!(a.delays_s[0].is_empty() && a.delays_s[1].len() == 4);
}
