//! The raw-estimate front end of the tracker (spec §4): the calibration stage (static clusters
//! per link, delay-only or by delay and amplitude (C7) on one shared skeleton), 3σ gating of
//! static estimates (E4), association of the remaining estimates to the scatterer, the gated
//! tracker that feeds any filter (EKF, UKF or particle filter, through the `Filter` seam), its
//! start, loss and restart in segments (C11), the simulated output of the per-snapshot
//! estimator, and the synthetic stand-in of the measurement case (spec §9.6).

mod amplitude_clusters;
mod association;
mod calibration;
mod clustering;
mod gated_track;
mod measurement_case;
mod raw_snapshot;
mod segments;
mod walk_sim;

pub use amplitude_clusters::AmplitudeClusterConfig;
pub use association::{
    associate, select, AssociationRule, Choice, DelayEstimate, Selection, INNOVATION_GATE,
    MAX_ESTIMATES_PER_LINK,
};
pub use calibration::{
    Calibration, ClusterConfig, LinkCalibration, StaticCluster, GATE_SIGMAS,
    MAX_CALIBRATION_DELAYS, MAX_CALIBRATION_SNAPSHOTS,
};
pub use gated_track::{
    start_from_snapshot, GatedStep, GatedTracker, StartFix, START_SPEED_SIGMA_MPS,
};
pub use measurement_case::{default_channel, LoopPath, LOOP_DURATION_S};
pub use raw_snapshot::{StaticChannel, MAX_FALSE_ALARMS};
pub use segments::{
    EndReason, SegmentConfig, SegmentEvent, SegmentSetup, SegmentStart, SegmentStep,
    SegmentTracker, MAX_FIXES_PER_SNAPSHOT, MAX_START_GRID_NODES, MAX_START_TABLE, MISS_LINKS,
};
pub use walk_sim::{WalkRequest, WalkSimulation, WalkSnapshot};
