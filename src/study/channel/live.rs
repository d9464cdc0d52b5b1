//! The channel chain live (issue 40 §3): snapshot after snapshot as frames arrive, each one's
//! track output as soon as it is estimated. The same computation as [`estimate_recording`]
//! followed by [`cir_track`] — per recorded link the same statics, estimator (C5), path tracker
//! (C6), recursive background (C9) and delay reference (C10); the same [`SegmentTracker`] (C11:
//! start, confirmation, loss, restart) with the same weights and the body extent's consider
//! term — so a recording fed frame by frame gives the batch run's states to the bit
//! (`tests.rs`, `live_equals_batch_*`).
//!
//! Two steps, because the tracker borrows the static clusters that the first frame makes (the
//! recursive background starts at it): [`LiveFront::new`] builds the statics from the first
//! frame (or the empty area) and returns them with the per-link front end; [`LiveRun::new`]
//! borrows them and [`LiveRun::push`] takes every frame, the first included.
//!
//! **Memory is flat**: nothing is kept per snapshot. What is held is bounded: per link the
//! estimator's scratch, the path tracker (at most `paths.max_tracks` tracks) and the background
//! (one response); the segment tracker's hypotheses (at most `segments.max_hypotheses`) and
//! the held track's NIS window (`segments.loss_window`); and the snapshots a confirmation may
//! replay — those since the oldest held hypothesis' fix (a confirmation replays the snapshots
//! from its hypothesis' fix), at most [`LIVE_REPLAY_SNAPSHOTS`]: a hypothesis older than that
//! (one that keeps its hits without being confirmed for that long) is dropped
//! ([`LiveState::dropped_hypotheses`] counts them), the one way a live run can differ from the
//! batch run, which keeps every snapshot.
//!
//! **What the batch run knows later**: a segment is confirmed `segments.confirm_n` snapshots
//! (or more) after its fix, and the batch output holds the replayed states of the snapshots in
//! between; live, those snapshots were reported without a state when they arrived (`event`
//! `searching`), and the confirming snapshot reports `started` with its own state.

use alloc::collections::VecDeque;
use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use serde::Serialize;

use crate::channel::{FrameHeader, Recording, Snapshot};
use crate::error::{Cancel, Error, Result};
use crate::math::{sqrt, Complex, Mat2, Real, SPEED_OF_LIGHT};
use crate::measure::{rng, Model};
use crate::scenario::Area;
use crate::study::channel::estimates::{prepare, ChannelStatics, LinkStaticsInfo};
use crate::study::channel::front::LinkFront;
use crate::study::channel::track::extent_floor;
use crate::study::channel::{ChannelRequest, DelaySigma, FrontEndConfig};
use crate::track::gating::{
    Calibration, LinkCalibration, SegmentEvent, SegmentSetup, SegmentStep, SegmentTracker,
};

#[cfg(doc)]
use crate::study::channel::{cir_track, estimate_recording};

/// Most snapshots a live run keeps for a confirmation's replay (module docs): 1024, 2 s at
/// [S]'s 2.048 ms, 20 s at 50 Hz CSI; with 4 links of 8 paths, about 1.3 MB.
pub const LIVE_REPLAY_SNAPSHOTS: usize = 1024;

/// The per-link front end of a live run: the statics built, one [`LinkFront`] per recorded
/// link, the frames' shape.
#[derive(Debug, Clone)]
pub struct LiveFront {
    fronts: Vec<LinkFront>,
    /// Recorded link → model link.
    map: Vec<usize>,
    links: usize,
    bins: usize,
}

impl LiveFront {
    /// The statics and the front end of a stream of `header`'s frames on `model` (`bandwidth_hz`
    /// the scenario's), from its first frame (`first_t_s`, `first`: link-major samples) — the
    /// recursive background starts at it — or from the empty area `empty` (on the same links
    /// and bins). Errors as [`estimate_recording`]'s (`prepare`: the links on the scenario, the
    /// band; the front end's settings).
    pub fn new(
        model: &Model,
        bandwidth_hz: Real,
        header: &FrameHeader,
        first_t_s: Real,
        first: &[Complex],
        empty: Option<&Recording>,
        cfg: &FrontEndConfig,
    ) -> Result<(ChannelStatics, LiveFront)> {
        cfg.validate()?;
        if let Some(c) = cfg.cpi {
            return Err(Error::OutOfRange {
                field: "cpi_snapshots".into(),
                value: c.snapshots as Real,
                allowed: "1 for a live run (a CPI's Doppler is read from recordings only)",
            });
        }
        let rec = header.recording(first_t_s, first.to_vec());
        let p = prepare(model, bandwidth_hz, &rec, empty, cfg)?;
        let n = model.link_count();
        let mut statics = ChannelStatics {
            calibration: Calibration {
                links: vec![LinkCalibration::default(); n],
            },
            links: vec![None; n],
        };
        let mut fronts = Vec::with_capacity(p.links());
        for link in 0..p.links() {
            let front = p.link(&rec, empty, link, cfg, Cancel::NEVER)?;
            let m = p.map[link];
            statics.links[m] = Some(LinkStaticsInfo::of(front.statics()));
            statics.calibration.links[m] = front.statics().clusters.clone();
            fronts.push(front);
        }
        Ok((
            statics,
            LiveFront {
                fronts,
                map: p.map.clone(),
                links: n,
                bins: header.freq_hz.len(),
            },
        ))
    }

    /// Snapshot `s` at `t_s` (the previous one at `prev_t_s`): every recorded link's paths, as
    /// the tracker reads them (per model link; a link not recorded has none).
    fn step(
        &mut self,
        s: usize,
        t_s: Real,
        prev_t_s: Option<Real>,
        samples: &[Complex],
    ) -> Result<Snapshot> {
        let mut snap: Snapshot = vec![Vec::new(); self.links];
        for (link, front) in self.fronts.iter_mut().enumerate() {
            let h = &samples[link * self.bins..(link + 1) * self.bins];
            let (tracked, ..) = front.step_response(s, t_s, prev_t_s, h, Cancel::NEVER)?;
            snap[self.map[link]] = tracked
                .iter()
                .map(|t| t.estimate.delay_estimate())
                .collect();
        }
        Ok(snap)
    }
}

/// One snapshot's output of a live run (one JSON line of `cir track --follow`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiveState {
    /// The snapshot's time, s.
    pub t_s: Real,
    /// `[x, y, vx, vy]` after its update (`null`: no track).
    pub state: Option<[Real; 4]>,
    /// Its covariance, as `cir track`'s (the filter's plus the body extent's consider term).
    pub covariance: Option<[[Real; 4]; 4]>,
    /// The segment (0, 1, … in the order they started; `null`: no track).
    pub segment: Option<usize>,
    /// The model links whose delay was used.
    pub links_used: Vec<usize>,
    /// Per model link the delay used, s (`null`: none).
    pub delays_s: Vec<Option<Real>>,
    /// The snapshot's index (0 = the stream's first frame).
    pub snapshot: usize,
    /// What happened: `searching`, `started` (a segment was confirmed; its state is this
    /// snapshot's), `tracked`, `lost`.
    pub event: &'static str,
    /// Why the segment ended (`lost`): `innovation`, `misses`, `outside_area`, `filter`.
    pub end: Option<&'static str>,
    /// Hypotheses dropped so far because their replay left the window (module docs).
    pub dropped_hypotheses: usize,
}

impl LiveState {
    /// Its JSON text: the line `cir track --follow` writes for the frame (without the `\n`) and
    /// the object the page's Replay shows (`wasm::ChannelReplay::push`), serialised here once
    /// for both. Keys: `t_s`, `state`, `covariance`, `segment`, `links_used`, `delays_s`,
    /// `snapshot`, `event`, `end`, `dropped_hypotheses` (non-finite numbers as `null`).
    /// Errors: [`Error::InvalidFile`] of `frames[k]` if serde fails (it does not on these types).
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| Error::InvalidFile {
            field: format!("frames[{}]", self.snapshot),
            reason: format!("cannot encode the frame's state: {e}"),
        })
    }
}

/// A live run (module docs): frames in, one [`LiveState`] per frame out.
#[derive(Debug, Clone)]
pub struct LiveRun<'a> {
    front: LiveFront,
    tracker: SegmentTracker<'a>,
    model: &'a Model,
    extent_s: Option<Real>,
    floor: Option<Mat2>,
    /// `(t, snapshot)` of snapshots `ring_base ..`.
    ring: VecDeque<(Real, Snapshot)>,
    ring_base: usize,
    segments: usize,
    segment: Option<usize>,
    k: usize,
    prev_t_s: Option<Real>,
    dropped: usize,
}

impl<'a> LiveRun<'a> {
    /// The run of `req`'s tracker on `model` in `area` with `statics` (from [`LiveFront::new`],
    /// with `front`). Errors: the request's ([`ChannelRequest::check`]) and the tracker's.
    pub fn new(
        req: &ChannelRequest,
        model: &'a Model,
        area: &'a Area,
        statics: &'a ChannelStatics,
        front: LiveFront,
    ) -> Result<LiveRun<'a>> {
        req.check()?;
        let own = req.sigma == DelaySigma::Estimator;
        let extent = req.extent_sigma_m / SPEED_OF_LIGHT;
        let extent_s = own.then_some(extent);
        let setup = SegmentSetup {
            model,
            calibration: &statics.calibration,
            area,
            kind: req.filter_kind()?,
            process_noise: req.process_noise,
            rule: req.association,
            estimate_sigmas: own,
            gate_sigma_s: extent_s,
            segments: req.segments,
        };
        Ok(LiveRun {
            front,
            tracker: SegmentTracker::searching(setup, rng(req.seed(), 0))?,
            model,
            extent_s,
            floor: None,
            ring: VecDeque::new(),
            ring_base: 0,
            segments: 0,
            segment: None,
            k: 0,
            prev_t_s: None,
            dropped: 0,
        })
    }

    /// Snapshots pushed.
    pub fn snapshots(&self) -> usize {
        self.k
    }

    /// Snapshots held for a confirmation's replay (at most [`LIVE_REPLAY_SNAPSHOTS`]).
    pub fn replay_window(&self) -> usize {
        self.ring.len()
    }

    /// The next frame: its time `t_s` and its `P·N` samples (link-major). Errors naming the
    /// frame (`frames[k]`): a time not after the previous frame's, a sample count other than
    /// `P·N`; then the front end's and the tracker's.
    pub fn push(&mut self, t_s: Real, samples: &[Complex]) -> Result<LiveState> {
        let k = self.k;
        let field = || format!("frames[{k}]");
        let want = self.front.fronts.len() * self.front.bins;
        if samples.len() != want {
            return Err(Error::InvalidFile {
                field: field(),
                reason: format!("{} samples, expected P·N = {want}", samples.len()),
            });
        }
        if !t_s.is_finite() || self.prev_t_s.is_some_and(|p| t_s <= p) {
            return Err(Error::InvalidFile {
                field: field(),
                reason: format!(
                    "time {} s is not after the previous frame's ({} s)",
                    crate::error::Num(t_s),
                    crate::error::Num(self.prev_t_s.unwrap_or(Real::NEG_INFINITY))
                ),
            });
        }
        let mut snap = self.front.step(k, t_s, self.prev_t_s, samples)?;
        if let Some(x) = self.extent_s {
            for e in snap.iter_mut().flatten() {
                e.sigma_s = e.sigma_s.map(|v| sqrt(v * v + x * x));
            }
        }
        self.prev_t_s = Some(t_s);
        self.k += 1;
        self.make_room(k);
        self.ring.push_back((t_s, snap));
        let (ring, base) = (&self.ring, self.ring_base);
        let replay = |j: usize| {
            j.checked_sub(base)
                .and_then(|i| ring.get(i))
                .cloned()
                .ok_or(Error::IndexOutOfRange {
                    field: "replay",
                    index: j,
                    len: base + ring.len(),
                })
        };
        let snap = &ring[ring.len() - 1].1;
        let event = self.tracker.step(k, t_s, snap, &replay)?;
        let out = self.output(k, t_s, event);
        self.prune(k + 1);
        Ok(out)
    }

    /// Before snapshot `k` joins the window: drops the hypotheses whose replay would need more
    /// than [`LIVE_REPLAY_SNAPSHOTS`] snapshots, then the snapshots no one can replay.
    fn make_room(&mut self, k: usize) {
        if k + 1 > LIVE_REPLAY_SNAPSHOTS {
            let k0 = k + 1 - LIVE_REPLAY_SNAPSHOTS;
            self.dropped += self.tracker.drop_hypotheses_before(k0);
        }
        self.prune(k);
    }

    /// Keeps the snapshots from the oldest held hypothesis' fix (none held: from `next`).
    fn prune(&mut self, next: usize) {
        let keep = self.tracker.oldest_fix().unwrap_or(next);
        while self.ring_base < keep && !self.ring.is_empty() {
            self.ring.pop_front();
            self.ring_base += 1;
        }
        if self.ring.is_empty() {
            self.ring_base = next;
        }
    }

    /// The state of snapshot `k` from its event; the consider term as `cir_track` adds it.
    fn output(&mut self, k: usize, t_s: Real, event: SegmentEvent) -> LiveState {
        let n = self.front.links;
        let mut out = LiveState {
            t_s,
            state: None,
            covariance: None,
            segment: None,
            links_used: Vec::new(),
            delays_s: vec![None; n],
            snapshot: k,
            event: "searching",
            end: None,
            dropped_hypotheses: self.dropped,
        };
        let step = match event {
            SegmentEvent::Searching { .. } => return out,
            SegmentEvent::Lost(reason) => {
                self.segment = None;
                out.event = "lost";
                out.end = Some(reason.name());
                return out;
            }
            SegmentEvent::Started { steps, .. } => {
                self.floor = None;
                self.segment = Some(self.segments);
                self.segments += 1;
                out.event = "started";
                let mut last = None;
                for (i, s) in steps.into_iter().enumerate() {
                    let floor = if i == 0 { None } else { self.consider(&s) };
                    last = Some((s, floor));
                }
                last
            }
            SegmentEvent::Tracked(s) => {
                out.event = "tracked";
                let floor = self.consider(&s);
                Some((s, floor))
            }
        };
        let Some((s, floor)) = step else { return out };
        let mut c: [[Real; 4]; 4] =
            core::array::from_fn(|i| core::array::from_fn(|j| s.covariance[(i, j)]));
        if let Some(f) = floor {
            for (i, row) in c.iter_mut().take(2).enumerate() {
                for (j, v) in row.iter_mut().take(2).enumerate() {
                    *v += f[(i, j)];
                }
            }
        }
        out.state = Some(s.state.into());
        out.covariance = Some(c);
        out.segment = self.segment;
        out.delays_s = s.step.selection.delays.clone();
        out.links_used = (0..n)
            .filter(|&p| out.delays_s.get(p).is_some_and(Option::is_some))
            .collect();
        out
    }

    /// The body extent's consider term after step `s` (`cir_track`'s: the last one of the
    /// segment where fewer than two links were used).
    fn consider(&mut self, s: &SegmentStep) -> Option<Mat2> {
        let e = self.extent_s.filter(|e| *e > 0.0)?;
        if let Some(f) = extent_floor(self.model, &s.state, &s.step.selection.delays, e) {
            self.floor = Some(f);
        }
        self.floor
    }
}

#[cfg(test)]
mod tests;
