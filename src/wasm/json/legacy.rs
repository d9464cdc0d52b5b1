//! TEMPORARY: the hand-written `json!` builders as they were before the serde structs, kept
//! only to prove the structs serialise to the same values. Deleted once compared.
#![allow(missing_docs)]

use serde_json::{json, Value};

use crate::localize::CrlbPoint;
use crate::measure::Ellipse;
use crate::mtl::view::MtlView;
use crate::present::{format_length_m, Tick};
use crate::present::Session;
use crate::present::{LinkSim, SnapshotFix, SnapshotSimulation};
use crate::present::{track_estimate, TrackEstimate, TrackFrame};
use crate::track::{MonteCarloConfig, MonteCarloResult, PartialSums, TrackRun};
use crate::{Model, Scenario, Vec2};

fn label(m: f64) -> String {
    format_length_m(m, 3)
}

/// `{cx, cy, a, b, angle}` or null.
pub(crate) fn ellipse_json(e: Option<Ellipse>) -> Value {
    match e {
        Some(e) => json!({
            "cx": e.center.x, "cy": e.center.y,
            "a": e.semi_major, "b": e.semi_minor, "angle": e.angle_rad,
        }),
        None => Value::Null,
    }
}

/// `[[x, y], …]`.
pub(crate) fn points_json(p: &[Vec2]) -> Value {
    p.iter().map(|q| [q.x, q.y]).collect::<Vec<_>>().into()
}

/// `{x, y, bounded, sigma_x_m, sigma_y_m, rmse_m, *_label, ellipse}`; unbounded: nulls, `∞`.
pub(crate) fn crlb_json(c: &CrlbPoint) -> Value {
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
pub(crate) fn nodes_json(session: &Session) -> Value {
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
pub(crate) fn link_json(l: &LinkSim, s: &Scenario) -> Value {
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

pub(crate) fn fix_json(f: &SnapshotFix) -> Value {
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
pub(crate) fn snapshot_json(sim: &SnapshotSimulation, s: &Scenario) -> Value {
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
pub(crate) fn estimate_json(e: &TrackEstimate) -> Value {
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
pub(crate) fn frame_json(f: &TrackFrame, s: &Scenario) -> Value {
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

/// Was `Track::data`.
pub(crate) fn track_data_json(kind: &str, seed: u32, steps: usize, run: &TrackRun, model: &Model) -> Value {
    let est: Vec<_> = (0..run.estimates.len())
        .map(|n| track_estimate(run, n))
        .collect::<crate::Result<_>>()
        .unwrap();
    let net = &model.network;
    let measurements: Vec<Value> = run
        .delays_s
        .iter()
        .map(|d| {
            let per_link = d.iter().enumerate();
            Value::Array(
                per_link
                    .map(|(p, t)| ellipse_json(net.iso_delay_ellipse(p, *t)))
                    .collect(),
            )
        })
        .collect();
    json!({
        "kind": kind, "seed": seed, "steps": steps,
        "dt_s": run.t_s.get(1).copied(),
        "failed_at": run.failed_at,
        "t_s": run.t_s,
        "truth": run.truth.iter().map(|x| [x[0], x[1]]).collect::<Vec<_>>(),
        "estimates": run.estimates.iter().map(|x| [x[0], x[1], x[2], x[3]]).collect::<Vec<_>>(),
        "ellipses": est.iter().map(|e| ellipse_json(e.ellipse)).collect::<Vec<_>>(),
        "sigma_m": est.iter().map(|e| e.sigma_m).collect::<Vec<_>>(),
        "error_m": est.iter().map(|e| e.error_m).collect::<Vec<_>>(),
        "nis": run.nis,
        "measurements": measurements,
    })
}

/// Was `MonteCarloJob::result_json` (before `.to_string()`).
pub(crate) fn monte_carlo_json(r: &MonteCarloResult, cfg: &MonteCarloConfig, sums: &PartialSums, chunks_done: usize) -> Value {
    let done = chunks_done >= cfg.chunk_count();
    json!({
        "t_s": r.t_s, "rmse_ekf_m": r.rmse_ekf_m, "rmse_pcrlb_m": r.rmse_pcrlb_m,
        "nees": r.nees, "runs": r.runs, "failed_runs": r.failed_runs, "seed": r.seed,
        "trajectories": cfg.trajectories, "noise_runs": cfg.noise_runs,
        "trajectories_done": sums.trajectories,
        "steps": cfg.steps, "dt_s": cfg.motion.dt_s,
        "chunks_done": chunks_done, "chunk_count": cfg.chunk_count(),
        "done": done,
    })
}

/// Was `colorbar_ticks`.
pub(crate) fn colorbar_ticks_json(ticks: Vec<(f64, Tick)>) -> Value {
    let ticks: Vec<Value> = ticks
        .into_iter()
        .map(|(frac, t)| json!({"frac": frac, "value_m": t.value, "label": t.label}))
        .collect();
    Value::Array(ticks)
}

/// Was `axis_ticks`.
pub(crate) fn axis_ticks_json(ticks: Vec<Tick>) -> Value {
    let t: Vec<Value> = ticks
        .into_iter()
        .map(|t| json!({"value": t.value, "label": t.label}))
        .collect();
    Value::Array(t)
}

/// Was `scale_bar`.
pub(crate) fn scale_bar_json(t: Option<Tick>) -> Value {
    match t {
        Some(t) => json!({"length_m": t.value, "label": t.label}),
        None => Value::Null,
    }
}

/// Was `view_json` (with the time given).
pub(crate) fn mtl_view_json(view: &MtlView, compute_ms: f64) -> Value {
    let mut value = serde_json::to_value(view).unwrap();
    if let Some(obj) = value.as_object_mut() {
        obj.insert("compute_ms".into(), compute_ms.into());
    }
    value
}
