//! The use cases against their own contract, by topic: the filter study (any driver, any order
//! of work items and any split into shards give the same sums bit for bit — the sums are exact;
//! the lead and widest rules; the particle budget's closed form; cancelling and failing runs) in
//! `filters.rs`, the cost model in `cost.rs`, and sharded studies merged from their part files
//! (the unsharded sums again; impossible sums and bad headers as named errors) in `merge.rs`.
//! The part set's own checks are tested in `part/tests.rs`, the Monte Carlo configuration in
//! `montecarlo/tests.rs`.

use super::*;
use crate::measure::Model;
use crate::scenario::presets;
use crate::track::{
    paper_initial_covariance, ConstantVelocity, FilterKind, MonteCarloConfig, PfConfig,
    TrackScenario,
};

mod cost;
mod filters;
mod merge;

fn model() -> Model {
    Model::new(&presets::preset("sensors2019").unwrap()).unwrap()
}

fn config(trajectories: usize, noise_runs: usize, steps: usize, seed: u64) -> MonteCarloConfig {
    MonteCarloConfig {
        motion: ConstantVelocity::validated(0.1, 1.0).unwrap(),
        steps,
        mean_state: TrackScenario::II.mean_state(),
        initial_covariance: paper_initial_covariance(),
        trajectories,
        noise_runs,
        seed,
        oracle_noise: false,
    }
}

const PF: FilterKind = FilterKind::Pf(PfConfig {
    particles: 40,
    roughening: None,
    regularized: true,
});
