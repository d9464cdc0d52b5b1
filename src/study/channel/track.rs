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
use crate::math::{sqrt, Mat2, Mat4, Real, Vec4, SPEED_OF_LIGHT};
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
    /// Their covariances (`null` outside segments): the filter's, plus, with the estimator's σ
    /// and a body extent `σ_e > 0`, the extent's consider term in the position block
    /// ([`extent_floor`]).
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

    /// Adds the consider term `floor` (m²) to the position block of snapshot `k`'s covariance.
    fn add_floor(&mut self, k: usize, floor: &Mat2) {
        if let Some(c) = self.covariances[k].as_mut() {
            for (i, row) in c.iter_mut().take(2).enumerate() {
                for (j, v) in row.iter_mut().take(2).enumerate() {
                    *v += floor[(i, j)];
                }
            }
        }
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

/// The body extent's share of the position covariance that filtering cannot average away
/// (issue 38 §11): `σ_e²·(JᵀJ)⁻¹`, `J` the rows (E3, s/m) of the links whose delay was used at
/// state `x`, `extent_s = σ_e/c`. `None` with fewer than two links or a singular `JᵀJ` (the
/// caller keeps the segment's previous term).
///
/// The delay a person's echo shows is that of the body's scattering centre, which wanders over
/// the body (its extent `σ_e`) slowly against the snapshot rate: the error it adds is an offset
/// per link held over many snapshots, not white noise. The filter weights each delay with
/// `σ̂² + σ_e²` as if the errors were independent from snapshot to snapshot and so averages the
/// offset down; an offset held still passes through a filter in steady state as through a
/// least-squares fix, with covariance `σ_e²·(JᵀJ)⁻¹`. Added to the filter's position
/// covariance as a consider term (the filter's own covariance, its gates and its NIS are
/// unchanged), it makes the reported 1σ consistent with the error: on the simulated walk the
/// mean NEES of a track was 5.1–6.5 without it (2 is consistent), 1.5–2.1 with it
/// (`tests/cli/cir.rs`, `track_nees_is_in_its_band_over_seeds`).
pub fn extent_floor(
    model: &Model,
    x: &Vec4,
    used: &[Option<Real>],
    extent_s: Real,
) -> Option<Mat2> {
    let at = crate::math::Vec2::new(x[0], x[1]);
    let mut info = Mat2::zeros();
    let mut rows = 0;
    for (p, d) in used.iter().enumerate() {
        if d.is_none() || p >= model.link_count() {
            continue;
        }
        let j = model.network.jacobian_row(p, at);
        info += j * j.transpose();
        rows += 1;
    }
    if rows < 2 {
        return None;
    }
    let inv = info.try_inverse()?;
    let floor = inv * (extent_s * extent_s);
    floor.iter().all(|v| v.is_finite()).then_some(floor)
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
    // The extent's consider term ([`extent_floor`]): the last one of the segment where a
    // snapshot used fewer than two links (the offset is still there).
    let consider = extent_s.filter(|e| *e > 0.0);
    let mut floor: Option<Mat2> = None;
    let record = |out: &mut CirTrackOutput, s: &SegmentStep, floor: &mut Option<Mat2>| {
        out.record(s);
        if let Some(e) = consider {
            if let Some(f) = extent_floor(model, &s.state, &s.step.selection.delays, e) {
                *floor = Some(f);
            }
            if let Some(f) = floor.as_ref() {
                out.add_floor(s.k, f);
            }
        }
    };
    for k in 0..est.len() {
        if k % every == 0 {
            cancel.check()?;
        }
        let snap = widened(est, k, extent_s);
        match tracker.step(k, est.t_s[k], &snap, &replay)? {
            SegmentEvent::Searching { .. } => {}
            SegmentEvent::Started { start, steps } => {
                // The fix's own covariance (one snapshot, nothing averaged) holds the extent
                // already; the filtered snapshots after it get the consider term.
                floor = None;
                for (i, s) in steps.iter().enumerate() {
                    if i == 0 {
                        out.record(s);
                    } else {
                        record(&mut out, s, &mut floor);
                    }
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
                record(&mut out, &s, &mut floor);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::presets;

    /// `σ_e²·(JᵀJ)⁻¹` against the closed-form 2 × 2 inverse of the information from E3's rows
    /// (unit vectors to the Tx and Rx, over c); `None` below two links and on collinear rows.
    #[test]
    fn extent_floor_is_the_least_squares_covariance_of_an_offset() {
        let model = Model::new(&presets::preset("sensors2019").unwrap()).unwrap();
        let net = &model.network;
        let x = Vec4::new(3.0, 5.0, 1.0, 0.0);
        let at = crate::math::Vec2::new(3.0, 5.0);
        let e = 0.2 / SPEED_OF_LIGHT;
        let used = [Some(1e-7), None, Some(1e-7), Some(1e-7)];
        let (mut a, mut b, mut d) = (0.0, 0.0, 0.0);
        for p in [0, 2, 3] {
            let (tx, rx) = net.link_nodes(p);
            let u = |n: crate::math::Vec2| {
                let v = at - n;
                v / v.norm()
            };
            let g = (u(tx) + u(rx)) / SPEED_OF_LIGHT;
            a += g.x * g.x;
            b += g.x * g.y;
            d += g.y * g.y;
        }
        let det = a * d - b * b;
        let f = extent_floor(&model, &x, &used, e).unwrap();
        let want = [
            [d / det * e * e, -b / det * e * e],
            [-b / det * e * e, a / det * e * e],
        ];
        for i in 0..2 {
            for j in 0..2 {
                let rel = (f[(i, j)] - want[i][j]).abs() / want[0][0].abs();
                assert!(rel < 1e-12, "({i}, {j}): {} vs {}", f[(i, j)], want[i][j]);
            }
        }
        assert!(extent_floor(&model, &x, &[Some(1e-7), None, None, None], e).is_none());
        assert!(extent_floor(&model, &x, &[None; 4], e).is_none());
    }
}
