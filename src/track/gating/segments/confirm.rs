//! The search without a track (C11): every held **hypothesis** (an EKF at its fix) is gated and
//! updated on each snapshot (the [`AssociationRule::Gated`] rule, 3σ); a snapshot is a hit when
//! `≥ min_links` links associate. At the end of its window of `confirm_n` snapshots after its
//! fix, a hypothesis with `confirm_m` hits (its candidates on average no weaker than
//! [`CONFIRM_PRIOR`] below each link's strongest) is **confirmed** (of several at once: most
//! hits, then the lowest NIS plus prior per associated link — C11's "best-confirmed"); one that
//! cannot reach `confirm_m` any more, or leaves the area, is dropped. The confirmed hypothesis
//! starts the segment at its fix's snapshot: the chosen filter (EKF, UKF or particle filter)
//! starts at the fix and replays the snapshots since, so the segment's states are that filter's.

use alloc::vec::Vec;

use super::events::numerical;
use super::loss::outside;
use super::state::{Held, Hypothesis};
use super::{SegmentEvent, SegmentStep, SegmentTracker, CONFIRM_PRIOR, MISS_LINKS};
use crate::error::Result;
use crate::math::{Real, Vec4};
use crate::track::gating::{DelayEstimate, GatedStep, GatedTracker};
use crate::track::{Filter, MeasurementNoise, Tracker};

#[cfg(doc)]
use crate::track::gating::AssociationRule;

impl<'a> SegmentTracker<'a> {
    /// One snapshot without a track: advance the hypotheses, confirm one or add new ones.
    pub(super) fn search(
        &mut self,
        k: usize,
        t_s: Real,
        dt: Option<Real>,
        snapshot: &[Vec<DelayEstimate>],
        replay: &dyn Fn(usize) -> Result<(Real, Vec<Vec<DelayEstimate>>)>,
    ) -> Result<SegmentEvent> {
        let cfg = self.cfg;
        // Each link's strongest non-static amplitude (the prior of the hits).
        let strongest: Vec<Real> = snapshot
            .iter()
            .enumerate()
            .map(|(p, l)| {
                l.iter()
                    .filter(|e| !self.calibration.links[p].is_static(e.delay_s))
                    .map(|e| e.amplitude)
                    .fold(0.0, Real::max)
            })
            .collect();
        if let Some(dt) = dt {
            let motion = self.motion(dt)?;
            let (area, margin) = (self.area, cfg.area_margin_m);
            let mut kept = Vec::with_capacity(self.hypotheses.len());
            for mut h in core::mem::take(&mut self.hypotheses) {
                h.tracker.set_motion(motion);
                // A hypothesis whose filter fails numerically is dropped.
                let s = match h.tracker.step(snapshot) {
                    Ok(s) => s,
                    Err(e) if numerical(&e) => continue,
                    Err(e) => return Err(e),
                };
                h.age += 1;
                if s.summary.links_used >= cfg.min_links {
                    h.hits += 1;
                    h.nis += s.summary.nis;
                    h.links += s.summary.links_used;
                    h.prior += prior_of(snapshot, &s.selection.delays, &strongest);
                }
                let reachable =
                    h.hits + (cfg.confirm_n - h.age.min(cfg.confirm_n)) >= cfg.confirm_m;
                if reachable && !outside(area, margin, h.tracker.filter.state()) {
                    kept.push(h);
                }
            }
            self.hypotheses = kept;
        }
        // Confirmation at the end of a hypothesis' window of N snapshots, with ≥ M hits; of
        // several, the most hits, then the lowest NIS per associated link.
        let best = self
            .hypotheses
            .iter()
            .enumerate()
            .filter(|(_, h)| {
                h.age >= cfg.confirm_n && h.hits >= cfg.confirm_m && h.mean_prior() <= CONFIRM_PRIOR
            })
            .min_by(|(_, a), (_, b)| {
                b.hits.cmp(&a.hits).then(
                    (a.mean_nis() + a.mean_prior()).total_cmp(&(b.mean_nis() + b.mean_prior())),
                )
            })
            .map(|(i, _)| i);
        if let Some(i) = best {
            let h = self.hypotheses.swap_remove(i);
            self.hypotheses.clear();
            return self.start_segment(h, k, t_s, replay);
        }
        self.add_hypotheses(k, snapshot)?;
        Ok(SegmentEvent::Searching {
            hypotheses: self.hypotheses.len(),
        })
    }

    /// Starts the segment of confirmed hypothesis `h` at its fix and replays the snapshots
    /// since, up to `k`.
    pub(super) fn start_segment(
        &mut self,
        h: Hypothesis<'a>,
        k: usize,
        t_s: Real,
        replay: &dyn Fn(usize) -> Result<(Real, Vec<Vec<DelayEstimate>>)>,
    ) -> Result<SegmentEvent> {
        let mut start = h.fix.clone();
        start.hits = h.hits;
        let fix = &start.report;
        let x0 = Vec4::new(fix.position.x, fix.position.y, 0.0, 0.0);
        let p0 = h.fix_p;
        let filter = Tracker::new(self.kind, x0, p0, self.rng.clone())?;
        let mut tracker = GatedTracker::new(
            filter,
            self.model,
            self.calibration,
            self.motion(1.0)?,
            MeasurementNoise::AtPrediction,
            self.rule,
        )?
        .with_estimate_sigmas(self.estimate_sigmas)
        .with_gate_sigma(self.gate_sigma_s);
        let (mut t_prev, _) = replay(h.born)?;
        let mut steps = Vec::with_capacity(k - h.born + 1);
        steps.push(SegmentStep {
            k: h.born,
            state: x0,
            covariance: p0,
            step: GatedStep {
                summary: crate::track::UpdateSummary {
                    nis: 0.0,
                    links_used: fix.links_used,
                },
                selection: start.selection.clone(),
                sigmas_s: start.selection.sigmas.clone(),
            },
        });
        let mut window = Vec::new();
        let mut last_hit_t = t_prev;
        for j in h.born + 1..=k {
            let (tj, snap) = replay(j)?;
            tracker.set_motion(self.motion(tj - t_prev)?);
            t_prev = tj;
            // A confirmed hypothesis whose filter fails numerically on the way to `k` is
            // dropped: the search goes on.
            let s = match tracker.step(&snap) {
                Ok(s) => s,
                Err(e) if numerical(&e) => {
                    return Ok(SegmentEvent::Searching { hypotheses: 0 });
                }
                Err(e) => return Err(e),
            };
            if s.summary.links_used > 0 {
                if s.summary.links_used >= MISS_LINKS {
                    last_hit_t = tj;
                }
                window.push((s.summary.nis, s.summary.links_used));
                if window.len() > self.cfg.loss_window {
                    window.remove(0);
                }
            }
            let f = &tracker.filter;
            steps.push(SegmentStep {
                k: j,
                state: *f.state(),
                covariance: *f.covariance(),
                step: s,
            });
        }
        let _ = t_s;
        self.held = Some(Held {
            tracker,
            window,
            last_hit_t,
        });
        Ok(SegmentEvent::Started { start, steps })
    }
}

/// `Σ_p 2·ln(A_max,p/A_p)` over the links whose delay was taken (`delays[p]`), `A_p` the
/// amplitude of that delay's estimate, `A_max,p` the link's strongest non-static one.
pub(super) fn prior_of(
    snapshot: &[Vec<DelayEstimate>],
    delays: &[Option<Real>],
    strongest: &[Real],
) -> Real {
    let mut sum = 0.0;
    for (p, d) in delays.iter().enumerate() {
        let Some(d) = d else { continue };
        let a = snapshot[p]
            .iter()
            .find(|e| e.delay_s == *d)
            .map_or(0.0, |e| e.amplitude);
        if a > 0.0 && strongest[p] > a {
            sum += 2.0 * crate::math::ln(strongest[p] / a);
        }
    }
    sum
}
