//! The channel front end's figures (issue 25 §4): [`draw_delays`], \[S\] Fig. 4 per link (the
//! response's delay profile as a grey image with its one colour bar, the path estimates as blue
//! dots, grey inside a static cluster, the static clusters as grey bands, the true paths dashed
//! on top, path length against time on a range axis robust to outliers; [`delays_svg`] with the
//! image layers as embedded PNGs), and [`draw_track_errors`], \[S\] Figs. 5–6 (the track on the
//! map, the position error over time, also alone as [`draw_error_time_chart`], and its empirical
//! CDF with the 90 % point). Each draws a [`crate::present`] view on any plotters
//! [`DrawingBackend`](plotters::prelude::DrawingBackend).

mod delays;
mod delays_svg;
mod error_time;
mod shared;
mod track_errors;

pub use delays::{delays_size, draw_delays, draw_delays_boxes, draw_delays_panels};
pub use delays_svg::delays_svg;
pub use error_time::{draw_error_time_chart, error_time_size};
pub use shared::{ChannelChartOptions, PlotBox};
pub use track_errors::{draw_track_errors, track_errors_size};

#[cfg(all(test, not(target_arch = "wasm32")))]
mod rate_tests;
#[cfg(all(test, not(target_arch = "wasm32")))]
mod tests;
