//! The settings table ([`channel_settings`]) against the request's own default and check.

use alloc::string::ToString;

use serde_json::{Map, Value};

use super::{channel_settings, channel_settings_json, ChannelRequest, ChannelSetting, SettingKind};
use crate::error::Error;

/// The request of `{key: v}` (with `filter` set to the setting's own filter, if it has one),
/// parsed and checked as the page's settings are.
fn request(s: &ChannelSetting, v: Value) -> crate::Result<ChannelRequest> {
    let mut obj = Map::new();
    if let Some(f) = s.filter {
        obj.insert("filter".to_string(), Value::from(f));
    }
    // The floor is checked with a CPI on only (`FrontEndCpi::validate`).
    if s.key == "range_rate_floor_mps" {
        obj.insert("cpi_snapshots".to_string(), Value::from(2));
    }
    obj.insert(s.key.to_string(), v);
    ChannelRequest::from_json(&Value::Object(obj).to_string())
}

/// `v` is refused naming the setting (a value the field's type cannot hold — a negative or
/// too large count, a non-finite number, which JSON writes as `null` — is refused by the parser).
fn refused(s: &ChannelSetting, v: Value) {
    let e = request(s, v.clone()).expect_err(&alloc::format!("{} = {v} accepted", s.key));
    let unholdable = (matches!(s.kind, SettingKind::Integer(_)) && !v.is_u64()) || v.is_null();
    match e {
        Error::Parse { .. } if unholdable => {}
        e => assert_eq!(e.field(), Some(s.key), "{} = {v}: {e}", s.key),
    }
}

fn accepted(s: &ChannelSetting, v: Value) {
    if let Err(e) = request(s, v.clone()) {
        panic!("{} = {v} refused: {e}", s.key);
    }
}

/// Every setting's default passes `check()` and is the request's (or its filter's) default; every
/// number's ends are `check()`'s: just outside each end refused naming the setting, just inside
/// accepted; every choice's values accepted. So the table the page reads cannot drift from the
/// check.
#[test]
fn settings_table_is_the_checks() {
    let defaults = serde_json::to_value(ChannelRequest::default()).unwrap();
    let table = channel_settings();
    // Every number and choice field of the request the page sets is in the table (a new setting
    // is listed once, with no count or position to update here).
    for key in [
        "filter",
        "pfa",
        "max_paths",
        "extent_sigma_m",
        "background_time_s",
        "cpi_snapshots",
        "range_rate_floor_mps",
    ] {
        assert!(table.iter().any(|s| s.key == key), "{key} missing");
    }
    for s in &table {
        accepted(s, s.default.clone());
        match s.key {
            "particles" => {
                let r = request(s, Value::Null).unwrap();
                let crate::track::FilterKind::Pf(pf) = r.filter_kind().unwrap() else {
                    panic!("not pf")
                };
                assert_eq!(Value::from(pf.particles), s.default);
            }
            "seed" => assert_eq!(Value::from(ChannelRequest::default().seed()), s.default),
            key => assert_eq!(defaults[key], s.default, "{key}"),
        }
        match &s.kind {
            SettingKind::Number(b) => {
                let (lo_in, lo_out) = if b.open[0] {
                    // An open end at 0: the core takes normal numbers only.
                    let inside = if b.min == 0.0 {
                        f64::MIN_POSITIVE
                    } else {
                        b.min.next_up()
                    };
                    (inside, b.min)
                } else {
                    (b.min, b.min.next_down())
                };
                let (hi_in, hi_out) = if b.open[1] {
                    (b.max.next_down(), b.max)
                } else {
                    (b.max, b.max.next_up())
                };
                for v in [lo_in, hi_in] {
                    accepted(s, Value::from(v));
                }
                for v in [lo_out, hi_out] {
                    refused(s, Value::from(v));
                }
                assert!(!b.allowed.is_empty());
            }
            SettingKind::Integer(b) => {
                let (min, max) = (b.min as u64, b.max as u64);
                assert_eq!((min as f64, max as f64), (b.min, b.max));
                accepted(s, Value::from(min));
                accepted(s, Value::from(max));
                refused(s, Value::from(min as i64 - 1));
                refused(
                    s,
                    max.checked_add(1)
                        .map_or(Value::from(b.max * 2.0), Value::from),
                );
            }
            SettingKind::Choice { values } => {
                for v in values {
                    accepted(s, Value::from(*v));
                }
                assert!(request(s, Value::from("nonsense")).is_err(), "{}", s.key);
            }
        }
    }
    // The JSON the page reads: kind-tagged entries.
    let json: Value = serde_json::from_str(&channel_settings_json()).unwrap();
    let entry = |key: &str| -> Value {
        json.as_array()
            .unwrap()
            .iter()
            .find(|e| e["key"] == key)
            .cloned()
            .unwrap_or_else(|| panic!("{key} not in the JSON"))
    };
    assert_eq!(entry("pfa")["kind"], "number");
    assert_eq!(entry("pfa")["open"], serde_json::json!([true, true]));
    assert_eq!(entry("particles")["filter"], "pf");
    assert_eq!(
        entry("filter")["values"],
        serde_json::json!(["ekf", "ukf", "pf"])
    );
    assert_eq!(entry("delay_reference")["default"], Value::Null);
    assert_eq!(entry("cpi_snapshots")["default"], Value::Null);
    assert_eq!(entry("cpi_snapshots")["kind"], "integer");
    assert_eq!(entry("range_rate_floor_mps")["kind"], "number");
}
