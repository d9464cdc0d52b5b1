//! `channel_settings` in the browser: the channel view's settings table the page reads is the
//! core's (its defaults the request's and the filters', its ranges the limits `check` applies).

use wasm_bindgen_test::*;

use scatterloc::error::limits;
use scatterloc::study::{ChannelRequest, DEFAULT_SEED};
use scatterloc::track::{PfConfig, MAX_PARTICLES};
use scatterloc::wasm;

#[wasm_bindgen_test]
fn channel_settings_are_the_cores() {
    let table: serde_json::Value = serde_json::from_str(&wasm::channel_settings()).unwrap();
    let entry = |key: &str| {
        table
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["key"] == key)
            .unwrap_or_else(|| panic!("no {key}"))
            .clone()
    };
    let d = ChannelRequest::default();
    let keys: Vec<&str> = table
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["key"].as_str().unwrap())
        .collect();
    assert_eq!(
        keys,
        [
            "filter",
            "particles",
            "seed",
            "process_noise",
            "pfa",
            "max_paths",
            "extent_sigma_m",
            "statics",
            "delay_reference",
            "background_time_s",
            "cpi_snapshots",
            "range_rate_floor_mps"
        ]
    );
    // Issue 42: the CPI of the front end (off by default) and the floor on the rates' σ.
    let cpi = entry("cpi_snapshots");
    assert_eq!(cpi["kind"], "integer");
    assert_eq!(cpi["default"], serde_json::Value::Null);
    assert_eq!(cpi["max"], scatterloc::measure::MAX_CPI_SNAPSHOTS as f64);
    let floor = entry("range_rate_floor_mps");
    assert_eq!(floor["kind"], "number");
    assert_eq!(floor["default"], d.range_rate_floor_mps);
    let pfa = entry("pfa");
    assert_eq!(pfa["kind"], "number");
    assert_eq!(pfa["default"], d.pfa);
    assert_eq!(pfa["open"], serde_json::json!([true, true]));
    assert_eq!(pfa["allowed"], limits::FALSE_ALARM_PROBABILITY.allowed);
    let paths = entry("max_paths");
    assert_eq!(paths["kind"], "integer");
    assert_eq!(paths["default"], d.max_paths);
    assert_eq!(paths["max"], limits::MAX_PATHS as f64);
    let particles = entry("particles");
    assert_eq!(particles["default"], PfConfig::default().particles);
    assert_eq!(particles["max"], MAX_PARTICLES as f64);
    assert_eq!(particles["filter"], "pf");
    assert_eq!(entry("seed")["default"], DEFAULT_SEED);
    let q = entry("process_noise");
    assert_eq!(q["default"], d.process_noise);
    assert_eq!((&q["min"], &q["open"][0]), (&0.0.into(), &true.into()));
    assert_eq!(q["max"], limits::PROCESS_NOISE.max);
    let extent = entry("extent_sigma_m");
    assert_eq!(extent["default"], d.extent_sigma_m);
    assert_eq!(extent["max"], limits::PERSON_EXTENT_M.max);
    let bg = entry("background_time_s");
    assert_eq!(bg["default"], d.background_time_s);
    assert_eq!(
        (bg["min"].as_f64(), bg["max"].as_f64()),
        (
            Some(limits::BACKGROUND_TIME_S.min),
            Some(limits::BACKGROUND_TIME_S.max)
        )
    );
    assert_eq!(entry("filter")["default"], d.filter.as_str());
    assert_eq!(
        entry("statics")["values"],
        serde_json::json!(["background", "clusters"])
    );
    assert_eq!(entry("delay_reference")["default"], serde_json::Value::Null);
}
