//! The CRLB map on threads: blocks of whole rows of the grid run the SIMD kernel
//! ([`crate::localize::crlb_map_rows`]) on rayon workers. Rows are independent, so the map is
//! bitwise the single-threaded one for any thread count.

use rayon::prelude::*;

use super::driver::thread_pool;
use crate::error::{check_len, Result};
use crate::localize::{crlb_map, crlb_map_rows, Grid};
use crate::math::Real;
use crate::measure::Model;

/// Grids with fewer cells than this (128²) run on the calling thread: below it, handing rows to
/// workers costs more than it saves.
pub const PARALLEL_MAP_MIN_CELLS: usize = 128 * 128;

/// Rows per task: enough tasks for load balance, each a few hundred microseconds at most.
const ROWS_PER_TASK: usize = 8;

/// [`crlb_map`] with its rows split over `threads` workers (0 = rayon's global pool, all cores)
/// from [`PARALLEL_MAP_MIN_CELLS`] cells up.
pub fn crlb_map_parallel(
    model: &Model,
    grid: &Grid,
    out: &mut [Real],
    threads: usize,
) -> Result<()> {
    check_len("map buffer", grid.len(), out.len())?;
    if grid.len() < PARALLEL_MAP_MIN_CELLS || threads == 1 {
        return crlb_map(model, grid, out);
    }
    let run = |out: &mut [Real]| {
        out.par_chunks_mut(ROWS_PER_TASK * grid.nx)
            .enumerate()
            .try_for_each(|(t, rows)| crlb_map_rows(model, grid, t * ROWS_PER_TASK, rows))
    };
    if threads == 0 {
        run(out)
    } else {
        thread_pool(threads)?.install(|| run(out))
    }
}
