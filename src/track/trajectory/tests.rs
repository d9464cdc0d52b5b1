use super::*;

/// §9.4: the scenarios end at (17.93, 3.46), (7.75, −9.07), (5.5, 1.5) after 10 s.
#[test]
fn scenario_end_points() {
    for (s, end) in [
        (TrackScenario::I, Vec2::new(17.93, 3.46)),
        (TrackScenario::II, Vec2::new(7.75, -9.07)),
        (TrackScenario::III, Vec2::new(5.5, 1.5)),
    ] {
        let e = s.start() + 10.0 * s.velocity();
        assert!((e - end).norm() < 0.01, "{}: {e:?}", s.name());
        assert!((s.velocity().norm() - 1.41).abs() < 0.01);
    }
}

/// §9.5: 10 s at 2.048 ms is 4883 steps; 0.1 s gives 100.
#[test]
fn step_counts() {
    assert_eq!(step_count(10.0, 2.048e-3), 4883);
    assert_eq!(step_count(10.0, 0.1), 100);
}

/// Sample mean and covariance of x(t₀) match 𝒩(x̄₀, P₀) within Monte Carlo error
/// (20 000 draws: standard error of a variance ≈ √(2/n) ≈ 1 %; 5σ bounds used).
#[test]
fn initial_states_follow_the_prior() {
    let s = TrackScenario::II;
    let sampler = TruthSampler::new(
        ConstantVelocity::new(0.1, 0.01),
        s.mean_state(),
        &paper_initial_covariance(),
    )
    .unwrap();
    let mut rng = crate::measure::rng(3, 0);
    let (n, mut mean, mut second) = (20_000, Vec4::zeros(), Mat4::zeros());
    let mut path = alloc::vec::Vec::new();
    for _ in 0..n {
        sampler.sample(0, &mut rng, &mut path);
        let d = path[0] - s.mean_state();
        mean += d;
        second += d * d.transpose();
    }
    mean /= n as Real;
    second /= n as Real;
    let p0 = paper_initial_covariance();
    for i in 0..4 {
        assert!(mean[i].abs() < 5.0 * (p0[(i, i)] / n as Real).sqrt());
        assert!((second[(i, i)] / p0[(i, i)] - 1.0).abs() < 5.0 * (2.0 / n as Real).sqrt());
    }
}
