//! The page's channel view (issues 26, 36): a channel recording (`.npz`, docs/recording.md) to
//! the delay figure and a track, through the same core entry points as the CLI's `cir simulate`,
//! `cir estimate` and `cir track` (`channel::SimulationRequest`, `npz::read_recording`,
//! `study::{ChannelRequest, EstimationRun, cir_track}`, `present::{estimates_doc, track_doc,
//! delay_figure, track_errors}`), so the page's files equal the CLI's for the same input.
//!
//! - [`simulate_channel`] → [`SimulatedChannel`]: the files `cir simulate` writes (`simulate.rs`).
//! - [`ChannelJob`] (run in a Web Worker, `www/js/channel-worker.js`; `job.rs`): reads the
//!   files, then estimates the statics and paths of every link, tracks (in segments: start, loss
//!   and restart, spec C11) and assembles the figures in slices (`step(budget_ms)`), so the
//!   worker reports progress and drops the job on Stop between two slices. Its settings are the
//!   core's `ChannelRequest` as JSON (no page copy of them or of their defaults); its results
//!   are JSON text: `estimates_json` (= `cir estimate --out`), `track_json` (= `cir track
//!   --out`), `figure_json` (the delay figure's data), `errors_json` (the error over time).
//! - [`ChannelFigures`] (on the page's main thread, from the worker's texts): the delay figure
//!   and the error chart on a `<canvas>` (plotters-canvas) or as SVG text (plotters' SVG
//!   backend), both by the CLI's chart code (`chart::channel`), and the map overlay of one
//!   snapshot (`overlay(k)`: the track's segments up to it, nothing outside a segment).
//!
//! - [`ChannelReplay`] (in the same worker; `live.rs`): the recording frame by frame through
//!   the core's live run, each frame's state the line `cir track --follow` writes ("Replay").
//! - [`channel_settings`]: the settings the view's panel shows, with their defaults and ranges.
//!
//! Every error is an exception carrying the core's one-line message (naming the field or the
//! array); sizes are capped before parsing ([`crate::error::limits::MAX_PAGE_RECORDING_BYTES`]);
//! non-finite numbers reach JavaScript as `null`.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters_canvas::CanvasBackend;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;
use web_sys::HtmlCanvasElement;

/// The charts with a time cursor (the page's channel view).
mod cursor;
/// `ChannelJob`: the chain from a recording to its track, in slices.
mod job;
/// `ChannelReplay`: a recording frame by frame through the core's live run (issue 40 §3).
mod live;
/// The checks at open: a recording's links, a truth file's times.
mod open;
/// Several people in a channel run: `cir track --targets auto`'s labelled tracks.
mod people;
/// `simulate_channel`: the simulation use case.
mod simulate;

pub use job::ChannelJob;
pub use live::ChannelReplay;
pub(crate) use open::page_recording;
pub use open::{channel_recording_summary, check_channel_truth};
pub use simulate::{simulate_channel, SimulatedChannel};

use super::base::err;
use super::json::to_js;
use super::now_ms;
use super::MAX_FIGURE_PX;
use crate::chart::{
    delays_size, draw_delays, draw_track_errors, scenario_nodes, track_errors_size,
    ChannelChartOptions,
};
use crate::error::limits::MAX_PAGE_TEXT_BYTES;
use crate::error::Error;
use crate::math::{Mat4, Vec4};
use crate::present::{position_ellipse, DelayFigure, EllipseView, TrackErrorView};
use crate::{Model, Scenario};

/// Most particle-steps (`snapshots × particles`) of a channel-view track: the track runs in
/// one call of the worker (a few seconds at most).
pub const MAX_CHANNEL_PARTICLE_STEPS: usize = 20_000_000;

/// The channel view's settings of the core's `ChannelRequest` as JSON: each one's key, kind,
/// default and range ([`crate::study::channel_settings`]), which the page's panel reads instead of
/// repeating them (`www/js/channel-settings.js`).
#[wasm_bindgen]
pub fn channel_settings() -> String {
    crate::study::channel_settings_json()
}

/// A core error as a JavaScript exception, its message prefixed by `what` (`recording`,
/// `calibration`, `truth`, …).
fn named(what: &str) -> impl Fn(Error) -> JsError + '_ {
    move |e| JsError::new(&format!("{what}: {e}"))
}

/// `Ok` when a dropped file of `len` bytes is within `max`, else [`Error::SizeLimit`] of
/// `field` (checked before the file is parsed).
fn check_size(field: &'static str, len: usize, max: u64) -> Result<(), Error> {
    if len as u64 > max {
        return Err(Error::SizeLimit {
            field,
            value: len,
            min: 0,
            max: max as usize,
        });
    }
    Ok(())
}

/// The scenario of the channel view and its model.
fn scenario_and_model(json: &str) -> Result<(Scenario, Model), JsError> {
    check_size("scenario", json.len(), MAX_PAGE_TEXT_BYTES as u64).map_err(err)?;
    let s = Scenario::from_json(json).map_err(named("scenario"))?;
    let m = Model::new(&s).map_err(named("scenario"))?;
    Ok((s, m))
}

/// The parts of `TRACK.json` the map overlay reads (other keys are ignored).
#[derive(Deserialize)]
struct TrackParts {
    t_s: Vec<f64>,
    states: Vec<Option<[f64; 4]>>,
    covariances: Vec<Option<[[f64; 4]; 4]>>,
    links_used: Vec<usize>,
    delays_used_s: Vec<Vec<Option<f64>>>,
    sigmas_used_s: Vec<Vec<Option<f64>>>,
    choices: Vec<Vec<String>>,
    segments: Vec<SegmentParts>,
}

/// The parts of a segment of `TRACK.json` the overlay reads.
#[derive(Deserialize)]
struct SegmentParts {
    first: usize,
    last: usize,
}

/// One used link of `ChannelFigures.overlay(k)`.
#[derive(Serialize)]
struct OverlayLinkJs {
    link: usize,
    tx: usize,
    rx: usize,
    delay_s: f64,
    range_m: f64,
    sigma_s: Option<f64>,
    choice: String,
    ellipse: Option<EllipseView>,
}

/// `ChannelFigures.overlay(k)`.
#[derive(Serialize)]
struct OverlayJs {
    index: usize,
    t_s: f64,
    track_m: Vec<Vec<[f64; 2]>>,
    segment: Option<usize>,
    state: Option<[f64; 4]>,
    sigma_ellipse: Option<EllipseView>,
    error_m: Option<f64>,
    links_used: usize,
    links: Vec<OverlayLinkJs>,
}

/// The channel view's pictures on the page's main thread, from a finished job's texts.
#[wasm_bindgen]
pub struct ChannelFigures {
    scenario: Scenario,
    model: Model,
    figure: DelayFigure,
    view: TrackErrorView,
    track: TrackParts,
}

/// A figure's size: `(0, 0)` the CLI's `default`, else both within 200 … [`MAX_FIGURE_PX`].
fn chart_size(default: (u32, u32), width: u32, height: u32) -> Result<(u32, u32), Error> {
    if width == 0 && height == 0 {
        return Ok(default);
    }
    for (field, v) in [("width", width), ("height", height)] {
        if !(200..=MAX_FIGURE_PX).contains(&v) {
            return Err(Error::SizeLimit {
                field,
                value: v as usize,
                min: 200,
                max: MAX_FIGURE_PX as usize,
            });
        }
    }
    Ok((width, height))
}

fn chart_options(title: &str, subtitle: &str) -> ChannelChartOptions {
    ChannelChartOptions {
        title: title.to_string(),
        subtitle: (!subtitle.is_empty()).then(|| subtitle.to_string()),
    }
}

/// Draws with `draw` on a canvas' drawing area and presents it.
fn on_canvas(
    func: &str,
    canvas: HtmlCanvasElement,
    draw: impl FnOnce(&DrawingArea<CanvasBackend, Shift>) -> Result<(), crate::chart::ChartError>,
) -> Result<(), JsError> {
    let root = CanvasBackend::with_canvas_object(canvas)
        .ok_or_else(|| JsError::new(&format!("{func}: the canvas has no 2-D context")))?
        .into_drawing_area();
    draw(&root).map_err(|e| JsError::new(&format!("{func}: {e}")))?;
    root.present()
        .map_err(|e| JsError::new(&format!("{func}: {e}")))
}

/// The SVG text of `size` px drawn by `draw`.
fn to_svg(
    func: &str,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), crate::chart::ChartError>,
) -> Result<String, JsError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(&root).map_err(|e| JsError::new(&format!("{func}: {e}")))?;
        root.present()
            .map_err(|e| JsError::new(&format!("{func}: {e}")))?;
    }
    Ok(svg)
}

#[wasm_bindgen]
impl ChannelFigures {
    /// The figures of scenario JSON `scenario_json` from a [`ChannelJob`]'s `figure_json`,
    /// `errors_json` and `track_json` texts. Throws the named parse error on malformed text or
    /// texts of different lengths.
    #[wasm_bindgen(constructor)]
    pub fn new(
        scenario_json: &str,
        figure_json: &str,
        errors_json: &str,
        track_json: &str,
    ) -> Result<ChannelFigures, JsError> {
        let (scenario, model) = scenario_and_model(scenario_json)?;
        let parse = |what: &'static str, e: serde_json::Error| {
            named(what)(Error::Parse {
                message: e.to_string(),
            })
        };
        let figure: DelayFigure =
            serde_json::from_str(figure_json).map_err(|e| parse("figure", e))?;
        let view: TrackErrorView =
            serde_json::from_str(errors_json).map_err(|e| parse("errors", e))?;
        let track: TrackParts = serde_json::from_str(track_json).map_err(|e| parse("track", e))?;
        let n = track.t_s.len();
        for (field, len) in [
            ("track.states", track.states.len()),
            ("track.covariances", track.covariances.len()),
            ("track.links_used", track.links_used.len()),
            ("track.delays_used_s", track.delays_used_s.len()),
            ("track.sigmas_used_s", track.sigmas_used_s.len()),
            ("track.choices", track.choices.len()),
            ("errors.error_m", view.error_m.len()),
        ] {
            crate::error::check_len(field, n, len).map_err(err)?;
        }
        // Segments in time order, each within the snapshots and after the one before.
        let mut next = 0;
        for (i, g) in track.segments.iter().enumerate() {
            if g.first < next || g.last < g.first || g.last >= n {
                return Err(err(Error::InvalidFile {
                    field: format!("track.segments[{i}]"),
                    reason: format!(
                        "snapshots {} … {} are not after the previous segment (from {next}) \
                         within 0 … {}",
                        g.first,
                        g.last,
                        n.saturating_sub(1)
                    ),
                }));
            }
            next = g.last + 1;
        }
        Ok(ChannelFigures {
            scenario,
            model,
            figure,
            view,
            track,
        })
    }

    /// Snapshots of the track.
    pub fn snapshot_count(&self) -> usize {
        self.track.t_s.len()
    }

    /// The size `[width, height]` px the CLI gives the delay figure (`chart::delays_size`).
    pub fn delays_size(&self) -> Vec<u32> {
        let (w, h) = delays_size(self.figure.links.len());
        vec![w, h]
    }

    /// The size `[width, height]` px the CLI gives the track figure (`chart::track_errors_size`).
    pub fn errors_size(&self) -> Vec<u32> {
        let (w, h) = track_errors_size();
        vec![w, h]
    }

    /// Draws the delay figure (`chart::draw_delays`, as `cir track --delays-figure`) on
    /// `canvas` at its pixel size with `title` and `subtitle` (`""`: none). Throws
    /// `draw_delays: …`.
    pub fn draw_delays(
        &self,
        canvas: HtmlCanvasElement,
        title: &str,
        subtitle: &str,
    ) -> Result<(), JsError> {
        let opts = chart_options(title, subtitle);
        on_canvas("draw_delays", canvas, |root| {
            draw_delays(root, &self.figure, &opts)
        })
    }

    /// The delay figure as SVG text of `width × height` px (0, 0: the CLI's size; else each
    /// 200 … 8000), its images embedded as PNGs (`chart::delays_svg`, as the CLI's). Throws
    /// `delays_svg: …`.
    pub fn delays_svg(
        &self,
        width: u32,
        height: u32,
        title: &str,
        subtitle: &str,
    ) -> Result<String, JsError> {
        let size = chart_size(delays_size(self.figure.links.len()), width, height)
            .map_err(named("delays_svg"))?;
        let opts = chart_options(title, subtitle);
        // The images as one PNG per panel, as the CLI writes it (issue 37 item 11).
        crate::chart::delays_svg(size, &self.figure, &opts)
            .map_err(|e| JsError::new(&format!("delays_svg: {e}")))
    }

    /// Draws the track figure (`chart::draw_track_errors`, as `cir track --figure`: the track on
    /// the map, the error over time and its CDF) on `canvas` at its pixel size. Throws
    /// `draw_errors: …`.
    pub fn draw_errors(
        &self,
        canvas: HtmlCanvasElement,
        title: &str,
        subtitle: &str,
    ) -> Result<(), JsError> {
        let opts = chart_options(title, subtitle);
        let nodes = scenario_nodes(&self.scenario);
        on_canvas("draw_errors", canvas, |root| {
            draw_track_errors(root, &self.view, &nodes, &self.scenario.area_m, &opts)
        })
    }

    /// The track figure as SVG text of `width × height` px (0, 0: the CLI's size; else each
    /// 200 … 8000). Throws `errors_svg: …`.
    pub fn errors_svg(
        &self,
        width: u32,
        height: u32,
        title: &str,
        subtitle: &str,
    ) -> Result<String, JsError> {
        let size = chart_size(track_errors_size(), width, height).map_err(named("errors_svg"))?;
        let opts = chart_options(title, subtitle);
        let nodes = scenario_nodes(&self.scenario);
        to_svg("errors_svg", size, |root| {
            draw_track_errors(root, &self.view, &nodes, &self.scenario.area_m, &opts)
        })
    }

    /// The map overlay of snapshot `k` (0 … snapshot_count − 1): `{index, t_s, track_m:
    /// [[[x, y]…] per segment begun by k] (each segment's estimated positions up to k; none
    /// outside a segment), segment: index | null (the segment holding k; null before the first,
    /// between two after a loss, or after the last), state: [x, y, vx, vy] | null (null
    /// outside a segment), sigma_ellipse: {cx, cy, a, b, angle} | null (the filter's 1σ
    /// position ellipse), error_m: m | null (with a truth), links_used, links: [{link, tx, rx,
    /// delay_s, range_m, sigma_s (s | null), choice, ellipse: {cx, cy, a, b, angle} | null}…]
    /// (the links whose delay was used at k, with the iso-delay ellipse of that delay; none
    /// outside a segment)}`. Throws on `k` out of range.
    pub fn overlay(&self, k: usize) -> Result<JsValue, JsError> {
        let t = &self.track;
        if k >= t.t_s.len() {
            return Err(err(Error::SizeLimit {
                field: "snapshot",
                value: k,
                min: 0,
                max: t.t_s.len().saturating_sub(1),
            }));
        }
        // Per segment begun by k its positions up to k: nothing is drawn outside a segment,
        // nor joins two of them.
        let track_m = t
            .segments
            .iter()
            .take_while(|g| g.first <= k)
            .map(|g| {
                t.states[g.first..=g.last.min(k)]
                    .iter()
                    .flatten()
                    .map(|x| [x[0], x[1]])
                    .collect()
            })
            .collect();
        let segment = t.segments.iter().position(|g| g.first <= k && k <= g.last);
        let state = segment.and(t.states[k]);
        let sigma_ellipse = match (state, t.covariances[k]) {
            (Some(x), Some(c)) => position_ellipse(
                &Vec4::new(x[0], x[1], x[2], x[3]),
                &Mat4::from_fn(|i, j| c[i][j]),
                1.0,
            )
            .map(EllipseView::from),
            _ => None,
        };
        let net = &self.model.network;
        let used: &[Option<f64>] = match segment {
            Some(_) => &t.delays_used_s[k],
            None => &[],
        };
        let links = used
            .iter()
            .enumerate()
            .filter_map(|(p, d)| {
                let (d, l) = ((*d)?, net.links.get(p)?);
                Some(OverlayLinkJs {
                    link: p,
                    tx: l.tx,
                    rx: l.rx,
                    delay_s: d,
                    range_m: crate::math::SPEED_OF_LIGHT * d,
                    sigma_s: t.sigmas_used_s[k].get(p).copied().flatten(),
                    choice: t.choices[k].get(p).cloned().unwrap_or_default(),
                    ellipse: net.iso_delay_ellipse(p, d).map(EllipseView::from),
                })
            })
            .collect();
        to_js(&OverlayJs {
            index: k,
            t_s: t.t_s[k],
            track_m,
            segment,
            state,
            sigma_ellipse,
            error_m: self.view.error_m[k],
            links_used: t.links_used[k],
            links,
        })
    }
}
