//! The [`SegmentTracker`] and what it runs with ([`SegmentSetup`]): searching from its first
//! snapshot or holding a given start, and per snapshot either the held track (`loss.rs`) or the
//! search (`confirm.rs`, `initiator.rs`) — after a loss the search starts again by itself.

use alloc::vec::Vec;

use super::state::{Held, Hypothesis, StartGrid};
use super::SegmentConfig;
use crate::error::{Error, Result};
use crate::math::Real;
use crate::measure::{Model, Rng};
use crate::scenario::Area;
use crate::track::gating::{
    AssociationRule, Calibration, DelayEstimate, GatedTracker, SegmentEvent,
};
use crate::track::{ConstantVelocity, FilterKind, Tracker};

/// A gated tracker that starts, loses and restarts its track (module docs).
#[derive(Debug, Clone)]
pub struct SegmentTracker<'a> {
    pub(super) model: &'a Model,
    pub(super) calibration: &'a Calibration,
    pub(super) area: &'a Area,
    pub(super) cfg: SegmentConfig,
    pub(super) kind: FilterKind,
    pub(super) process_noise: Real,
    pub(super) rule: AssociationRule,
    pub(super) estimate_sigmas: bool,
    pub(super) gate_sigma_s: Option<Real>,
    /// Loss detection on (off: the track of a measurement file, started from its given state).
    pub(super) loss: bool,
    pub(super) rng: Rng,
    pub(super) grid: Option<StartGrid>,
    pub(super) hypotheses: Vec<Hypothesis<'a>>,
    pub(super) held: Option<Held<'a>>,
    pub(super) last_t: Option<Real>,
    /// A fixed snapshot interval: the motion model's `Δt` exactly, not the difference of two
    /// times ([`SegmentTracker::with_interval`]).
    pub(super) interval: Option<Real>,
    /// The index of the last snapshot seen.
    pub(super) k: Option<usize>,
}

/// What a [`SegmentTracker`] runs with.
#[derive(Debug, Clone, Copy)]
pub struct SegmentSetup<'a> {
    /// The model.
    pub model: &'a Model,
    /// The static clusters (E4).
    pub calibration: &'a Calibration,
    /// The area (the initiator's grid, the loss margin).
    pub area: &'a Area,
    /// The segment filter.
    pub kind: FilterKind,
    /// `q̃` of the CV model (E7), m²/s³.
    pub process_noise: Real,
    /// The association rule of the segment filter (hypotheses always use the gated rule).
    pub rule: AssociationRule,
    /// Weight an associated delay with the estimator's σ̂ where it gave one.
    pub estimate_sigmas: bool,
    /// A floor of every link's σ in the association gate, s.
    pub gate_sigma_s: Option<Real>,
    /// Start, loss and restart.
    pub segments: SegmentConfig,
}

impl<'a> SegmentTracker<'a> {
    /// A tracker that searches from its first snapshot. `rng` is the particle filter's stream.
    pub fn searching(setup: SegmentSetup<'a>, rng: Rng) -> Result<SegmentTracker<'a>> {
        setup.segments.validate()?;
        setup.kind.validate()?;
        setup.calibration.check_links(setup.model.link_count())?;
        crate::error::limits::PROCESS_NOISE.check("process_noise", setup.process_noise)?;
        let grid = StartGrid::new(setup.model, setup.area, setup.segments.grid_step_m)?;
        Ok(SegmentTracker {
            grid: Some(grid),
            ..Self::from_setup(setup, rng, true)
        })
    }

    /// A tracker holding `tracker` from time `t0_s` (a measurement file's given start), with
    /// loss detection off: every later snapshot is [`SegmentEvent::Tracked`].
    pub fn holding(
        tracker: GatedTracker<'a, Tracker>,
        setup: SegmentSetup<'a>,
        t0_s: Real,
    ) -> Self {
        SegmentTracker {
            held: Some(Held {
                tracker,
                window: Vec::new(),
                last_hit_t: t0_s,
            }),
            last_t: Some(t0_s),
            ..Self::from_setup(setup, crate::measure::rng(0, 0), false)
        }
    }

    /// The settings of `setup`, nothing held, no start grid, no time seen yet.
    fn from_setup(setup: SegmentSetup<'a>, rng: Rng, loss: bool) -> Self {
        SegmentTracker {
            model: setup.model,
            calibration: setup.calibration,
            area: setup.area,
            cfg: setup.segments,
            kind: setup.kind,
            process_noise: setup.process_noise,
            rule: setup.rule,
            estimate_sigmas: setup.estimate_sigmas,
            gate_sigma_s: setup.gate_sigma_s,
            loss,
            rng,
            grid: None,
            hypotheses: Vec::new(),
            held: None,
            last_t: None,
            interval: None,
            k: None,
        }
    }

    /// Snapshots at the fixed interval `dt_s` (a measurement file's `dt_s`): the motion model
    /// takes `dt_s` itself, so a track equals the plain filter's to the bit (the difference of
    /// two times `(k + 1)·dt − k·dt` rounds differently). The times must still increase.
    pub fn with_interval(mut self, dt_s: Real) -> Self {
        self.interval = Some(dt_s);
        self
    }

    /// Whether a track is held.
    pub fn is_tracking(&self) -> bool {
        self.held.is_some()
    }

    /// Hypotheses held.
    pub fn hypotheses(&self) -> usize {
        self.hypotheses.len()
    }

    /// The earliest snapshot a confirmation may still replay from: the oldest held
    /// hypothesis' fix (`None`: no hypothesis held). A caller that keeps only a window of
    /// snapshots for `replay` (a live run) keeps those from here on.
    pub fn oldest_fix(&self) -> Option<usize> {
        self.hypotheses.iter().map(|h| h.born).min()
    }

    /// Drops the hypotheses whose fix is before snapshot `k0` (a live run's replay window is
    /// full: their replay could not be served); returns how many.
    pub fn drop_hypotheses_before(&mut self, k0: usize) -> usize {
        let before = self.hypotheses.len();
        self.hypotheses.retain(|h| h.born >= k0);
        before - self.hypotheses.len()
    }

    pub(super) fn motion(&self, dt: Real) -> Result<ConstantVelocity> {
        ConstantVelocity::validated(dt, self.process_noise)
    }

    /// Snapshot `k` at `t_s` (`k` and `t_s` increasing; `snapshot[p]` = link `p`'s estimates).
    /// `replay(j)` gives snapshot `j`'s time and estimates again (a confirmed hypothesis'
    /// filter replays the snapshots since its fix). Errors: a time not after the previous one,
    /// the filters' and gating's errors.
    pub fn step(
        &mut self,
        k: usize,
        t_s: Real,
        snapshot: &[Vec<DelayEstimate>],
        replay: &dyn Fn(usize) -> Result<(Real, Vec<Vec<DelayEstimate>>)>,
    ) -> Result<SegmentEvent> {
        let dt = match self.last_t {
            Some(t0) => {
                let dt = t_s - t0;
                if !(dt > 0.0) {
                    return Err(Error::OutOfRange {
                        field: alloc::format!("t_s[{k}]"),
                        value: t_s,
                        allowed: "after the previous snapshot's time",
                    });
                }
                Some(self.interval.unwrap_or(dt))
            }
            None => None,
        };
        self.last_t = Some(t_s);
        self.k = Some(k);
        if self.held.is_some() {
            return self.track(k, t_s, dt.unwrap_or(0.0), snapshot);
        }
        self.search(k, t_s, dt, snapshot, replay)
    }
}
