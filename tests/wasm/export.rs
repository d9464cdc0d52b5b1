//! The page's "Save figure" as SVG (`App.map_svg`, `Track.map_svg`, `tracking_chart_svg`): the
//! text is well-formed XML (parsed with roxmltree), draws every node's label once, the colour
//! bar's tick labels and its label, and the overlays' legend entries; bad input throws a message
//! naming the function and the field.

use wasm_bindgen_test::*;

use scatterloc::localize::{crlb_map, Grid};
use scatterloc::present::{colorbar_ticks, LogScale};
use scatterloc::wasm::{self, App};
use scatterloc::Model;

use super::svg::{count, svg_texts};
use super::{err, ok, sensors};

/// The node names of `app`'s scenario.
fn node_names(app: &App) -> Vec<String> {
    let s = app.scenario_ref();
    let tx = s.transmitters.iter().map(|t| t.name.clone());
    tx.chain(s.receivers.iter().map(|r| r.name.clone()))
        .collect()
}

/// The labels the colour bar of `app`'s map at `res`² over its area can carry.
fn colorbar_labels(app: &App, res: usize) -> Vec<String> {
    let s = app.scenario_ref();
    let model = Model::new(s).unwrap();
    let grid = Grid::new(s.area_m, res, res).unwrap();
    let mut v = vec![0.0; grid.len()];
    crlb_map(&model, &grid, &mut v).unwrap();
    let scale = LogScale::spanning(&v).expect("a bounded map");
    colorbar_ticks(scale.min, scale.max, 100)
        .into_iter()
        .map(|t| t.label)
        .filter(|l| !l.is_empty())
        .collect()
}

/// The map figure: well-formed, one label per node, the colour bar's ticks and label, the
/// scenario's name in the title, the size asked for.
#[wasm_bindgen_test]
fn map_svg_parses_and_has_nodes_and_colour_bar() {
    let app = sensors();
    let svg = ok(app.map_svg(1000, 0, r#"{"res": 64}"#));
    let texts = svg_texts("figure", &svg);
    assert!(svg.contains(r#"width="1000""#), "{}", &svg[..200]);
    let names = node_names(&app);
    assert!(names.len() >= 2);
    for n in &names {
        assert_eq!(count(&texts, n), 1, "node label {n} in {texts:?}");
    }
    let ticks = colorbar_labels(&app, 64);
    let shown = texts.iter().filter(|t| ticks.contains(t)).count();
    assert!(shown >= 2, "colour bar ticks {ticks:?} among {texts:?}");
    assert_eq!(count(&texts, "RMSE bound √(σx² + σy²)"), 1, "{texts:?}");
    assert!(texts.iter().any(|t| t.contains("sensors2019")), "{texts:?}");
    assert!(texts.iter().any(|t| t == "transmitter") && texts.iter().any(|t| t == "receiver"));
    // No overlay without a target.
    assert_eq!(count(&texts, "target"), 0);
}

/// With a target: its marker and the snapshot's legend entries; the default title names the
/// scenario, a given one replaces it; a window narrower than the area keeps only the nodes in it.
#[wasm_bindgen_test]
fn map_svg_draws_the_target_snapshot_and_window() {
    let app = sensors();
    let svg = ok(app.map_svg(
        800,
        600,
        r#"{"res": 32, "title": "A & B <figure>", "target": {"x": 4, "y": 1, "seed": 3}}"#,
    ));
    let texts = svg_texts("figure", &svg);
    for label in ["target", "LM fix ±1σ", "CRLB 1σ", "iso-delay (measured)"] {
        assert_eq!(count(&texts, label), 1, "{label} in {texts:?}");
    }
    assert_eq!(count(&texts, "A & B <figure>"), 1, "{texts:?}");
    // A window around one corner: fewer node labels than the whole area.
    let s = app.scenario_ref();
    let a = s.area_m;
    let (xm, ym) = ((a.x[0] + a.x[1]) / 2.0, (a.y[0] + a.y[1]) / 2.0);
    let inside = node_names(&app)
        .into_iter()
        .zip(
            s.transmitters
                .iter()
                .map(|t| t.position_m)
                .chain(s.receivers.iter().map(|r| r.position_m)),
        )
        .filter(|(_, p)| (a.x[0]..=xm).contains(&p[0]) && (a.y[0]..=ym).contains(&p[1]))
        .map(|(n, _)| n)
        .collect::<Vec<_>>();
    let opts = format!(
        r#"{{"res": 16, "window": [{}, {xm}, {}, {ym}]}}"#,
        a.x[0], a.y[0]
    );
    let texts = svg_texts("figure", &ok(app.map_svg(600, 0, &opts)));
    let shown: Vec<_> = node_names(&app)
        .into_iter()
        .filter(|n| count(&texts, n) == 1)
        .collect();
    assert_eq!(shown, inside);
}

/// A track's map figure: the truth, the filter's track and its magnified ellipses in the legend,
/// every node labelled.
#[wasm_bindgen_test]
fn track_map_svg_draws_the_track() {
    let app = sensors();
    let settings = serde_json::json!({
        "trajectory": { "kind": "II", "x0_m": 0, "y0_m": 0, "vx_mps": 0, "vy_mps": 0 },
        "dt_s": 0.1,
        "steps": 50,
        "seed": 7,
        "filter": "ukf",
        "particles": 1000,
    });
    let track = ok(app.simulate_track(&settings.to_string()));
    let texts = svg_texts(
        "figure",
        &ok(track.map_svg(1000, 0, 30, 100.0, r#"{"res": 32}"#)),
    );
    for label in ["truth", "UKF track", "UKF 1σ ×100", "target"] {
        assert_eq!(count(&texts, label), 1, "{label} in {texts:?}");
    }
    for n in node_names(&app) {
        assert_eq!(count(&texts, &n), 1, "node label {n}");
    }
    let e = err(track.map_svg(1000, 0, 30, 0.0, ""));
    assert!(
        e.starts_with("Track.map_svg: ") && e.contains("magnify"),
        "{e}"
    );
    let e = err(track.map_svg(
        1000,
        0,
        3,
        1.0,
        r#"{"target": {"x": 1, "y": 1, "seed": 1}}"#,
    ));
    assert!(e.starts_with("Track.map_svg: target"), "{e}");
}

/// The Monte Carlo chart as SVG: well-formed, with its title and caption, from a result or
/// empty; malformed JSON throws a named message.
#[wasm_bindgen_test]
fn tracking_chart_svg_parses() {
    let result = r#"{"t_s": [0, 0.1, 0.2], "rmse_pcrlb_m": [0.1, 0.05, 0.04],
        "filters": {"ekf": {"rmse_m": [0.12, 0.06, null], "runs": 10}}}"#;
    let svg = ok(wasm::tracking_chart_svg(
        result,
        "Position RMSE",
        "10 runs",
        "scenario II",
        1000,
        620,
    ));
    let texts = svg_texts("figure", &svg);
    assert_eq!(count(&texts, "Position RMSE"), 1, "{texts:?}");
    assert_eq!(count(&texts, "scenario II"), 1, "{texts:?}");
    // The label with its failed runs, the legend's last row what "failed" means (issue 26).
    assert_eq!(count(&texts, "EKF RMSE (0/10 failed)"), 1, "{texts:?}");
    assert_eq!(
        count(&texts, scatterloc::study::FAILED_NOTE),
        1,
        "{texts:?}"
    );
    svg_texts(
        "figure",
        &ok(wasm::tracking_chart_svg("", "t", "", "", 400, 0)),
    );
    let e = err(wasm::tracking_chart_svg("{", "t", "", "", 1000, 620));
    assert!(e.starts_with("tracking_chart_svg: invalid JSON"), "{e}");
    let e = err(wasm::tracking_chart_svg("", "t", "", "", 100, 620));
    assert!(
        e.starts_with("tracking_chart_svg: ") && e.contains("width"),
        "{e}"
    );
}

/// Bad sizes, grids, windows and options throw `map_svg: …` naming the field; nothing traps.
#[wasm_bindgen_test]
fn map_svg_rejects_bad_input_with_named_messages() {
    let app = sensors();
    for (w, h, opts, field) in [
        (100, 0, "", "width"),
        (9000, 0, "", "width"),
        (1000, 20, "", "height"),
        (1000, 0, r#"{"res": 4}"#, "res"),
        (1000, 0, r#"{"res": 5000}"#, "res"),
        (1000, 0, r#"{"window": [1, 0, 0, 1]}"#, "window.x"),
        (1000, 0, r#"{"window": [0, 1, 0, 1e300]}"#, "window.y"),
        (1000, 0, r#"{"colour": 1}"#, "colour"),
        (1000, 0, "{", "invalid JSON"),
        (
            1000,
            0,
            r#"{"target": {"x": 1e300, "y": 0, "seed": 1}}"#,
            "target.x",
        ),
    ] {
        let e = err(app.map_svg(w, h, opts));
        assert!(
            e.starts_with("map_svg: ") && e.contains(field),
            "{opts} ({w}×{h}): {e}"
        );
    }
}

/// The multi-target scene figure (`mtl_scene_svg`, the page's multi-target view): well-formed,
/// the six nodes' labels once each, the legend of every layer the V-B scene has, the detection
/// result in the subtitle equal to the core's view of the same scene, the size asked for; a
/// window leaves out what lies outside it; bad input names the function and the field.
#[wasm_bindgen_test]
fn mtl_scene_svg_draws_the_scene_and_its_detections() {
    use scatterloc::present::{mtl_view, MtlScene};
    let scene = MtlScene::vb();
    let json = scene.to_json();
    let view = mtl_view(&scene).unwrap();
    let svg = ok(wasm::mtl_scene_svg(&json, 900, 0, ""));
    assert!(svg.contains(r#"width="900""#), "{}", &svg[..200]);
    let texts = svg_texts("figure", &svg);
    for name in ["Tx1", "Tx2", "Tx3", "Rx1", "Rx2", "Rx3"] {
        assert_eq!(count(&texts, name), 1, "{name} in {texts:?}");
    }
    for label in ["region R", "blocked LoS", "clutter", "target", "detected"] {
        assert_eq!(count(&texts, label), 1, "legend {label} in {texts:?}");
    }
    let m = &view.metrics;
    let result = format!(
        "K̂/K = {}/{} · N_D = {} · N_FA = {}",
        m.estimates, m.targets, m.detected, m.false_alarms
    );
    assert!(
        texts.iter().any(|t| t.starts_with(&result)),
        "{result} in {texts:?}"
    );

    // A window holding no node: no node label.
    let svg = ok(wasm::mtl_scene_svg(
        &json,
        600,
        600,
        r#"{"window": [4.0, 6.0, 4.0, 6.0], "title": "middle"}"#,
    ));
    let texts = svg_texts("figure", &svg);
    assert_eq!(count(&texts, "middle"), 1);
    assert!(
        texts
            .iter()
            .all(|t| !t.starts_with("Tx") && !t.starts_with("Rx")),
        "{texts:?}"
    );

    let mut bad = scene.clone();
    bad.diameter = -1.0;
    for (m, field) in [
        (err(wasm::mtl_scene_svg("{", 900, 0, "")), "invalid JSON"),
        (err(wasm::mtl_scene_svg(&json, 100, 0, "")), "width"),
        (
            err(wasm::mtl_scene_svg(
                &json,
                900,
                0,
                r#"{"window": [1, 1, 0, 1]}"#,
            )),
            "window.x",
        ),
        (
            err(wasm::mtl_scene_svg(&json, 900, 0, r#"{"zoom": 2}"#)),
            "zoom",
        ),
        (
            err(wasm::mtl_scene_svg(&bad.to_json(), 900, 0, "")),
            "diameter",
        ),
    ] {
        assert!(m.starts_with("mtl_scene_svg: "), "{m}");
        assert!(m.contains(field), "message {m:?} should name {field}");
    }
}
