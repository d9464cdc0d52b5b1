//! Single-target tracking, one module per topic: the EKF against a batch Kalman filter (`ekf`),
//! the UKF (`ukf`) and particle filter (`pf`) of `filters-and-planning.md` §1–2, the motion model
//! (`motion`), the PCRLB and spec check 10 (`pcrlb`), check 11 (`check11`), the Monte Carlo
//! harness (`montecarlo`) and every filter on its data (`filters_mc`), named errors (`errors`),
//! and the gated tracker of `track::gating` with check 12 (`gating`).
//!
//! The full-size checks are `#[ignore]`d (run them with
//! `cargo test --release --test tracking -- --ignored pcrlb:: check11::`).
#![cfg(not(target_arch = "wasm32"))]

mod common;

#[path = "tracking/check11.rs"]
mod check11;

/// The crossing walkers of issue 41 §3 (shared with the CLI's tests).
#[path = "common/crossing.rs"]
mod crossing;

#[path = "tracking/cir_multi.rs"]
mod cir_multi;

#[path = "tracking/doppler.rs"]
mod doppler;

#[path = "tracking/ekf.rs"]
mod ekf;

#[path = "tracking/errors.rs"]
mod errors;

#[path = "tracking/filters_mc.rs"]
mod filters_mc;

#[path = "tracking/gating.rs"]
mod gating;

#[path = "tracking/multi.rs"]
mod multi;

#[path = "tracking/multi_studies.rs"]
mod multi_studies;

#[path = "tracking/multi_doppler.rs"]
mod multi_doppler;

#[path = "tracking/gospa.rs"]
mod gospa;

#[path = "tracking/montecarlo.rs"]
mod montecarlo;

#[path = "tracking/motion.rs"]
mod motion;

#[path = "tracking/pcrlb.rs"]
mod pcrlb;

#[path = "tracking/pf.rs"]
mod pf;

#[path = "tracking/pf_robust.rs"]
mod pf_robust;

#[path = "tracking/ukf.rs"]
mod ukf;
