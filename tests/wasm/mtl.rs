//! The multi-target API in the browser: `mtl_view_of` on the default (V-B) scene finds both
//! targets through the noise, the blocking-model switch works, nothing is NaN, and bad input
//! throws the core's named message (never a trap).

use js_sys::JSON;
use serde_json::{json, Value};
use wasm_bindgen::JsValue;
use wasm_bindgen_test::*;

use scatterloc::wasm;

use super::{err, ok};

fn value(v: &JsValue) -> Value {
    serde_json::from_str(&JSON::stringify(v).unwrap().as_string().unwrap()).unwrap()
}

fn default_scene() -> Value {
    serde_json::from_str(&wasm::mtl_default_scene()).unwrap()
}

fn view(scene: &Value) -> Value {
    value(&ok(wasm::mtl_view_of(&scene.to_string())))
}

/// Fields that may be `null` by design (a clutter range has no target, a LoS segment no disc,
/// a short range no ellipse, i.c.b no `exact`, PPP no `p_u`).
const NULLABLE: [&str; 7] = [
    "target",
    "disc",
    "ellipse",
    "exact",
    "p_u",
    "nearest_target",
    "error_m",
];

/// Every number finite and every `null` in a nullable field.
fn assert_no_nan(v: &Value, key: &str) {
    match v {
        Value::Null => assert!(NULLABLE.contains(&key), "null at {key}"),
        Value::Number(n) => assert!(n.as_f64().unwrap().is_finite(), "{key}: {n}"),
        Value::Array(a) => a.iter().for_each(|x| assert_no_nan(x, key)),
        Value::Object(o) => o.iter().for_each(|(k, x)| assert_no_nan(x, k)),
        _ => {}
    }
}

fn nearest(v: &Value, t: &Value) -> f64 {
    let (tx, ty) = (t[0].as_f64().unwrap(), t[1].as_f64().unwrap());
    v["detected"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| (d["x"][0].as_f64().unwrap() - tx).hypot(d["x"][1].as_f64().unwrap() - ty))
        .fold(f64::INFINITY, f64::min)
}

/// The default scene (noise, clutter and misses on): both targets detected within 0.5 m; one
/// TRP entry per Tx–Rx pair; the blocked TX 1 → T1 segment flagged; timing reported.
#[wasm_bindgen_test]
fn default_scene_detects_both_targets() {
    let s = default_scene();
    assert_eq!(s["range_sigma"], 0.1);
    assert_eq!(s["targets"].as_array().unwrap().len(), 2);
    let v = view(&s);
    assert_no_nan(&v, "");
    assert_eq!(v["trps"].as_array().unwrap().len(), 9);
    for t in s["targets"].as_array().unwrap() {
        let d = nearest(&v, t);
        assert!(d < 0.5, "target {t}: nearest detection {d} m");
    }
    assert_eq!(v["metrics"]["detected"], 2);
    assert_eq!(v["model"]["kind"], "ppp");
    let blocked: Vec<&Value> = v["segments"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|g| g["blocked"] == true)
        .collect();
    assert_eq!(blocked.len(), 1);
    assert_eq!(
        (&blocked[0]["node"], &blocked[0]["target"]),
        (&json!("tx"), &json!(0))
    );
    assert!(v["compute_ms"].as_f64().unwrap() >= 0.0);
    // Deterministic: the same scene gives the same view; another seed other ranges.
    let again = view(&s);
    assert_eq!(again["detected"], v["detected"]);
    let mut other = s.clone();
    other["seed"] = json!(9);
    assert_ne!(view(&other)["trps"], v["trps"]);
}

/// i.c.b with `p_u`, i.c.b from `p_d`, `p_LoS` (M7), exact PPP (M11): each runs, no NaN.
#[wasm_bindgen_test]
fn blocking_model_switch() {
    let mut s = default_scene();
    s["t_b"] = json!(20.0);
    s["model"] = json!({"kind": "icb", "p_u": 0.5329});
    let v = view(&s);
    assert_no_nan(&v, "");
    assert_eq!(v["model"]["kind"], "icb");
    assert_eq!(v["model"]["consistency"], false);
    assert_eq!(v["model"]["p_u"], 0.5329);
    s["model"] = json!({"kind": "icb", "p_los": 0.9});
    let v = view(&s);
    let p_u = v["model"]["p_u"].as_f64().unwrap();
    assert!((p_u - (1.0 - 0.9 * 0.81)).abs() < 1e-12, "{p_u}");
    s["model"] = json!({"kind": "ppp", "exact": true});
    s["t_b"] = json!(6.0);
    let v = view(&s);
    assert_no_nan(&v, "");
    assert_eq!(v["model"]["exact"], true);
    assert_eq!(v["metrics"]["detected"], 2);
    // The canonical scene round-trips.
    let text = ok(wasm::mtl_check_scene(&s.to_string()));
    assert_eq!(serde_json::from_str::<Value>(&text).unwrap(), s);
}

/// Bad input throws the core's message naming the field.
#[wasm_bindgen_test]
fn bad_input_throws_named_errors() {
    let m = err(wasm::mtl_view_of("{"));
    assert!(m.starts_with("invalid JSON"), "{m}");
    let s = default_scene();
    let bad = |f: &dyn Fn(&mut Value)| {
        let mut t = s.clone();
        f(&mut t);
        let a = err(wasm::mtl_view_of(&t.to_string()));
        assert_eq!(a, err(wasm::mtl_check_scene(&t.to_string())));
        a
    };
    let m = bad(&|t| t["lamda"] = json!(0.03));
    assert!(m.contains("lamda"), "{m}");
    let m = bad(&|t| t["t_e"] = Value::Null); // what JSON.stringify makes of NaN
    assert!(m.contains("t_e"), "{m}");
    let m = bad(&|t| t["t_b"] = json!(-1.0));
    assert!(m.starts_with("t_b:"), "{m}");
    let m = bad(&|t| t["discs"][0] = json!([1.1, 1.0])); // covers Tx1 at (1, 1)
    assert!(m.starts_with("discs[0]:") && m.contains("D/2"), "{m}");
    let m = bad(&|t| t["targets"][1] = json!([12.0, 5.0]));
    assert!(m.starts_with("targets[1]:") && m.contains("region"), "{m}");
    let m = bad(&|t| t["model"] = json!({"kind": "icb"}));
    assert!(m.contains("p_u, p_los"), "{m}");
    let m = bad(&|t| t["model"] = json!({"kind": "empirical"}));
    assert!(m.contains("model"), "{m}");
    let m = bad(&|t| t["receivers"] = json!([]));
    assert!(m.starts_with("receivers:"), "{m}");
}

/// A session (the worker's cache) gives the one-off views, also after a target moves.
#[wasm_bindgen_test]
fn session_equals_one_off_views() {
    let mut session = wasm::MtlSession::new();
    let mut s = default_scene();
    for step in 0..3 {
        s["targets"][1][0] = json!(7.0 - 0.2 * step as f64);
        let mut a = value(&ok(session.view(&s.to_string())));
        let mut b = view(&s);
        for v in [&mut a, &mut b] {
            v.as_object_mut().unwrap().remove("compute_ms");
        }
        assert_eq!(a, b, "step {step}");
    }
    let m = err(session.view("{\"seed\": 1}"));
    assert!(m.contains("missing field"), "{m}");
}
