//! What a [`SegmentTracker`](super::SegmentTracker) reports per snapshot ([`SegmentEvent`]): the
//! search, a segment's start ([`SegmentStart`], the fix that started it), its steps
//! ([`SegmentStep`]), and why it ended ([`EndReason`]).

use alloc::vec::Vec;

use crate::error::Error;
use crate::localize::LmReport;
use crate::math::{Mat4, Vec4};
use crate::track::gating::{GatedStep, Selection};

#[cfg(doc)]
use super::{SegmentConfig, MISS_LINKS};

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
pub(super) fn numerical(e: &Error) -> bool {
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
