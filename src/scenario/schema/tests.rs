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

/// Issue 24: names are capped at `limits::MAX_NAME_BYTES` (256) bytes in validation, the
/// scenario's, each node's and those a link list refers to, each error naming its field; 256
/// bytes pass. (A 100 MB name made figures take minutes.)
#[test]
fn names_longer_than_the_cap_are_named_errors() {
    use crate::error::limits::MAX_NAME_BYTES;
    use crate::scenario::presets;
    use crate::scenario::LinkSpec;
    assert_eq!(MAX_NAME_BYTES, 256);
    let long = "é".repeat(129); // 258 bytes, 129 characters: the cap counts bytes.
    let check = |s: &Scenario, field: &str| {
        let e = s.validate().unwrap_err();
        assert_eq!(
            e,
            Error::NameTooLong {
                field: field.into(),
                bytes: 258,
                max: 256
            }
        );
        assert_eq!(e.field(), Some(field));
        assert_eq!(
            e.to_string(),
            format!("{field}: 258 bytes long, at most 256 are allowed")
        );
    };
    let mut s = presets::sensors2019();
    s.name = long.clone();
    check(&s, "name");
    let mut s = presets::sensors2019();
    s.transmitters[0].name = long.clone();
    check(&s, "transmitters[0].name");
    let mut s = presets::sensors2019();
    s.receivers[3].name = long.clone();
    check(&s, "receivers[3].name");
    let mut s = presets::sensors2019();
    let rx = s.receivers[0].name.clone();
    s.links = LinkSpec::List(vec![[long.clone(), rx]]);
    check(&s, "links[0][0]");
    let mut s = presets::sensors2019();
    s.receivers[3].name = "R".repeat(256);
    assert!(s.validate().is_ok());
}
