//! CMA-ES with IPOP restarts: the derivative-free global optimiser of the planner.
//!
//! One run is the `(μ/μ_w, λ)`-CMA-ES of Hansen's tutorial (N. Hansen, "The CMA Evolution
//! Strategy: A Tutorial", arXiv:1604.00772, 2016, Table 1 and Fig. 6): weighted recombination,
//! cumulative step-size adaptation, rank-one and rank-μ covariance updates. Runs stop on the
//! tutorial's criteria (tolX, a flat history of best values, a condition number past 10¹⁴);
//! each restart doubles the population (IPOP-CMA-ES, A. Auger and N. Hansen, CEC 2005) and starts
//! from a point the problem draws. Only the ranks of scores are used, so a problem may rank by a
//! lexicographic key (feasibility first, then the objective).
//!
//! Every step is seeded arithmetic: normals by the polar method and `exp`/`ln` from
//! [`crate::math`] (the `libm` crate on every platform), the eigendecomposition by cyclic Jacobi rotations (only `+ − × ÷ √`),
//! so a run gives the same bits on every platform and thread count.

use alloc::vec;
use alloc::vec::Vec;
use core::cmp::Ordering;

use rand::Rng as _;

use crate::math::{exp, ln, sqrt, Real};
use crate::measure::{rng, Rng};

/// What CMA-ES minimises: a score per point of `ℝⁿ`, ranked by [`SearchProblem::rank`].
pub trait SearchProblem {
    /// The score of a point (e.g. constraint violation, then the objective).
    type Score: Copy;
    /// `n`, the number of variables.
    fn dimension(&self) -> usize;
    /// The score of `x` (`x.len() == n`).
    fn evaluate(&mut self, x: &[Real]) -> Self::Score;
    /// The order of scores: `Less` = better.
    fn rank(&self, a: &Self::Score, b: &Self::Score) -> Ordering;
    /// A restart's initial mean, drawn with `rng` (e.g. uniform over the search box).
    fn restart_point(&self, rng: &mut Rng, x: &mut [Real]);
}

/// Settings of [`minimize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CmaesConfig {
    /// Largest number of evaluations (over all runs).
    pub budget: usize,
    /// Seed of every random draw.
    pub seed: u64,
    /// Initial step size `σ₀` of every run, in the variables' units.
    pub sigma0: Real,
    /// Population `λ` of the first run; `0` = the default `4 + ⌊3 ln n⌋`.
    pub population: usize,
    /// Restarts after the first run (IPOP: `λ` doubles each time).
    pub max_restarts: usize,
    /// A run stops when `σ · max √C_ii` is below this (tolX).
    pub tol_x: Real,
}

impl Default for CmaesConfig {
    fn default() -> Self {
        CmaesConfig {
            budget: 4000,
            seed: 1,
            sigma0: 0.3,
            population: 0,
            max_restarts: 9,
            tol_x: 1e-7,
        }
    }
}

/// Why [`minimize`] returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Termination {
    /// The evaluation budget is spent.
    Budget,
    /// Every run (the first and `max_restarts` restarts) converged.
    Restarts,
    /// The observer asked to stop.
    Cancelled,
}

/// What the observer sees after every generation.
#[derive(Debug, Clone, Copy)]
pub struct Generation<'a, S> {
    /// Evaluations so far.
    pub evaluations: usize,
    /// The run (0 = first; each restart adds one).
    pub run: usize,
    /// Whether this generation found a new best point.
    pub improved: bool,
    /// The best point so far.
    pub best_x: &'a [Real],
    /// Its score.
    pub best: &'a S,
    /// The current step size.
    pub sigma: Real,
}

/// The result of [`minimize`].
#[derive(Debug, Clone, PartialEq)]
pub struct CmaesReport<S> {
    /// The best point evaluated.
    pub best_x: Vec<Real>,
    /// Its score.
    pub best: S,
    /// Evaluations made.
    pub evaluations: usize,
    /// Runs made (1 + restarts).
    pub runs: usize,
    /// Why it stopped.
    pub termination: Termination,
}

/// Minimises `problem` from the mean `x0` (`x0.len() == n ≥ 1`, `budget ≥ 1`); `observe` is called
/// after every generation and stops the search by returning `false`.
pub fn minimize<P: SearchProblem>(
    problem: &mut P,
    x0: &[Real],
    config: &CmaesConfig,
    mut observe: impl FnMut(&Generation<'_, P::Score>) -> bool,
) -> CmaesReport<P::Score> {
    let n = problem.dimension();
    debug_assert_eq!(x0.len(), n);
    let mut rng = rng(config.seed, 0x706c_616e); // "plan"
    let mut normal = Normal::default();
    let default_lambda = 4 + (3.0 * ln(n as Real)) as usize;
    let mut lambda = match config.population {
        0 => default_lambda,
        p => p.max(2),
    };
    let mut best: Option<(Vec<Real>, P::Score)> = None;
    let mut evaluations = 0;
    let mut mean = x0.to_vec();
    let mut run = 0;
    let termination = loop {
        let mut state = Run::new(n, lambda, config.sigma0, config.tol_x, mean.clone());
        // The run stops when its best has not improved for this many generations.
        let patience = 10 + (30 * n).div_ceil(lambda);
        let mut run_best: Option<P::Score> = None;
        let mut stale = 0;
        let stop = loop {
            let mut improved = false;
            let mut scored: Vec<(usize, P::Score)> = Vec::with_capacity(lambda);
            for k in 0..lambda {
                if evaluations >= config.budget {
                    break;
                }
                state.sample(k, &mut rng, &mut normal);
                let s = problem.evaluate(&state.xs[k]);
                evaluations += 1;
                scored.push((k, s));
                let better = best
                    .as_ref()
                    .is_none_or(|(_, b)| problem.rank(&s, b) == Ordering::Less);
                if better {
                    best = Some((state.xs[k].clone(), s));
                    improved = true;
                }
            }
            let Some((bx, bs)) = best.as_ref() else {
                break Some(Termination::Budget);
            };
            let go_on = observe(&Generation {
                evaluations,
                run,
                improved,
                best_x: bx,
                best: bs,
                sigma: state.sigma,
            });
            if !go_on {
                break Some(Termination::Cancelled);
            }
            if scored.len() < lambda {
                break Some(Termination::Budget);
            }
            // A stable sort by rank (ties in sampling order) keeps the run deterministic.
            scored.sort_by(|a, b| problem.rank(&a.1, &b.1));
            let generation_best = scored[0].1;
            if run_best.is_none_or(|b| problem.rank(&generation_best, &b) == Ordering::Less) {
                run_best = Some(generation_best);
                stale = 0;
            } else {
                stale += 1;
            }
            let order: Vec<usize> = scored.iter().map(|(k, _)| *k).collect();
            if state.update(&order) || stale > patience {
                break None;
            }
        };
        match stop {
            Some(t) => break t,
            None if run >= config.max_restarts => break Termination::Restarts,
            None => {
                run += 1;
                lambda *= 2;
                problem.restart_point(&mut rng, &mut mean);
            }
        }
    };
    let (best_x, best) = best.unwrap_or_else(|| (x0.to_vec(), problem.evaluate(x0)));
    CmaesReport {
        best_x,
        best,
        evaluations,
        runs: run + 1,
        termination,
    }
}

/// Standard normals by Marsaglia's polar method (uniforms from the crate's PCG; `ln` and `√`
/// portable), the second of each pair kept.
#[derive(Debug, Default)]
struct Normal {
    spare: Option<Real>,
}

impl Normal {
    fn sample(&mut self, rng: &mut Rng) -> Real {
        if let Some(s) = self.spare.take() {
            return s;
        }
        loop {
            let u = 2.0 * rng.random::<Real>() - 1.0;
            let v = 2.0 * rng.random::<Real>() - 1.0;
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                let f = sqrt(-2.0 * ln(s) / s);
                self.spare = Some(v * f);
                return u * f;
            }
        }
    }
}

/// The state of one CMA-ES run (the tutorial's notation).
struct Run {
    n: usize,
    tol_x: Real,
    weights: Vec<Real>,
    mueff: Real,
    cc: Real,
    cs: Real,
    c1: Real,
    cmu: Real,
    damps: Real,
    chi_n: Real,
    mean: Vec<Real>,
    sigma: Real,
    pc: Vec<Real>,
    ps: Vec<Real>,
    /// `C`, row-major.
    c: Vec<Real>,
    /// Eigenvectors of `C` (columns), row-major.
    b: Vec<Real>,
    /// Square roots of the eigenvalues.
    d: Vec<Real>,
    /// Samples `x_k` of the current generation.
    xs: Vec<Vec<Real>>,
    /// `(1 − c_σ)^(2 g)`, for `h_σ`.
    ps_decay: Real,
    generation: usize,
    eigen_generation: usize,
}

impl Run {
    fn new(n: usize, lambda: usize, sigma: Real, tol_x: Real, mean: Vec<Real>) -> Run {
        let mu = lambda / 2;
        let raw: Vec<Real> = (0..mu)
            .map(|i| ln((lambda as Real + 1.0) / 2.0) - ln((i + 1) as Real))
            .collect();
        let sum: Real = raw.iter().sum();
        let weights: Vec<Real> = raw.iter().map(|w| w / sum).collect();
        let mueff = 1.0 / weights.iter().map(|w| w * w).sum::<Real>();
        let nf = n as Real;
        let cc = (4.0 + mueff / nf) / (nf + 4.0 + 2.0 * mueff / nf);
        let cs = (mueff + 2.0) / (nf + mueff + 5.0);
        let c1 = 2.0 / ((nf + 1.3) * (nf + 1.3) + mueff);
        let cmu =
            (1.0 - c1).min(2.0 * (mueff - 2.0 + 1.0 / mueff) / ((nf + 2.0) * (nf + 2.0) + mueff));
        let damps = 1.0 + 2.0 * (sqrt((mueff - 1.0) / (nf + 1.0)) - 1.0).max(0.0) + cs;
        let mut c = vec![0.0; n * n];
        let mut b = vec![0.0; n * n];
        for i in 0..n {
            c[i * n + i] = 1.0;
            b[i * n + i] = 1.0;
        }
        Run {
            n,
            tol_x,
            weights,
            mueff,
            cc,
            cs,
            c1,
            cmu,
            damps,
            chi_n: sqrt(nf) * (1.0 - 1.0 / (4.0 * nf) + 1.0 / (21.0 * nf * nf)),
            mean,
            sigma,
            pc: vec![0.0; n],
            ps: vec![0.0; n],
            c,
            b,
            d: vec![1.0; n],
            xs: vec![vec![0.0; n]; lambda],
            ps_decay: 1.0,
            generation: 0,
            eigen_generation: 0,
        }
    }

    /// `x_k = m + σ B D z`, `z ~ 𝒩(0, I)`.
    fn sample(&mut self, k: usize, rng: &mut Rng, normal: &mut Normal) {
        let n = self.n;
        let dz: Vec<Real> = (0..n).map(|j| self.d[j] * normal.sample(rng)).collect();
        let x = &mut self.xs[k];
        for (i, xi) in x.iter_mut().enumerate() {
            let row = &self.b[i * n..(i + 1) * n];
            let y: Real = row.iter().zip(&dz).map(|(b, z)| b * z).sum();
            *xi = self.mean[i] + self.sigma * y;
        }
    }

    /// Updates mean, paths, `C` and `σ` from the samples in rank order; returns true when the run
    /// should stop.
    fn update(&mut self, order: &[usize]) -> bool {
        let n = self.n;
        let mu = self.weights.len();
        let old = self.mean.clone();
        for i in 0..n {
            self.mean[i] = (0..mu)
                .map(|r| self.weights[r] * self.xs[order[r]][i])
                .sum();
        }
        let yw: Vec<Real> = (0..n)
            .map(|i| (self.mean[i] - old[i]) / self.sigma)
            .collect();
        // C^(-1/2) y_w = B D⁻¹ Bᵀ y_w.
        let bty: Vec<Real> = (0..n)
            .map(|j| (0..n).map(|i| self.b[i * n + j] * yw[i]).sum::<Real>() / self.d[j])
            .collect();
        let cs_norm = sqrt(self.cs * (2.0 - self.cs) * self.mueff);
        for i in 0..n {
            let z: Real = (0..n).map(|j| self.b[i * n + j] * bty[j]).sum();
            self.ps[i] = (1.0 - self.cs) * self.ps[i] + cs_norm * z;
        }
        self.generation += 1;
        self.ps_decay *= (1.0 - self.cs) * (1.0 - self.cs);
        let ps_norm = sqrt(self.ps.iter().map(|v| v * v).sum());
        let hsig = ps_norm / sqrt(1.0 - self.ps_decay) / self.chi_n < 1.4 + 2.0 / (n as Real + 1.0);
        let hsig_f = if hsig { 1.0 } else { 0.0 };
        let cc_norm = sqrt(self.cc * (2.0 - self.cc) * self.mueff);
        for (pc, y) in self.pc.iter_mut().zip(&yw) {
            *pc = (1.0 - self.cc) * *pc + hsig_f * cc_norm * y;
        }
        // C ← (1 − c1 − cμ + (1 − h_σ) c1 cc (2 − cc)) C + c1 pc pcᵀ + cμ Σ w_r y_r y_rᵀ.
        let keep = 1.0 - self.c1 - self.cmu + (1.0 - hsig_f) * self.c1 * self.cc * (2.0 - self.cc);
        let ys: Vec<Vec<Real>> = order[..mu]
            .iter()
            .map(|&k| {
                (0..n)
                    .map(|i| (self.xs[k][i] - old[i]) / self.sigma)
                    .collect()
            })
            .collect();
        for i in 0..n {
            for j in 0..=i {
                let rank_mu: Real = (0..mu).map(|r| self.weights[r] * ys[r][i] * ys[r][j]).sum();
                let v = keep * self.c[i * n + j]
                    + self.c1 * self.pc[i] * self.pc[j]
                    + self.cmu * rank_mu;
                self.c[i * n + j] = v;
                self.c[j * n + i] = v;
            }
        }
        let step = ((self.cs / self.damps) * (ps_norm / self.chi_n - 1.0)).min(1.0);
        self.sigma *= exp(step);
        // Eigendecomposition every ⌈1/(10 n (c1 + cμ))⌉ generations (the tutorial's lazy update).
        let every = (1.0 / (10.0 * n as Real * (self.c1 + self.cmu))).max(1.0) as usize;
        if self.generation - self.eigen_generation >= every {
            self.eigen_generation = self.generation;
            let (values, vectors) = jacobi_eigen(&self.c, n);
            self.b = vectors;
            self.d = values.iter().map(|&v| sqrt(v.max(1e-300))).collect();
        }
        self.stop()
    }

    /// tolX (`σ · max √C_ii` below it), a σ that is not finite or exploded, a condition number of
    /// `C` past 10¹⁴.
    fn stop(&self) -> bool {
        let n = self.n;
        let max_sd = (0..n).map(|i| sqrt(self.c[i * n + i])).fold(0.0, Real::max);
        let (dmin, dmax) = self
            .d
            .iter()
            .fold((Real::INFINITY, 0.0 as Real), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        let spread = self.sigma * max_sd;
        spread.is_nan() || spread < self.tol_x || self.sigma > 1e8 || dmax > 1e7 * dmin
    }
}

/// Eigenvalues and eigenvectors (columns of a row-major matrix) of the symmetric `n × n` row-major
/// `a`, by cyclic Jacobi rotations until the off-diagonal part is negligible.
pub(super) fn jacobi_eigen(a: &[Real], n: usize) -> (Vec<Real>, Vec<Real>) {
    let mut m = a.to_vec();
    let mut v = vec![0.0; n * n];
    for i in 0..n {
        v[i * n + i] = 1.0;
    }
    for _sweep in 0..100 {
        let off: Real = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| m[i * n + j] * m[i * n + j])
            .sum();
        let diag: Real = (0..n).map(|i| m[i * n + i] * m[i * n + i]).sum();
        if off <= 1e-30 * diag || off == 0.0 {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = m[p * n + q];
                if apq == 0.0 {
                    continue;
                }
                let (app, aqq) = (m[p * n + p], m[q * n + q]);
                // t = tan θ of the rotation that zeroes a_pq (Golub & Van Loan, Alg. 8.4.1).
                let theta = (aqq - app) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + sqrt(theta * theta + 1.0));
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / sqrt(t * t + 1.0);
                let s = t * c;
                for k in 0..n {
                    let (mkp, mkq) = (m[k * n + p], m[k * n + q]);
                    m[k * n + p] = c * mkp - s * mkq;
                    m[k * n + q] = s * mkp + c * mkq;
                }
                for k in 0..n {
                    let (mpk, mqk) = (m[p * n + k], m[q * n + k]);
                    m[p * n + k] = c * mpk - s * mqk;
                    m[q * n + k] = s * mpk + c * mqk;
                }
                for k in 0..n {
                    let (vkp, vkq) = (v[k * n + p], v[k * n + q]);
                    v[k * n + p] = c * vkp - s * vkq;
                    v[k * n + q] = s * vkp + c * vkq;
                }
            }
        }
    }
    ((0..n).map(|i| m[i * n + i]).collect(), v)
}
