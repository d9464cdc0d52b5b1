//! The Levenberg–Marquardt iteration (E6) from one start: damped normal equations, step
//! acceptance and the termination tests.

use super::problem::Problem;
use super::{LmConfig, LmReport, Termination};
use crate::math::{Mat2, Real, Vec2};

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

/// One LM run from `start` until a [`Termination`]; the report's covariance is `(JᵀR⁻¹J)⁻¹` at
/// the end point.
pub(super) fn iterate(p: &Problem, cfg: &LmConfig, start: Vec2) -> LmReport {
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
    let covariance_m2 = crate::localize::bound_from_fisher(n[(0, 0)], n[(0, 1)], n[(1, 1)])
        .map(|b| b.covariance_m2);
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
