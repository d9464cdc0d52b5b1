//! Snapshot fix by weighted non-linear least squares with Levenberg–Marquardt (spec §5, E5–E6).
//!
//! Shaped like `rust-cv/levenberg-marquardt`: an [`LmConfig`] and a problem (a [`Network`] and
//! its [`DelayMeasurements`]) give an [`LmReport`] with a [`Termination`] reason. Bad input is a
//! named [`Error`]; numerical trouble is a reported termination, never a panic.
//!
//! Internally the problem is solved in range units (`cτ`, `c²R`, `cJ`), which the spec states is
//! identical to the delay domain and keeps the normal equations well scaled.

use crate::error::{limits, Error, Result};
use crate::math::{Mat2, Real, Vec2};
use crate::measure::Network;
use crate::scenario::Area;

mod chi2;
mod free_z;
mod iterate;
mod problem;
mod start;

pub use chi2::chi_square_upper_tail;
pub use free_z::{locate_free_z, FreeZReport, FREE_Z_START_OFFSETS_M};
pub use start::{GRID_STARTS, MAX_GRID_START_NODES};

use iterate::{iterate, Run};
use problem::Problem;
use start::grid_starts;

/// Fewest links a snapshot fix needs (spec §5).
pub const MIN_LINKS: usize = 3;

/// LM settings; the defaults are spec §5's \[choice\] values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmConfig {
    /// `λ⁽⁰⁾ = factor · max diag(J₀ᵀR⁻¹J₀)`; default 1e-3.
    pub initial_damping_factor: Real,
    /// Lower limit of λ as a multiple of that max diag; default 1e-12.
    pub min_damping_factor: Real,
    /// Stop when the accepted step is shorter than this, m; default 1e-6.
    pub step_tolerance_m: Real,
    /// Stop when the relative decrease of the cost is below this; default 1e-12.
    pub relative_cost_tolerance: Real,
    /// Iteration cap; default 100.
    pub max_iterations: usize,
    /// Rejected trial steps in a row before giving up; default 30.
    pub max_rejections: usize,
    /// Spacing of the start grid search over the area, m; default 0.5.
    pub grid_step_m: Real,
    /// When a run from the caller's start ends with a cost above the χ² quantile of this upper
    /// tail probability (m − 2 degrees of freedom), it is a spurious local minimum with
    /// overwhelming likelihood (they occur near nodes, where ellipses of a start 3 m off can
    /// fold over); the fix is then repeated from the grid-search start and the better one kept.
    /// Default 1e-3; `None` disables the restart. **\[choice\]** beyond spec §5.
    pub restart_tail_probability: Option<Real>,
}

impl Default for LmConfig {
    fn default() -> Self {
        LmConfig {
            initial_damping_factor: 1e-3,
            min_damping_factor: 1e-12,
            step_tolerance_m: 1e-6,
            relative_cost_tolerance: 1e-12,
            max_iterations: 100,
            max_rejections: 30,
            grid_step_m: 0.5,
            restart_tail_probability: Some(1e-3),
        }
    }
}

/// Why the iteration stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Termination {
    /// The last step was shorter than `step_tolerance_m`.
    StepTolerance,
    /// The relative cost decrease fell below `relative_cost_tolerance`.
    CostTolerance,
    /// The residuals are exactly zero.
    ExactFit,
    /// `max_iterations` reached.
    MaxIterations,
    /// `max_rejections` trial steps in a row failed to decrease the cost.
    NoImprovement,
    /// The damped normal equations could not be solved or gave a non-finite step.
    NumericalFailure,
}

impl Termination {
    /// Stable snake_case name used in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            Termination::StepTolerance => "step_tolerance",
            Termination::CostTolerance => "cost_tolerance",
            Termination::ExactFit => "exact_fit",
            Termination::MaxIterations => "max_iterations",
            Termination::NoImprovement => "no_improvement",
            Termination::NumericalFailure => "numerical_failure",
        }
    }

    /// True for the terminations that mean a converged fix.
    pub fn converged(self) -> bool {
        matches!(
            self,
            Termination::StepTolerance | Termination::CostTolerance | Termination::ExactFit
        )
    }
}

/// Measured delays of one snapshot in scenario link order.
#[derive(Debug, Clone, Copy)]
pub struct DelayMeasurements<'a> {
    /// `τ̂_p`, s; `None` = no measurement on that link.
    pub delays_s: &'a [Option<Real>],
    /// `σ_p`, s, one per link (entries of missing links are ignored).
    pub sigmas_s: &'a [Real],
}

/// Result of a fix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmReport {
    /// `r̂`, m.
    pub position: Vec2,
    /// `(JᵀR⁻¹J)⁻¹` at `r̂`, m²; `None` when singular.
    pub covariance_m2: Option<Mat2>,
    /// `𝓛(r̂)` (E5), dimensionless.
    pub cost: Real,
    /// Iterations (Jacobian evaluations) performed.
    pub iterations: usize,
    /// Why it stopped.
    pub termination: Termination,
    /// Links that carried a measurement.
    pub links_used: usize,
    /// Where the (kept) iteration started, m.
    pub start: Vec2,
    /// True when the caller's start led to an implausible cost and the kept fix comes from the
    /// grid-search restart (see [`LmConfig::restart_tail_probability`]).
    pub restarted: bool,
}

/// One planar LM run from `start` as a report; the covariance is `(JᵀR⁻¹J)⁻¹` at the end point.
fn fix(p: &Problem, cfg: &LmConfig, start: Vec2) -> LmReport {
    let Run {
        x,
        normal: n,
        cost,
        iterations,
        termination,
    } = iterate(p, cfg, start);
    LmReport {
        position: x,
        covariance_m2: crate::localize::bound_from_fisher(n[(0, 0)], n[(0, 1)], n[(1, 1)])
            .map(|b| b.covariance_m2),
        cost,
        iterations,
        termination,
        links_used: p.rows.len(),
        start,
        restarted: false,
    }
}

/// Weighted LM fix (E5–E6). Starts at `initial` or, when `None`, at the best node of a
/// `config.grid_step_m` grid over `area`.
pub fn locate(
    net: &Network,
    m: &DelayMeasurements,
    config: &LmConfig,
    initial: Option<Vec2>,
    area: &Area,
) -> Result<LmReport> {
    let problem = Problem::new(net, m)?;
    if let Some(p) = initial {
        limits::COORDINATE_M.check("initial_m", p.x)?;
        limits::COORDINATE_M.check("initial_m", p.y)?;
    }
    let from_grid = |problem: &Problem| -> Result<LmReport> {
        area.validate()?;
        if !(config.grid_step_m.is_finite() && config.grid_step_m > 0.0) {
            return Err(Error::NotPositive {
                field: "grid_step_m".into(),
                value: config.grid_step_m,
            });
        }
        let starts = grid_starts(problem, area, config.grid_step_m);
        let best = starts
            .into_iter()
            .map(|s| fix(problem, config, s))
            .min_by(|a, b| a.cost.total_cmp(&b.cost));
        // An empty list means every node had a non-finite cost: start at the area's centre.
        Ok(best.unwrap_or_else(|| {
            let centre = Vec2::new(0.5 * (area.x[0] + area.x[1]), 0.5 * (area.y[0] + area.y[1]));
            fix(problem, config, centre)
        }))
    };
    let Some(start) = initial else {
        return from_grid(&problem);
    };
    if !(start.x.is_finite() && start.y.is_finite()) {
        return Err(Error::NonFinite {
            field: "initial_m".into(),
        });
    }
    let report = fix(&problem, config, start);
    let dof = problem.rows.len() - 2;
    let implausible = config.restart_tail_probability.is_some_and(|p| {
        dof > 0 && report.cost > dof as Real && chi_square_upper_tail(dof, report.cost) < p
    });
    if implausible && area.validate().is_ok() {
        let retry = from_grid(&problem)?;
        if retry.cost < report.cost {
            return Ok(LmReport {
                restarted: true,
                ..retry
            });
        }
    }
    Ok(report)
}
