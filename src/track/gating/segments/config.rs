//! The settings of start, loss and restart (C11 **\[choice\]**): [`SegmentConfig`], its
//! defaults and checks, and the fixed bounds of the initiator and the loss test.

use crate::error::{Error, Result};
use crate::math::Real;

/// Most fixes tried per snapshot while searching (the best local minima of the backprojection).
pub const MAX_FIXES_PER_SNAPSHOT: usize = 4;
/// Most nodes of the initiator's grid: past it the step doubles until the grid fits.
pub const MAX_START_GRID_NODES: usize = 1 << 16;
/// Most entries (nodes × links) of the initiator's delay table.
pub const MAX_START_TABLE: usize = 1 << 22;
/// A new hypothesis within this distance of a held one is the same one, m.
pub(super) const SAME_HYPOTHESIS_M: Real = 1.0;
/// A hypothesis is confirmed only if its associated candidates are on average no weaker than
/// this below each link's strongest non-static candidate, as `2·ln(A_max/A)` (4.6 = 10 dB): a
/// person's direct echo is the strongest dynamic path on most links, and the consistent ghosts
/// (the mirror image of the walker in a wall, from double bounces) are 10–20 dB weaker.
pub const CONFIRM_PRIOR: Real = 4.6;
/// Links that must associate for a snapshot to reset the miss clock of the loss test (one link's
/// association is often a false alarm inside a widened gate; two at once rarely are).
pub const MISS_LINKS: usize = 2;
/// The backprojection's cap on a link's normalised residual.
pub(super) const BACKPROJECTION_CAP: Real = 3.0;

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
