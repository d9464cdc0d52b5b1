//! A recording's track from its estimates (spec §4, §6, C11): each snapshot's delays, weighted
//! with the estimator's σ̂_τ widened by the scatterer's extent (or the link budget's σ), gated
//! against the static clusters (E4) and associated, through a [`SegmentTracker`] — which
//! starts the track by itself, ends it with a named reason when it is lost and starts it again
//! — with any filter. States outside segments are `null`.
//!
//! Delays are weighted with the estimator's own σ̂_τ (C4 at the fitted SNR) by default: it
//! comes from the data, where the link budget's σ (E8) needs the target's RCS and the radio's
//! losses, which a user of a recording rarely knows.

use alloc::vec;
use alloc::vec::Vec;

use serde::Serialize;

use crate::channel::{DelayEstimate, Snapshot};
use crate::error::{check_every, Cancel, Result};
use crate::math::{sqrt, Mat4, Real, Vec4, SPEED_OF_LIGHT};
use crate::measure::{rng, Model};
use crate::scenario::Area;
use crate::study::channel::{ChannelRequest, DelaySigma, RecordingEstimates};
use crate::study::TrackStart;
use crate::track::gating::{
    Calibration, EndReason, SegmentEvent, SegmentSetup, SegmentStart, SegmentStep, SegmentTracker,
    Selection,
};
use crate::track::step_ns;

/// The track of a recording: one entry per snapshot; `null` outside the track's segments.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CirTrackOutput {
    /// Snapshot times, s.
    pub t_s: Vec<Real>,
    /// The estimates `[x, y, vx, vy]` after each snapshot's update (`null` outside segments).
    pub states: Vec<Option<[Real; 4]>>,
    /// Their covariances (`null` outside segments).
    pub covariances: Vec<Option<[[Real; 4]; 4]>>,
    /// Links used per snapshot.
    pub links_used: Vec<usize>,
    /// Per snapshot the delay taken per link (`null` = absent), s.
    pub delays_used_s: Vec<Vec<Option<Real>>>,
    /// Per snapshot the σ each used delay was weighted with, s (`null` = link absent; at a
    /// segment's first snapshot the σ its fix weighted with).
    pub sigmas_used_s: Vec<Vec<Option<Real>>>,
    /// Per snapshot how each link was chosen (absent/single/nearest/strongest).
    pub choices: Vec<Vec<&'static str>>,
    /// Per snapshot per link the estimates discarded as static (E4).
    pub static_removed: Vec<Vec<usize>>,
    /// The first segment's start (`null`: the track never started).
    pub start: Option<CirStart>,
    /// The segments (C11), in time order.
    pub segments: Vec<SegmentDoc>,
}

/// Where a segment started.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CirStart {
    /// The snapshot index.
    pub snapshot: usize,
    /// Its time, s.
    pub t_s: Real,
    /// The fix.
    #[serde(flatten)]
    pub fix: TrackStart,
}

/// One segment of a track (C11).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SegmentDoc {
    /// Its first snapshot (the fix's).
    pub first: usize,
    /// Its last snapshot with a state.
    pub last: usize,
    /// The time of its first snapshot, s.
    pub t_first_s: Real,
    /// The time of its last snapshot, s.
    pub t_last_s: Real,
    /// Why it ended: `innovation`, `misses`, `outside_area`, `filter` (a numerical failure of
    /// the filter) or `end` (the recording ended).
    pub end: &'static str,
    /// The snapshot at which its hypothesis was confirmed.
    pub confirmed_at: usize,
    /// Its hypothesis' hits when confirmed.
    pub hits: usize,
    /// The fix that started it.
    pub start: CirStart,
}

impl CirTrackOutput {
    fn new(t_s: &[Real], links: usize) -> CirTrackOutput {
        let n = t_s.len();
        CirTrackOutput {
            t_s: t_s.to_vec(),
            states: vec![None; n],
            covariances: vec![None; n],
            links_used: vec![0; n],
            delays_used_s: vec![vec![None; links]; n],
            sigmas_used_s: vec![vec![None; links]; n],
            choices: vec![vec!["absent"; links]; n],
            static_removed: vec![vec![0; links]; n],
            start: None,
            segments: Vec::new(),
        }
    }

    /// Snapshot `k`: the state and covariance, the links used, gating and association, the σ
    /// of each used delay.
    fn set(
        &mut self,
        k: usize,
        x: &Vec4,
        p: &Mat4,
        links_used: usize,
        sel: &Selection,
        sig: &[Option<Real>],
    ) {
        self.states[k] = Some((*x).into());
        self.covariances[k] = Some(core::array::from_fn(|i| {
            core::array::from_fn(|j| p[(i, j)])
        }));
        self.links_used[k] = links_used;
        self.delays_used_s[k] = sel.delays.clone();
        self.sigmas_used_s[k] = sig.to_vec();
        self.choices[k] = sel.choices.iter().map(|c| c.name()).collect();
        self.static_removed[k] = sel.static_removed.clone();
    }

    fn record(&mut self, s: &SegmentStep) {
        self.set(
            s.k,
            &s.state,
            &s.covariance,
            s.step.summary.links_used,
            &s.step.selection,
            &s.step.sigmas_s,
        );
    }

    /// Whether snapshot `k` has a state.
    pub fn has_state(&self, k: usize) -> bool {
        self.states.get(k).is_some_and(Option::is_some)
    }
}

/// The start document of a segment's fix at snapshot time `t_s`.
fn start_doc(s: &SegmentStart, t_s: Real, p0: &Mat4) -> CirStart {
    CirStart {
        snapshot: s.k,
        t_s,
        fix: TrackStart {
            position_m: [s.report.position.x, s.report.position.y],
            covariance_m2: [[p0[(0, 0)], p0[(0, 1)]], [p0[(1, 0)], p0[(1, 1)]]],
            termination: s.report.termination.as_str(),
            links_used: s.report.links_used,
            choices: s.selection.choices.iter().map(|c| c.name()).collect(),
            delays_used_s: s.selection.delays.clone(),
        },
    }
}

/// The snapshots of `est` as the tracker reads them: with `sigma = estimator` each σ̂ widened
/// by `extent_s` in quadrature.
fn widened(est: &RecordingEstimates, k: usize, extent_s: Option<Real>) -> Snapshot {
    let mut s = est.snapshot(k);
    if let Some(x) = extent_s {
        for e in s.iter_mut().flatten() {
            e.sigma_s = e.sigma_s.map(|v| sqrt(v * v + x * x));
        }
    }
    s
}

/// Tracks a recording's estimates (module docs) with the request's tracker settings; asks
/// `cancel` about every millisecond of work. Errors: the settings' ([`ChannelRequest::check`]),
/// a calibration of another link count, the filters' and gating's.
pub fn cir_track(
    req: &ChannelRequest,
    model: &Model,
    area: &Area,
    calibration: &Calibration,
    est: &RecordingEstimates,
    cancel: Cancel,
) -> Result<CirTrackOutput> {
    req.check()?;
    let n = model.link_count();
    calibration.check_links(n)?;
    let kind = req.filter_kind()?;
    let own = req.sigma == DelaySigma::Estimator;
    let extent = req.extent_sigma_m / SPEED_OF_LIGHT;
    let extent_s = own.then_some(extent);
    let setup = SegmentSetup {
        model,
        calibration,
        area,
        kind,
        process_noise: req.process_noise,
        rule: req.association,
        estimate_sigmas: own,
        gate_sigma_s: extent_s,
        segments: req.segments,
    };
    let mut tracker = SegmentTracker::searching(setup, rng(req.seed(), 0))?;
    let mut out = CirTrackOutput::new(&est.t_s, n);
    let every = check_every(step_ns(kind, n));
    let replay = |j: usize| -> Result<(Real, Vec<Vec<DelayEstimate>>)> {
        Ok((est.t_s[j], widened(est, j, extent_s)))
    };
    let mut open: Option<SegmentDoc> = None;
    for k in 0..est.len() {
        if k % every == 0 {
            cancel.check()?;
        }
        let snap = widened(est, k, extent_s);
        match tracker.step(k, est.t_s[k], &snap, &replay)? {
            SegmentEvent::Searching { .. } => {}
            SegmentEvent::Started { start, steps } => {
                for s in &steps {
                    out.record(s);
                }
                let p0 = steps
                    .first()
                    .map(|s| s.covariance)
                    .unwrap_or_else(Mat4::zeros);
                let doc = start_doc(&start, est.t_s[start.k], &p0);
                if out.start.is_none() {
                    out.start = Some(doc.clone());
                }
                open = Some(SegmentDoc {
                    first: start.k,
                    last: k,
                    t_first_s: est.t_s[start.k],
                    t_last_s: est.t_s[k],
                    end: EndReason::End.name(),
                    confirmed_at: k,
                    hits: start.hits,
                    start: doc,
                });
            }
            SegmentEvent::Tracked(s) => {
                out.record(&s);
                if let Some(seg) = open.as_mut() {
                    seg.last = k;
                    seg.t_last_s = est.t_s[k];
                }
            }
            SegmentEvent::Lost(reason) => {
                if let Some(mut seg) = open.take() {
                    seg.end = reason.name();
                    out.segments.push(seg);
                }
            }
        }
    }
    if let Some(seg) = open.take() {
        out.segments.push(seg);
    }
    Ok(out)
}
