//! Start, loss and restart of a track (spec channel-estimation.md C11): a gated tracker that
//! starts by itself, notices when it has lost the scatterer, says why, and starts again — so a
//! track is a list of segments, never a state wandering 100 m outside the area. One role per
//! part (as Stone Soup's initiator, deleter and tracker): the initiator (`initiator.rs`:
//! backprojection grid, LM fixes, χ²) makes hypotheses, `confirm.rs` confirms one and starts its
//! segment with the chosen filter, the deleter (`loss.rs`: NIS window, misses, area) ends it,
//! and [`SegmentTracker`] (`tracker.rs`) runs them per snapshot; `config.rs` holds the settings,
//! `events.rs` what each snapshot reports, `state.rs` what it holds between them. Every loop is
//! bounded: candidates per link, fixes per snapshot, hypotheses, LM's own iteration cap, and the
//! grid's node count ([`MAX_START_GRID_NODES`]).

// `!(x > 0.0)` is meant: a NaN must fail these checks as well.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod config;
mod confirm;
mod events;
mod initiator;
mod loss;
mod state;
mod tracker;

pub use config::{
    SegmentConfig, CONFIRM_PRIOR, MAX_FIXES_PER_SNAPSHOT, MAX_START_GRID_NODES, MAX_START_TABLE,
    MISS_LINKS,
};
pub use events::{EndReason, SegmentEvent, SegmentStart, SegmentStep};
pub use tracker::{SegmentSetup, SegmentTracker};

#[cfg(test)]
mod tests;
