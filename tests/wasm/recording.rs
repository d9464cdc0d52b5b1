//! `read_recording_summary` in the browser: the committed int16 I/Q CIR fixture
//! (scripts/make-recording-fixture.py) is summarised, and a malformed file throws the reader's
//! named message.

use wasm_bindgen_test::*;

use scatterloc::wasm;

use super::{err, get, num, ok};

#[wasm_bindgen_test]
fn recording_summary_of_the_int16_cir_fixture() {
    let bytes = include_bytes!("../data/recording-cir-int16.npz");
    let s = ok(wasm::read_recording_summary(bytes));
    assert_eq!(num(&s, "snapshots"), 3.0);
    assert_eq!(num(&s, "links"), 4.0);
    assert_eq!(get(&s, "layout").as_string().unwrap(), "cir");
    assert_eq!(num(&s, "samples_per_link"), 64.0);
    assert_eq!(num(&s, "duration_s"), 4.096e-3);
    let m = err(wasm::read_recording_summary(b"hello"));
    assert!(m.starts_with("npz: not a zip archive"), "{m}");
    let mut cut = bytes.to_vec();
    cut.truncate(cut.len() / 2);
    let m = err(wasm::read_recording_summary(&cut));
    assert!(m.starts_with("npz:"), "{m}");
}

/// The channel view's bindings (issue 36): `simulate_channel` takes the core's
/// `SimulationRequest`, `ChannelJob` the core's `ChannelRequest` (errors by field, unknown
/// fields refused) and runs without an empty area (the background learnt from the recording),
/// and `ChannelFigures.overlay` shows only the segments of a track.
mod channel {
    use js_sys::{Reflect, Uint8Array};
    use serde_json::{json, Value};
    use wasm_bindgen::JsValue;
    use wasm_bindgen_test::*;

    use scatterloc::present::track_errors;
    use scatterloc::scenario::presets;
    use scatterloc::wasm::{self, ChannelFigures, ChannelJob};

    use super::super::{err, get, num, ok};

    fn scenario() -> String {
        presets::sensors2019().to_json()
    }

    /// A short simulated walk of the hangar scene: (recording, calibration, truth text).
    fn simulated(duration_s: f64) -> (Vec<u8>, Vec<u8>, String) {
        let settings =
            json!({ "duration_s": duration_s, "dt_s": 0.05, "calibration_duration_s": 0.2 });
        let sim = ok(wasm::simulate_channel(&scenario(), &settings.to_string()));
        (sim.recording(), sim.calibration(), sim.truth_json())
    }

    /// Steps `job` to its end; its progress objects' phases, in order, without repeats.
    fn finish(job: &mut ChannelJob) -> Result<Vec<String>, String> {
        let mut phases: Vec<String> = Vec::new();
        for _ in 0..100_000 {
            let p = job.step(20.0).map_err(super::super::message)?;
            let phase = get(&p, "phase").as_string().unwrap();
            if phases.last() != Some(&phase) {
                phases.push(phase);
            }
            if get(&p, "finished").as_bool() == Some(true) {
                return Ok(phases);
            }
        }
        Err("the job did not finish".into())
    }

    #[wasm_bindgen_test]
    fn simulate_takes_the_cores_request_and_names_its_fields() {
        let s = scenario();
        let (rec, cal, truth) = simulated(0.5);
        assert!(rec.len() > 1000 && cal.len() > 1000);
        let t: Value = serde_json::from_str(&truth).unwrap();
        assert_eq!(t["t_s"].as_array().unwrap().len(), 11);
        let m = err(wasm::simulate_channel(&s, r#"{"speed_mps": 0}"#));
        assert!(m.starts_with("speed_mps:"), "{m}");
        let m = err(wasm::simulate_channel(&s, r#"{"walk": [[0, 0]]}"#));
        assert!(m.starts_with("walk:"), "{m}");
        let m = err(wasm::simulate_channel(&s, r#"{"colour": 1}"#));
        assert!(
            m.starts_with("settings: invalid JSON:") && m.contains("colour"),
            "{m}"
        );
        // The page's own size check, before anything is simulated.
        let m = err(wasm::simulate_channel(
            &s,
            r#"{"duration_s": 100000, "dt_s": 0.001}"#,
        ));
        assert!(m.starts_with("duration_s:"), "{m}");
    }

    #[wasm_bindgen_test]
    fn a_recording_is_tracked_without_an_empty_area() {
        let s = scenario();
        let (rec, _, truth) = simulated(1.0);
        let bytes = Uint8Array::from(rec.as_slice());
        let mut job = ok(ChannelJob::new(&s, &bytes, None, Some(truth), ""));
        let sum = ok(job.summary());
        let cal = get(&sum, "calibration");
        assert_eq!(get(&cal, "source").as_string().unwrap(), "none");
        assert_eq!(num(&cal, "snapshots"), 0.0);
        assert_eq!(get(&sum, "statics").as_string().unwrap(), "background");
        assert_eq!(
            get(&sum, "delay_reference").as_string().unwrap(),
            "absolute"
        );
        let phases = finish(&mut job).unwrap();
        // The track and the figure are one unit each (a progress report may skip them).
        assert_eq!(
            phases.first().map(String::as_str),
            Some("estimate"),
            "{phases:?}"
        );
        assert_eq!(
            phases.last().map(String::as_str),
            Some("done"),
            "{phases:?}"
        );
        assert!(!phases.iter().any(|p| p == "calibration"), "{phases:?}");
        let track: Value = serde_json::from_str(&ok(job.track_json())).unwrap();
        assert_eq!(track["t_s"].as_array().unwrap().len(), 21);
        assert!(track["segments"].is_array(), "{}", track["segments"]);
        assert_eq!(track["front_end"]["statics"], "background");
        for l in track["front_end"]["links"].as_array().unwrap() {
            assert_eq!(l["empty_snapshots"], 0, "{l}");
        }
        let est: Value = serde_json::from_str(&ok(job.estimates_json())).unwrap();
        assert_eq!(est["format"], "scatterloc-estimates");
        let timings = ok(job.timings());
        for k in ["parse_ms", "estimate_ms", "track_ms", "figure_ms"] {
            assert!(num(&timings, k) >= 0.0, "{k}");
        }
        assert!(Reflect::get(&timings, &JsValue::from_str("calibration_ms"))
            .unwrap()
            .is_undefined());
    }

    #[wasm_bindgen_test]
    fn job_settings_are_the_cores_request() {
        let s = scenario();
        let (rec, cal, _) = simulated(1.0);
        let rec = Uint8Array::from(rec.as_slice());
        let cal = Uint8Array::from(cal.as_slice());
        let new = |cal: Option<Uint8Array>, settings: &str| {
            ChannelJob::new(&s, &rec, cal, None, settings).map(|_| ())
        };
        let m = err(new(None, r#"{"colour": 1}"#));
        assert!(
            m.starts_with("settings: invalid JSON:") && m.contains("colour"),
            "{m}"
        );
        let m = err(new(None, r#"{"pfa": 2}"#));
        assert!(m.starts_with("p_fa:") || m.starts_with("pfa:"), "{m}");
        let m = err(new(None, r#"{"background_time_s": 0}"#));
        assert!(m.starts_with("background_time_s:"), "{m}");
        let m = err(new(None, r#"{"statics": "walls"}"#));
        assert!(
            m.starts_with("settings: invalid JSON:") && m.contains("statics"),
            "{m}"
        );
        let m = err(new(None, r#"{"seed": 3}"#));
        assert!(m.starts_with("seed:"), "{m}");
        // The page's cap on a particle filter: 21 snapshots × 10⁶ particles > 2·10⁷.
        let m = err(new(None, r#"{"filter": "pf", "particles": 1000000}"#));
        assert!(m.starts_with("particles:"), "{m}");
        let m = err(new(
            Some(cal.clone()),
            r#"{"calibration_range_s": [0, 0.2]}"#,
        ));
        assert!(m.starts_with("calibration_range_s:"), "{m}");
        // Statics "clusters" needs an empty area: the core's error names it when the run is set
        // up (before any work).
        let m = err(ChannelJob::new(
            &s,
            &rec,
            None,
            None,
            r#"{"statics": "clusters"}"#,
        ));
        assert!(m.starts_with("calibration: statics clusters:"), "{m}");
        // … and runs with one, or with a time range of the recording.
        let mut job = ok(ChannelJob::new(
            &s,
            &rec,
            Some(cal),
            None,
            r#"{"statics": "clusters", "delay_reference": "absolute"}"#,
        ));
        finish(&mut job).unwrap();
        let est: Value = serde_json::from_str(&ok(job.estimates_json())).unwrap();
        assert_eq!(est["front_end"]["statics"], "clusters");
        let mut job = ok(ChannelJob::new(
            &s,
            &rec,
            None,
            None,
            r#"{"calibration_range_s": [0, 0.1], "background_time_s": 5}"#,
        ));
        let cal = get(&ok(job.summary()), "calibration");
        assert_eq!(get(&cal, "source").as_string().unwrap(), "range");
        assert_eq!(num(&cal, "snapshots"), 3.0);
        finish(&mut job).unwrap();
        let track: Value = serde_json::from_str(&ok(job.track_json())).unwrap();
        assert_eq!(track["front_end"]["background_time_s"], 5.0);
    }

    /// A track of two segments (snapshots 1–3, lost by innovation; 6–8 to the end) on a
    /// 10-snapshot recording: the overlay draws each segment alone and nothing in the gap.
    #[wasm_bindgen_test]
    fn overlay_shows_only_the_segments() {
        let n = 10;
        let t_s: Vec<f64> = (0..n).map(|k| k as f64 * 0.1).collect();
        let inside = |k: usize| (1..=3).contains(&k) || (6..=9).contains(&k);
        let states: Vec<Option<[f64; 4]>> = (0..n)
            .map(|k| inside(k).then_some([2.0 + k as f64, 4.0, 1.0, 0.0]))
            .collect();
        let cov = json!([[0.01, 0, 0, 0], [0, 0.01, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]);
        let links = 4;
        let used = |k: usize| -> Value {
            if inside(k) {
                json!([2.0e-8, 3.0e-8, null, 4.0e-8])
            } else {
                json!(vec![Value::Null; links])
            }
        };
        let seg = |first: usize, last: usize, end: &str| {
            json!({ "first": first, "last": last, "t_first_s": t_s[first], "t_last_s": t_s[last],
                    "end": end, "confirmed_at": first + 2, "hits": 6, "start": null })
        };
        let track = json!({
            "t_s": t_s,
            "states": states,
            "covariances": (0..n).map(|k| if inside(k) { cov.clone() } else { Value::Null }).collect::<Vec<_>>(),
            "links_used": (0..n).map(|k| if inside(k) { 3 } else { 0 }).collect::<Vec<_>>(),
            "delays_used_s": (0..n).map(used).collect::<Vec<_>>(),
            "sigmas_used_s": (0..n).map(used).collect::<Vec<_>>(),
            "choices": (0..n).map(|_| vec!["single"; links]).collect::<Vec<_>>(),
            "segments": [seg(1, 3, "innovation"), seg(6, 9, "end")],
        });
        let view = track_errors(&t_s, &states, &[]).unwrap();
        let figure = json!({ "t_range_s": [0.0, 0.9], "amplitude_db_range": null, "links": [] });
        let fig = ok(ChannelFigures::new(
            &scenario(),
            &figure.to_string(),
            &serde_json::to_string(&view).unwrap(),
            &track.to_string(),
        ));
        let ov = |k: usize| -> Value {
            let v = ok(fig.overlay(k));
            serde_json::from_str(&String::from(js_sys::JSON::stringify(&v).unwrap())).unwrap()
        };
        let floats = |v: &Value| -> Vec<f64> {
            v.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        };
        let runs = |v: &Value| -> Vec<usize> {
            v["track_m"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| r.as_array().unwrap().len())
                .collect()
        };
        // Before the first segment: nothing.
        let o = ov(0);
        assert_eq!(
            (o["segment"].clone(), o["state"].clone()),
            (Value::Null, Value::Null)
        );
        assert_eq!(runs(&o), Vec::<usize>::new());
        assert!(o["links"].as_array().unwrap().is_empty());
        // Inside the first.
        let o = ov(2);
        assert_eq!(o["segment"], 0);
        assert_eq!(floats(&o["state"]), [4.0, 4.0, 1.0, 0.0]);
        assert_eq!(runs(&o), [2]);
        assert_eq!(o["links"].as_array().unwrap().len(), 3);
        assert!(o["sigma_ellipse"]["a"].as_f64().unwrap() > 0.0);
        // In the gap: the first segment whole, no state, no links, no ellipse.
        let o = ov(4);
        assert_eq!(o["segment"], Value::Null);
        assert_eq!(o["state"], Value::Null);
        assert_eq!(o["sigma_ellipse"], Value::Null);
        assert_eq!(runs(&o), [3]);
        assert!(o["links"].as_array().unwrap().is_empty());
        // The second: two runs, never joined.
        let o = ov(9);
        assert_eq!(o["segment"], 1);
        assert_eq!(runs(&o), [3, 4]);
        assert_eq!(floats(&o["track_m"][1][0]), [8.0, 4.0]);
        // A segment outside the snapshots, or out of order, is refused by name.
        let mut bad = track.clone();
        bad["segments"] = json!([seg(6, 9, "end"), seg(1, 3, "innovation")]);
        let m = err(ChannelFigures::new(
            &scenario(),
            &figure.to_string(),
            &serde_json::to_string(&view).unwrap(),
            &bad.to_string(),
        ));
        assert!(m.starts_with("track.segments[1]:"), "{m}");
    }
}
