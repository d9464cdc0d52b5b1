//! From a channel recording to a track, as one use case (issue 36; spec channel-estimation.md
//! C1–C11, §4–§6): the one home of the chain that the CLI's `cir estimate` and `cir track`, the
//! page's channel view and the Python package drive. A [`ChannelRequest`] holds every setting
//! and its default, [`channel_settings`] lists those the page shows with their defaults and
//! ranges (the page reads them from there); per recorded link the front end builds its statics — the background of
//! the empty area (C9) with the static clusters that gate what is left of it, a recursive
//! background, or C7's clusters — and estimates every snapshot (C5 on the residual, C6 path
//! tracks, delays absolute or relative to the direct path, C10) ([`estimate_recording`], one
//! driver job per link, or [`EstimationRun`] in slices); the track ([`cir_track`]) starts by
//! itself, detects its loss and restarts (C11) with any filter; [`LiveFront`] + [`LiveRun`]
//! run the same chain frame by frame, as frames arrive (issue 40 §3); [`cir_track_multi`]
//! tracks several people of a recording from the same estimates (issue 41 §2).
//!
//! ```
//! use scatterloc::channel::{simulate_recording, ChannelScene};
//! use scatterloc::scenario::presets;
//! use scatterloc::study::{cir_track, estimate_recording, ChannelRequest, Sequential};
//! use scatterloc::{error::Cancel, Model};
//!
//! let scenario = presets::preset("sensors2019").unwrap();
//! let model = Model::new(&scenario).unwrap();
//! let mut scene = ChannelScene::hangar();
//! scene.duration_s = Some(1.0);
//! scene.dt_s = 0.02;
//! let (walk, _truth) = simulate_recording(&scenario, &model, &scene, true, 1).unwrap();
//! scene.duration_s = Some(0.2);
//! let (empty, _) = simulate_recording(&scenario, &model, &scene, false, 1).unwrap();
//! let req = ChannelRequest::default(); // background subtraction, EKF, C11 segments
//! let bw = scenario.radio.bandwidth_hz;
//! let (statics, est) = estimate_recording(
//!     &model, bw, &walk, Some(&empty), &req.front_end(walk.synchronized),
//!     &mut Sequential::new(), &|_| {},
//! )
//! .unwrap();
//! let track = cir_track(&req, &model, &scenario.area_m, &statics.calibration, &est, Cancel::NEVER)
//!     .unwrap();
//! assert_eq!(track.states.len(), walk.t_s.len());
//! assert!(!track.segments.is_empty());
//! ```

mod direct;
mod estimates;
mod front;
mod live;
mod multi;
mod request;
mod settings;
mod track;

pub use direct::{direct_paths, LinkDirectPath};
pub use estimates::{
    estimate_link, estimate_recording, prepare, BoundCounts, ChannelStatics, EstimationRun,
    LinkStaticsInfo, Prepared, RecordingEstimates,
};
pub use front::{
    LinkEstimates, LinkFront, LinkStatics, BACKGROUND_MAX_PATHS, LOS_WITHIN_DB,
    RECURSIVE_CLUSTER_DB,
};
pub use live::{LiveFront, LiveRun, LiveState, LIVE_REPLAY_SNAPSHOTS};
pub use multi::{
    cir_track_multi, recording_measurements, recording_multi_settings, uniform_step, walkers_truth,
    RECORDING_CLUTTER, RECORDING_CLUTTER_WINDOW_S, RECORDING_DETECTION, RECORDING_EXTENT_SIGMA_M,
};
pub use request::{
    ChannelRequest, DelayReference, DelaySigma, FrontEndConfig, FrontEndCpi, StaticMode,
    DEFAULT_PROCESS_NOISE, DEFAULT_SEED, EXTENT_SIGMA_M,
};
pub use settings::{channel_settings, channel_settings_json, Bounds, ChannelSetting, SettingKind};
pub use track::{cir_track, CirStart, CirTrackOutput, SegmentDoc};

#[cfg(test)]
mod tests;

use alloc::vec::Vec;

use crate::channel::DelayEstimate;
use crate::math::Real;

/// The estimates of one snapshot as plain delay lists (the form `calibrate --snapshots` reads).
pub fn delays_only(snapshot: &[Vec<DelayEstimate>]) -> Vec<Vec<Real>> {
    snapshot
        .iter()
        .map(|l| l.iter().map(|e| e.delay_s).collect())
        .collect()
}
