//! Start, loss and restart of a track (spec channel-estimation.md C11): a gated tracker that
//! starts by itself, notices when it has lost the scatterer, says why, and starts again — so a
//! track is a list of segments, never a state wandering 100 m outside the area.
//!
//! One role per part (as Stone Soup's initiator, deleter and tracker):
//! - **Initiator** (searching): per snapshot, each link's non-static candidates (E4), at most
//!   [`SegmentConfig::candidates_per_link`] of the strongest; a backprojection over a grid of
//!   the area (step [`SegmentConfig::grid_step_m`]; per node and link the best candidate by
//!   `d² + 2·ln(A_max/A)`, `d = |τ̂ − τ(node)|/√(σ̂² + (√2·step/c)²)` the normalised delay
//!   residual (within 3) and the second term a prior for the link's strongest candidate, the
//!   score capped at 9) picks the nodes where ≥ [`SegmentConfig::min_links`] links agree; from the best local minima
//!   (at most [`MAX_FIXES_PER_SNAPSHOT`]) Levenberg–Marquardt (E5) fixes the position with
//!   those candidates, and a fix whose cost passes χ² at `1 − fix_tail_probability` with
//!   `links − 2` degrees of freedom becomes a **hypothesis** (an EKF at the fix, velocity 0 ±
//!   [`START_SPEED_SIGMA_MPS`]), unless it lies within 1 m of one already held (at most
//!   [`SegmentConfig::max_hypotheses`]). Each hypothesis is gated and updated on the following
//!   snapshots (the [`AssociationRule::Gated`] rule, 3σ); a snapshot is a hit when
//!   ≥ `min_links` links associate. At the end of its window of `confirm_n` snapshots after
//!   its fix, a hypothesis with `confirm_m` hits is **confirmed** (of several at once: most
//!   hits, then the lowest NIS per associated link — C11's "best-confirmed"); one that cannot
//!   reach `confirm_m` any more, or leaves the area, is dropped.
//! - **Tracker**: the confirmed hypothesis starts the segment at its fix's snapshot: the chosen
//!   filter (EKF, UKF or particle filter) starts at the fix and replays the snapshots since, so
//!   the segment's states are that filter's.
//! - **Deleter** (loss): the summed NIS of the last [`SegmentConfig::loss_window`] updates
//!   beyond its χ² quantile at `1 − loss_tail_probability` (degrees of freedom: the links used)
//!   ([`EndReason::Innovation`]); fewer than [`MISS_LINKS`] links associated in every snapshot
//!   for [`SegmentConfig::miss_time_s`] ([`EndReason::Misses`]); the position outside the area by more than
//!   [`SegmentConfig::area_margin_m`] ([`EndReason::OutsideArea`]). The snapshot of the loss has
//!   no state; the search starts again from the next one.
//!
//! Every loop is bounded: candidates per link, fixes per snapshot, hypotheses, LM's own
//! iteration cap, and the grid's node count ([`MAX_START_GRID_NODES`]).

// `!(x > 0.0)` is meant: a NaN must fail these checks as well.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use alloc::vec;
use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::localize::{chi_square_upper_tail, locate, DelayMeasurements, LmConfig, LmReport};
use crate::math::{sqrt, Mat4, Real, Vec2, Vec4, SPEED_OF_LIGHT};
use crate::measure::{Model, Rng};
use crate::scenario::Area;
use crate::track::gating::{
    select, AssociationRule, Calibration, DelayEstimate, GatedStep, GatedTracker, Selection,
    START_SPEED_SIGMA_MPS,
};
use crate::track::{ConstantVelocity, Ekf, Filter, FilterKind, MeasurementNoise, Tracker};

/// Most fixes tried per snapshot while searching (the best local minima of the backprojection).
pub const MAX_FIXES_PER_SNAPSHOT: usize = 4;
/// Most nodes of the initiator's grid: past it the step doubles until the grid fits.
pub const MAX_START_GRID_NODES: usize = 1 << 16;
/// Most entries (nodes × links) of the initiator's delay table.
pub const MAX_START_TABLE: usize = 1 << 22;
/// A new hypothesis within this distance of a held one is the same one, m.
const SAME_HYPOTHESIS_M: Real = 1.0;
/// A hypothesis is confirmed only if its associated candidates are on average no weaker than
/// this below each link's strongest non-static candidate, as `2·ln(A_max/A)` (4.6 = 10 dB): a
/// person's direct echo is the strongest dynamic path on most links, and the consistent ghosts
/// (the mirror image of the walker in a wall, from double bounces) are 10–20 dB weaker.
pub const CONFIRM_PRIOR: Real = 4.6;
/// Links that must associate for a snapshot to reset the miss clock of the loss test (one link's
/// association is often a false alarm inside a widened gate; two at once rarely are).
pub const MISS_LINKS: usize = 2;
/// The backprojection's cap on a link's normalised residual.
const BACKPROJECTION_CAP: Real = 3.0;

/// Settings of start, loss and restart (C11 **\[choice\]**).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentConfig {
    /// Hits needed to confirm a hypothesis (C11: M = 6).
    pub confirm_m: usize,
    /// … among this many snapshots after its fix (C11: N = 10; at most 64).
    pub confirm_n: usize,
    /// Links a fix needs, and that must associate for a hit (3: a fix in the plane and one
    /// degree of freedom to test it).
    pub min_links: usize,
    /// A fix becomes a hypothesis when its χ² tail probability is at least this (10⁻³).
    pub fix_tail_probability: Real,
    /// Candidates per link the initiator considers, the strongest first (4).
    pub candidates_per_link: usize,
    /// Hypotheses held at once (8).
    pub max_hypotheses: usize,
    /// Updates in the NIS window of the loss test (C11: W = 10).
    pub loss_window: usize,
    /// The loss test's tail probability (10⁻³).
    pub loss_tail_probability: Real,
    /// A track with fewer than [`MISS_LINKS`] associated links for this long is lost, s (1).
    pub miss_time_s: Real,
    /// A track further than this outside the area is lost, m (2).
    pub area_margin_m: Real,
    /// Node spacing of the initiator's backprojection grid, m (0.5).
    pub grid_step_m: Real,
}

impl Default for SegmentConfig {
    fn default() -> Self {
        SegmentConfig {
            confirm_m: 6,
            confirm_n: 10,
            min_links: 3,
            fix_tail_probability: 1e-3,
            candidates_per_link: 4,
            max_hypotheses: 8,
            loss_window: 10,
            loss_tail_probability: 1e-3,
            miss_time_s: 1.0,
            area_margin_m: 2.0,
            grid_step_m: 0.5,
        }
    }
}

impl SegmentConfig {
    /// Checks the settings (each error names `segments.<field>`): `1 ≤ confirm_m ≤ confirm_n ≤
    /// 64`, `min_links ≥ 3`, probabilities in (0, 1), `candidates_per_link` 1 … 64,
    /// `max_hypotheses` 1 … 256, `loss_window` 1 … 10⁴, a finite `miss_time_s > 0`, a finite
    /// `area_margin_m ≥ 0`, a finite `grid_step_m > 0`.
    pub fn validate(&self) -> Result<()> {
        let sizes: [(&'static str, usize, usize, usize); 6] = [
            ("segments.confirm_n", self.confirm_n, 1, 64),
            (
                "segments.confirm_m",
                self.confirm_m,
                1,
                self.confirm_n.max(1),
            ),
            (
                "segments.min_links",
                self.min_links,
                3,
                crate::error::limits::MAX_LINKS,
            ),
            (
                "segments.candidates_per_link",
                self.candidates_per_link,
                1,
                64,
            ),
            ("segments.max_hypotheses", self.max_hypotheses, 1, 256),
            ("segments.loss_window", self.loss_window, 1, 10_000),
        ];
        for (field, value, min, max) in sizes {
            if !(min..=max).contains(&value) {
                return Err(Error::SizeLimit {
                    field,
                    value,
                    min,
                    max,
                });
            }
        }
        for (field, v) in [
            ("segments.fix_tail_probability", self.fix_tail_probability),
            ("segments.loss_tail_probability", self.loss_tail_probability),
        ] {
            if !(v > 0.0 && v < 1.0) {
                return Err(Error::OutOfRange {
                    field: field.into(),
                    value: v,
                    allowed: "0 < p < 1",
                });
            }
        }
        for (field, v, zero_ok) in [
            ("segments.miss_time_s", self.miss_time_s, false),
            ("segments.area_margin_m", self.area_margin_m, true),
            ("segments.grid_step_m", self.grid_step_m, false),
        ] {
            let ok = v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0));
            if !ok {
                return Err(Error::OutOfRange {
                    field: field.into(),
                    value: v,
                    allowed: if zero_ok {
                        "finite and ≥ 0"
                    } else {
                        "finite and > 0"
                    },
                });
            }
        }
        Ok(())
    }
}

/// Why a segment ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndReason {
    /// The summed NIS of the last updates beyond its χ² quantile.
    Innovation,
    /// Fewer than [`MISS_LINKS`] links associated for [`SegmentConfig::miss_time_s`].
    Misses,
    /// The state left the area by more than the margin.
    OutsideArea,
    /// The filter failed numerically (its covariance stopped being positive definite, or the
    /// particle filter degenerated): the segment ends where it last had a state, and the
    /// search starts again.
    Filter,
    /// The recording ended with the track held.
    End,
}

/// Whether `e` is a filter's numerical failure (a covariance not positive definite, a
/// degenerate particle filter) rather than bad input: it ends a segment, it does not fail the
/// run.
fn numerical(e: &Error) -> bool {
    matches!(
        e,
        Error::NotPositiveDefinite { .. } | Error::Degenerate { .. }
    )
}

impl EndReason {
    /// The name in `TRACK.json`: `innovation`, `misses`, `outside_area`, `filter`, `end`.
    pub fn name(self) -> &'static str {
        match self {
            EndReason::Innovation => "innovation",
            EndReason::Misses => "misses",
            EndReason::OutsideArea => "outside_area",
            EndReason::Filter => "filter",
            EndReason::End => "end",
        }
    }
}

/// The filter after one snapshot of a segment.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentStep {
    /// The snapshot's index.
    pub k: usize,
    /// The state after the update.
    pub state: Vec4,
    /// Its covariance.
    pub covariance: Mat4,
    /// Gating, association and update (at the segment's first snapshot: the fix's selection,
    /// with `sigmas_s` those the fix weighted with and no update).
    pub step: GatedStep,
}

/// The fix that started a segment.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentStart {
    /// The fix's snapshot.
    pub k: usize,
    /// The LM fix.
    pub report: LmReport,
    /// The candidates it used.
    pub selection: Selection,
    /// Hits of its hypothesis when confirmed.
    pub hits: usize,
}

/// What one snapshot did.
#[derive(Debug, Clone, PartialEq)]
pub enum SegmentEvent {
    /// No track: searching, with this many hypotheses held after the snapshot.
    Searching {
        /// Hypotheses held.
        hypotheses: usize,
    },
    /// A hypothesis was confirmed: a segment starts at its fix (`steps[0]`) and runs to this
    /// snapshot (the last of `steps`).
    Started {
        /// The fix.
        start: SegmentStart,
        /// The segment's states from the fix's snapshot to this one.
        steps: Vec<SegmentStep>,
    },
    /// The track went on.
    Tracked(SegmentStep),
    /// The track was lost at this snapshot (which has no state).
    Lost(EndReason),
}

/// A hypothesis of the initiator.
#[derive(Debug, Clone)]
struct Hypothesis<'a> {
    born: usize,
    fix: SegmentStart,
    fix_p: Mat4,
    tracker: GatedTracker<'a, Ekf>,
    age: usize,
    hits: usize,
    nis: Real,
    /// Links associated over the hits.
    links: usize,
    /// `Σ 2·ln(A_max/A)` of the associated candidates over the hits (the strongest prior).
    prior: Real,
}

impl Hypothesis<'_> {
    /// The strongest prior per associated link over the hits.
    fn mean_prior(&self) -> Real {
        if self.links == 0 {
            Real::INFINITY
        } else {
            self.prior / self.links as Real
        }
    }

    /// The summed NIS per associated link over the hits.
    fn mean_nis(&self) -> Real {
        if self.links == 0 {
            Real::INFINITY
        } else {
            self.nis / self.links as Real
        }
    }
}

/// The track currently held.
#[derive(Debug, Clone)]
struct Held<'a> {
    tracker: GatedTracker<'a, Tracker>,
    /// `(nis, links used)` of the last updates (at most `loss_window`).
    window: Vec<(Real, usize)>,
    last_hit_t: Real,
}

/// The backprojection grid of the initiator: node positions and their delays per link.
#[derive(Debug, Clone)]
struct StartGrid {
    nodes: Vec<Vec2>,
    /// `delays[node·links + p]`, s.
    delays: Vec<Real>,
    nx: usize,
    ny: usize,
    step: Real,
}

impl StartGrid {
    fn new(model: &Model, area: &Area, step: Real) -> Result<StartGrid> {
        area.validate()?;
        let links = model.link_count().max(1);
        let (w, h) = (area.x[1] - area.x[0], area.y[1] - area.y[0]);
        let mut step = step;
        let count = |s: Real| ((w / s) as usize + 1).saturating_mul((h / s) as usize + 1);
        while count(step) > MAX_START_GRID_NODES
            || count(step).saturating_mul(links) > MAX_START_TABLE
        {
            step *= 2.0;
        }
        let (nx, ny) = ((w / step) as usize + 1, (h / step) as usize + 1);
        let mut nodes = Vec::with_capacity(nx * ny);
        let mut delays = Vec::with_capacity(nx * ny * links);
        for j in 0..ny {
            for i in 0..nx {
                let p = Vec2::new(area.x[0] + i as Real * step, area.y[0] + j as Real * step);
                nodes.push(p);
                delays.extend(model.network.delays(p));
            }
        }
        Ok(StartGrid {
            nodes,
            delays,
            nx,
            ny,
            step,
        })
    }
}

/// A gated tracker that starts, loses and restarts its track (module docs).
#[derive(Debug, Clone)]
pub struct SegmentTracker<'a> {
    model: &'a Model,
    calibration: &'a Calibration,
    area: &'a Area,
    cfg: SegmentConfig,
    kind: FilterKind,
    process_noise: Real,
    rule: AssociationRule,
    estimate_sigmas: bool,
    gate_sigma_s: Option<Real>,
    /// Loss detection on (off: the track of a measurement file, started from its given state).
    loss: bool,
    rng: Rng,
    grid: Option<StartGrid>,
    hypotheses: Vec<Hypothesis<'a>>,
    held: Option<Held<'a>>,
    last_t: Option<Real>,
    /// A fixed snapshot interval: the motion model's `Δt` exactly, not the difference of two
    /// times ([`SegmentTracker::with_interval`]).
    interval: Option<Real>,
    /// The index of the last snapshot seen.
    k: Option<usize>,
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
            model: setup.model,
            calibration: setup.calibration,
            area: setup.area,
            cfg: setup.segments,
            kind: setup.kind,
            process_noise: setup.process_noise,
            rule: setup.rule,
            estimate_sigmas: setup.estimate_sigmas,
            gate_sigma_s: setup.gate_sigma_s,
            loss: true,
            rng,
            grid: Some(grid),
            hypotheses: Vec::new(),
            held: None,
            last_t: None,
            interval: None,
            k: None,
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
            model: setup.model,
            calibration: setup.calibration,
            area: setup.area,
            cfg: setup.segments,
            kind: setup.kind,
            process_noise: setup.process_noise,
            rule: setup.rule,
            estimate_sigmas: setup.estimate_sigmas,
            gate_sigma_s: setup.gate_sigma_s,
            loss: false,
            rng: crate::measure::rng(0, 0),
            grid: None,
            hypotheses: Vec::new(),
            held: Some(Held {
                tracker,
                window: Vec::new(),
                last_hit_t: t0_s,
            }),
            last_t: Some(t0_s),
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

    fn motion(&self, dt: Real) -> Result<ConstantVelocity> {
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

    /// One snapshot of the held track, with the loss tests.
    fn track(
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

    /// One snapshot without a track: advance the hypotheses, confirm one or add new ones.
    fn search(
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
    fn start_segment(
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

    /// New hypotheses from snapshot `k` (module docs: backprojection, LM, χ²).
    fn add_hypotheses(&mut self, k: usize, snapshot: &[Vec<DelayEstimate>]) -> Result<()> {
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

/// `Σ_p 2·ln(A_max,p/A_p)` over the links whose delay was taken (`delays[p]`), `A_p` the
/// amplitude of that delay's estimate, `A_max,p` the link's strongest non-static one.
fn prior_of(snapshot: &[Vec<DelayEstimate>], delays: &[Option<Real>], strongest: &[Real]) -> Real {
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

/// Whether the position of `x` lies outside `area` grown by `margin`.
fn outside(area: &Area, margin: Real, x: &Vec4) -> bool {
    !(x[0] >= area.x[0] - margin
        && x[0] <= area.x[1] + margin
        && x[1] >= area.y[0] - margin
        && x[1] <= area.y[1] + margin)
}

#[cfg(test)]
mod tests;
