//! View models shared by every front end (the page through `wasm`, the figures through `chart`):
//! axis ticks and length labels, the log colour scale of CRLB maps, one simulated snapshot as the
//! page draws it, a simulated track's frames, the planner's request and report (`plan.json`), a
//! multi-target scene turned into what the page draws ([`mtl_view`]: nodes, targets, discs,
//! measurements, Algorithm 1's trace), and the interactive [`Session`] (a validated scenario and
//! its compiled model, kept in step), and the channel front end's delay and track-error figures
//! ([`DelayFigure`], [`TrackErrorView`], [`ErrorStats`]), and the documents of the
//! single-snapshot use cases ([`CrlbDoc`], [`FixDoc`]) the CLI prints and the Python package
//! returns, and a several-people run's map view and data file ([`people_map_view`],
//! [`people_data_text`]). Pure `no_std` functions of the core's results:
//! no maths of their own beyond layout.

mod channel_figure;
mod channel_files;
mod channel_view;
mod colormap;
mod doppler_docs;
mod free_z_docs;
mod multi_view;
mod plan_view;
mod scene;
mod session;
mod snapshot;
mod snapshot_docs;
mod ticks;
mod track_view;

pub use channel_figure::{delay_figure, delay_figure_link};
pub use channel_files::{
    estimates_doc, link_names, track_doc, AlignmentDoc, EstimatesDoc, FrontEndDoc, PathDoc,
    TrackDoc,
};
pub use channel_view::{
    delay_image, delay_points, quantile_pct, static_bands, suggest_range_m, track_errors,
    DelayFigure, DelayImage, DelayPoint, DrawnEstimate, ErrorStats, ImageConfig, ImageFloor,
    LinkDelays, SegmentSpan, StaticBand, TrackErrorView, TruthCurve,
};
pub use colormap::{
    colorbar_rgba, fill_rgba, render_rgba, viridis, LogScale, LINK_RGB, UNBOUNDED_RGB,
};
pub use doppler_docs::{DopplerDoc, DopplerMapText, RangeRateDoc};
pub use free_z_docs::{sym3, CrlbFreeZDoc, FixFreeZDoc};
pub use multi_view::{
    people_csv_header, people_data_text, people_doc_from_json, people_map_view, track_ellipses,
    PeopleMapView, PeopleRun, PeopleTrackView,
};
pub use plan_view::{
    area_of, run_plan, run_plan_with, PlanHistoryJson, PlanImprovementJson, PlanJson,
    PlanObjectiveJson, PlanPathJson, PlanProgressJson, PlanRequest, DEFAULT_PLAN_BUDGET,
};
pub use scene::output::{
    DetectedView, EllipseView, HypothesisView, MetricsView, ModelView, MtlView, RangeView,
    SeedView, SegmentView, StageCounts, TargetView, TrpView,
};
pub use scene::{
    mtl_view, mtl_view_cached, BlockingChoice, MtlScene, ViewCache, MAX_CACHED_TABLES,
    MAX_VIEW_CLUTTER, MAX_VIEW_DISCS, MAX_VIEW_NODES, MAX_VIEW_TARGETS,
};
pub use session::Session;
pub(crate) use snapshot::{link_sim, view_radius};
pub use snapshot::{
    simulate_snapshot, LinkSim, SnapshotFix, SnapshotSimulation, ARC_POINTS, FALLBACK_EXTENT_M,
    OUTLINE_POINTS, VIEW_MARGIN,
};
pub use snapshot_docs::{sym2, CrlbDoc, EllipseDoc, FixDoc, LinkDoc};
pub use ticks::{
    colorbar_ticks, decimal, format_length_m, linear_ticks, log_length_ticks, nice_below,
    scale_bar, Tick,
};
pub use track_view::{
    position_ellipse, track_estimate, track_frame, track_mean_state, velocity_through,
    TrackEstimate, TrackFrame, TRAJECTORY_KINDS,
};
