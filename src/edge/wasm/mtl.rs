//! The multi-target ("MTL") view for the page: a scene as JSON in, its view
//! ([`crate::present::MtlView`]) as a JavaScript object out, either one-off
//! ([`mtl_view_of`]) or from an [`MtlSession`] that keeps the core's [`ViewCache`] between
//! recomputes (the page's worker). Bad input throws the core's named message; no math here.

use wasm_bindgen::prelude::*;

use super::json::{to_js, MtlViewJs};
use super::{err, now_ms};
use crate::present::{mtl_view_cached, MtlScene, ViewCache};

/// The default scene (the V-B setting, [`MtlScene::vb`]) as JSON.
#[wasm_bindgen]
pub fn mtl_default_scene() -> String {
    MtlScene::vb().to_json()
}

/// The core's ranges of the scene's numbers the page range-checks before the core does
/// ([`crate::error::limits`]): `{"range_sigma": [min, max], "clutter_mean": [0, max]}`, so the
/// page's fields and the core share one definition.
#[wasm_bindgen]
pub fn mtl_field_ranges() -> String {
    let cs = crate::error::limits::C_SIGMA_M;
    serde_json::json!({
        "range_sigma": [cs.min, cs.max],
        "clutter_mean": [0.0, crate::present::MAX_VIEW_CLUTTER],
    })
    .to_string()
}

/// Parses and validates a scene; returns it re-serialised (canonical JSON). Throws the named
/// error of [`MtlScene::from_json`].
#[wasm_bindgen]
pub fn mtl_check_scene(scene_json: &str) -> Result<String, JsError> {
    Ok(MtlScene::from_json(scene_json).map_err(err)?.to_json())
}

/// The view of a scene (JSON, schema [`MtlScene`]): `{trps, seeds, hypotheses, detected,
/// targets, segments, metrics, stages, model, mpcs, compute_ms}` (see
/// [`crate::present::MtlView`]); `compute_ms` is the core's own time for parse, data and
/// Algorithm 1. Throws the core's named error on bad input.
#[wasm_bindgen]
pub fn mtl_view_of(scene_json: &str) -> Result<JsValue, JsError> {
    view_json(scene_json, &mut ViewCache::default())
}

/// Views of successive scenes sharing the core's [`ViewCache`] (results identical to
/// [`mtl_view_of`]).
#[wasm_bindgen]
#[derive(Default)]
pub struct MtlSession {
    cache: ViewCache,
}

#[wasm_bindgen]
impl MtlSession {
    /// An empty session.
    #[wasm_bindgen(constructor)]
    pub fn new() -> MtlSession {
        MtlSession::default()
    }

    /// As [`mtl_view_of`], reusing this session's cache.
    pub fn view(&mut self, scene_json: &str) -> Result<JsValue, JsError> {
        view_json(scene_json, &mut self.cache)
    }
}

fn view_json(scene_json: &str, cache: &mut ViewCache) -> Result<JsValue, JsError> {
    let t0 = now_ms();
    let scene = MtlScene::from_json(scene_json).map_err(err)?;
    let view = mtl_view_cached(&scene, cache).map_err(err)?;
    to_js(&MtlViewJs {
        view: &view,
        compute_ms: now_ms() - t0,
    })
}
