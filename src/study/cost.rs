//! The predicted cost of a study or a track before it starts (issue 24, "Long work"): the
//! filters' step cost ([`step_ns`], its model and calibration) times the steps they will run,
//! and the cap front ends refuse work over ([`check_cost`], [`Error::TooLong`]) with the
//! predicted time.
//!
//! - A Monte Carlo study of chunks `c`: `Σ_filters runs(c) × steps × step_ns(filter, links)`
//!   ([`FilterStudy::predicted_cpu_s`]); the truth simulation is part of the calibrated step
//!   costs.
//! - A track: `steps × step_ns(filter, links)` ([`track_cpu_s`]); gating and association add
//!   per-estimate work that is small next to a filter step. With range rates,
//!   `steps × step_ns_doppler(filter, links)` ([`track_doppler_cpu_s`]).

use core::ops::Range;

use crate::error::{Error, Result};
use crate::math::Real;
use crate::study::FilterStudy;
use crate::track::{step_ns, step_ns_doppler, FilterKind};

/// The CLI's default cap on predicted work: one CPU-day (24 CPU-hours), s. The paper-scale
/// studies of docs/reproduction.md (EKF + UKF ≈ 1 CPU-hour) fit; a full-mesh 64 × 64-node UKF
/// study, or a particle filter of 10⁶ particles at paper scale, do not. `--max-cpu-hours` changes it.
pub const MAX_CPU_S: Real = 86_400.0;

/// The page's cap on a track computed on its main thread, s (a tab must not freeze).
pub const PAGE_TRACK_CPU_S: Real = 2.0;

/// The page's cap on a Monte Carlo study in its worker, s (Stop ends it at any time; the cap
/// keeps a shared link from starting hours of work).
pub const PAGE_STUDY_CPU_S: Real = 600.0;

/// Predicted CPU time of a track of `steps` steps by `filter` over `links` links, s.
pub fn track_cpu_s(filter: FilterKind, links: usize, steps: usize) -> Real {
    steps as Real * step_ns(filter, links) * 1e-9
}

/// [`track_cpu_s`] of a track that updates on delays and range rates (issue 42 §3;
/// [`step_ns_doppler`]).
pub fn track_doppler_cpu_s(filter: FilterKind, links: usize, steps: usize) -> Real {
    steps as Real * step_ns_doppler(filter, links) * 1e-9
}

/// `Ok` when `predicted_s` is within `limit_s`; else [`Error::TooLong`] naming `field` (the
/// inputs that drive the work) with both times.
pub fn check_cost(field: &str, predicted_s: Real, limit_s: Real) -> Result<()> {
    if predicted_s <= limit_s {
        Ok(())
    } else {
        Err(Error::TooLong {
            field: field.into(),
            predicted_s,
            limit_s,
        })
    }
}

impl FilterStudy {
    /// Predicted CPU time of running `chunks` of every filter (each within its own chunks) on a
    /// model of `links` links, s (module docs).
    pub fn predicted_cpu_s(&self, links: usize, chunks: &Range<usize>) -> Real {
        let cfg = self.config();
        self.filters()
            .iter()
            .map(|f| {
                let own = chunks.start.min(f.chunks)..chunks.end.min(f.chunks);
                let runs = cfg.trajectories_in(&own) * cfg.noise_runs;
                runs as Real * cfg.steps as Real * step_ns(f.kind, links) * 1e-9
            })
            .sum()
    }
}
