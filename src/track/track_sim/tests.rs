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
        FilterKind::Ekf,
    )
    .unwrap();
    let b = simulate_track(
        &model,
        &motion,
        &s.mean_state(),
        &paper_initial_covariance(),
        100,
        5,
        FilterKind::Ekf,
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

/// Every filter of one seed sees the same truth and the same delays, and the UKF and the
/// particle filter (2000 particles) track scenario I as the EKF does: over steps 10 … 100 their
/// RMS position error is within 1.5× the EKF's on each of three seeds (the filters agree within
/// their Monte Carlo error on the near-linear case, `tests/tracking/filters_mc.rs`; one run's
/// error is one draw, so the margin is loose).
#[test]
fn every_filter_sees_the_same_data_and_tracks() {
    let model = Model::new(&sensors2019()).unwrap();
    let motion = ConstantVelocity::new(0.1, PAPER_INTENSITY);
    let s = TrackScenario::I;
    let kinds = [
        FilterKind::Ekf,
        FilterKind::Ukf(Default::default()),
        FilterKind::Pf(crate::track::PfConfig {
            particles: 2000,
            roughening: None,
            regularized: true,
        }),
    ];
    for seed in [1, 2, 3] {
        let runs: Vec<TrackRun> = kinds
            .iter()
            .map(|&k| {
                let p0 = paper_initial_covariance();
                simulate_track(&model, &motion, &s.mean_state(), &p0, 100, seed, k).unwrap()
            })
            .collect();
        let rms = |r: &TrackRun| {
            let sq: Real = (10..=100)
                .map(|n| {
                    (r.estimates[n] - r.truth[n])
                        .fixed_rows::<2>(0)
                        .norm_squared()
                })
                .sum();
            crate::math::sqrt(sq / 91.0)
        };
        let ekf = rms(&runs[0]);
        for (k, r) in kinds.iter().zip(&runs) {
            assert_eq!(r.truth, runs[0].truth, "{}", k.name());
            assert_eq!(r.delays_s, runs[0].delays_s, "{}", k.name());
            assert!(r.failed_at.is_none(), "{} seed {seed}", k.name());
            let e = rms(r);
            assert!(
                e < 1.5 * ekf,
                "{} seed {seed}: RMS {e} m, EKF {ekf} m",
                k.name()
            );
        }
    }
}
