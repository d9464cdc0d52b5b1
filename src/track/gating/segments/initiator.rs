//! The initiator (C11, searching): per snapshot, each link's non-static candidates (E4), at most
//! [`SegmentConfig::candidates_per_link`] of the strongest; a backprojection over a grid of the
//! area (step [`SegmentConfig::grid_step_m`]; per node and link the best candidate by
//! `d² + 2·ln(A_max/A)`, `d = |τ̂ − τ(node)|/√(σ̂² + (√2·step/c)²)` the normalised delay residual
//! (within 3) and the second term a prior for the link's strongest candidate, the score capped at
//! 9) picks the nodes where ≥ [`SegmentConfig::min_links`] links agree; from the best local minima
//! (at most [`MAX_FIXES_PER_SNAPSHOT`]) Levenberg–Marquardt (E5) fixes the position with those
//! candidates, and a fix whose cost passes χ² at `1 − fix_tail_probability` with `links − 2`
//! degrees of freedom becomes a **hypothesis** (an EKF at the fix, velocity 0 ±
//! [`START_SPEED_SIGMA_MPS`]), unless it lies within 1 m of one already held (at most
//! [`SegmentConfig::max_hypotheses`]); `confirm.rs` then confirms or drops it.

use alloc::vec;
use alloc::vec::Vec;

use super::config::{BACKPROJECTION_CAP, SAME_HYPOTHESIS_M};
use super::loss::outside;
use super::state::Hypothesis;
use super::{SegmentStart, SegmentTracker, MAX_FIXES_PER_SNAPSHOT};
use crate::error::Result;
use crate::localize::{chi_square_upper_tail, locate, DelayMeasurements, LmConfig};
use crate::math::{sqrt, Mat4, Real, Vec2, Vec4, SPEED_OF_LIGHT};
use crate::track::gating::{
    select, AssociationRule, DelayEstimate, GatedTracker, Selection, START_SPEED_SIGMA_MPS,
};
use crate::track::{Ekf, Filter, MeasurementNoise};

#[cfg(doc)]
use super::SegmentConfig;

impl<'a> SegmentTracker<'a> {
    pub(super) fn add_hypotheses(
        &mut self,
        k: usize,
        snapshot: &[Vec<DelayEstimate>],
    ) -> Result<()> {
        let cfg = self.cfg;
        if self.hypotheses.len() >= cfg.max_hypotheses {
            return Ok(());
        }
        let Some(grid) = self.grid.as_ref() else {
            return Ok(());
        };
        let n = self.model.link_count();
        // Checks the estimates as the tracker does (delays in range, finite amplitudes).
        select(self.calibration, snapshot, None, AssociationRule::Spec)?;
        // Each link's non-static candidates, the strongest first.
        let mut cands: Vec<Vec<DelayEstimate>> = Vec::with_capacity(n);
        for (p, list) in snapshot.iter().enumerate() {
            let mut c: Vec<DelayEstimate> = list
                .iter()
                .filter(|e| !self.calibration.links[p].is_static(e.delay_s))
                .copied()
                .collect();
            c.sort_by(|a, b| b.amplitude.total_cmp(&a.amplitude));
            c.truncate(cfg.candidates_per_link);
            cands.push(c);
        }
        if cands.iter().filter(|c| !c.is_empty()).count() < cfg.min_links {
            return Ok(());
        }
        // A prior for the strongest: a candidate A below the link's strongest costs
        // 2·ln(A_max/A) (10 dB weaker ≈ a 2σ residual). A person's direct echo is the strongest
        // dynamic path on most links; double bounces via walls and misfits are weaker, and
        // their combinations can be as consistent as the truth for a few snapshots.
        let prior: Vec<Vec<Real>> = cands
            .iter()
            .map(|c| {
                let top = c.first().map_or(0.0, |e| e.amplitude);
                c.iter()
                    .map(|e| {
                        if top > 0.0 && e.amplitude > 0.0 {
                            2.0 * crate::math::ln(top / e.amplitude)
                        } else {
                            0.0
                        }
                    })
                    .collect()
            })
            .collect();
        let tol = core::f64::consts::SQRT_2 * grid.step / SPEED_OF_LIGHT;
        let cap2 = BACKPROJECTION_CAP * BACKPROJECTION_CAP;
        let sig2 = |e: &DelayEstimate, p: usize, at: Vec2| {
            let s = match e.sigma_s {
                Some(s) if self.estimate_sigmas => s,
                _ => self.model.sigma_delay(p, at),
            };
            let s = match self.gate_sigma_s {
                Some(g) => s.max(g),
                None => s,
            };
            s * s
        };
        // Per node: the capped score and the links that agree.
        let nodes = grid.nodes.len();
        let mut score = vec![Real::INFINITY; nodes];
        for (i, &at) in grid.nodes.iter().enumerate() {
            let d = &grid.delays[i * n..(i + 1) * n];
            let (mut sum, mut agree) = (0.0, 0usize);
            for p in 0..n {
                let (mut best, mut fits) = (cap2, false);
                for (e, pen) in cands[p].iter().zip(&prior[p]) {
                    let r = e.delay_s - d[p];
                    let v = r * r / (sig2(e, p, at) + tol * tol);
                    if v < cap2 {
                        fits = true;
                        best = best.min(v + pen);
                    }
                }
                agree += usize::from(fits);
                sum += best.min(cap2);
            }
            if agree >= cfg.min_links {
                score[i] = sum;
            }
        }
        // The best local minima.
        let (nx, ny) = (grid.nx, grid.ny);
        let mut minima: Vec<(Real, usize)> = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let c = score[j * nx + i];
                if !c.is_finite() {
                    continue;
                }
                let lowest = (j.saturating_sub(1)..(j + 2).min(ny)).all(|jj| {
                    (i.saturating_sub(1)..(i + 2).min(nx)).all(|ii| {
                        let o = score[jj * nx + ii];
                        o > c || (o == c && jj * nx + ii >= j * nx + i)
                    })
                });
                if lowest {
                    minima.push((c, j * nx + i));
                }
            }
        }
        minima.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        minima.truncate(MAX_FIXES_PER_SNAPSHOT);
        let lm = LmConfig {
            restart_tail_probability: None,
            ..LmConfig::default()
        };
        for &(_, node) in &minima {
            if self.hypotheses.len() >= cfg.max_hypotheses {
                break;
            }
            let at = grid.nodes[node];
            let d = &grid.delays[node * n..(node + 1) * n];
            // The candidate per link nearest the node's delay, if within the cap.
            let mut delays = vec![None; n];
            let mut sigmas = vec![0.0; n];
            let mut chosen: Vec<Option<DelayEstimate>> = vec![None; n];
            for p in 0..n {
                let mut best = (Real::INFINITY, None);
                for (e, pen) in cands[p].iter().zip(&prior[p]) {
                    let r = e.delay_s - d[p];
                    let v = r * r / (sig2(e, p, at) + tol * tol);
                    if v < cap2 && v + pen < best.0 {
                        best = (v + pen, Some(*e));
                    }
                }
                if let Some(e) = best.1 {
                    delays[p] = Some(e.delay_s);
                    sigmas[p] = sqrt(sig2(&e, p, at));
                    chosen[p] = Some(e);
                }
            }
            let m = DelayMeasurements {
                delays_s: &delays,
                sigmas_s: &sigmas,
            };
            let Ok(report) = locate(&self.model.network, &m, &lm, Some(at), self.area) else {
                continue;
            };
            let used = report.links_used;
            if used < cfg.min_links {
                continue;
            }
            let dof = used - 2;
            if !(report.cost.is_finite()
                && chi_square_upper_tail(dof, report.cost) >= cfg.fix_tail_probability)
            {
                continue;
            }
            if outside(
                self.area,
                0.0,
                &Vec4::new(report.position.x, report.position.y, 0.0, 0.0),
            ) {
                continue;
            }
            let Some(c) = report.covariance_m2 else {
                continue;
            };
            if self.hypotheses.iter().any(|h| {
                let s = h.tracker.filter.state();
                let (dx, dy) = (s[0] - report.position.x, s[1] - report.position.y);
                dx * dx + dy * dy < SAME_HYPOTHESIS_M * SAME_HYPOTHESIS_M
            }) {
                continue;
            }
            let v2 = START_SPEED_SIGMA_MPS * START_SPEED_SIGMA_MPS;
            let mut p0 = Mat4::zeros();
            p0.fixed_view_mut::<2, 2>(0, 0).copy_from(&c);
            p0[(2, 2)] = v2;
            p0[(3, 3)] = v2;
            let x0 = Vec4::new(report.position.x, report.position.y, 0.0, 0.0);
            let Ok(ekf) = Ekf::new(x0, p0) else {
                continue;
            };
            let tracker = GatedTracker::new(
                ekf,
                self.model,
                self.calibration,
                self.motion(1.0)?,
                MeasurementNoise::AtPrediction,
                AssociationRule::Gated,
            )?
            .with_estimate_sigmas(self.estimate_sigmas)
            .with_gate_sigma(self.gate_sigma_s);
            let selection = Selection {
                delays: delays.clone(),
                choices: chosen
                    .iter()
                    .map(|c| match c {
                        Some(_) => crate::track::gating::Choice::Nearest,
                        None => crate::track::gating::Choice::Absent,
                    })
                    .collect(),
                static_removed: snapshot
                    .iter()
                    .enumerate()
                    .map(|(p, l)| {
                        l.iter()
                            .filter(|e| self.calibration.links[p].is_static(e.delay_s))
                            .count()
                    })
                    .collect(),
                sigmas: (0..n).map(|p| delays[p].map(|_| sigmas[p])).collect(),
            };
            self.hypotheses.push(Hypothesis {
                born: k,
                fix: SegmentStart {
                    k,
                    report,
                    selection,
                    hits: 0,
                },
                fix_p: p0,
                tracker,
                age: 0,
                hits: 0,
                nis: 0.0,
                links: 0,
                prior: 0.0,
            });
        }
        Ok(())
    }
}
