//! The simulations of spec `multi-target.md` §7: settings (the §7 table, V-A / V-B presets), the
//! seeded data generator (steps (1)–(7), optional geometric IPs), the metrics (M12) and the
//! Table II helpers (§8, spec checks 4 and 11). `no_std` + `alloc`; every result depends on the
//! settings and the seed only (realisation `i` uses the stream `rng(seed, i)`).
//!
//! - [`settings`]: [`SimSettings`] and its presets.
//! - [`scene`]: steps (1)–(4): discs, nodes, targets, LoS and the true blocking vectors.
//! - [`generator`]: steps (5)–(7): DP ranges, IPs, clutter, resolution merge, ground truth.
//! - [`metrics`]: `N_D`, `N_FA`, `P_D`, `P_FA` (M12).
//! - [`table2`]: the "True" and i.c.b rows of Table II.

pub mod generator;
pub mod metrics;
pub mod scene;
pub mod settings;
pub mod table2;

pub use generator::{generate, resolution_merge, Realisation, Source, TargetTruth, TrpRanges};
pub use metrics::{count_detections, DetectionCounts, Metrics};
pub use scene::{draw_scene, Scene, TargetBlocking};
pub use settings::{GeometricIps, LosModel, NodeLayout, SimSettings, VB_ICB_P_U};
pub use table2::{dp_counts, icb_row, table2_buckets, true_row};

#[cfg(test)]
mod tests;
