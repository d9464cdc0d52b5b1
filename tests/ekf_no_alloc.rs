#![cfg(not(target_arch = "wasm32"))]
//! Issue 13 §3: an EKF step (predict + update) allocates nothing. This binary counts every
//! allocation with `stats_alloc` as its global allocator; it has a single test, so no other test
//! thread allocates while the steps run.

use std::alloc::System;

use stats_alloc::{Region, StatsAlloc, INSTRUMENTED_SYSTEM};

mod common;

use common::sensors_model;
use common::tracking::mesh;
use scatterloc::math::{Real, Vec2, Vec4};
use scatterloc::track::{paper_initial_covariance, TrackScenario, TruthSampler};
use scatterloc::track::{ConstantVelocity, Ekf, Filter, MeasurementNoise, PAPER_INTENSITY};
use scatterloc::{measure, Model};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// The delays of `steps` steps of a scenario-I truth (noisy, σ from E8 at the truth) with some
/// links missing, and the σ at the truth; made before counting.
fn measurements(
    model: &Model,
    motion: &ConstantVelocity,
    steps: usize,
) -> Vec<(Vec<Option<Real>>, Vec<Real>, Vec2)> {
    let s = TrackScenario::I;
    let sampler = TruthSampler::new(*motion, s.mean_state(), &paper_initial_covariance()).unwrap();
    let mut truth: Vec<Vec4> = Vec::new();
    sampler.sample(steps, &mut measure::rng(3, 0), &mut truth);
    let mut rng = measure::rng(3, 1);
    let n = model.link_count();
    truth[1..]
        .iter()
        .enumerate()
        .map(|(k, x)| {
            let r = Vec2::new(x[0], x[1]);
            let mut z: Vec<Option<Real>> = measure::noisy_delays(model, r, &mut rng)
                .into_iter()
                .map(Some)
                .collect();
            if k % 3 == 0 {
                z[k % n] = None;
            }
            if k % 11 == 0 {
                z.fill(None);
            }
            (z, model.sigma_delays(r), r)
        })
        .collect()
}

#[test]
fn ekf_steps_do_not_allocate() {
    let motion = ConstantVelocity::new(0.01, PAPER_INTENSITY);
    // 4 links; 9 links (two full blocks and a padded one, 3 transmitters); 10 links with
    // transmitters past the table of 4.
    for model in [sensors_model(), mesh(3, 3), mesh(5, 2)] {
        let data = measurements(&model, &motion, 400);
        let mut innovations = vec![None; model.link_count()];
        let start = Ekf::new(TrackScenario::I.mean_state(), paper_initial_covariance()).unwrap();
        let (mut a, mut b, mut c, mut d) = (start, start, start, start);
        let region = Region::new(GLOBAL);
        for (z, sigma, truth) in &data {
            a.step(&motion, &model, z, MeasurementNoise::AtPrediction)
                .unwrap();
            b.predict(&motion);
            b.update(
                &model,
                z,
                MeasurementNoise::Fixed(sigma),
                Some(&mut innovations),
            )
            .unwrap();
            c.step(&motion, &model, z, MeasurementNoise::At(*truth))
                .unwrap();
            d.predict(&motion);
            d.update(&model, z, MeasurementNoise::AtPrediction, None)
                .unwrap();
        }
        let stats = region.change();
        assert_eq!(
            (
                stats.allocations,
                stats.reallocations,
                stats.bytes_allocated
            ),
            (0, 0, 0),
            "{} links: {stats:?}",
            model.link_count()
        );
        assert!(innovations.iter().any(|v| v.is_some()));
        assert!((a.position() - data.last().unwrap().2).norm() < 0.05);
    }
}
