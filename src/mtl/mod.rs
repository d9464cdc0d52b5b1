//! Localization of multiple identical targets under correlated blocking (the Bayesian MTL method
//! of `shared/spec/multi-target.md`; equation tags such as (M3) refer to it).
//!
//! - [`trp`]: the TRP index map (Table I) and the range function (M1).
//! - [`blocking`]: blocking vectors (M3), consistency, unit-Hamming neighbours and the relaxed
//!   probability (M4–M5), the blocking likelihood `L_b` and the [`blocking::BlockingModel`]
//!   interface shared by all blocking models.
//! - [`icb`]: the i.c.b model and its threshold (M7–M8).
//! - [`input`]: serde schemas of one localization (network, ranges, model spec) and its report.
//! - [`geometry`]: ellipses per (TRP, range) and ellipse–ellipse intersection (§5).
//! - [`polygon`]: convex polygons, clipping and areas (for §6.2).
//! - [`ppp`]: the PPP-disc blocking model (M9–M11).
//! - [`empirical`]: node-pattern probabilities tabulated per grid cell (§6.3).
//! - [`experiment`]: the §8 experiments as ROC sweeps (Figs. 3–5), one realisation at a time.
//!   (The parallel experiment driver is native-only: `crate::native::run_experiment_parallel`.)
//! - [`sim`]: the §7 data generator, metrics (M12) and Table II helpers.
//! - [`algorithm`]: Algorithm 1 (§4), staged matching with the vector likelihood (M6) and
//!   the final selection by `J` (M2).
//! - [`brute`]: the brute-force reference over all matchings (small instances, tests).
//!
//! This layer stays planar (issue 40): its nodes and targets share one plane and its ranges are
//! the 2-D (M1) of [`crate::measure::bistatic_range`]. It never reads a [`crate::scenario`]
//! file, so node heights cannot reach it silently: its own inputs hold `[x, y]` positions only
//! and refuse a third coordinate or an unknown field such as `height_m` with a parse error that
//! names the field (tested in `tests/spec_checks_3d.rs`). The single-target model (`measure`)
//! is the one with heights.

pub mod algorithm;
pub mod blocking;
pub mod brute;
pub mod empirical;
pub mod experiment;
pub mod geometry;
pub mod icb;
pub mod input;
pub mod polygon;
pub mod ppp;
pub mod sim;
pub mod trp;
