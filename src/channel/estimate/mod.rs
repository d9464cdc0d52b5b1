//! The snapshot estimator (C5): greedy ML with cyclic refinement, a CFAR stop and per-path delay
//! standard deviations from the joint Fisher matrix; every loop has a stated bound and what a
//! snapshot did against them is in [`SnapshotEstimate::work`]. `config` holds the settings,
//! `output` the per-snapshot result and its work and stop accounting, `estimator` the band's plans
//! and buffers, `greedy` the loop per snapshot (the algorithm, step by step), `periodogram` the
//! periodogram, noise level and masked cells, `residual` the correlation moments and Newton,
//! `refine` the cyclic and joint refinement and the merge, `fisher` the kernels and `σ̂_τ`;
//! `kernels` and `linalg` are their numeric kernels.

// `!(x > 0.0)` is meant: a NaN must fail these checks as well.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod config;
mod estimator;
mod fisher;
mod greedy;
mod kernels;
mod linalg;
mod output;
mod periodogram;
mod refine;
mod residual;

pub use config::{EstimatorConfig, MERGE_FRACTION};
pub use estimator::Estimator;
pub use fisher::fisher_matrix;
pub(crate) use linalg::{inverse_spd_scaled, solve_complex};
pub use output::{EstimateWork, PathEstimate, SnapshotEstimate, Stop};

#[cfg(test)]
mod tests;
