use core::cmp::Ordering;

use rand::Rng as _;

use super::cmaes::jacobi_eigen;
use super::objective::percentile;
use super::problem::distance_outside;
use super::*;
use crate::error::Error;
use crate::math::{Real, Vec2};
use crate::measure::rng;
use crate::scenario::presets::sensors2019;
use crate::scenario::Area;

/// numpy's default percentile, written out: sort, rank q (N − 1), interpolate; +∞ dominates.
fn numpy_percentile(v: &[Real], q: Real) -> Real {
    let mut s = v.to_vec();
    s.sort_by(Real::total_cmp);
    let rank = q * (s.len() - 1) as Real;
    let lo = rank.floor() as usize;
    let hi = rank.ceil() as usize;
    if hi == lo {
        return s[lo];
    }
    if s[hi].is_infinite() {
        return Real::INFINITY;
    }
    s[lo] + (rank - lo as Real) * (s[hi] - s[lo])
}

#[test]
fn p90_is_numpys_linear_percentile_with_infinity_dominating() {
    let mut r = rng(3, 0);
    for n in [1, 2, 3, 10, 11, 97, 1000] {
        for holes in [0, 1, n / 10, n / 2] {
            let mut v: Vec<Real> = (0..n).map(|_| r.random::<Real>() * 5.0).collect();
            for h in v.iter_mut().take(holes) {
                *h = Real::INFINITY;
            }
            let expected = numpy_percentile(&v, 0.9);
            let got = percentile(&mut v.clone(), 0.9);
            assert!(
                got == expected || (got - expected).abs() <= 1e-15 * expected,
                "n {n} holes {holes}: {got} vs {expected}"
            );
        }
    }
    // Known values: numpy.percentile([1, 2, 3, 4], 90) = 3.7.
    assert!((percentile(&mut [4.0, 1.0, 3.0, 2.0], 0.9) - 3.7).abs() < 1e-15);
    assert_eq!(
        percentile(&mut [1.0, 2.0, Real::INFINITY], 0.9),
        Real::INFINITY
    );
}

#[test]
fn objective_values_and_ranks() {
    let cells = [0.1, 0.2, 0.3, 0.4];
    let s = |o: Objective, c: &[Real]| o.score(&mut c.to_vec());
    assert!((s(Objective::Mean, &cells).value - 0.25).abs() < 1e-15);
    assert_eq!(s(Objective::Max, &cells).value, 0.4);
    let cov = s(Objective::Coverage { threshold_m: 0.25 }, &cells);
    assert_eq!((cov.value, cov.cost), (0.5, -0.5));
    let holes = [0.1, Real::INFINITY, 0.3, 0.2];
    let m = s(Objective::Mean, &holes);
    assert_eq!((m.value, m.unbounded), (Real::INFINITY, 1));
    assert!((m.bounded_mean - 0.2).abs() < 1e-15);
    // Ranking: finite before unbounded; among unbounded, fewer holes; coverage: more, then mean.
    let two_holes = s(Objective::Mean, &[Real::INFINITY, Real::INFINITY, 0.1, 0.1]);
    assert_eq!(s(Objective::Mean, &cells).rank(&m), Ordering::Less);
    assert_eq!(m.rank(&two_holes), Ordering::Less);
    let c = Objective::Coverage { threshold_m: 0.25 };
    let better_mean = s(c, &[0.1, 0.1, 0.3, 0.4]);
    assert_eq!(s(c, &[0.1, 0.1, 0.2, 0.4]).rank(&cov), Ordering::Less);
    assert_eq!(better_mean.rank(&cov), Ordering::Less);
    // Parsing.
    assert_eq!(Objective::parse("p90"), Ok(Objective::P90));
    assert_eq!(
        Objective::parse("coverage:0.1"),
        Ok(Objective::Coverage { threshold_m: 0.1 })
    );
    assert_eq!(
        Objective::parse("coverage:0.1").unwrap().label(),
        "coverage:0.1"
    );
    for bad in [
        "p95",
        "coverage:",
        "coverage:-1",
        "coverage:nan",
        "coverage:inf",
        "",
    ] {
        assert!(
            matches!(Objective::parse(bad), Err(Error::OutOfRange { .. })),
            "{bad:?}"
        );
    }
}

#[test]
fn jacobi_eigen_diagonalises_symmetric_matrices() {
    let mut r = rng(5, 1);
    for n in [1, 2, 3, 7, 20] {
        let g: Vec<Real> = (0..n * n).map(|_| r.random::<Real>() - 0.5).collect();
        // A = G Gᵀ + diag, symmetric positive definite with a spread of eigenvalues.
        let a: Vec<Real> = (0..n * n)
            .map(|ij| {
                let (i, j) = (ij / n, ij % n);
                let s: Real = (0..n).map(|k| g[i * n + k] * g[j * n + k]).sum();
                s + if i == j { 1e-3 * (i + 1) as Real } else { 0.0 }
            })
            .collect();
        let (vals, v) = jacobi_eigen(&a, n);
        let norm: Real = a.iter().map(|x| x * x).sum::<Real>().sqrt();
        for i in 0..n {
            for j in 0..n {
                // (A V)_ij = λ_j V_ij and (VᵀV)_ij = δ_ij.
                let av: Real = (0..n).map(|k| a[i * n + k] * v[k * n + j]).sum();
                assert!((av - vals[j] * v[i * n + j]).abs() <= 1e-12 * norm, "n {n}");
                let vtv: Real = (0..n).map(|k| v[k * n + i] * v[k * n + j]).sum();
                let id = if i == j { 1.0 } else { 0.0 };
                assert!((vtv - id).abs() <= 1e-12, "n {n}");
            }
        }
    }
}

/// A test function on ℝⁿ with its minimum 0 at `shift`.
struct Bench {
    n: usize,
    kind: u8,
}

impl SearchProblem for Bench {
    type Score = Real;
    fn dimension(&self) -> usize {
        self.n
    }
    fn evaluate(&mut self, x: &[Real]) -> Real {
        let y: Vec<Real> = x.iter().map(|v| v - 0.3).collect();
        match self.kind {
            // Sphere.
            0 => y.iter().map(|v| v * v).sum(),
            // Ellipsoid, condition 10⁶, rotated by a fixed 45° mix of neighbours.
            1 => (0..self.n)
                .map(|i| {
                    let z = if i + 1 < self.n {
                        (y[i] + y[i + 1]) / 2f64.sqrt()
                    } else {
                        y[i]
                    };
                    let w = 1e6f64.powf(i as Real / (self.n - 1).max(1) as Real);
                    w * z * z
                })
                .sum(),
            // Rosenbrock (minimum at 1 + 0.3 shift... i.e. y = 1).
            _ => (0..self.n - 1)
                .map(|i| {
                    let (a, b) = (y[i] + 0.7, y[i + 1] + 0.7);
                    100.0 * (b - a * a).powi(2) + (1.0 - a).powi(2)
                })
                .sum(),
        }
    }
    fn rank(&self, a: &Real, b: &Real) -> Ordering {
        a.total_cmp(b)
    }
    fn restart_point(&self, rng: &mut crate::measure::Rng, x: &mut [Real]) {
        for v in x.iter_mut() {
            *v = rng.random::<Real>() * 2.0 - 1.0;
        }
    }
}

#[test]
fn cmaes_minimises_test_functions_on_every_seed() {
    for seed in 1..=4 {
        for (kind, n, budget, tol) in [
            (0u8, 2, 4000, 1e-12),
            (0, 10, 20_000, 1e-12),
            (1, 6, 40_000, 1e-10),
            (2, 4, 40_000, 1e-8),
        ] {
            let config = CmaesConfig {
                budget,
                seed,
                ..CmaesConfig::default()
            };
            let mut p = Bench { n, kind };
            let x0 = vec![-0.5; n];
            let r = minimize(&mut p, &x0, &config, |_| true);
            assert!(
                r.best <= tol,
                "kind {kind} n {n} seed {seed}: best {} after {} evaluations ({:?})",
                r.best,
                r.evaluations,
                r.termination
            );
            assert!(r.evaluations <= budget);
        }
    }
}

#[test]
fn cmaes_is_deterministic_respects_the_budget_and_cancels() {
    let config = CmaesConfig {
        budget: 777,
        seed: 9,
        max_restarts: 100,
        ..CmaesConfig::default()
    };
    let run = |c: &CmaesConfig| minimize(&mut Bench { n: 5, kind: 2 }, &[0.0; 5], c, |_| true);
    let (a, b) = (run(&config), run(&config));
    assert_eq!(a, b);
    assert_eq!(a.evaluations, 777);
    assert_eq!(a.termination, Termination::Budget);
    let other = run(&CmaesConfig { seed: 10, ..config });
    assert_ne!(a.best_x, other.best_x);
    let mut generations = 0;
    let cancelled = minimize(&mut Bench { n: 5, kind: 0 }, &[0.0; 5], &config, |g| {
        generations += 1;
        assert!(g.evaluations > 0 && g.best.is_finite());
        generations < 3
    });
    assert_eq!(cancelled.termination, Termination::Cancelled);
    assert_eq!(generations, 3);
}

#[test]
fn polygon_distance_is_zero_inside_and_euclidean_outside() {
    // An L-shaped room.
    let l = vec![
        [0.0, 0.0],
        [4.0, 0.0],
        [4.0, 1.0],
        [1.0, 1.0],
        [1.0, 3.0],
        [0.0, 3.0],
    ];
    for (p, d) in [
        ((0.5, 0.5), 0.0),
        ((3.0, 0.5), 0.0),
        ((0.5, 2.5), 0.0),
        ((2.0, 2.0), 1.0), // in the notch: 1 m from both inner edges
        ((5.0, 0.5), 1.0),
        ((-3.0, -4.0), 5.0),
        ((4.0, 1.0), 0.0), // a vertex
    ] {
        let got = distance_outside(&l, Vec2::new(p.0, p.1));
        assert!((got - d).abs() < 1e-12, "{p:?}: {got} vs {d}");
    }
}

fn area(x0: Real, x1: Real, y0: Real, y1: Real) -> Area {
    Area {
        x: [x0, x1],
        y: [y0, y1],
    }
}

#[test]
fn plan_space_encodes_decodes_and_names_bad_problems() {
    let s = sensors2019();
    let c = |b: Area, spacing: Real| Constraints {
        bounds: b,
        allowed: vec![],
        min_spacing_m: spacing,
    };
    let space = PlanSpace::new(&s, &MoveSpec::Receivers, c(s.area_m, 0.0)).unwrap();
    assert_eq!(space.dimension(), 8);
    let base = space.base_layout();
    let x = space.encode(&base);
    let (back, excess) = space.decode(&x);
    assert_eq!(excess, 0.0);
    for (a, b) in back.positions.iter().zip(&base.positions) {
        assert!((a - b).norm() < 1e-12);
    }
    assert_eq!(space.violation(&base), 0.0);
    // Outside the box: projected, and the excess is the squared distance in unit coordinates.
    let mut out = x.clone();
    out[0] = -0.5;
    out[1] = 1.25;
    let (proj, excess) = space.decode(&out);
    assert!((excess - (0.25 + 0.0625)).abs() < 1e-15);
    assert_eq!(proj.positions[0], Vec2::new(s.area_m.x[0], s.area_m.y[1]));
    // Beams turn in wrapped turns.
    let beams = PlanSpace::new(&s, &MoveSpec::TransmittersWithBoresight, c(s.area_m, 0.0)).unwrap();
    assert_eq!(beams.turned(), &[0]);
    let (l, _) = beams.decode(&[0.5, 0.5, -0.25]);
    assert!((l.boresights_deg[0] - 270.0).abs() < 1e-12);
    let scen = beams.apply_to_scenario(&l);
    assert!(scen.validate().is_ok());
    // Named errors.
    let err = |spec: MoveSpec, cons: Constraints| PlanSpace::new(&s, &spec, cons).unwrap_err();
    assert!(matches!(
        err(MoveSpec::Names(vec!["Nope".into()]), c(s.area_m, 0.0)),
        Error::UnknownNode { ref name, .. } if name == "Nope"
    ));
    assert!(matches!(
        err(MoveSpec::Names(vec![]), c(s.area_m, 0.0)),
        Error::Infeasible { ref field, .. } if field == "move"
    ));
    // The receivers stay when the transmitter moves: two of them are closer than 100 m.
    assert!(matches!(
        err(MoveSpec::Transmitters, c(s.area_m, 100.0)),
        Error::Infeasible { ref field, .. } if field == "min_spacing"
    ));
    // All nodes move: five nodes 30 m apart cannot fit in a 2 m box.
    assert!(matches!(
        err(MoveSpec::All, c(area(0.0, 2.0, 0.0, 2.0), 30.0)),
        Error::Infeasible { ref field, .. } if field == "min_spacing"
    ));
    assert!(matches!(
        err(MoveSpec::Receivers, c(area(3.0, 1.0, 0.0, 2.0), 0.0)),
        Error::InvertedArea {
            field: "bounds.x",
            ..
        }
    ));
    let degenerate = Constraints {
        allowed: vec![vec![[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]],
        ..c(s.area_m, 0.0)
    };
    assert!(matches!(
        err(MoveSpec::Receivers, degenerate),
        Error::Infeasible { ref field, .. } if field == "allowed[0]"
    ));
}

#[test]
fn plan_errors_name_the_roi_grid_and_budget() {
    let s = sensors2019();
    let cfg = PlanConfig::new(Objective::Mean, s.area_m);
    let run = |c: &PlanConfig| plan(&s, c, |_| true).unwrap_err();
    let outside = PlanConfig {
        roi: area(-100.0, 0.0, 0.0, 1.0),
        ..cfg.clone()
    };
    assert!(matches!(run(&outside), Error::Infeasible { ref field, .. } if field == "roi"));
    let inverted = PlanConfig {
        roi: area(0.0, 1.0, 3.0, 2.0),
        ..cfg.clone()
    };
    assert!(matches!(
        run(&inverted),
        Error::InvertedArea { field: "roi.y", .. }
    ));
    for (grid, budget, field) in [(1, 10, "grid"), (513, 10, "grid"), (8, 0, "budget")] {
        let c = PlanConfig {
            grid,
            budget,
            ..cfg.clone()
        };
        assert!(matches!(run(&c), Error::SizeLimit { field: f, .. } if f == field));
    }
    let cancelled = plan(&s, &PlanConfig { budget: 500, ..cfg }, |_| false);
    assert_eq!(cancelled, Err(Error::Cancelled));
}
