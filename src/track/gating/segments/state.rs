//! What a [`SegmentTracker`](super::SegmentTracker) holds between snapshots: the track
//! ([`Held`]: its gated filter and the loss test's window), the initiator's hypotheses
//! ([`Hypothesis`]: an EKF at a fix and its hits) and the initiator's backprojection grid
//! ([`StartGrid`]: node positions and their delays per link, at most [`MAX_START_GRID_NODES`]
//! nodes and [`MAX_START_TABLE`] entries).

use alloc::vec::Vec;

use super::{SegmentStart, MAX_START_GRID_NODES, MAX_START_TABLE};
use crate::error::Result;
use crate::math::{Mat4, Real, Vec2};
use crate::measure::Model;
use crate::scenario::Area;
use crate::track::gating::GatedTracker;
use crate::track::{Ekf, Tracker};

/// The track currently held.
#[derive(Debug, Clone)]
pub(super) struct Held<'a> {
    pub(super) tracker: GatedTracker<'a, Tracker>,
    /// `(nis, links used)` of the last updates (at most `loss_window`).
    pub(super) window: Vec<(Real, usize)>,
    pub(super) last_hit_t: Real,
}

/// A hypothesis of the initiator.
#[derive(Debug, Clone)]
pub(super) struct Hypothesis<'a> {
    pub(super) born: usize,
    pub(super) fix: SegmentStart,
    pub(super) fix_p: Mat4,
    pub(super) tracker: GatedTracker<'a, Ekf>,
    pub(super) age: usize,
    pub(super) hits: usize,
    pub(super) nis: Real,
    /// Links associated over the hits.
    pub(super) links: usize,
    /// `Σ 2·ln(A_max/A)` of the associated candidates over the hits (the strongest prior).
    pub(super) prior: Real,
}

impl Hypothesis<'_> {
    /// The strongest prior per associated link over the hits.
    pub(super) fn mean_prior(&self) -> Real {
        if self.links == 0 {
            Real::INFINITY
        } else {
            self.prior / self.links as Real
        }
    }

    /// The summed NIS per associated link over the hits.
    pub(super) fn mean_nis(&self) -> Real {
        if self.links == 0 {
            Real::INFINITY
        } else {
            self.nis / self.links as Real
        }
    }
}

/// The backprojection grid of the initiator: node positions and their delays per link.
#[derive(Debug, Clone)]
pub(super) struct StartGrid {
    pub(super) nodes: Vec<Vec2>,
    /// `delays[node·links + p]`, s.
    pub(super) delays: Vec<Real>,
    pub(super) nx: usize,
    pub(super) ny: usize,
    pub(super) step: Real,
}

impl StartGrid {
    pub(super) fn new(model: &Model, area: &Area, step: Real) -> Result<StartGrid> {
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
