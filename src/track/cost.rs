//! The predicted cost of a filter step (issue 24, "Long work"): what a Monte Carlo study, a
//! track or the page's worker will cost before it starts, so front ends refuse work past a cap
//! with the predicted time and check cancellation every few milliseconds of work
//! ([`crate::error::check_every`]).
//!
//! The model follows each filter's operation count for `L` links and `n = 4` states:
//! - EKF (spec §6, sequential scalar updates, S16–S17): `a + b·L` (`L·n²` for the updates,
//!   `n³` for the prediction and the NEES);
//! - UKF (`filters-and-planning.md` §1): the `L × L` innovation covariance `S` is built
//!   (`L²/2` entries of 4 products) and factorised (`L³/6` multiply-adds, [`crate::track::Ukf`]),
//!   so `a + b·L + c·L² + d·L³`;
//! - particle filter (§2): every particle evaluates every link, and the NIS of the update
//!   (`S = Σ w (h − ẑ)(h − ẑ)ᵀ + R`, `src/track/pf.rs`) accumulates an `L × L` matrix per
//!   particle (`L²/2` products) and factorises it (`L³/3`): `N·(a + b·L + c·L²/2) + d·L³/3`.
//!   Above a few hundred links the `N·L²` term dominates.
//!
//! The constants are nanoseconds per unit on this project's 2-core development machine, release
//! build, one thread: the fixed and per-link terms from the criterion benches of
//! docs/benchmarks.md ("UKF and particle filter", `montecarlo_chunk`: truth, measurements and
//! NEES included), the large-`L` terms from timing `scatterloc track` on 1024- and 4096-link full
//! meshes (docs/benchmarks.md, "Cost model"). A prediction is a CPU time; front ends divide by
//! their threads. It is an estimate for refusing hopeless work (within a factor of about 2 on
//! that machine), not a promise.

use crate::math::Real;
use crate::track::FilterKind;

/// EKF step, fixed part, ns.
pub const EKF_NS: Real = 80.0;
/// EKF step, per link, ns.
pub const EKF_NS_PER_LINK: Real = 15.0;
/// UKF step, fixed part, ns.
pub const UKF_NS: Real = 450.0;
/// UKF step, per link, ns.
pub const UKF_NS_PER_LINK: Real = 60.0;
/// UKF step, per entry of the `L × L` innovation covariance, ns.
pub const UKF_NS_PER_LINK2: Real = 2.0;
/// UKF step, per multiply-add of its Cholesky factorisation (`L³/6`), ns.
pub const UKF_NS_PER_LINK3: Real = 1.4;
/// Particle filter step, per particle, ns.
pub const PF_NS_PER_PARTICLE: Real = 40.0;
/// Particle filter step, per particle and link, ns.
pub const PF_NS_PER_PARTICLE_LINK: Real = 3.0;
/// Particle filter step, per particle and product of its NIS matrix (`L²/2`), ns.
pub const PF_NS_PER_PARTICLE_LINK2: Real = 1.1;
/// Particle filter step, per multiply-add of the NIS matrix's Cholesky factorisation
/// (`L³/3`), ns.
pub const PF_NS_PER_LINK3: Real = 0.16;

/// EKF step with delays and range rates (issue 42 §3, D8), fixed part, ns: the factored 4-D
/// update (two 4×4 `LDLᵀ`, the posterior's products) and the prediction.
pub const EKF_DOPPLER_NS: Real = 130.0;
/// EKF step with delays and range rates, per link (a delay row and a rate row from one
/// evaluation of the link's geometry and link budget), ns. With [`EKF_DOPPLER_NS`]: 250 ns on 4
/// links, the criterion bench's step (docs/benchmarks.md, "EKF step with Doppler"); the split
/// between the two follows the operation counts (twice the delay-only rows per link).
pub const EKF_DOPPLER_NS_PER_LINK: Real = 30.0;

/// [`step_ns`] of a step that updates on delays and range rates (issue 42 §3): the EKF's own
/// calibration ([`EKF_DOPPLER_NS`]); the UKF and the particle filter as with `2·links`
/// measurement rows (each link gives a delay and a range rate: their `S` and NIS matrices are
/// `2L × 2L`).
pub fn step_ns_doppler(filter: FilterKind, links: usize) -> Real {
    match filter {
        FilterKind::Ekf => EKF_DOPPLER_NS + EKF_DOPPLER_NS_PER_LINK * links as Real,
        other => step_ns(other, 2 * links),
    }
}

/// The predicted CPU time of one step (predict, measurements, update, error and NEES) of
/// `filter` with `links` links, ns (module docs).
pub fn step_ns(filter: FilterKind, links: usize) -> Real {
    let l = links as Real;
    match filter {
        FilterKind::Ekf => EKF_NS + EKF_NS_PER_LINK * l,
        FilterKind::Ukf(_) => {
            UKF_NS
                + UKF_NS_PER_LINK * l
                + UKF_NS_PER_LINK2 * l * l
                + UKF_NS_PER_LINK3 * l * l * l / 6.0
        }
        FilterKind::Pf(c) => {
            let per_particle = PF_NS_PER_PARTICLE
                + PF_NS_PER_PARTICLE_LINK * l
                + PF_NS_PER_PARTICLE_LINK2 * l * l / 2.0;
            c.particles as Real * per_particle + PF_NS_PER_LINK3 * l * l * l / 3.0
        }
    }
}
