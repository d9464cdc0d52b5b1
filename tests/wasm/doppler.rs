//! Issue 42 §1: the page's bound with Doppler at a point (`App.doppler_at`, the hover read-out
//! and the pinned probe) and its maps' Save figure (`App.map_svg` with `doppler`). The point's
//! numbers are the core's [`DopplerDoc`] (as `crlb --doppler` writes it) bit for bit, and equal
//! the cells of `App.compute_doppler_maps_in`'s maps at their centres; one snapshot is
//! unbounded (null, never NaN); bad input throws a message naming the field. (Included from
//! `export.rs`, whose module holds the figure tests.)

use js_sys::{Array, Float64Array};
use wasm_bindgen::JsValue;
use wasm_bindgen_test::*;

use scatterloc::localize::Grid;
use scatterloc::measure::Cpi;
use scatterloc::present::DopplerDoc;
use scatterloc::scenario::Area;
use scatterloc::wasm::App;
use scatterloc::Model;

use super::svg::{count, svg_texts};
use super::{err, get, ok, sensors};

/// The settings object (JSON text) of `snapshots` snapshots 1.5 ms apart, floor 0.05 m/s, at
/// v = (1.25, -0.5) m/s.
fn job(snapshots: usize) -> String {
    serde_json::json!({
        "cpi": {"snapshots": snapshots, "spacing_ms": 1.5, "floor_mps": 0.05},
        "velocity_mps": [1.25, -0.5],
    })
    .to_string()
}

/// The core's document for the same settings (the binding's `spacing_ms / 1000`).
fn core_doc(app: &App, at: [f64; 2], snapshots: usize) -> DopplerDoc {
    let s = app.scenario_ref();
    let model = Model::new(s).unwrap();
    let cpi = Cpi::new(s.radio.carrier_hz, snapshots, 1.5 / 1e3, 0.05).unwrap();
    DopplerDoc::at(&model, at, [1.25, -0.5], &cpi)
}

/// A number or null (`None`) of `obj[key]`.
fn opt(obj: &JsValue, key: &str) -> Option<f64> {
    let v = get(obj, key);
    if v.is_null() {
        None
    } else {
        Some(v.as_f64().unwrap_or_else(|| panic!("{key}: {v:?}")))
    }
}

/// Bits of an optional bound (`None` as +∞'s), for exact comparison.
fn bits(v: Option<f64>) -> u64 {
    v.unwrap_or(f64::INFINITY).to_bits()
}

/// `doppler_at` is the core's document bit for bit (bounds, per-link range rates and σ), with
/// labels; a cell of the maps equals it at the cell's centre.
#[wasm_bindgen_test]
fn doppler_at_is_the_core_document_and_the_map_cell() {
    let app = sensors();
    let at = [3.5, 2.25];
    let d = ok(app.doppler_at(at[0], at[1], &job(24)));
    let doc = core_doc(&app, at, 24);
    assert!(doc.position_rmse_m.is_some() && doc.velocity_rmse_mps.is_some());
    for (key, want) in [
        ("position_rmse_m", doc.position_rmse_m),
        ("velocity_rmse_mps", doc.velocity_rmse_mps),
        ("delay_only_position_rmse_m", doc.delay_only_position_rmse_m),
    ] {
        assert_eq!(bits(opt(&d, key)), bits(want), "{key}");
    }
    assert_eq!(get(&d, "bounded"), JsValue::TRUE);
    let links: Array = get(&d, "links").into();
    assert_eq!(links.length() as usize, doc.links.len());
    for (k, l) in doc.links.iter().enumerate() {
        let js = links.get(k as u32);
        assert_eq!(
            bits(opt(&js, "range_rate_mps")),
            bits(Some(l.range_rate_mps))
        );
        assert_eq!(
            bits(opt(&js, "sigma_range_rate_mps")),
            bits(l.sigma_range_rate_mps)
        );
    }
    let cpi = get(&d, "cpi");
    assert_eq!(opt(&cpi, "spacing_s"), Some(1.5 / 1e3));
    let label = |k: &str| get(&d, k).as_string().unwrap();
    assert_eq!(
        label("position_label"),
        scatterloc::wasm::format_length(doc.position_rmse_m.unwrap(), 3)
    );
    assert_eq!(
        label("velocity_label"),
        format!(
            "{}/s",
            scatterloc::wasm::format_length(doc.velocity_rmse_mps.unwrap(), 3)
        )
    );

    // The maps' cells at their centres: the same numbers through the map kernel.
    let (w, n) = ([1.0, 7.0, -1.0, 5.0], 4);
    let settings = serde_json::json!({
        "window": w, "nx": n, "ny": n,
        "cpi": {"snapshots": 24, "spacing_ms": 1.5, "floor_mps": 0.05},
        "velocity_mps": [1.25, -0.5],
    })
    .to_string();
    let (pos, vel) = (
        Float64Array::new_with_length(16),
        Float64Array::new_with_length(16),
    );
    ok(app.compute_doppler_maps_in(&settings, &pos, &vel));
    let area = Area {
        x: [w[0], w[1]],
        y: [w[2], w[3]],
    };
    let grid = Grid::new(area, n, n).unwrap();
    let mut bounded = 0;
    for j in 0..n {
        for i in 0..n {
            let k = (j * n + i) as u32;
            let c = ok(app.doppler_at(grid.x(i), grid.y(j), &job(24)));
            assert_eq!(bits(opt(&c, "position_rmse_m")), pos.get_index(k).to_bits());
            assert_eq!(
                bits(opt(&c, "velocity_rmse_mps")),
                vel.get_index(k).to_bits()
            );
            bounded += usize::from(pos.get_index(k).is_finite());
        }
    }
    assert!(bounded > 0, "some bounded cells");
}

/// One snapshot measures no Doppler: both bounds null (not NaN), labelled `unbounded`; the
/// delays alone still bound the position. Bad input throws a message naming the field.
#[wasm_bindgen_test]
fn doppler_at_unbounded_and_bad_input() {
    let app = sensors();
    let d = ok(app.doppler_at(3.5, 2.25, &job(1)));
    assert!(get(&d, "position_rmse_m").is_null());
    assert!(get(&d, "velocity_rmse_mps").is_null());
    assert_eq!(get(&d, "bounded"), JsValue::FALSE);
    assert_eq!(get(&d, "velocity_label").as_string().unwrap(), "unbounded");
    let delay = opt(&d, "delay_only_position_rmse_m");
    assert_eq!(
        bits(delay),
        bits(core_doc(&app, [3.5, 2.25], 1).delay_only_position_rmse_m)
    );
    assert!(delay.unwrap().is_finite());

    let good = job(16);
    for (m, field) in [
        (err(app.doppler_at(f64::NAN, 1.0, &good)), "x"),
        (err(app.doppler_at(1.0, f64::INFINITY, &good)), "y"),
        (err(app.doppler_at(1.0, 1.0, &job(0))), "cpi.snapshots"),
        (
            err(app.doppler_at(1.0, 1.0, r#"{"cpi": {"snapshots": 4, "spacing_ms": 0, "floor_mps": 0.1}, "velocity_mps": [0, 0]}"#)),
            "cpi.spacing_s",
        ),
        (
            err(app.doppler_at(1.0, 1.0, r#"{"cpi": {"snapshots": 4, "spacing_ms": 1, "floor_mps": 0.1}, "velocity_mps": [null, 0]}"#)),
            "settings: invalid JSON",
        ),
        (
            err(app.doppler_at(1.0, 1.0, r#"{"cpi": {"snapshots": 4, "spacing_ms": 1, "floor_mps": 0.1}}"#)),
            "velocity_mps",
        ),
        (err(app.doppler_at(1.0, 1.0, "{")), "settings: invalid JSON"),
    ] {
        assert!(m.contains(field), "message {m:?} should name {field}");
    }
}

/// `App.map_svg` with `doppler`: the position and the velocity map with Doppler, titled as
/// `crlb-map --doppler` titles them plus the σṙ floor, the velocity bar's labels in m/s; the
/// delay-only figure without it is unchanged; bad options are named.
#[wasm_bindgen_test]
fn map_svg_with_doppler_titles_and_errors() {
    let app = sensors();
    let opts = |quantity: &str| {
        serde_json::json!({
            "res": 32,
            "doppler": {
                "cpi": {"snapshots": 24, "spacing_ms": 1.5, "floor_mps": 0.05},
                "velocity_mps": [1.25, -0.5],
                "quantity": quantity,
            },
        })
        .to_string()
    };
    let cpi = "CPI 24 × 1.5 ms, v = (1.25, -0.5) m/s · σṙ floor 0.05 m/s";
    for (quantity, title, bar) in [
        (
            "position",
            "Position CRLB with Doppler",
            "RMSE bound √(σx² + σy²)",
        ),
        (
            "velocity",
            "Velocity CRLB with Doppler",
            "velocity RMSE bound √(σvx² + σvy²)",
        ),
    ] {
        let svg = ok(app.map_svg(1000, 0, &opts(quantity)));
        let texts = svg_texts(quantity, &svg);
        assert_eq!(count(&texts, title), 1, "{texts:?}");
        assert_eq!(count(&texts, bar), 1, "{texts:?}");
        assert_eq!(
            texts.iter().filter(|t| t.ends_with(cpi)).count(),
            1,
            "{texts:?}"
        );
        let per_s = texts
            .iter()
            .filter(|t| t.ends_with("/s") && !t.contains("CPI"));
        if quantity == "velocity" {
            assert!(per_s.count() >= 2, "velocity bar labels in m/s: {texts:?}");
        } else {
            assert_eq!(per_s.count(), 0, "{texts:?}");
        }
    }
    let plain = svg_texts("delay-only", &ok(app.map_svg(1000, 0, r#"{"res": 32}"#)));
    assert!(plain
        .iter()
        .all(|t| !t.contains("Doppler") && !t.contains("CPI")));

    let bad = |d: &str| err(app.map_svg(1000, 0, &format!(r#"{{"res": 32, "doppler": {d}}}"#)));
    for (m, field) in [
        (
            bad(
                r#"{"cpi": {"snapshots": 0, "spacing_ms": 1, "floor_mps": 0.1}, "velocity_mps": [0, 0], "quantity": "position"}"#,
            ),
            "cpi.snapshots",
        ),
        (
            bad(
                r#"{"cpi": {"snapshots": 4, "spacing_ms": 1, "floor_mps": -1}, "velocity_mps": [0, 0], "quantity": "position"}"#,
            ),
            "cpi.floor_mps",
        ),
        (
            bad(
                r#"{"cpi": {"snapshots": 4, "spacing_ms": 1, "floor_mps": 0.1}, "velocity_mps": [0, 0], "quantity": "speed"}"#,
            ),
            "speed",
        ),
        (
            bad(
                r#"{"cpi": {"snapshots": 4, "spacing_ms": 1, "floor_mps": 0.1}, "velocity_mps": [0, 0]}"#,
            ),
            "quantity",
        ),
    ] {
        assert!(m.starts_with("map_svg: "), "{m}");
        assert!(m.contains(field), "message {m:?} should name {field}");
    }
}
