//! The Levenberg–Marquardt iteration (E6) from one start: damped normal equations, step
//! acceptance and the termination tests — one loop for the planar fix (`D = 2`, `[x, y]`) and
//! the fix with a free height (`D = 3`, `[x, y, δz]`, issue 40 §2), behind [`LmProblem`].

use nalgebra::{SMatrix, SVector};

use super::{LmConfig, Termination};
use crate::math::Real;

/// A weighted least-squares problem in range units over `D` unknowns: the cost 𝓛 (E5) and its
/// linearisation (cost, normal matrix `JᵀWJ`, gradient term `JᵀW(ρ̂ − h)`).
pub(super) trait LmProblem<const D: usize> {
    /// 𝓛(x).
    fn cost(&self, x: &SVector<Real, D>) -> Real;
    /// Cost, `JᵀWJ` and `JᵀW(ρ̂ − h)` at `x`.
    fn linearize(&self, x: &SVector<Real, D>) -> (Real, SMatrix<Real, D, D>, SVector<Real, D>);
}

/// Where one run ended.
pub(super) struct Run<const D: usize> {
    /// The end point.
    pub(super) x: SVector<Real, D>,
    /// `JᵀWJ` there (its inverse is the fix's covariance).
    pub(super) normal: SMatrix<Real, D, D>,
    /// 𝓛 there (`Real::MAX` when not finite).
    pub(super) cost: Real,
    /// Iterations (Jacobian evaluations).
    pub(super) iterations: usize,
    /// Why it stopped.
    pub(super) termination: Termination,
}

/// Solves `(N + λI) Δ = g` for a symmetric `N`; `None` if singular or non-finite. `D = 2` is the
/// closed form (the planar fix's bits, unchanged since spec §5), larger `D` a Cholesky solve.
#[inline]
fn solve_damped<const D: usize>(
    n: &SMatrix<Real, D, D>,
    lambda: Real,
    g: &SVector<Real, D>,
) -> Option<SVector<Real, D>> {
    if D == 2 {
        let (a, b, c) = (n[(0, 0)] + lambda, n[(0, 1)], n[(1, 1)] + lambda);
        let det = a * c - b * b;
        if !(det.is_finite() && det > 0.0) {
            return None;
        }
        let (x, y) = ((c * g[0] - b * g[1]) / det, (a * g[1] - b * g[0]) / det);
        let d = SVector::<Real, D>::from_fn(|i, _| if i == 0 { x } else { y });
        return (x.is_finite() && y.is_finite()).then_some(d);
    }
    let m = n + SMatrix::<Real, D, D>::identity() * lambda;
    if !m.iter().all(|v| v.is_finite()) {
        return None;
    }
    let d = m.cholesky()?.solve(g);
    d.iter().all(|v| v.is_finite()).then_some(d)
}

/// One LM run from `start` until a [`Termination`] (at most `max_iterations` Jacobian
/// evaluations, each with at most `max_rejections` trial steps).
pub(super) fn iterate<const D: usize, P: LmProblem<D>>(
    p: &P,
    cfg: &LmConfig,
    start: SVector<Real, D>,
) -> Run<D> {
    let mut r = start;
    let (mut cost, mut n, mut g) = p.linearize(&r);
    let max_diag = (1..D).fold(n[(0, 0)], |m, i| m.max(n[(i, i)]));
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
            let trial_cost = p.cost(&trial);
            if trial_cost < cost {
                let decrease = (cost - trial_cost) / cost;
                r = trial;
                lambda = (lambda / 10.0).max(lambda_min);
                (cost, n, g) = p.linearize(&r);
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
    Run {
        x: r,
        normal: n,
        cost: if cost.is_finite() { cost } else { Real::MAX },
        iterations,
        termination,
    }
}
