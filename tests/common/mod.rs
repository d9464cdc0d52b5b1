//! Helpers shared by the integration tests: one home per helper.
//!
//! - tolerance checks (below): [`abs_close`] / [`rel_close`] assert with a readable message,
//!   [`within_abs`] / [`within_rel`] are the same tests as predicates (for `assert!` with a
//!   custom message or inside `prop_assert!`). *Absolute* means `|got − want| ≤ tol`;
//!   *relative* means `|got − want| ≤ rel · |want|`, relative to the reference value `want`;
//! - [`sensors_model`]: the L4 model of the tracking paper's preset; [`noise_free`]: the inputs
//!   of a noise-free fix;
//! - [`cli`]: running the binary, temporary directories and the bad-input contract;
//! - [`tracking`]: the §9.5 Monte Carlo studies and covariance comparisons of the `tracking`
//!   tests.
//!
//! Each test crate root includes this module with `mod common;` (its modules `use crate::common;`)
//! and uses what it needs.
#![allow(dead_code)]

pub mod cli;
pub mod multipath;
pub mod tracking;

use scatterloc::math::{Real, Vec2};
use scatterloc::{scenario::presets, Model};

/// `|got − want| ≤ tol`.
pub fn within_abs(got: Real, want: Real, tol: Real) -> bool {
    (got - want).abs() <= tol
}

/// `|got − want| ≤ rel · |want|` (relative to the reference `want`).
pub fn within_rel(got: Real, want: Real, rel: Real) -> bool {
    (got - want).abs() <= rel * want.abs()
}

/// Asserts [`within_abs`], naming `what` and the offset.
#[track_caller]
pub fn abs_close(what: &str, got: Real, want: Real, tol: Real) {
    assert!(
        within_abs(got, want, tol),
        "{what}: got {got}, want {want} ± {tol} (off by {})",
        got - want
    );
}

/// Asserts [`within_rel`], naming `what` and the relative error.
#[track_caller]
pub fn rel_close(what: &str, got: Real, want: Real, rel: Real) {
    assert!(
        within_rel(got, want, rel),
        "{what}: got {got}, want {want} (relative error {:.3e} > {rel:e})",
        ((got - want) / want).abs()
    );
}

/// The model of the tracking paper's L4 preset (`presets::sensors2019`).
pub fn sensors_model() -> Model {
    Model::new(&presets::sensors2019()).expect("preset is valid")
}

/// Noise-free delays of `truth` on every link (all present) and the (E8) σ at `truth`: the
/// inputs of a noise-free fix, `DelayMeasurements { delays_s: &delays, sigmas_s: &sigmas }`.
pub fn noise_free(model: &Model, truth: Vec2) -> (Vec<Option<Real>>, Vec<Real>) {
    let delays = model.network.delays(truth).into_iter().map(Some).collect();
    (delays, model.sigma_delays(truth))
}
