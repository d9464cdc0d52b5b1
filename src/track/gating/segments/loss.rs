//! The deleter (C11, loss) of the held track: the summed NIS of the last
//! [`SegmentConfig::loss_window`] updates beyond its χ² quantile at `1 − loss_tail_probability`
//! (degrees of freedom: the links used) ([`EndReason::Innovation`]); fewer than [`MISS_LINKS`]
//! links associated in every snapshot for [`SegmentConfig::miss_time_s`]
//! ([`EndReason::Misses`]); the position outside the area by more than
//! [`SegmentConfig::area_margin_m`] ([`EndReason::OutsideArea`]); a filter's numerical failure
//! ([`EndReason::Filter`]). The snapshot of the loss has no state; the search starts again from
//! the next one.

use alloc::vec::Vec;

use super::events::numerical;
use super::{EndReason, SegmentEvent, SegmentStep, SegmentTracker, MISS_LINKS};
use crate::error::Result;
use crate::localize::chi_square_upper_tail;
use crate::math::{Real, Vec4};
use crate::scenario::Area;
use crate::track::gating::DelayEstimate;
use crate::track::Filter;

#[cfg(doc)]
use super::SegmentConfig;

impl<'a> SegmentTracker<'a> {
    /// One snapshot of the held track, with the loss tests.
    pub(super) fn track(
        &mut self,
        k: usize,
        t_s: Real,
        dt: Real,
        snapshot: &[Vec<DelayEstimate>],
    ) -> Result<SegmentEvent> {
        let motion = self.motion(dt)?;
        let cfg = self.cfg;
        let loss = self.loss;
        let (area, margin) = (self.area, cfg.area_margin_m);
        let Some(held) = self.held.as_mut() else {
            return Ok(SegmentEvent::Searching { hypotheses: 0 });
        };
        held.tracker.set_motion(motion);
        let step = match held.tracker.step(snapshot) {
            Ok(step) => step,
            Err(e) if numerical(&e) => {
                self.held = None;
                self.hypotheses.clear();
                return Ok(SegmentEvent::Lost(EndReason::Filter));
            }
            Err(e) => return Err(e),
        };
        let f = &held.tracker.filter;
        let (state, covariance) = (*f.state(), *f.covariance());
        if !loss {
            return Ok(SegmentEvent::Tracked(SegmentStep {
                k,
                state,
                covariance,
                step,
            }));
        }
        if step.summary.links_used > 0 {
            if step.summary.links_used >= MISS_LINKS {
                held.last_hit_t = t_s;
            }
            held.window
                .push((step.summary.nis, step.summary.links_used));
            if held.window.len() > cfg.loss_window {
                held.window.remove(0);
            }
        }
        let dof: usize = held.window.iter().map(|w| w.1).sum();
        let nis: Real = held.window.iter().map(|w| w.0).sum();
        let reason = if outside(area, margin, &state) {
            Some(EndReason::OutsideArea)
        } else if held.window.len() == cfg.loss_window
            && dof > 0
            && chi_square_upper_tail(dof, nis) < cfg.loss_tail_probability
        {
            Some(EndReason::Innovation)
        } else if t_s - held.last_hit_t >= cfg.miss_time_s {
            Some(EndReason::Misses)
        } else {
            None
        };
        match reason {
            Some(r) => {
                self.held = None;
                self.hypotheses.clear();
                Ok(SegmentEvent::Lost(r))
            }
            None => Ok(SegmentEvent::Tracked(SegmentStep {
                k,
                state,
                covariance,
                step,
            })),
        }
    }
}

/// Whether the position of `x` lies outside `area` grown by `margin`.
pub(super) fn outside(area: &Area, margin: Real, x: &Vec4) -> bool {
    !(x[0] >= area.x[0] - margin
        && x[0] <= area.x[1] + margin
        && x[1] >= area.y[0] - margin
        && x[1] <= area.y[1] + margin)
}
