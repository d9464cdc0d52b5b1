use super::*;
use crate::scenario::presets::sensors2019;
use crate::track::{paper_initial_covariance, step_count, TrackScenario, PAPER_INTENSITY};

/// Spec check 5: ε_PCRLB(t₀) = √(0.1 + 0.1) = 0.4472 m exactly (F_B(t₀) = P(t₀)⁻¹).
#[test]
fn check5_initial_bound() {
    let fb = PosteriorInformation::new(&paper_initial_covariance()).unwrap();
    assert!((fb.position_rmse().unwrap() - 0.2f64.sqrt()).abs() < 1e-15);
    let b = fb.bound().unwrap();
    assert!(((b[(2, 2)] + b[(3, 3)]).sqrt() - 0.1414).abs() < 1e-4);
}

/// Spec check 9: nominal PCRLB RMSE (cm) at 1, 2, 5, 10 s, to 0.1 %.
#[test]
fn check9_nominal_pcrlb() {
    let model = Model::new(&sensors2019()).unwrap();
    let table: [(Real, [[Real; 4]; 3]); 2] = [
        (
            0.1,
            [
                [0.4581, 0.5278, 0.6685, 1.3631],
                [2.9315, 3.1668, 2.2581, 1.7823],
                [3.5225, 3.1921, 2.1020, 0.4707],
            ],
        ),
        (
            2.048e-3,
            [
                [0.1396, 0.1580, 0.1944, 0.3685],
                [0.7332, 0.8025, 0.5824, 0.4715],
                [0.8456, 0.8104, 0.5459, 0.1429],
            ],
        ),
    ];
    for (dt, rows) in table {
        let motion = ConstantVelocity::new(dt, PAPER_INTENSITY);
        let steps = step_count(10.0, dt);
        for (s, expect) in TrackScenario::ALL.iter().zip(rows) {
            let rmse = nominal_pcrlb_rmse(
                &model,
                &motion,
                &s.mean_state(),
                &paper_initial_covariance(),
                steps,
            )
            .unwrap();
            for (t, e) in [1.0, 2.0, 5.0, 10.0].iter().zip(expect) {
                // Step round(t/T): 10, 20, 50, 100 and 488, 977, 2441, 4883 (check 9).
                let n = (t / dt).round() as usize;
                let got = rmse[n].unwrap() * 100.0;
                assert!(
                    (got / e - 1.0).abs() < 1e-3,
                    "T {dt} {} {t} s: {got} cm vs {e}",
                    s.name()
                );
            }
        }
    }
}
