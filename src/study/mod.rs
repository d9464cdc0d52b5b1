//! Use cases: the studies every front end runs the same way — the native CLI (whole or one
//! shard of a cluster run), its `merge`, the page's workers and library users (a Python
//! binding). A study takes its configuration, runs its units through a [`Driver`] (the core's
//! [`Sequential`], or `crate::native::Parallel` on threads), and returns sums that add exactly
//! ([`crate::math::ExactSum`]), so a result depends on its seed only. The part file of a
//! sharded run and the checks of a set of them ([`PartSet`]) live here too, returning core
//! [`crate::Error`]s.
//!
//! - [`MonteCarloStudy`]: the tracker(s) against the posterior CRLB (spec §8, §9.5), over any
//!   list of filters ([`FilterStudy`]: lead filter, particle budget), its part-file
//!   configuration [`McConfig`] and result documents [`CurveDoc`].
//! - [`RocStudy`]: the multi-target method's ROC experiments (§8 of `multi-target.md`), its
//!   record [`RocConfig`].
//! - [`track_measurements`]: a measurement file (`steps` or gated `raw_steps`) tracked by any
//!   filter ([`TrackOutput`], the document of `scatterloc track`).
//! - [`ChannelRequest`], [`estimate_recording`] / [`EstimationRun`], [`cir_track`]: a channel
//!   recording through the front end (C5–C10) to a track with segments (C11) (issues 25, 36).
//! - [`LiveFront`] + [`LiveRun`]: the same chain live, frame by frame (issue 40 §3).
//! - [`check_cost`], [`track_cpu_s`], [`FilterStudy::predicted_cpu_s`]: the predicted work
//!   of a study or a track and the caps front ends refuse work over (issue 24).
//! - [`track_multi`]: a measurements file's `raw_steps` with several targets, tracked by the
//!   PMB tracker or the GNN baseline ([`MultiTrackOutput`], issue 41).
//! - [`MultiStudy`]: the multi-target Monte Carlo (PMB and GNN against the known-association
//!   bound, GOSPA per scan; sharded as `multi-target` parts).
//! - [`DopplerStudy`]: a filter with and without the range rates of each scan's CPI against the
//!   PCRLB of each (issue 42).
//! - [`PartSet`], [`PartFile`]: the part file format (`scatterloc-part`, version 2, with a digest of its sums) and what `merge` checks.

mod channel;
mod cost;
mod doppler;
mod drive;
mod filters;
mod montecarlo;
mod multi;
mod multi_study;
mod part;
mod roc;
mod sums;
mod track;

pub use channel::{
    channel_settings, channel_settings_json, cir_track, delays_only, direct_paths, estimate_link,
    estimate_recording, prepare, BoundCounts, Bounds, ChannelRequest, ChannelSetting,
    ChannelStatics, CirStart, CirTrackOutput, DelayReference, DelaySigma, EstimationRun,
    FrontEndConfig, FrontEndCpi, LinkDirectPath, LinkEstimates, LinkFront, LinkStatics,
    LinkStaticsInfo, LiveFront, LiveRun, LiveState, Prepared, RecordingEstimates, SegmentDoc,
    SettingKind, StaticMode, BACKGROUND_MAX_PATHS, DEFAULT_PROCESS_NOISE, DEFAULT_SEED,
    EXTENT_SIGMA_M, LIVE_REPLAY_SNAPSHOTS, LOS_WITHIN_DB, RECURSIVE_CLUSTER_DB,
};
pub use channel::{
    cir_track_multi, recording_measurements, recording_multi_settings, uniform_step, walkers_truth,
    RECORDING_CLUTTER, RECORDING_CLUTTER_WINDOW_S, RECORDING_DETECTION, RECORDING_EXTENT_SIGMA_M,
};
pub use cost::{
    check_cost, track_cpu_s, track_doppler_cpu_s, MAX_CPU_S, PAGE_STUDY_CPU_S, PAGE_TRACK_CPU_S,
};
pub use doppler::{CpiDoc, DopplerArm, DopplerResult, DopplerStudy, MAX_DOPPLER_RUNS};
pub use drive::{Driver, Sequential};
pub use filters::{particle_chunks, FilterResults, FilterRun, FilterStudy};
pub use montecarlo::{
    curve_label, failed_label, CurveDoc, FilterCurves, FilterDoc, FiltersConfig, McConfig, McMeta,
    MonteCarloStudy, PcrlbMeta, RunTime, TrackStudy, FAILED_NOTE,
};
pub use multi::{
    lives, multi_scans, multi_tracker, score_multi, simulate_people, track_multi,
    track_multi_clocked, track_scans, walk_region, LabelledTrack, MultiScoreDoc, MultiSettings,
    MultiTiming, MultiTrackOutput, MultiTruth, Scans, TargetDoc, TruthTarget, Walkers,
};
pub use multi_study::{
    known_association_bound, multi_study_doc, MethodDoc, MethodSums, MultiStudy, MultiStudyConfig,
    MultiStudyDoc, MultiSums, MAX_MULTI_RUNS,
};
pub use part::{
    differs, inconsistent, load_sums, merged_timing, software, sums_digest, Part, PartFile,
    PartSet, ShardDoc, Timing, MAX_PART_CONFIG_BYTES, MAX_TIMING_ENTRIES, PART_FORMAT,
    PART_VERSION,
};
pub use roc::{RocConfig, RocStudy};
pub use track::{
    track_measurements, track_measurements_in, TrackDoppler, TrackOutput, TrackRequest, TrackStart,
};

#[cfg(test)]
mod tests;
