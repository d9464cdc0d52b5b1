//! Snapshot fix by weighted non-linear least squares with Levenberg–Marquardt (spec §5, E5–E6).
//!
//! Shaped like `rust-cv/levenberg-marquardt`: an [`LmConfig`] and a problem (a [`Network`] and
//! its [`DelayMeasurements`]) give an [`LmReport`] with a [`Termination`] reason. Bad input is a
//! named [`Error`]; numerical trouble is a reported termination, never a panic.
//!
//! Internally the problem is solved in range units (`cτ`, `c²R`, `cJ`), which the spec states is
//! identical to the delay domain and keeps the normal equations well scaled.

use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::geometry::{unit_from, Network};
use crate::math::{erfc, exp, sqrt, Mat2, Real, Vec2, PI, SPEED_OF_LIGHT};
use crate::scenario::Area;

/// Fewest links a snapshot fix needs (spec §5).
pub const MIN_LINKS: usize = 3;

/// LM settings; the defaults are spec §5's [choice] values.
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
    /// Default 1e-6; `None` disables the restart. **[choice]** beyond spec §5.
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

/// One used link in range units: foci, measured range `cτ̂` and weight `1/(cσ)²`.
#[derive(Clone, Copy)]
struct Row {
    tx: Vec2,
    rx: Vec2,
    range: Real,
    weight: Real,
}

/// Validated problem in range units.
struct Problem {
    rows: Vec<Row>,
}

impl Problem {
    fn new(net: &Network, m: &DelayMeasurements) -> Result<Problem> {
        let n = net.link_count();
        if m.delays_s.len() != n {
            return Err(Error::LengthMismatch {
                field: "delays_s",
                expected: n,
                found: m.delays_s.len(),
            });
        }
        if m.sigmas_s.len() != n {
            return Err(Error::LengthMismatch {
                field: "sigma_s",
                expected: n,
                found: m.sigmas_s.len(),
            });
        }
        let mut rows = Vec::with_capacity(n);
        for (p, (d, s)) in m.delays_s.iter().zip(m.sigmas_s).enumerate() {
            let Some(d) = *d else { continue };
            if !d.is_finite() {
                return Err(Error::NonFiniteDelay { link: p });
            }
            if !(s.is_finite() && *s > 0.0) {
                return Err(Error::InvalidSigma { link: p, value: *s });
            }
            let (tx, rx) = net.link_nodes(p);
            let sr = SPEED_OF_LIGHT * s;
            rows.push(Row {
                tx,
                rx,
                range: SPEED_OF_LIGHT * d,
                weight: 1.0 / (sr * sr),
            });
        }
        if rows.len() < MIN_LINKS {
            return Err(Error::TooFewLinks {
                available: rows.len(),
                required: MIN_LINKS,
            });
        }
        Ok(Problem { rows })
    }

    /// 𝓛(r) (E5).
    #[inline]
    fn cost(&self, r: Vec2) -> Real {
        self.rows
            .iter()
            .map(|row| {
                let e = row.range - ((r - row.tx).norm() + (r - row.rx).norm());
                row.weight * e * e
            })
            .sum()
    }

    /// Cost, normal matrix `JᵀWJ` and gradient term `JᵀW(ρ̂ − h)` at `r` (range units).
    #[inline]
    fn linearize(&self, r: Vec2) -> (Real, Mat2, Vec2) {
        let (mut cost, mut n, mut g) = (0.0, Mat2::zeros(), Vec2::zeros());
        for row in &self.rows {
            let (ut, dt) = unit_from(row.tx, r);
            let (ur, dr) = unit_from(row.rx, r);
            let j = ut + ur;
            let e = row.range - (dt + dr);
            cost += row.weight * e * e;
            n += row.weight * j * j.transpose();
            g += (row.weight * e) * j;
        }
        (cost, n, g)
    }
}

/// Solves `(N + λI) Δ = g` for a symmetric 2×2 `N`; `None` if singular or non-finite.
#[inline]
fn solve_damped(n: &Mat2, lambda: Real, g: &Vec2) -> Option<Vec2> {
    let (a, b, c) = (n[(0, 0)] + lambda, n[(0, 1)], n[(1, 1)] + lambda);
    let det = a * c - b * b;
    if !(det.is_finite() && det > 0.0) {
        return None;
    }
    let d = Vec2::new((c * g.x - b * g.y) / det, (a * g.y - b * g.x) / det);
    (d.x.is_finite() && d.y.is_finite()).then_some(d)
}

/// Most grid nodes evaluated by the start search; a larger area gets a coarser grid.
pub const MAX_GRID_START_NODES: usize = 1 << 20;
/// Number of grid local minima LM is started from when no start is given.
pub const GRID_STARTS: usize = 4;

/// Start candidates (spec §5 [choice], extended): the nodes of a `step` grid over `area` whose
/// cost is a local minimum among their 8 neighbours, best first, at most [`GRID_STARTS`], each
/// followed by its 8 neighbours. The first is the spec's "best node of the grid"; the others
/// cover the small basins of truths near a node, which a 0.5 m grid can straddle.
fn grid_starts(p: &Problem, area: &Area, step: Real) -> Vec<Vec2> {
    let (w, h) = (area.x[1] - area.x[0], area.y[1] - area.y[0]);
    let mut step = step;
    while ((w / step) as usize + 1) * ((h / step) as usize + 1) > MAX_GRID_START_NODES {
        step *= 2.0;
    }
    let (nx, ny) = ((w / step) as usize + 1, (h / step) as usize + 1);
    let at =
        |i: usize, j: usize| Vec2::new(area.x[0] + i as Real * step, area.y[0] + j as Real * step);
    let mut cost = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            cost.push(p.cost(at(i, j)));
        }
    }
    let mut minima: Vec<(Real, usize)> = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let c = cost[j * nx + i];
            let lowest = (j.saturating_sub(1)..(j + 2).min(ny))
                .all(|jj| (i.saturating_sub(1)..(i + 2).min(nx)).all(|ii| cost[jj * nx + ii] >= c));
            if lowest && c.is_finite() {
                minima.push((c, j * nx + i));
            }
        }
    }
    minima.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut starts = Vec::with_capacity(9 * GRID_STARTS);
    for &(_, k) in minima.iter().take(GRID_STARTS) {
        let (i, j) = (k % nx, k / nx);
        starts.push(at(i, j));
        for jj in j.saturating_sub(1)..(j + 2).min(ny) {
            for ii in i.saturating_sub(1)..(i + 2).min(nx) {
                if (ii, jj) != (i, j) {
                    starts.push(at(ii, jj));
                }
            }
        }
    }
    starts
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
            .map(|s| iterate(problem, config, s))
            .min_by(|a, b| a.cost.total_cmp(&b.cost));
        // An empty list means every node had a non-finite cost: start at the area's centre.
        Ok(best.unwrap_or_else(|| {
            let centre = Vec2::new(0.5 * (area.x[0] + area.x[1]), 0.5 * (area.y[0] + area.y[1]));
            iterate(problem, config, centre)
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
    let report = iterate(&problem, config, start);
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

/// Upper-tail probability `P(χ²_k > x)` of the χ² distribution with `k ≥ 1` degrees of freedom,
/// in closed form for integer `k`: `e^{−x/2} Σ_{j<k/2} (x/2)^j/j!` for even `k`;
/// `erfc(√(x/2)) + √(2x/π) e^{−x/2} Σ_{j<(k−1)/2} x^j/(1·3···(2j+1))` for odd `k`.
pub fn chi_square_upper_tail(k: usize, x: Real) -> Real {
    if x.is_nan() || x <= 0.0 {
        return 1.0;
    }
    let e = exp(-0.5 * x);
    if k % 2 == 0 {
        let (mut term, mut sum) = (1.0, 0.0);
        for j in 0..k / 2 {
            if j > 0 {
                term *= 0.5 * x / j as Real;
            }
            sum += term;
        }
        (e * sum).min(1.0)
    } else {
        let (mut term, mut sum) = (1.0, 0.0);
        for j in 0..(k - 1) / 2 {
            if j > 0 {
                term *= x / (2 * j + 1) as Real;
            }
            sum += term;
        }
        (erfc(sqrt(0.5 * x)) + sqrt(2.0 * x / PI) * e * sum).min(1.0)
    }
}

fn iterate(p: &Problem, cfg: &LmConfig, start: Vec2) -> LmReport {
    let mut r = start;
    let (mut cost, mut n, mut g) = p.linearize(r);
    let max_diag = n[(0, 0)].max(n[(1, 1)]);
    let mut lambda = cfg.initial_damping_factor * max_diag;
    let lambda_min = cfg.min_damping_factor * max_diag;
    let mut iterations = 0;
    let termination = 'outer: loop {
        if cost == 0.0 {
            break Termination::ExactFit;
        }
        if iterations >= cfg.max_iterations {
            break Termination::MaxIterations;
        }
        iterations += 1;
        let mut rejections = 0;
        loop {
            let Some(step) = solve_damped(&n, lambda, &g) else {
                break 'outer Termination::NumericalFailure;
            };
            let trial = r + step;
            let trial_cost = p.cost(trial);
            if trial_cost < cost {
                let decrease = (cost - trial_cost) / cost;
                r = trial;
                lambda = (lambda / 10.0).max(lambda_min);
                (cost, n, g) = p.linearize(r);
                if step.norm() < cfg.step_tolerance_m {
                    break 'outer Termination::StepTolerance;
                }
                if decrease < cfg.relative_cost_tolerance {
                    break 'outer Termination::CostTolerance;
                }
                break;
            }
            if step.norm() < cfg.step_tolerance_m {
                // Even the smallest useful move does not lower the cost: r is a minimum to tolerance.
                break 'outer Termination::StepTolerance;
            }
            rejections += 1;
            if rejections >= cfg.max_rejections {
                break 'outer Termination::NoImprovement;
            }
            lambda *= 10.0;
        }
    };
    let covariance_m2 =
        crate::crlb::bound_from_fisher(n[(0, 0)], n[(0, 1)], n[(1, 1)]).map(|b| b.covariance_m2);
    LmReport {
        position: r,
        covariance_m2,
        cost: if cost.is_finite() { cost } else { Real::MAX },
        iterations,
        termination,
        links_used: p.rows.len(),
        start,
        restarted: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tail probabilities at reference quantiles (χ² tables): P(χ²_k > q) = 1e-6 at q = 23.9281
    /// (k = 1), 27.6310 (k = 2), 30.6648 (k = 3), 35.8882 (k = 5); and P(χ²_4 > 9.4877) = 0.05.
    #[test]
    fn chi_square_tail_matches_tables() {
        for (k, q, p) in [
            (1, 23.928127, 1e-6),
            (2, 27.631021, 1e-6),
            (3, 30.664850, 1e-6),
            (5, 35.888187, 1e-6),
            (4, 9.487729, 0.05),
        ] {
            let got = chi_square_upper_tail(k, q);
            assert!((got - p).abs() < 1e-5 * p, "k {k}: {got} vs {p}");
        }
        assert_eq!(chi_square_upper_tail(3, 0.0), 1.0);
    }
}
