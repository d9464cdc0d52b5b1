//! Helpers of the `tracking_*` tests (spec §6, §8, §9.5): the fast-profile motion model, the
//! §9.5 Monte Carlo study of a scenario, step indices, covariance comparisons and larger
//! networks than the presets.

use scatterloc::math::{Mat4, Real};
use scatterloc::scenario::{presets, Pattern, Receiver, Transmitter};
use scatterloc::track::{paper_initial_covariance, step_count, TrackScenario, PAPER_INTENSITY};
use scatterloc::track::{ConstantVelocity, MonteCarloConfig};
use scatterloc::Model;

/// The spec's fast profile step (§9.5), s.
pub const FAST_STEP_S: Real = 0.1;
/// The default seed of the Monte Carlo runs (the lead's reference runs use seed 1); tests of
/// statistical claims run over several seeds instead.
pub const SEED: u64 = 1;

/// The CV model of the fast profile (T = 0.1 s, q̃ = 0.01 m²/s³).
pub fn fast_motion() -> ConstantVelocity {
    ConstantVelocity::new(FAST_STEP_S, PAPER_INTENSITY)
}

/// The §9.5 study of scenario `s` over 10 s at step `dt_s` (seed [`SEED`]).
pub fn study(
    s: TrackScenario,
    dt_s: Real,
    trajectories: usize,
    noise_runs: usize,
) -> MonteCarloConfig {
    MonteCarloConfig {
        motion: ConstantVelocity::new(dt_s, PAPER_INTENSITY),
        steps: step_count(10.0, dt_s),
        mean_state: s.mean_state(),
        initial_covariance: paper_initial_covariance(),
        trajectories,
        noise_runs,
        seed: SEED,
        oracle_noise: false,
    }
}

/// Index of time `t` (s) at step `dt`.
pub fn at(t: Real, dt: Real) -> usize {
    (t / dt).round() as usize
}

/// `a` and `b` agree entry by entry to `rel` of the scale `√(B_ii B_jj)` of the reference `b`
/// (a covariance's natural per-entry scale; exact zeros in `b` are not divided by).
#[track_caller]
pub fn covariance_close(what: &str, a: &Mat4, b: &Mat4, rel: Real) {
    for i in 0..4 {
        for j in 0..4 {
            let scale = (b[(i, i)] * b[(j, j)]).sqrt();
            assert!(
                (a[(i, j)] - b[(i, j)]).abs() <= rel * scale,
                "{what} [{i},{j}]: {} vs {} (scale {scale:e}, rel {:.3e} > {rel:e})",
                a[(i, j)],
                b[(i, j)],
                (a[(i, j)] - b[(i, j)]).abs() / scale
            );
        }
    }
}

/// A full mesh of `k` transmitters and `l` receivers around the `sensors2019` area (its radio
/// and node parameters; the odd-numbered transmitters omni, the others its parabolic pattern):
/// `k·l` links, transmitter fastest (spec §1). The EKF evaluates links in blocks of 4 and keeps
/// the views of the first 4 transmitters in a table, so meshes such as 3 × 3 and 5 × 2 exercise
/// a padded last block, links of different transmitters in one block and transmitters past the
/// table.
pub fn mesh(k: usize, l: usize) -> Model {
    let mut s = presets::sensors2019();
    let tx = s.transmitters[0].clone();
    s.transmitters = (0..k)
        .map(|i| Transmitter {
            name: format!("T{i}"),
            height_m: 0.0,
            position_m: [3.0 * i as Real - 2.0, -1.0 + 0.5 * i as Real],
            pattern: if i % 2 == 1 {
                Pattern::Omni
            } else {
                tx.pattern
            },
            ..tx.clone()
        })
        .collect();
    let rx = s.receivers[0].clone();
    s.receivers = (0..l)
        .map(|i| Receiver {
            name: format!("R{i}"),
            height_m: 0.0,
            position_m: [-6.0 + 4.5 * i as Real, if i % 2 == 0 { 12.0 } else { -8.0 }],
            ..rx.clone()
        })
        .collect();
    Model::new(&s).expect("a valid mesh")
}
