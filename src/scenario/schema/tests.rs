//! Unit tests of [`crate::scenario`]: JSON errors name the offending field's path.

use super::*;

fn with_radio(radio: &str) -> String {
    format!(
        r#"{{"name":"x","radio":{radio},"transmitters":[{{"name":"Tx","position_m":[0,0],"power_dbm":30,"gain_dbi":0}}],
            "receivers":[{{"name":"Rx","position_m":[1,0],"gain_dbi":0}}],"target":{{"rcs_m2":1}},"area_m":{{"x":[0,1],"y":[0,1]}}}}"#
    )
}

/// A value of the wrong type is reported with the path of its field.
#[test]
fn wrong_type_names_the_field_path() {
    let e = Scenario::from_json(&with_radio(
        r#"{"carrier_hz":5.2e9,"bandwidth_hz":"120e6"}"#,
    ))
    .unwrap_err();
    assert!(matches!(e, Error::Parse { .. }));
    assert!(e.to_string().contains("radio.bandwidth_hz"), "{e}");
}

/// A typo inside a nested object names that object and the unknown field.
#[test]
fn nested_unknown_field_is_named() {
    let e =
        Scenario::from_json(&with_radio(r#"{"carrier_hz":5.2e9,"bandwith_hz":1e8}"#)).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("radio") && text.contains("bandwith_hz"),
        "{text}"
    );
}

/// Trailing garbage after the object is an error, not silently ignored.
#[test]
fn trailing_characters_are_rejected() {
    let good = with_radio(r#"{"carrier_hz":5.2e9,"bandwidth_hz":1e8}"#);
    assert!(Scenario::from_json(&good).is_ok());
    assert!(matches!(
        Scenario::from_json(&(good + " x")),
        Err(Error::Parse { .. })
    ));
}
