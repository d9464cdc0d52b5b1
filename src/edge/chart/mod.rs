//! Publication-style figures of CRLB maps, drawn with plotters on any [`DrawingBackend`](plotters::prelude::DrawingBackend): SVG and
//! PNG natively (the CLI), a `<canvas>` in the browser.
//!
//! [`draw_crlb_map`] draws the CRLB map figure (the same colours and colour-bar ticks as the page);
//! [`draw_crlb_map_with`] adds a [`MapOverlay`] (a target's snapshot or a track, as the page shows).
//! [`draw_tracking_filters`] draws the tracking figure of \[S\] Fig. 3 (spec §10) in the same style.
//! [`draw_plan_maps`] draws a network plan: the maps before and after side by side.
//! [`draw_curves`] draws the ROC and missed-detection curves of the multi-target experiments.
//! [`draw_delays`] and [`draw_track_errors`] draw the channel front end's figures (\[S\] Figs. 4–6).
//! [`draw_mtl_scene`] draws a multi-target scene and its view (the page's multi-target view).
//! [`draw_people_map`] and [`draw_gospa_chart`] draw a several-people run (issue 41 §2).

mod channel;
mod clip;
mod layout;
mod map;
mod overlay;
mod panel;
mod people;
mod plan;
mod raster;
mod roc;
mod scene;
mod tracking;

pub use channel::{
    delays_size, delays_svg, draw_delays, draw_track_errors, track_errors_size, ChannelChartOptions,
};
pub use channel::{
    draw_delays_boxes, draw_delays_panels, draw_error_time_chart, error_time_size, PlotBox,
};
pub(crate) use layout::{axis_label, chart_err};
pub use layout::{register_fonts, suggested_size, ChartError};
pub use map::{
    crlb_map_svg, default_titles, draw_crlb_map, draw_crlb_map_with, scenario_nodes, ChartOptions,
    ChartSummary,
};
pub use overlay::{MapOverlay, OverlayLine, OverlayMark, OverlayMarkKind, OverlayPath};
pub use panel::{check_area, ChartNode, MapData, NodeKind};
pub use people::{
    draw_gospa_chart, draw_people_map, people_rgb, people_titles, PeopleChartOptions,
};
pub use plan::{
    draw_plan_maps, plan_caption, plan_chart_size, PlanChartOptions, PlanPanel, PlanPath,
};
pub use raster::{base64, embed_pngs, encode_png, map_rgb, PNG_DATA_URI, PNG_SIGNATURE};
pub use roc::{
    curve_chart_size, draw_curves, CurveChartOptions, CurveSeries, LineKind, Marker, CURVE_PALETTE,
};
pub use scene::{draw_mtl_scene, scene_nodes, scene_titles, scene_window, SceneChartOptions};
pub use tracking::{
    draw_tracking_filters, tracking_size, FilterCurve, FiltersPanel, TrackingChartOptions,
};
