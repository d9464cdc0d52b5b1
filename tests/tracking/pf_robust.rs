#![cfg(not(target_arch = "wasm32"))]
//! Issue 26: the regularised particle filter (`track::pf` module docs) in the page's default
//! Monte Carlo — scenario I, T = 0.1 s, 100 steps, one noise run per truth, 1000 particles, the
//! prior `P(t₀)` of spec §9.5 — fails in few runs, where the spec's plain bootstrap SIR failed
//! in 105 of the page's 192. A run "fails" when its filter breaks down numerically: an update
//! error or a weighted covariance that is not positive definite (no NEES), the run then being
//! left out of the curves (`track::run_filter_chunk`).

use crate::common;

use common::sensors_model as model;
use common::tracking::study;
use scatterloc::math::Real;
use scatterloc::track::{
    finish, run_filter_chunk, FilterKind, MonteCarloConfig, PfConfig, StudySums, TrackScenario,
};

/// The failed runs and the curves of `pf` over the study `cfg` (every chunk).
fn pf_study(cfg: &MonteCarloConfig, pf: PfConfig) -> (usize, scatterloc::track::MonteCarloResult) {
    let model = model();
    let mut sums = StudySums::new(cfg.steps);
    for c in 0..cfg.chunk_count() {
        sums.add(&run_filter_chunk(&model, cfg, FilterKind::Pf(pf), c).unwrap());
    }
    (sums.failed_runs, finish(cfg, &sums).unwrap())
}

/// The page's study of scenario I with `trajectories` runs and `seed`.
fn page_study(trajectories: usize, seed: u64) -> MonteCarloConfig {
    MonteCarloConfig {
        seed,
        ..study(TrackScenario::I, 0.1, trajectories, 1)
    }
}

/// The failure rate of the regularised PF measured natively at the page's settings (release
/// build, `scatterloc montecarlo --trajectory I --filters pf --particles 1000 --runs 192
/// --noise-runs 1 --dt 0.1 --seed S`, S = 1 … 5: 1, 1, 0, 1, 1 failed, MEASURED_FAILED of
/// MEASURED_RUNS; docs/reproduction.md "Particle filter robustness").
const MEASURED_FAILED: usize = 4;
/// The runs of that measurement.
const MEASURED_RUNS: usize = 960;

/// The most failures tolerated in `runs` runs: the expected count at the measured rate plus 3
/// binomial standard errors, `n p + 3 √(n p (1 − p))` (2.9 → 2 for 144 runs), the rate taken
/// as at least the 95 % upper bound of a measured zero (`3 / MEASURED_RUNS`, the rule of three).
fn tolerated(runs: usize) -> usize {
    let p = (MEASURED_FAILED as Real / MEASURED_RUNS as Real).max(3.0 / MEASURED_RUNS as Real);
    let n = runs as Real;
    (n * p + 3.0 * (n * p * (1.0 - p)).sqrt()).floor() as usize
}

/// Three seeds × 48 runs of the page's scenario I study at 1000 particles: the regularised PF
/// fails in at most [`tolerated`] of the 144 runs (the measured rate plus 3 standard errors),
/// while the spec's bootstrap SIR on the same runs of the first seed fails in at least a quarter
/// (measured: 107 of 192 runs of seed 1), so the test tells the two apart. The RMSE at 10 s stays
/// within 1.5× the posterior CRLB (measured ≈ 1.2×). About 3 min in the debug build on the
/// shared 2-core machine; the cheaper test below runs by default.
#[test]
#[ignore = "3 seeds × 48 runs × 1000 particles: minutes in the debug build; run with --ignored (or --release)"]
fn regularized_pf_rarely_fails_in_the_page_study_of_scenario_i() {
    let runs_per_seed = 48;
    let mut failed = 0;
    for seed in 1..=3 {
        let cfg = page_study(runs_per_seed, seed);
        let (f, r) = pf_study(&cfg, PfConfig::default());
        failed += f;
        let n = cfg.steps;
        let bound = r.rmse_pcrlb_m[n].unwrap();
        assert!(
            r.rmse_m[n] < 1.5 * bound,
            "seed {seed}: RMSE {} vs PCRLB {bound}",
            r.rmse_m[n]
        );
    }
    let total = 3 * runs_per_seed;
    assert!(
        failed <= tolerated(total),
        "{failed} of {total} runs failed (tolerated {})",
        tolerated(total)
    );
    let (bootstrap, _) = pf_study(&page_study(runs_per_seed, 1), PfConfig::bootstrap(1000));
    assert!(
        4 * bootstrap >= runs_per_seed,
        "bootstrap SIR: {bootstrap} of {runs_per_seed} failed"
    );
}

/// The cheap version (one chunk of 16 runs, seed 1): the regularised PF fails in at most
/// [`tolerated`]`(16)` = 0 of them, the bootstrap SIR in at least a quarter of the same runs.
#[test]
fn regularized_pf_beats_the_bootstrap_on_one_chunk_of_scenario_i() {
    let cfg = page_study(16, 1);
    let (failed, _) = pf_study(&cfg, PfConfig::default());
    assert!(failed <= tolerated(16), "{failed} of 16 runs failed");
    let (bootstrap, _) = pf_study(&cfg, PfConfig::bootstrap(1000));
    assert!(
        4 * bootstrap >= 16,
        "bootstrap SIR: {bootstrap} of 16 failed"
    );
}
