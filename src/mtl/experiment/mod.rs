//! The experiments of spec `multi-target.md` §8 as ROC sweeps: V-A (Fig. 3, \[SM\]'s size rule vs
//! Bayesian MTL with i.c.b, sweeping `T_e`), V-B (Fig. 4, PPP vs i.c.b (and optionally the
//! empirical model of §6.3), sweeping `T_b`) and V-C (Fig. 5, Bayesian MTL vs the genie-aided
//! method, sweeping `T_b`).
//!
//! Every realisation `i` is drawn by the §7 generator from the stream `rng(seed, i)` and
//! evaluated on its own ([`realisation::evaluate`]; the empirical model trains on its own stream
//! `rng(seed, 2⁴⁰ + i)`); the sums over realisations are exact ([`Tally`]), so results depend
//! on the configuration and seed only — the native parallel driver (`native`) gives bitwise the
//! same numbers as [`run_sequential`], and tallies of disjoint ranges of realisations (shards,
//! [`crate::math::Shard`]) merge into exactly the tally of their union.
//!
//! - [`config`]: the configuration and its curves; [`result`]: ROC points and the sums.
//! - [`realisation`]: one realisation, every curve and threshold.
//! - [`memo`]: memoised blocking likelihoods shared by the thresholds of one realisation.
//! - [`genie`]: the genie-aided detector of Fig. 5 (**\[C\]**).
//!
//! Reconstruction choices (**\[P\]**, all fields of [`ExperimentConfig`]): the sweeps, `N_u`
//! values, the V-B i.c.b `p_u`, the PPP variant (bound (M10) as in \[A\], or exact (M11)), the
//! empirical table's grid and training size, and the x-axis of Fig. 5 (`T_b`: the figure's axis
//! was lost; the V-C text compares missed-detection probabilities, so we sweep the V-B
//! threshold and report `1 − P_D` against it).

pub mod config;
pub mod genie;
pub mod memo;
pub mod realisation;
pub mod result;

use crate::error::{Error, Result};

pub use config::{
    grid, CurveSpec, EmpiricalTraining, Experiment, ExperimentConfig, Method, MAX_REALISATIONS,
    MAX_SWEEP_POINTS,
};
pub use realisation::{evaluate, RealisationCounts};
pub use result::{Curve, ExperimentResult, RocPoint, Tally};

/// Runs the experiment on one thread, calling `on_progress(done, total)` after each
/// realisation; `cancelled()` is polled between realisations ([`Error::Cancelled`]).
pub fn run_sequential(
    cfg: &ExperimentConfig,
    mut on_progress: impl FnMut(usize, usize),
    cancelled: impl Fn() -> bool,
) -> Result<ExperimentResult> {
    cfg.validate()?;
    let mut tally = Tally::new(cfg.curves().len(), cfg.sweep.len());
    for i in 0..cfg.realisations {
        if cancelled() {
            return Err(Error::Cancelled);
        }
        tally.add(&evaluate(cfg, i as u64)?);
        on_progress(i + 1, cfg.realisations);
    }
    Ok(tally.finish(cfg))
}
