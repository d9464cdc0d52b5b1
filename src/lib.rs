//! # scatterloc
//!
//! Localization and tracking of non-cooperative scatterers (people, cars) from bistatic radio
//! propagation delays measured on a network of transmitters and receivers.
//!
//! The core is `no_std` + `alloc` (with `libm` math) and follows the project spec
//! (`shared/spec/*.md`); equation tags such as (E3) or (M6) in doc comments refer to it.
//! `ARCHITECTURE.md` at the repository root draws the layers and the data flow.
//!
//! ## Module map
//! The core (`no_std` + `alloc`, builds for every target):
//! - [`math`]: scalar and small-matrix aliases, constants, elementary functions.
//! - [`error`]: the one error type; every bad input has a named variant.
//! - [`scenario`]: scenario JSON (schema v1), validation, presets, validated editing.
//! - [`measure`]: bistatic geometry (E1, E3), the Tx pattern, the link budget and `σ_τ` (E8),
//!   ellipses and seeded noise draws (E2).
//! - [`localize`]: the snapshot CRLB and its map kernel (E8, S18–S24) and the weighted
//!   Levenberg–Marquardt fix (E5–E6).
//! - [`channel`]: the channel front end's signal processing (`channel-estimation.md` C1–C10):
//!   recordings, the background and its alignment, the bounded snapshot estimator (C5), the path
//!   tracker (C6), the FFTs and the signal-level simulator.
//! - [`track`]: the motion model (E7), the EKF (§6), UKF and particle filter behind one
//!   [`track::Filter`] seam, the posterior CRLB (E9), trajectories and the Monte Carlo chunks
//!   (§8, §9.5).
//! - [`track::gating`], a stage of tracking: calibration, 3σ gating (E4), association (§4), the
//!   gated tracker of any filter, C11's segments (start, loss, restart) and the §9.6 stand-in.
//! - [`formats`]: one serde type per file the tracker reads or writes (measurements with
//!   `steps` or `raw_steps`, calibration snapshots, calibration result, truth), with checks.
//! - [`mtl`]: multi-target localization under correlated blocking (`multi-target.md`).
//! - [`plan`]: network planning — move nodes to minimise a CRLB objective over a region
//!   (CMA-ES with restarts, constraints).
//! - [`study`]: the use cases every front end shares — the Monte Carlo study over any list of
//!   filters, its part files and their merge, tracking from a measurement file, the channel
//!   chain from a recording to a track (`study::ChannelRequest`, `estimate_recording`,
//!   `cir_track`), run through a [`study::Driver`].
//! - [`present`]: view models shared by the page and the figures: ticks, colour map, snapshot and
//!   track views, the interactive session.
//!
//! Platform edges, one cargo feature each (all in `default`; each implies `std`):
//! - `native` (feature `parallel`, not on wasm32): the one ordered parallel driver (rayon) of
//!   Monte Carlo studies and multi-target sweeps.
//! - `chart` (feature `chart`): plotters figures on any drawing backend (SVG/PNG natively, a
//!   canvas in the page).
//! - `npz` (feature `npz`): the `.npz` channel-recording reader and writer (docs/recording.md).
//! - `csi` (feature `npz`): the readers of the Wi-Fi CSI tools' files (Intel 5300, Nexmon,
//!   PicoScenes, FeitCSI, ESP32) and `open_recording` for any recording file (issue 40).
//! - `wasm` (feature `wasm`, wasm32 only; implies `chart` and `npz`): the page's bindings; they
//!   only wrap the core.
//!
//! The CLI lives in `src/bin/scatterloc` (feature `cli`, which implies `parallel` and `chart`) and
//! uses only the public API. `--no-default-features --features parallel` is the core with the
//! parallel driver and neither plotters nor wasm-bindgen.
#![cfg_attr(not(feature = "std"), no_std)]

extern crate alloc;

pub mod channel;
pub mod error;
pub mod formats;
pub mod localize;
pub mod math;
pub mod measure;
pub mod mtl;
pub mod plan;
pub mod present;
pub mod scenario;
pub mod study;
pub mod track;

mod edge;
#[cfg(feature = "chart")]
pub use edge::chart;
#[cfg(feature = "npz")]
pub use edge::csi;
#[cfg(all(feature = "parallel", not(target_arch = "wasm32")))]
pub use edge::native;
#[cfg(feature = "npz")]
pub use edge::npz;
#[cfg(all(feature = "wasm", target_arch = "wasm32"))]
pub use edge::wasm;

pub use error::{Error, Result};
pub use math::{Mat2, Real, Vec2};
pub use measure::Model;
pub use scenario::Scenario;

#[cfg(all(not(feature = "std"), target_family = "wasm"))]
#[global_allocator]
static ALLOCATOR: dlmalloc::GlobalDlmalloc = dlmalloc::GlobalDlmalloc;

#[cfg(all(not(feature = "std"), not(test), target_family = "wasm"))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    core::arch::wasm32::unreachable()
}
