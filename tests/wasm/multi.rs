//! Several people in the tracking view (`track_people`, `draw_people_chart`): the binding's
//! document is the core use case's (simulate_people over walk_region, track_multi, score_multi at
//! the CLI's defaults) number for number, its ellipses follow the reported targets, its chart
//! draws every scan, and bad input throws the core's named message (never a trap).

use js_sys::Function;
use serde_json::{json, Value};
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::*;

use scatterloc::error::Cancel;
use scatterloc::scenario::presets;
use scatterloc::study::{score_multi, simulate_people, track_multi, walk_region, MultiSettings};
use scatterloc::track::multi::MultiKind;
use scatterloc::{wasm, Model};

use super::{err, ok};

/// Two walkers tracked by the GNN baseline: the binding's truth, track and score are the core's
/// own for the same seed (10 s at 0.1 s, process noise 0.5, c = 1 m); one ellipse per target.
#[wasm_bindgen_test]
fn track_people_is_the_core_use_case() {
    let scenario = presets::sensors2019();
    let request = json!({"walkers": 2, "method": "gnn", "seed": 4}).to_string();
    let doc: Value =
        serde_json::from_str(&ok(wasm::track_people(&scenario.to_json(), &request))).unwrap();

    let model = Model::new(&scenario).unwrap();
    let cfg = MultiSettings {
        method: MultiKind::Gnn,
        ..MultiSettings::default()
    };
    let region = walk_region(&scenario.area_m);
    let (m, truth) = simulate_people(&model, &region, 2, 101, 0.1, 0.5, &cfg, 4).unwrap();
    let out = track_multi(&model, &scenario.area_m, &m, None, &cfg, Cancel::NEVER).unwrap();
    let score = score_multi(&out, &truth, 1.0).unwrap();
    assert_eq!(doc["truth"], serde_json::to_value(&truth).unwrap());
    assert_eq!(doc["track"], serde_json::to_value(&out).unwrap());
    assert_eq!(doc["score"], serde_json::to_value(&score).unwrap());
    assert_eq!(doc["track"]["method"], "gnn");
    assert_eq!(doc["walkers"], 2);
    assert_eq!(doc["region_m"], json!({"x": region.x, "y": region.y}));
    let targets = doc["track"]["targets"].as_array().unwrap();
    let ellipses = doc["ellipses"].as_array().unwrap();
    assert_eq!(targets.len(), 101);
    assert_eq!(ellipses.len(), 101);
    for (t, e) in targets.iter().zip(ellipses) {
        assert_eq!(t.as_array().unwrap().len(), e.as_array().unwrap().len());
        for (t, e) in t.as_array().unwrap().iter().zip(e.as_array().unwrap()) {
            // Centred at the target's position, its semi-axes those of the covariance's
            // position block (a² + b² = trace).
            assert_eq!(e["cx"], t["state"][0]);
            assert_eq!(e["cy"], t["state"][1]);
            let (a, b) = (e["a"].as_f64().unwrap(), e["b"].as_f64().unwrap());
            let trace =
                t["covariance"][0][0].as_f64().unwrap() + t["covariance"][1][1].as_f64().unwrap();
            assert!((a * a + b * b - trace).abs() <= 1e-12 * trace, "{e} vs {t}");
        }
    }
    let label = doc["gospa_label"].as_str().unwrap();
    assert!(label.contains("mean"), "{label}");

    // The chart draws one point per scan; no document draws the axes only.
    let make = Function::new_no_args(
        "const c = document.createElement('canvas'); c.width = 800; c.height = 500; return c;",
    );
    let canvas = || make.call0(&JsValue::NULL).unwrap().dyn_into().unwrap();
    let text = doc.to_string();
    assert_eq!(
        ok(wasm::draw_people_chart(
            canvas(),
            &text,
            "GOSPA",
            "2 walkers"
        )),
        101
    );
    assert_eq!(ok(wasm::draw_people_chart(canvas(), "", "GOSPA", "")), 0);
    assert!(
        err(wasm::draw_people_chart(canvas(), "{\"track\": 1", "", "")).contains("invalid JSON")
    );
}

/// Bad input is the core's named error: walkers outside 1–5, an unknown method, an unknown
/// field, a bad setting, a birth grid over its cap, a broken scenario.
#[wasm_bindgen_test]
fn track_people_names_bad_input() {
    let s = presets::sensors2019();
    let run = |scenario: &str, r: Value| err(wasm::track_people(scenario, &r.to_string()));
    let json = s.to_json();
    for w in [0, 6] {
        let e = run(&json, json!({"walkers": w, "method": "pmb", "seed": 1}));
        assert!(e.contains("walkers") && e.contains("1..=5"), "{e}");
    }
    let e = run(&json, json!({"walkers": 2, "method": "jpda", "seed": 1}));
    assert!(e.contains("method (pmb, gnn)") && e.contains("jpda"), "{e}");
    let e = run(
        &json,
        json!({"walkers": 2, "method": "pmb", "seed": 1, "speed": 2}),
    );
    assert!(e.starts_with("settings:") && e.contains("speed"), "{e}");
    let e = run(
        &json,
        json!({"walkers": 2, "method": "pmb", "seed": 1, "settings": {"detection_probability": 1.5}}),
    );
    assert!(e.contains("detection"), "{e}");
    let mut big = s.clone();
    big.area_m.x = [-70.0, 70.0];
    big.area_m.y = [-60.0, 60.0];
    let e = run(
        &big.to_json(),
        json!({"walkers": 2, "method": "pmb", "seed": 1}),
    );
    assert!(
        e.contains("birth grid cells") && e.contains("250000"),
        "{e}"
    );
    let e = run("{", json!({"walkers": 2, "method": "pmb", "seed": 1}));
    assert!(!e.is_empty());
}

/// Save figure and Export data of a run (issue 41 §2): the map from `people_map_svg` holds every
/// track's legend entry and the label of every target at the last scan, the GOSPA chart its
/// legend, the CSV every number of the document bit for bit and the JSON its truth, track and
/// score; bad input throws the function's named message.
#[wasm_bindgen_test]
fn people_figures_and_data_come_from_the_document() {
    let scenario = presets::sensors2019().to_json();
    let request = json!({"walkers": 2, "method": "pmb", "seed": 2}).to_string();
    let text = ok(wasm::track_people(&scenario, &request));
    let doc: Value = serde_json::from_str(&text).unwrap();

    let svg = ok(wasm::people_map_svg(
        &scenario, &text, 800, 0, 1000, 2.0, "",
    ));
    let texts = super::svg::svg_texts("people map", &svg);
    let tracks = doc["track"]["tracks"].as_array().unwrap();
    assert!(!tracks.is_empty());
    for t in tracks {
        let legend = format!("track #{}", t["label"]);
        assert_eq!(super::svg::count(&texts, &legend), 1, "{legend}");
    }
    let last = doc["track"]["targets"].as_array().unwrap().last().unwrap();
    for t in last.as_array().unwrap() {
        let label = format!("#{}", t["label"]);
        assert_eq!(super::svg::count(&texts, &label), 1, "{label}");
    }
    let chart = ok(wasm::people_chart_svg(&text, "GOSPA per scan", "", 800, 0));
    let texts = super::svg::svg_texts("GOSPA chart", &chart);
    let legend = doc["gospa_label"].as_str().unwrap();
    assert_eq!(super::svg::count(&texts, legend), 1, "{legend}");

    let csv = ok(wasm::people_data_text(&text, "csv"));
    let bits = |s: &str| s.parse::<f64>().unwrap().to_bits();
    let num = |v: &Value| v.as_f64().unwrap().to_bits();
    let mut rows = 0;
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let k: usize = f[0].parse().unwrap();
        let part = if f[2] == "truth" { "truth" } else { "track" };
        let t = doc[part]["targets"][k]
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["label"].as_u64() == Some(f[3].parse().unwrap()))
            .unwrap();
        assert_eq!(bits(f[1]), num(&doc[part]["t_s"][k]), "{line}");
        for j in 0..4 {
            assert_eq!(bits(f[4 + j]), num(&t["state"][j]), "{line}");
        }
        if part == "track" {
            for c in 0..16 {
                assert_eq!(
                    bits(f[9 + c]),
                    num(&t["covariance"][c / 4][c % 4]),
                    "{line}"
                );
            }
        }
        rows += 1;
    }
    let count = |v: &Value| -> usize {
        v.as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_array().unwrap().len())
            .sum()
    };
    assert_eq!(
        rows,
        count(&doc["truth"]["targets"]) + count(&doc["track"]["targets"])
    );
    let data: Value = serde_json::from_str(&ok(wasm::people_data_text(&text, "json"))).unwrap();
    for key in ["truth", "track", "score"] {
        assert_eq!(data[key], doc[key], "{key}");
    }

    let m = err(wasm::people_data_text(&text, "xml"));
    assert!(
        m.starts_with("people_data_text: invalid JSON: format: \"xml\""),
        "{m}"
    );
    let m = err(wasm::people_data_text("{}", "csv"));
    assert!(m.starts_with("people_data_text: invalid JSON"), "{m}");
    let m = err(wasm::people_map_svg(&scenario, &text, 800, 0, 0, 0.0, ""));
    assert!(m.starts_with("people_map_svg: magnify"), "{m}");
    let m = err(wasm::people_map_svg(&scenario, &text, 50, 0, 0, 1.0, ""));
    assert!(m.starts_with("people_map_svg: width"), "{m}");
    let m = err(wasm::people_map_svg(
        &scenario,
        &text,
        800,
        0,
        0,
        1.0,
        "{\"zoom\": 2}",
    ));
    assert!(m.contains("zoom"), "{m}");
    let m = err(wasm::people_chart_svg("[", "t", "", 800, 0));
    assert!(m.starts_with("people_chart_svg: invalid JSON"), "{m}");
}
