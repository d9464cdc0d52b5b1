//! Refinement after new paths (C5 step 3): cyclic sweeps (SAGE with one Newton step per path and
//! sweep, as NOMP), joint Gauss–Newton on a few strongly coupled paths (variable projection), the
//! merge of paths closer than [`MERGE_FRACTION`]`/B` and the joint least-squares fit of all
//! amplitudes.

use alloc::vec;
use alloc::vec::Vec;

use super::estimator::fold;
use super::residual::Phasor;
use super::{kernels, linalg};
use crate::channel::{EstimateWork, Estimator};
use crate::error::{check_len, limits, Error, Result};
use crate::math::{sqrt, Complex, Real, PI};

#[cfg(doc)]
use crate::channel::MERGE_FRACTION;

/// Convergence of the refinement sweeps, in units of `1/B`.
const SAGE_TOL: Real = 1e-3;
/// Refinement stops once a sweep raises the log-likelihood `‖r‖²/σ²` by less than this.
const LL_TOL: Real = 0.05;
/// Most paths refined jointly (more: cyclic sweeps on).
const MAX_JOINT: usize = 3;
/// Cyclic sweeps before the paths still moving are refined jointly.
const CYCLIC_SWEEPS: usize = 1;

/// Amplitudes by least squares at fixed delays ([`Estimator::project`]).
struct Projection {
    taus: Vec<Real>,
    alpha: Vec<Complex>,
    resid: Vec<Complex>,
    cost: Real,
    /// The basis columns, column-major (`k` columns of `n`).
    basis: Vec<Complex>,
}

impl Estimator {
    /// Refinement after new paths (`paths[new..]`): the new paths and the paths coupled to one
    /// of them — within `2/B`, or so much stronger that their sidelobe there (`|α_j|/(πBΔ)`) is
    /// a tenth of its amplitude (a weak path beside a strong one; other paths are moved by a
    /// new one far below their own error) — cyclic sweeps (one Newton step per path and sweep)
    /// while they converge fast; the paths still moving after [`CYCLIC_SWEEPS`] (strongly
    /// coupled ones: closer than about `1/B`, where a Gauss–Seidel sweep converges slowly) are
    /// refined jointly with their neighbours within `2/B` ([`Estimator::joint_refine`]:
    /// Gauss–Newton with Levenberg damping, amplitudes by least squares, quadratic near the
    /// optimum). At most [`limits::ESTIMATOR_SWEEPS`] sweeps and joint iterations together,
    /// until no delay moves by `SAGE_TOL/B`, a sweep gains less than `LL_TOL` in log-likelihood
    /// (`‖r‖²/σ²`) or two paths come closer than the merge separation;
    /// then the merge of close paths (and a joint LS of the amplitudes); leaves `resid = h − Ĥ`.
    pub(super) fn refine(
        &mut self,
        h: &[Complex],
        paths: &mut Vec<(Real, Complex)>,
        new: usize,
        sigma2: Real,
        work: &mut EstimateWork,
    ) {
        let n = self.band.len();
        let tol = SAGE_TOL / (self.df * n as Real);
        // A sweep or joint step that lowers ‖r‖² by less than this changes the log-likelihood
        // by less than LL_TOL: converged in what the data can tell, wherever the delays drift
        // (diffuse scattering fitted by a few paths leaves such flat valleys).
        let gain_tol = LL_TOL * sigma2;
        let max_step = 0.25 / (self.df * n as Real);
        let near = 2.0 / (self.df * n as Real);
        let bw = self.df * n as Real;
        // Coupled to a new path: within 2/B, or strong enough that its sidelobe there (the
        // Dirichlet envelope 1/(πBΔ) of its amplitude) is a tenth of the new path's amplitude.
        let coupled = |i: usize, j: usize| {
            let d = (paths[i].0 - paths[j].0).abs();
            d < near
                || sqrt(paths[i].1.norm_sqr()) >= 0.1 * PI * bw * d * sqrt(paths[j].1.norm_sqr())
        };
        let group: Vec<usize> = (0..paths.len())
            .filter(|&i| i >= new || (new..paths.len()).any(|j| coupled(i, j)))
            .collect();
        let mut sweeps = 0;
        let mut converged = group.len() < 2;
        let mut moves: Vec<Real> = vec![0.0; paths.len()];
        while !converged && sweeps < CYCLIC_SWEEPS {
            sweeps += 1;
            let gain = self.sweep(paths, &group, &mut moves, max_step);
            converged = group.iter().all(|&i| moves[i] < tol)
                || gain.abs() < gain_tol
                || self.crowded(paths);
        }
        if !converged {
            // The paths still moving and their neighbours within 2/B: refined jointly when
            // they are few (a resolvable pair or triple, where Gauss–Seidel crawls and
            // Gauss–Newton converges in two or three steps), else by more cyclic sweeps (a dense
            // cluster — diffuse scattering fitted by several paths — where joint steps are
            // ill-conditioned and cost O(k²) kernels each).
            let joint: Vec<usize> = group
                .iter()
                .copied()
                .filter(|&i| {
                    moves[i] >= tol
                        || group
                            .iter()
                            .any(|&j| moves[j] >= tol && (paths[i].0 - paths[j].0).abs() < near)
                })
                .collect();
            let budget = limits::ESTIMATOR_SWEEPS - sweeps;
            if joint.len() <= MAX_JOINT {
                let (iterations, ok) = self.joint_refine(paths, &joint, budget, tol, gain_tol);
                sweeps += iterations;
                converged = ok;
            } else {
                while !converged && sweeps < limits::ESTIMATOR_SWEEPS {
                    sweeps += 1;
                    let gain = self.sweep(paths, &group, &mut moves, max_step);
                    converged = group.iter().all(|&i| moves[i] < tol)
                        || gain.abs() < gain_tol
                        || self.crowded(paths);
                }
            }
        }
        work.sweeps = work.sweeps.max(sweeps);
        work.sweeps_capped |= !converged;
        // merge: keep the stronger of paths closer than MERGE_FRACTION/B
        paths.sort_by(|a, b| a.0.total_cmp(&b.0));
        let sep = self.merge_sep();
        let before = paths.len();
        let mut i = 1;
        while i < paths.len() {
            if paths[i].0 - paths[i - 1].0 < sep {
                if paths[i].1.norm_sqr() > paths[i - 1].1.norm_sqr() {
                    paths.remove(i - 1);
                } else {
                    paths.remove(i);
                }
            } else {
                i += 1;
            }
        }
        if paths.len() < before {
            self.joint_ls(h, paths);
        }
    }

    /// One cyclic sweep: each path of `group` in turn added back, moved by one Newton step
    /// (clipped to `max_step`) and taken out again with its least-squares amplitude; `moves[i]`
    /// its step. Returns the fall of `‖r‖²`: `(|c(τ')|² − |c(τ)|²)/ΣP²` summed over the moves.
    fn sweep(
        &mut self,
        paths: &mut [(Real, Complex)],
        group: &[usize],
        moves: &mut [Real],
        max_step: Real,
    ) -> Real {
        let mut gain = 0.0;
        for &i in group {
            let (t, a) = paths[i];
            let m = self.add_back(t, a);
            let dt = m.newton_step(max_step);
            let c2 = m.at(dt);
            let a2 = c2 / self.energy;
            let t2 = fold(t + dt, self.win_start, self.span).min(self.win_end);
            self.add_path(t2, -a2);
            paths[i] = (t2, a2);
            moves[i] = dt.abs();
            gain += (c2.norm_sqr() - m.c0.norm_sqr()) / self.energy;
        }
        gain
    }

    /// Whether two paths are closer than the merge separation.
    fn crowded(&self, paths: &[(Real, Complex)]) -> bool {
        let sep = self.merge_sep();
        (0..paths.len())
            .any(|i| (i + 1..paths.len()).any(|j| (paths[i].0 - paths[j].0).abs() < sep))
    }

    /// Gauss–Newton with Levenberg damping on the delays of `paths[group]` (the other paths
    /// fixed), their amplitudes by least squares at every trial (variable projection in
    /// Kaufman's form): at most `budget` trials, until an accepted step moves no delay by
    /// `tol`. Steps are clipped to `1/(4B)`. Returns the trials used and whether it converged;
    /// leaves `resid = h − Ĥ` for the updated paths.
    fn joint_refine(
        &mut self,
        paths: &mut [(Real, Complex)],
        group: &[usize],
        budget: usize,
        tol: Real,
        gain_tol: Real,
    ) -> (usize, bool) {
        let k = group.len();
        if k == 0 {
            return (0, true);
        }
        let n = self.band.len();
        let max_step = 0.25 / (self.df * n as Real);
        // The data the group explains: the residual with the group's paths added back.
        for &g in group {
            let (t, a) = paths[g];
            self.add_path(t, a);
        }
        let y = self.resid.clone();
        let mut taus: Vec<Real> = group.iter().map(|&g| paths[g].0).collect();
        let mut fit = self.project(&y, &taus);
        let mut lambda = 1e-6;
        let (mut used, mut converged) = (0, false);
        while used < budget {
            used += 1;
            let Some((grad, hess)) = self.gauss_newton_terms(&fit) else {
                break;
            };
            let mut sys = hess.clone();
            for i in 0..k {
                sys[i * k + i] *= 1.0 + lambda;
            }
            let Some(inv) = linalg::inverse_sym(sys, k) else {
                lambda *= 10.0;
                continue;
            };
            let mut trial = taus.clone();
            let mut moved: Real = 0.0;
            for i in 0..k {
                let d: Real = -(0..k).map(|j| inv[i * k + j] * grad[j]).sum::<Real>();
                let d = if d.is_finite() {
                    d.clamp(-max_step, max_step)
                } else {
                    0.0
                };
                trial[i] = fold(taus[i] + d, self.win_start, self.span).min(self.win_end);
                moved = moved.max(d.abs());
            }
            let next = self.project(&y, &trial);
            if next.cost <= fit.cost {
                let gain = fit.cost - next.cost;
                taus = trial;
                fit = next;
                lambda = (lambda * 0.1).max(1e-12);
                // Converged, or two paths about to merge (the merge decides; their joint fit is
                // degenerate and would drift on).
                let sep = self.merge_sep();
                let crowded = (0..k).any(|i| (i + 1..k).any(|j| (taus[i] - taus[j]).abs() < sep));
                if moved < tol || gain < gain_tol || crowded {
                    converged = true;
                    break;
                }
            } else {
                lambda *= 10.0;
                if moved < tol {
                    converged = true;
                    break;
                }
            }
        }
        for (i, &g) in group.iter().enumerate() {
            paths[g] = (taus[i], fit.alpha[i]);
        }
        self.resid.clear();
        self.resid.extend_from_slice(&fit.resid);
        (used, converged)
    }

    /// The least-squares amplitudes of paths at `taus` explaining `y`, the residual, its
    /// energy, and the basis columns `a_i` (`P·e^{−j2π(f_n−f_c)τ_i}`).
    fn project(&self, y: &[Complex], taus: &[Real]) -> Projection {
        let (n, k) = (y.len(), taus.len());
        let mut basis = Vec::with_capacity(n * k);
        for &t in taus {
            let ph0 = Phasor::at(self.fc[0], self.df, t);
            let from = basis.len();
            kernels::push_rotating(&mut basis, n, ph0.start.conj(), ph0.step.conj());
            if !self.flat {
                for (v, p) in basis[from..].iter_mut().zip(&self.band.response) {
                    *v *= p;
                }
            }
        }
        let mut g = vec![Complex::new(0.0, 0.0); k * k];
        let mut b = vec![Complex::new(0.0, 0.0); k];
        for i in 0..k {
            let ai = &basis[i * n..(i + 1) * n];
            b[i] = kernels::dot_conj(ai, y);
            g[i * k + i] = Complex::new(self.energy, 0.0);
            for j in i + 1..k {
                let s = self.gram(taus[j] - taus[i]);
                g[i * k + j] = s;
                g[j * k + i] = s.conj();
            }
        }
        let alpha = linalg::solve_complex(&mut g, &mut b, k)
            .unwrap_or_else(|| vec![Complex::new(0.0, 0.0); k]);
        let mut resid = y.to_vec();
        for (i, a) in alpha.iter().enumerate() {
            for (r, v) in resid.iter_mut().zip(&basis[i * n..(i + 1) * n]) {
                *r -= v * a;
            }
        }
        let cost = kernels::norm_sqr_sum(&resid);
        Projection {
            taus: taus.to_vec(),
            alpha,
            resid,
            cost,
            basis,
        }
    }

    /// The gradient and Gauss–Newton Hessian of `‖r‖²` in the delays at `fit` (amplitudes
    /// held): `∂r/∂τ_i = −α_i·(−j2π(f_n−f_c))·a_i`. `None` if not finite.
    fn gauss_newton_terms(&self, fit: &Projection) -> Option<(Vec<Real>, Vec<Real>)> {
        let k = fit.alpha.len();
        let n = fit.resid.len();
        let tp = 2.0 * PI;
        // dr_i[n] = j2π f_n α_i a_i[n]
        let mut dr = Vec::with_capacity(n * k);
        for i in 0..k {
            let a = fit.alpha[i];
            for (v, f) in fit.basis[i * n..(i + 1) * n].iter().zip(&self.fc) {
                let x = v * a * (tp * f);
                dr.push(Complex::new(-x.im, x.re));
            }
        }
        let mut grad = vec![0.0; k];
        let mut hess = vec![0.0; k * k];
        // Kaufman's variable projection: the Jacobian projected off the amplitudes' span,
        // J = (I − A G⁻¹Aᴴ)D, so JᴴJ = DᴴD − Bᴴ G⁻¹ B with G = AᴴA, B = AᴴD; every entry a
        // kernel: (DᴴD)_ij = (2π)² conj(α_i) α_j S_2(τ_j − τ_i), B_ij = j2π α_j S_1(τ_j − τ_i),
        // G_ij = S_0(τ_j − τ_i). Without the projection the steps of strongly coupled paths are
        // far too short (amplitude and delay trade off within 1/B).
        let taus = &fit.taus;
        let mut g = vec![Complex::new(0.0, 0.0); k * k];
        let mut bm = vec![Complex::new(0.0, 0.0); k * k];
        let mut dd = vec![Complex::new(0.0, 0.0); k * k];
        for i in 0..k {
            for j in 0..k {
                let (s0, s1, s2) = self.kernels(taus[j] - taus[i]);
                g[i * k + j] = s0;
                bm[i * k + j] = Complex::new(0.0, tp) * fit.alpha[j] * s1;
                dd[i * k + j] = fit.alpha[i].conj() * fit.alpha[j] * s2 * (tp * tp);
            }
        }
        // X = G⁻¹B, column by column.
        let mut x = vec![Complex::new(0.0, 0.0); k * k];
        for j in 0..k {
            let mut gg = g.clone();
            let mut col: Vec<Complex> = (0..k).map(|i| bm[i * k + j]).collect();
            let sol = linalg::solve_complex(&mut gg, &mut col, k)?;
            for i in 0..k {
                x[i * k + j] = sol[i];
            }
        }
        for i in 0..k {
            let di = &dr[i * n..(i + 1) * n];
            grad[i] = 2.0 * kernels::re_dot_conj(&fit.resid, di);
            for j in i..k {
                // (Bᴴ X)_ij = Σ_m conj(B_mi) X_mj
                let c: Complex = (0..k).map(|m| bm[m * k + i].conj() * x[m * k + j]).sum();
                let h = 2.0 * (dd[i * k + j] - c).re;
                hess[i * k + j] = h;
                hess[j * k + i] = h;
            }
        }
        (grad.iter().all(|v| v.is_finite()) && hess.iter().all(|v| v.is_finite()))
            .then_some((grad, hess))
    }

    /// The joint least-squares amplitudes `α̂` of paths at the fixed `delays` (s) in the response
    /// `h`: C5's amplitude step without a delay search, what a CPI's Doppler is read from in
    /// each of its snapshots (issue 42 §2). Zeros when the delays make the fit singular (two
    /// equal). Errors: `h` of the wrong length ([`Error::LengthMismatch`]) or not finite, a
    /// delay not finite.
    pub fn amplitudes_at(&mut self, h: &[Complex], delays: &[Real]) -> Result<Vec<Complex>> {
        check_len("response", self.band.len(), h.len())?;
        if h.iter().any(|v| !(v.re.is_finite() && v.im.is_finite())) {
            return Err(Error::NonFinite {
                field: "response".into(),
            });
        }
        if delays.iter().any(|t| !t.is_finite()) {
            return Err(Error::NonFinite {
                field: "delays".into(),
            });
        }
        let mut paths: Vec<(Real, Complex)> = delays
            .iter()
            .map(|&t| (t, Complex::new(0.0, 0.0)))
            .collect();
        self.joint_ls(h, &mut paths);
        Ok(paths.into_iter().map(|p| p.1).collect())
    }

    /// Joint least squares of all amplitudes at fixed delays; `resid` ← `h − Ĥ`.
    pub(super) fn joint_ls(&mut self, h: &[Complex], paths: &mut [(Real, Complex)]) {
        let k = paths.len();
        if k == 0 {
            self.resid.clear();
            self.resid.extend_from_slice(h);
            return;
        }
        let mut g = vec![Complex::new(0.0, 0.0); k * k];
        let mut b = vec![Complex::new(0.0, 0.0); k];
        self.resid.clear();
        self.resid.extend_from_slice(h);
        for i in 0..k {
            b[i] = self.correlation(paths[i].0);
            g[i * k + i] = Complex::new(self.energy, 0.0);
            for j in i + 1..k {
                let s = self.gram(paths[j].0 - paths[i].0);
                g[i * k + j] = s;
                g[j * k + i] = s.conj();
            }
        }
        if let Some(a) = linalg::solve_complex(&mut g, &mut b, k) {
            for (p, v) in paths.iter_mut().zip(a) {
                p.1 = v;
            }
        }
        for &(t, a) in paths.iter() {
            self.add_path(t, -a);
        }
    }
}
