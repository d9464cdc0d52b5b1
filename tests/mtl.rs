//! Multi-target localization (`multi-target.md`), one module per step of the method: ellipse
//! geometry and polygons (`geometry`), blocking models (`blocking`), empirical node patterns
//! (`empirical`), Algorithm 1 against brute force (`algorithm`), the data generator and Table II
//! (`sim`), and the experiments V-A to V-C (`experiment`).
//!
//! The 10⁶-draw check is `#[ignore]`d (run it with `cargo test --release --test mtl -- --ignored sim::`).
#![cfg(not(target_arch = "wasm32"))]

mod common;

#[path = "mtl/algorithm.rs"]
mod algorithm;

#[path = "mtl/blocking.rs"]
mod blocking;

#[path = "mtl/empirical.rs"]
mod empirical;

#[path = "mtl/experiment.rs"]
mod experiment;

#[path = "mtl/geometry.rs"]
mod geometry;

#[path = "mtl/sim.rs"]
mod sim;
