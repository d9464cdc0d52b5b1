//! Several targets over time (issue 41): the PMB tracker with belief-propagation association
//! ([`Pmb`]) and the GNN baseline ([`Gnn`]) behind one value ([`MultiTracker`]), fed scan by
//! scan with every sensor's unlabelled detections through a [`MeasurementModel`] (a position
//! sensor, or the links of a delay network, E1/E8); new targets from the Poisson intensity or
//! the delays left free on several links ([`BirthGrid`]); the scenarios (Williams-15, people
//! walking in a delay network) and the scores (GOSPA per step, label switches, cardinality
//! error) of the studies.

mod association;
mod birth;
mod config;
mod gaussian;
mod gnn;
mod pmb;
mod score;
mod sensors;
mod sim;

pub use association::{
    bp_marginals, clustered_marginals, exact_marginals, gnn_assignment, Marginals, BP_TOLERANCE,
    MAX_BP_ITERATIONS, MAX_EXACT_CLUSTER,
};
pub use birth::{BirthFix, BirthGrid, DelayBirth, MAX_BIRTH_CELLS};
pub use config::{
    check_scan, Component, MultiConfig, MultiKind, MultiTracker, Scan, TargetEstimate,
    MAX_DETECTIONS_PER_SENSOR, MAX_TRACKS,
};
pub use gaussian::{kalman_update, moment_match, Bernoulli, Updated};
pub use gnn::{Gnn, GnnManagement};
pub use pmb::{map_cardinality, Births, Pmb, MAX_UNDETECTED_COMPONENTS};
pub use score::{score_run, RunScore, StepScore};
pub use sensors::{
    check_detection, DelayLinks, Detection, MeasurementModel, Observation, PositionSensor,
    CLUTTER_RATE_SPAN_MPS,
};
pub use sim::{
    check_drawn_paths, delay_rate_scans, delay_scans, people_layout, people_region, people_truth,
    people_truth_drawn, people_truth_in, poisson, position_scans, williams15, williams15_truth,
    DrawnPath, Truth, Williams15, MAX_WALKERS,
};
