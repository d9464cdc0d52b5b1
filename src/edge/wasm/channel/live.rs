//! [`ChannelReplay`] (issue 40 §3): the page's "Replay" — an opened recording fed frame by frame
//! through the core's live run ([`LiveFront`], [`LiveRun`], the chain `cir track --follow`
//! runs), each frame's state the JSON text that command writes as its line
//! ([`LiveState::to_json`], the one serialisation both share). Run by the channel worker
//! (`www/js/channel-worker.js`, job `replay`), which paces the frames at their own times and
//! drops the replay at Stop.
//!
//! The live run borrows its model, area and static clusters for as long as it lives; a
//! `wasm_bindgen` object cannot hold a borrow of itself, so they are moved to the heap and kept
//! for the life of the module's instance (`Box::leak`: a few kB per replay). The page starts a
//! fresh worker (a fresh instance) for every replay and terminates it at the end or at Stop,
//! which frees them (`www/js/channel-replay.js`).

use alloc::boxed::Box;
use alloc::string::String;
use alloc::vec::Vec;

use serde::Serialize;
use wasm_bindgen::prelude::*;

use super::job::{check_particle_steps, estimation_error, read_page_recording};
use super::{check_size, named, scenario_and_model};
use crate::channel::{FrameHeader, Recording};
use crate::edge::wasm::base::err;
use crate::edge::wasm::json::to_js;
use crate::error::limits::MAX_PAGE_TEXT_BYTES;
use crate::error::Error;
use crate::math::{Mat4, Vec4};
use crate::present::{position_ellipse, EllipseView};
use crate::scenario::Area;
use crate::study::{ChannelRequest, ChannelStatics, LiveFront, LiveRun, LiveState};
use crate::Model;

/// What a live run borrows (module docs).
struct Held {
    model: Model,
    area: Area,
    statics: ChannelStatics,
}

/// One used link of `ChannelReplay.overlay()`.
#[derive(Serialize)]
struct ReplayLinkJs {
    link: usize,
    tx: usize,
    rx: usize,
    delay_s: f64,
    ellipse: Option<EllipseView>,
}

/// `ChannelReplay.overlay()`.
#[derive(Serialize)]
struct ReplayOverlayJs {
    sigma_ellipse: Option<EllipseView>,
    links: Vec<ReplayLinkJs>,
}

/// A recording replayed through the core's live run, one frame per [`ChannelReplay::push`].
#[wasm_bindgen]
pub struct ChannelReplay {
    held: &'static Held,
    rec: Recording,
    run: LiveRun<'static>,
    last: Option<LiveState>,
}

#[wasm_bindgen]
impl ChannelReplay {
    /// A replay of the recording `recording` (bytes of a `.npz` or a CSI file) on scenario JSON
    /// `scenario_json`, with the empty area `calibration` (`undefined`: the settings'
    /// `calibration_range_s`, or without one a background learnt from the recording) and the
    /// settings `settings_json` (the core's `ChannelRequest` as JSON, as [`super::ChannelJob`]
    /// takes them). Builds the statics from the first frame (or the empty area), as `cir track
    /// --follow` does. Throws the named errors of [`super::ChannelJob::new`] (files, links,
    /// settings), and `recording: …` for a recording of impulse responses (a stream carries
    /// frequency responses).
    #[wasm_bindgen(constructor)]
    pub fn new(
        scenario_json: &str,
        recording: &js_sys::Uint8Array,
        calibration: Option<js_sys::Uint8Array>,
        settings_json: &str,
    ) -> Result<ChannelReplay, JsError> {
        let (scenario, model) = scenario_and_model(scenario_json)?;
        check_size("settings", settings_json.len(), MAX_PAGE_TEXT_BYTES as u64).map_err(err)?;
        let req = ChannelRequest::from_json(settings_json).map_err(|e| match e {
            Error::Parse { .. } => named("settings")(e),
            e => err(e),
        })?;
        let rec = read_page_recording("recording", recording, &model)?;
        check_particle_steps(&req, rec.t_s.len()).map_err(err)?;
        let file = match calibration {
            Some(bytes) => Some(read_page_recording("calibration", &bytes, &model)?),
            None => None,
        };
        let empty = req.empty_area(file.as_ref(), &rec).map_err(err)?;
        let header = FrameHeader::of_recording(&rec).map_err(named("recording"))?;
        let cfg = req.front_end(rec.synchronized);
        let bw = scenario.radio.bandwidth_hz;
        let (statics, front) = LiveFront::new(
            &model,
            bw,
            &header,
            rec.t_s[0],
            frame(&rec, 0),
            empty.as_deref(),
            &cfg,
        )
        .map_err(estimation_error)?;
        drop(empty);
        let held: &'static Held = Box::leak(Box::new(Held {
            model,
            area: scenario.area_m,
            statics,
        }));
        let run = LiveRun::new(&req, &held.model, &held.area, &held.statics, front).map_err(err)?;
        Ok(ChannelReplay {
            held,
            rec,
            run,
            last: None,
        })
    }

    /// Frames of the recording.
    pub fn frames(&self) -> usize {
        self.rec.t_s.len()
    }

    /// The frames' times, s (the page paces the replay at them).
    pub fn t_s(&self) -> Vec<f64> {
        self.rec.t_s.clone()
    }

    /// Frames pushed so far (the next `push` takes this one).
    pub fn pushed(&self) -> usize {
        self.run.snapshots()
    }

    /// Pushes frame `k` (frames go in order: `k` is [`ChannelReplay::pushed`]) through the live
    /// run and returns its state as JSON text, exactly the line `cir track --follow` writes
    /// for it (without the `\n`): `{t_s, state: [x, y, vx, vy] | null, covariance, segment,
    /// links_used, delays_s, snapshot, event: "searching" | "started" | "tracked" | "lost", end,
    /// dropped_hypotheses}`. Throws `replay: index k …` for a frame out of order, or the core's
    /// named error (`recording: frames[k]: …`).
    pub fn push(&mut self, k: usize) -> Result<String, JsError> {
        let next = self.run.snapshots();
        if k != next || k >= self.rec.t_s.len() {
            return Err(err(Error::IndexOutOfRange {
                field: "replay",
                index: k,
                len: next.min(self.rec.t_s.len()),
            }));
        }
        let state = self
            .run
            .push(self.rec.t_s[k], frame(&self.rec, k))
            .map_err(named("recording"))?;
        let text = state.to_json().map_err(err)?;
        self.last = Some(state);
        Ok(text)
    }

    /// The map overlay of the last frame pushed: `{sigma_ellipse: {cx, cy, a, b, angle} | null
    /// (the 1σ position ellipse of its state), links: [{link, tx, rx, delay_s, ellipse}…] (the
    /// links whose delay was used, with that delay's iso-delay ellipse)}`; `null` before the
    /// first push.
    pub fn overlay(&self) -> Result<JsValue, JsError> {
        let Some(s) = &self.last else {
            return Ok(JsValue::NULL);
        };
        let sigma_ellipse = match (s.state, s.covariance) {
            (Some(x), Some(c)) => position_ellipse(
                &Vec4::new(x[0], x[1], x[2], x[3]),
                &Mat4::from_fn(|i, j| c[i][j]),
                1.0,
            )
            .map(EllipseView::from),
            _ => None,
        };
        let net = &self.held.model.network;
        let links = s
            .delays_s
            .iter()
            .enumerate()
            .filter_map(|(p, d)| {
                let (d, l) = ((*d)?, net.links.get(p)?);
                Some(ReplayLinkJs {
                    link: p,
                    tx: l.tx,
                    rx: l.rx,
                    delay_s: d,
                    ellipse: net.iso_delay_ellipse(p, d).map(EllipseView::from),
                })
            })
            .collect();
        to_js(&ReplayOverlayJs {
            sigma_ellipse,
            links,
        })
    }
}

/// Frame `k`'s samples (link-major), as a stream carries them.
fn frame(rec: &Recording, k: usize) -> &[crate::math::Complex] {
    let per = rec.links.len() * rec.samples_per_link();
    &rec.samples[k * per..(k + 1) * per]
}
