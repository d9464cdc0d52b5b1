//! Native (`std`, not wasm32) drivers: the CRLB map over threads ([`crlb_map_parallel`], rows
//! split over rayon workers) on this CPU's widest registers ([`MapPath`]: AVX2 or AVX-512
//! chosen at run time, issue 29), [`run_ordered`], the one ordered parallel driver (rayon waves,
//! results merged in job order, progress and cancel between waves), [`Parallel`], the
//! [`crate::study::Driver`] on it that the studies of [`crate::study`] run through, and the
//! two studies' convenience entry points: the tracker's Monte Carlo ([`run_parallel`], [`run_pcrlb_parallel`], and
//! [`run_chunks_parallel`] for a shard, [`run_filter_chunks_parallel`] for
//! the UKF or the particle filter) and the multi-target experiment sweeps
//! ([`run_experiment_parallel`], and [`run_experiment_range`] for a shard). Results never
//! depend on the thread count, and the sums of shards merge exactly into the whole study's.

mod dispatch;
mod driver;
#[cfg(target_arch = "x86_64")]
mod lanes;
mod map;
mod parallel;
mod sweep;

pub use dispatch::{
    crlb_map_exact, crlb_map_fast, crlb_map_on, crlb_map_rows_on, exact_path, fast_path, map_paths,
    MapPath,
};
pub use driver::{run_ordered, thread_pool, Parallel};
#[cfg(target_arch = "x86_64")]
pub use lanes::{Avx2, Avx512};
pub use map::{crlb_map_parallel, crlb_map_parallel_in, PARALLEL_MAP_MIN_CELLS};
pub use parallel::{
    run_chunks_parallel, run_filter_chunks_parallel, run_parallel, run_pcrlb_parallel,
};
pub use sweep::{run_experiment_parallel, run_experiment_range};
