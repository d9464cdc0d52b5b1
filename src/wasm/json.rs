//! Core results as JavaScript values (parsed JSON). Field names and shapes are the page's API;
//! labels are the core's [`format_length_m`] with 3 significant digits.

use serde_json::{json, Value};
use wasm_bindgen::prelude::*;

use crate::localize::CrlbPoint;
use crate::measure::Ellipse;
use crate::present::format_length_m;
use crate::present::Session;
use crate::present::{LinkSim, SnapshotFix, SnapshotSimulation};
use crate::present::{TrackEstimate, TrackFrame};
use crate::{Scenario, Vec2};

/// Parsed JSON for JavaScript (numbers that are not finite are already `null` in `Value`).
pub(super) fn to_js(v: &Value) -> Result<JsValue, JsError> {
    js_sys::JSON::parse(&v.to_string()).map_err(|_| JsError::new("internal error: bad JSON"))
}

fn label(m: f64) -> String {
    format_length_m(m, 3)
}

/// `{cx, cy, a, b, angle}` or null.
pub(super) fn ellipse_json(e: Option<Ellipse>) -> Value {
    match e {
        Some(e) => json!({
            "cx": e.center.x, "cy": e.center.y,
            "a": e.semi_major, "b": e.semi_minor, "angle": e.angle_rad,
        }),
        None => Value::Null,
    }
}

/// `[[x, y], …]`.
fn points_json(p: &[Vec2]) -> Value {
    p.iter().map(|q| [q.x, q.y]).collect::<Vec<_>>().into()
}

/// `{x, y, bounded, sigma_x_m, sigma_y_m, rmse_m, *_label, ellipse}`; unbounded: nulls, `∞`.
pub(super) fn crlb_json(c: &CrlbPoint) -> Value {
    match c.bound {
        Some(b) => json!({
            "x": c.position.x, "y": c.position.y, "bounded": true,
            "sigma_x_m": b.sigma_x_m, "sigma_y_m": b.sigma_y_m, "rmse_m": b.rmse_m,
            "rmse_label": label(b.rmse_m),
            "sigma_x_label": label(b.sigma_x_m),
            "sigma_y_label": label(b.sigma_y_m),
            "ellipse": ellipse_json(c.ellipse()),
        }),
        None => json!({
            "x": c.position.x, "y": c.position.y, "bounded": false,
            "sigma_x_m": null, "sigma_y_m": null, "rmse_m": null,
            "rmse_label": "unbounded", "sigma_x_label": "\u{221e}", "sigma_y_label": "\u{221e}",
            "ellipse": null,
        }),
    }
}

/// `{transmitters: [{name, x, y, boresight: [ux, uy] | null}], receivers: [{name, x, y}],
/// links: [[tx, rx], …]}`.
pub(super) fn nodes_json(session: &Session) -> Value {
    let (s, model) = (session.scenario(), session.model());
    let tx: Vec<Value> = s
        .transmitters
        .iter()
        .zip(&model.patterns)
        .map(|(t, p)| {
            json!({
                "name": t.name, "x": t.position_m[0], "y": t.position_m[1],
                "boresight": p.beam.map(|b| [b.boresight.x, b.boresight.y]),
            })
        })
        .collect();
    let rx: Vec<Value> = s
        .receivers
        .iter()
        .map(|r| json!({"name": r.name, "x": r.position_m[0], "y": r.position_m[1]}))
        .collect();
    let links: Vec<[usize; 2]> = model.network.links.iter().map(|l| [l.tx, l.rx]).collect();
    json!({"transmitters": tx, "receivers": rx, "links": links})
}

/// `{tx, rx, name, delay_s, sigma_s, range_sigma_label, ellipse, outline, arc}`.
fn link_json(l: &LinkSim, s: &Scenario) -> Value {
    let (tx, rx) = (l.link.tx, l.link.rx);
    json!({
        "tx": tx, "rx": rx,
        "name": format!("{}\u{2013}{}", s.transmitters[tx].name, s.receivers[rx].name),
        "delay_s": l.delay_s, "sigma_s": l.sigma_s,
        "range_sigma_label": label(l.range_sigma_m),
        "ellipse": ellipse_json(l.ellipse),
        "outline": points_json(&l.outline),
        "arc": points_json(&l.arc),
    })
}

fn fix_json(f: &SnapshotFix) -> Value {
    let r = &f.report;
    json!({
        "x": r.position.x, "y": r.position.y,
        "error_m": f.error_m, "error_label": label(f.error_m),
        "cost": r.cost, "iterations": r.iterations,
        "termination": r.termination.as_str(),
        "converged": r.termination.converged(),
        "ellipse": ellipse_json(f.ellipse),
    })
}

/// `{truth: {x, y}, seed, links: [{tx, rx, name, delay_s, sigma_s, range_sigma_label, ellipse,
/// outline, arc}], fix | null, fix_error | null, crlb, view_radius_m}`.
pub(super) fn snapshot_json(sim: &SnapshotSimulation, s: &Scenario) -> Value {
    let links: Vec<Value> = sim.links.iter().map(|l| link_json(l, s)).collect();
    let (fix, fix_error) = match &sim.fix {
        Ok(f) => (fix_json(f), Value::Null),
        Err(e) => (Value::Null, Value::String(e.to_string())),
    };
    json!({
        "truth": {"x": sim.truth.x, "y": sim.truth.y},
        "seed": sim.seed,
        "links": links,
        "fix": fix,
        "fix_error": fix_error,
        "crlb": crlb_json(&sim.crlb),
        "view_radius_m": sim.view_radius_m,
    })
}

/// `{x, y, vx, vy, ellipse, error_m, error_label, sigma_m, sigma_label, nis}`.
pub(super) fn estimate_json(e: &TrackEstimate) -> Value {
    json!({
        "x": e.position.x, "y": e.position.y, "vx": e.velocity.x, "vy": e.velocity.y,
        "ellipse": ellipse_json(e.ellipse),
        "error_m": e.error_m, "error_label": label(e.error_m),
        "sigma_m": e.sigma_m, "sigma_label": label(e.sigma_m),
        "nis": e.nis,
    })
}

/// A track step shaped like [`snapshot_json`], the EKF estimate in place of the fix: `{step,
/// t_s, truth: {x, y, vx, vy}, links, fix: estimate, fix_error: null, crlb, view_radius_m}`.
pub(super) fn frame_json(f: &TrackFrame, s: &Scenario) -> Value {
    json!({
        "step": f.step, "t_s": f.t_s,
        "truth": {"x": f.truth.x, "y": f.truth.y, "vx": f.truth_velocity.x, "vy": f.truth_velocity.y},
        "links": f.links.iter().map(|l| link_json(l, s)).collect::<Vec<_>>(),
        "fix": estimate_json(&f.estimate),
        "fix_error": null,
        "crlb": crlb_json(&f.crlb),
        "view_radius_m": f.view_radius_m,
    })
}
