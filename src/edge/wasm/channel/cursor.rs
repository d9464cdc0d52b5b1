//! The channel view's charts with a time cursor: [`ChannelFigures::draw_link_delays`] (one
//! link's panel of the delay figure) and [`ChannelFigures::draw_error_time`] (the error over
//! time of the track figure) draw through the CLI's chart code (`chart::draw_delays_panels`,
//! `chart::draw_error_time_chart`) and return where the plotting area lies on the canvas and
//! the time it spans, so the page draws its time cursor over them without redrawing the chart.

use alloc::vec;

use serde::Serialize;
use wasm_bindgen::prelude::*;
use web_sys::HtmlCanvasElement;

use super::{chart_options, on_canvas, ChannelFigures};
use crate::chart::{draw_delays_panels, draw_error_time_chart, PlotBox};
use crate::edge::wasm::base::err;
use crate::edge::wasm::json::to_js;
use crate::error::Error;
use crate::present::DelayFigure;

/// A plot box for the page: `{x_px: [left, right], y_px: [top, bottom], t_range_s: [t0, t1]}`
/// (canvas pixels, s).
#[derive(Serialize)]
struct PlotBoxJs {
    x_px: [i32; 2],
    y_px: [i32; 2],
    t_range_s: [f64; 2],
}

impl From<PlotBox> for PlotBoxJs {
    fn from(b: PlotBox) -> PlotBoxJs {
        PlotBoxJs {
            x_px: b.x_px,
            y_px: b.y_px,
            t_range_s: b.t_range_s,
        }
    }
}

#[wasm_bindgen]
impl ChannelFigures {
    /// Draws the panel of link `link` (0 … links − 1) of the delay figure alone on `canvas` at
    /// its pixel size (`chart::draw_delays_panels` on a figure of that link, with the whole
    /// figure's time axis; no legend in the panel: the page shows its own, with the time
    /// cursor) with `title` and `subtitle` (`""`: none), and
    /// returns its plot box `{x_px, y_px, t_range_s}` (canvas pixels). Throws on `link` out of
    /// range or a drawing failure (`draw_link_delays: …`).
    pub fn draw_link_delays(
        &self,
        canvas: HtmlCanvasElement,
        link: usize,
        title: &str,
        subtitle: &str,
    ) -> Result<JsValue, JsError> {
        let n = self.figure.links.len();
        let one = self.figure.links.get(link).ok_or_else(|| {
            err(Error::SizeLimit {
                field: "link",
                value: link,
                min: 0,
                max: n.saturating_sub(1),
            })
        })?;
        let fig = DelayFigure {
            t_range_s: self.figure.t_range_s,
            amplitude_db_range: self.figure.amplitude_db_range,
            links: vec![one.clone()],
        };
        let opts = chart_options(title, subtitle);
        let mut plot = None;
        on_canvas("draw_link_delays", canvas, |root| {
            plot = draw_delays_panels(root, &fig, &opts)?.first().copied();
            Ok(())
        })?;
        to_js(&plot.map(PlotBoxJs::from))
    }

    /// Draws the error over time (the track figure's middle panel, `chart::draw_error_time_chart`)
    /// alone on `canvas` at its pixel size and returns its plot box `{x_px, y_px, t_range_s}`
    /// (canvas pixels). Throws on a drawing failure (`draw_error_time: …`).
    pub fn draw_error_time(
        &self,
        canvas: HtmlCanvasElement,
        title: &str,
        subtitle: &str,
    ) -> Result<JsValue, JsError> {
        let opts = chart_options(title, subtitle);
        let mut plot = None;
        on_canvas("draw_error_time", canvas, |root| {
            plot = Some(draw_error_time_chart(root, &self.view, &opts)?);
            Ok(())
        })?;
        to_js(&plot.map(PlotBoxJs::from))
    }
}
