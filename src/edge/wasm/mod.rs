//! WebAssembly bindings for the page: a thin edge over the core, no math here.
//!
//! [`App`] wraps a core [`Session`](crate::present::Session) (a validated scenario and its
//! compiled model; rejected edits change nothing). This layer only checks the numbers JavaScript
//! hands over (many at once as one settings object: its JSON text read into the binding's serde
//! struct, unknown fields refused, a bad field named), calls the core and converts the results:
//! objects as serde structs, serialised by one helper to parsed JSON (serde_json, whose
//! non-finite numbers become `null`, so no NaN reaches JavaScript), maps as typed arrays
//! (unbounded cells are `Infinity`), and errors as exceptions (`JsError`) carrying the core
//! [`Error`]'s one-line message, which names the offending field; nothing panics on input.
//!
//! Files: `base.rs` (module start, presets, and the error, settings-object and point conversions
//! every binding uses), `app.rs` (the `App` class), `render.rs` (colours, ticks and labels for
//! drawing), `json.rs` (the page's object shapes and `to_js`), `tracking.rs` (`App.simulate_track`
//! and the `Track` it returns), `montecarlo.rs` (`MonteCarloJob`, run chunk by chunk in a Web
//! Worker), `chart.rs` (the plotters ε_EKF / ε_PCRLB chart on a canvas), `mtl.rs` (the multi-target
//! view of a scene, [`crate::present::scene`]), `plan.rs` (the planner, run in a Web Worker),
//! `export.rs` (the page's "Save figure": the map and tracking figures as SVG through the CLI's
//! chart code), `recording.rs` (`read_recording_summary`: a dropped `.npz` channel recording),
//! `channel.rs` (the channel view: `simulate_channel`, `ChannelJob` run in a Web Worker,
//! `ChannelFigures`), `multi.rs` (several people in the tracking view: `track_people`, run in a
//! Web Worker, and `draw_people_chart`, its GOSPA chart), `multi_export.rs` (its Save figure and
//! Export data: `people_map_svg`, `people_chart_svg`, `people_data_text`), `doppler.rs`
//! (`App.compute_doppler_maps_in`: the position and velocity bounds with Doppler over a window;
//! `App.doppler_at`: both at one point, for the hover and the probe).

mod app;
mod base;
mod channel;
mod chart;
mod doppler;
mod export;
mod json;
mod montecarlo;
mod mtl;
mod multi;
mod multi_export;
mod plan;
mod recording;
mod render;
mod tracking;

pub use app::App;
pub use base::{check_point, check_rect, preset_json, preset_names, start};
use base::{err, now_ms, point, settings, window};
pub use channel::ChannelReplay;
pub use channel::{
    channel_recording_summary, channel_settings, check_channel_truth, simulate_channel,
    ChannelFigures, ChannelJob, SimulatedChannel,
};
pub use chart::draw_tracking_chart;
pub use export::{map_data_text, mtl_scene_svg, tracking_chart_svg, MAX_FIGURE_PX, MAX_FIGURE_RES};
pub use montecarlo::MonteCarloJob;
pub use mtl::{mtl_check_scene, mtl_default_scene, mtl_view_of, MtlSession};
pub use multi::{
    draw_people_chart, track_people, PEOPLE_DT_S, PEOPLE_DURATION_S, PEOPLE_GOSPA_C_M,
    PEOPLE_PROCESS_NOISE,
};
pub use multi_export::{people_chart_svg, people_data_text, people_map_svg};
pub use plan::{plan_field_ranges, plan_network};
pub use recording::read_recording_summary;
pub use render::{
    axis_ticks, colorbar_rgba, colorbar_ticks, format_length, link_rgb, render_map_rgba, scale_bar,
    unbounded_rgb, MAX_AXIS_TICKS,
};
pub use tracking::{drag_velocity, track_field_ranges, track_steps, Track, MAX_TRACK_STEPS};
