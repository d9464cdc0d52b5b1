//! The CRLB map on threads: blocks of whole rows of the grid run the kernel on this CPU's
//! fastest path ([`super::fast_path`]: AVX-512 or AVX2 when present, issue 29) on rayon workers.
//! Rows are independent, so the map is bitwise the single-threaded one for any thread count.
//! [`crlb_map_parallel_in`] also stops on a cancel flag (Ctrl-C in the Python package).

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::driver::thread_pool;
use crate::error::{check_len, Error, Result};
use crate::localize::Grid;

use super::dispatch::{crlb_map_rows_on, fast_path};
use crate::math::Real;
use crate::measure::Model;

/// Grids with fewer cells than this (128²) run on the calling thread: below it, handing rows to
/// workers costs more than it saves.
pub const PARALLEL_MAP_MIN_CELLS: usize = 128 * 128;

/// Rows per task: enough tasks for load balance, each a few hundred microseconds at most.
const ROWS_PER_TASK: usize = 8;

/// The CRLB map ([`crate::localize::crlb_map`]) on this CPU's fastest kernel path
/// ([`super::fast_path`]; within the bound of [`super::lanes`] of the core's kernel) with its
/// rows split over `threads` workers (0 = rayon's global pool, all cores) from
/// [`PARALLEL_MAP_MIN_CELLS`] cells up.
pub fn crlb_map_parallel(
    model: &Model,
    grid: &Grid,
    out: &mut [Real],
    threads: usize,
) -> Result<()> {
    crlb_map_parallel_in(model, grid, out, threads, &AtomicBool::new(false))
}

/// [`crlb_map_parallel`] that stops with [`Error::Cancelled`] when `cancel` becomes true (checked
/// before each task of [`ROWS_PER_TASK`] rows: a 2048² map of 4096 links stops within a
/// fraction of a second). `out` is then partly written.
pub fn crlb_map_parallel_in(
    model: &Model,
    grid: &Grid,
    out: &mut [Real],
    threads: usize,
    cancel: &AtomicBool,
) -> Result<()> {
    check_len("map buffer", grid.len(), out.len())?;
    let path = fast_path();
    if grid.len() < PARALLEL_MAP_MIN_CELLS || threads == 1 {
        // Row blocks on this thread, with the same cancel checks.
        for (t, rows) in out.chunks_mut(ROWS_PER_TASK * grid.nx).enumerate() {
            if cancel.load(Ordering::Relaxed) {
                return Err(Error::Cancelled);
            }
            crlb_map_rows_on(path, model, grid, t * ROWS_PER_TASK, rows)?;
        }
        return Ok(());
    }
    let run = |out: &mut [Real]| {
        out.par_chunks_mut(ROWS_PER_TASK * grid.nx)
            .enumerate()
            .try_for_each(|(t, rows)| {
                if cancel.load(Ordering::Relaxed) {
                    return Err(Error::Cancelled);
                }
                crlb_map_rows_on(path, model, grid, t * ROWS_PER_TASK, rows)
            })
    };
    // The global pool when it has the threads asked for (building a pool per map cost 0.2 ms
    // of a 0.8 ms 256² map).
    if threads == 0 || threads == rayon::current_num_threads() {
        run(out)
    } else {
        thread_pool(threads)?.install(|| run(out))
    }
}
