//! Snapshot localization: the Fisher matrix and Cramér–Rao bound at a point and the map kernel
//! over a grid (E8, S18–S24, spec §7), the bound with Doppler over a grid (`doppler_map`, D7),
//! and the weighted Levenberg–Marquardt fix with its starts, termination report and χ²
//! consistency test (E5–E6, spec §5). Shaped like `rust-cv/levenberg-marquardt`: a problem, a
//! config ([`LmConfig`]) and a report ([`LmReport`]) with a [`Termination`] reason.

mod crlb;
mod lm;

pub use crlb::{
    bound3_from_fisher, bound_from_fisher, crlb_at, crlb_free_z, crlb_map, crlb_map_rows,
    crlb_map_rows_with, crlb_map_scalar, doppler_map, fisher, fisher_free_z, Bound, Bound3,
    CrlbFreeZ, CrlbPoint, Grid, MapQuantity, MAX_GRID_CELLS, MAX_GRID_SIDE, SINGULAR_RCOND,
};
pub use lm::{
    chi_square_upper_tail, locate, locate_free_z, DelayMeasurements, FreeZReport, LmConfig,
    LmReport, Termination, FREE_Z_START_OFFSETS_M, GRID_STARTS, MAX_GRID_START_NODES, MIN_LINKS,
};
