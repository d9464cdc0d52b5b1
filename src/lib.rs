//! # scatterloc
//!
//! Localization and tracking of non-cooperative scatterers (people, cars) from bistatic radio
//! propagation delays measured on a network of transmitters and receivers.
//!
//! The core is `no_std` + `alloc` (with `libm` math) and follows the project spec
//! (`shared/spec/delay-localization.md`); equation tags such as (E3) refer to it.
//!
//! - [`scenario`]: scenario JSON (schema v1) and validation.
//! - [`geometry`]: bistatic delays (E1), Jacobian (E3), iso-delay ellipses.
//! - [`model`]: link budget, SNR and delay standard deviations (E8).
//! - [`crlb`]: Fisher matrix, CRLB and the fast map kernel (E8, S18–S24).
//! - [`lm`]: weighted Levenberg–Marquardt snapshot fix (E5–E6).
//! - [`simulate`]: seeded noisy delays.
//! - [`calibration`], [`association`]: the calibration stage, 3σ gating (E4) and the association
//!   of the remaining delays to the scatterer (spec §4); [`raw_snapshot`] simulates the
//!   estimator's per-snapshot lists; [`gated_track`] runs the EKF on them;
//!   [`measurement_case`] is the synthetic stand-in of the measurement case (spec §9.6).
//! - [`snapshot`]: one simulated snapshot with its ellipses, fix and CRLB (what the page draws).
//! - [`track_view`]: a simulated track's steps as the page draws them (snapshot-shaped frames).
//! - [`edit`], [`session`]: validated, rolled-back scenario edits for interactive front ends.
//! - [`presets`]: the `sensors2019` and `iclgnss2019` case studies.
//! - [`ticks`]: axis ticks and length labels shared by the front ends.
#![cfg_attr(not(feature = "std"), no_std)]

extern crate alloc;

pub mod association;
pub mod calibration;
#[cfg(feature = "std")]
pub mod chart;
pub mod colormap;
pub mod crlb;
pub mod edit;
pub mod ekf;
pub mod ellipse;
pub mod error;
pub mod gated_track;
pub mod geometry;
pub mod lm;
pub mod math;
pub mod measurement_case;
pub mod model;
pub mod montecarlo;
pub mod motion;
pub mod mtl;
#[cfg(all(feature = "std", not(target_arch = "wasm32")))]
pub mod parallel;
pub mod pattern;
pub mod pcrlb;
pub mod presets;
pub mod raw_snapshot;
pub mod scenario;
pub mod session;
pub mod simulate;
pub mod snapshot;
pub mod ticks;
pub mod track_sim;
pub mod track_view;
pub mod trajectory;

#[cfg(all(feature = "std", target_arch = "wasm32"))]
pub mod wasm;

pub use error::{Error, Result};
pub use math::{Mat2, Real, Vec2};
pub use model::Model;
pub use scenario::Scenario;

#[cfg(all(not(feature = "std"), target_family = "wasm"))]
#[global_allocator]
static ALLOCATOR: dlmalloc::GlobalDlmalloc = dlmalloc::GlobalDlmalloc;

#[cfg(all(not(feature = "std"), not(test), target_family = "wasm"))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    core::arch::wasm32::unreachable()
}
