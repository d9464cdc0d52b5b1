//! The channel front end (spec `channel-estimation.md`, C1–C10): from channel recordings to the
//! delay estimates that gating and the trackers read. A [`Recording`] holds per snapshot and link
//! a channel frequency response (C1) or a band-limited impulse response (C2); [`Band`] is its
//! frequency-domain view; the [`LinkBackground`] removes the static channel, each snapshot
//! aligned to it (C9, receivers without a common clock: C10); the [`Estimator`] finds each
//! snapshot's paths (C5: greedy ML with cyclic refinement and a CFAR stop), the [`PathTracker`]
//! follows them over snapshots (C6); the signal-level [`simulate`](simulate_recording) makes
//! recordings of a scene (walls, point scatterers, a walking person, receiver clocks). Its
//! output, per snapshot and link a list of [`DelayEstimate`]s (a [`Snapshot`]), is what
//! `track::gating` reads, whatever filter runs (EKF, UKF or particle filter).

mod background;
mod band;
mod doppler;
mod estimate;
mod fft;
mod paths;
mod recording;
mod simulate;
mod snapshot;
mod stream;

pub use background::{
    AlignMode, Alignment, JointAlignment, LinkBackground, DEFAULT_BACKGROUND_TIME_S,
};
pub use band::{Band, ResponseMap};
pub use doppler::{
    ml_frequency, path_rate, RateEstimate, DOPPLER_OVERSAMPLING, DOPPLER_REFINE_STEPS,
};
pub use estimate::{
    fisher_matrix, EstimateWork, Estimator, EstimatorConfig, PathEstimate, SnapshotEstimate, Stop,
    MERGE_FRACTION,
};
/// The chirp-z delay profile (the delay figure's image, `present::delay_image`).
pub(crate) use fft::ChirpZ;
pub use paths::{PathTracker, PathTrackerConfig, TrackedPath};
pub use recording::{Layout, Pulse, Recording};
pub use simulate::{
    simulate_recording, Body, ChannelScene, ChannelTruth, Clock, ClockState, PathKind,
    PointScatterer, SceneCpi, Simulated, SimulationRequest, SimulationTruth, TruePath, Walk,
    Walker, Wall, DEFAULT_CALIBRATION_DURATION_S, DEFAULT_DT_S, DEFAULT_SUBCARRIERS,
    MAX_OTHER_WALKERS, MAX_SCENE_CPI_SNAPSHOTS,
};
pub use snapshot::{DelayEstimate, Snapshot};
pub use stream::{
    encode_frame, rounded_to_f32, FrameHeader, END_MARKER, LENGTH_BYTES, STREAM_FORMAT,
    STREAM_VERSION,
};
