//! Snapshot localization: the Fisher matrix and Cramér–Rao bound at a point and the map kernel
//! over a grid (E8, S18–S24, spec §7), and the weighted Levenberg–Marquardt fix with its starts,
//! termination report and χ² consistency test (E5–E6, spec §5). Shaped like
//! `rust-cv/levenberg-marquardt`: a problem, a config ([`LmConfig`]) and a report
//! ([`LmReport`]) with a [`Termination`] reason.

mod crlb;
mod lm;

pub use crlb::{
    bound_from_fisher, crlb_at, crlb_map, crlb_map_rows, crlb_map_rows_with, crlb_map_scalar,
    fisher, Bound, CrlbPoint, Grid, MAX_GRID_CELLS, MAX_GRID_SIDE, SINGULAR_RCOND,
};
pub use lm::{
    chi_square_upper_tail, locate, DelayMeasurements, LmConfig, LmReport, Termination, GRID_STARTS,
    MAX_GRID_START_NODES, MIN_LINKS,
};
