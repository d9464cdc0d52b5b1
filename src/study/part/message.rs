//! The words of the part checks' errors: values and keys clipped for a message, serde paths
//! under `sums`/`timing`, lists of files and shard ranges, the first difference between two
//! configurations, and the two errors ([`inconsistent`] for one part, `set_error` for a set).

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use serde_json::value::RawValue;
use serde_json::Value;

use crate::error::Error;

/// Raw JSON text for a message: at most 60 characters.
pub(super) fn shown_raw(v: Option<&RawValue>) -> String {
    match v {
        Some(v) => clip(v.get().trim()),
        None => "absent".to_string(),
    }
}

/// At most 60 characters of `text`, then `…`.
pub(super) fn clip(text: &str) -> String {
    match text.char_indices().nth(60) {
        Some((i, _)) => format!("{}…", &text[..i]),
        None => text.to_string(),
    }
}

/// `sums` or `timing` followed by a serde path (`[0].runs`, `.threads`) and the message.
pub(super) fn at_path(what: &str, path: &str, inner: impl core::fmt::Display) -> String {
    match path {
        "" | "." => format!("{what}: {inner}"),
        p if p.starts_with('[') => format!("{what}{p}: {inner}"),
        p => format!("{what}.{p}: {inner}"),
    }
}

/// `raw` as `T`, errors naming the field under `what` (`sums[0].runs: invalid value: …`).
pub(super) fn parse_at<T: serde::de::DeserializeOwned>(
    what: &str,
    raw: &str,
) -> core::result::Result<T, String> {
    let mut de = serde_json::Deserializer::from_str(raw);
    serde_path_to_error::deserialize(&mut de)
        .map_err(|e| at_path(what, &e.path().to_string(), e.into_inner()))
}

/// A part that does not fit its set: `merge: inconsistent part PATH: what`.
pub fn inconsistent(path: &str, what: impl core::fmt::Display) -> Error {
    Error::InconsistentPart {
        path: path.to_string(),
        what: what.to_string(),
    }
}

/// A set of files that is not one study's complete set of parts.
pub(super) fn set_error(what: String) -> Error {
    Error::PartSet { what }
}

/// At most 10 items joined with `; `, then how many more.
pub(super) fn listed(items: &[String]) -> String {
    const SHOWN: usize = 10;
    let mut text = items
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join("; ");
    if items.len() > SHOWN {
        text.push_str(&format!("; … and {} more", items.len() - SHOWN));
    }
    text
}

/// `0, 2-5, 9` for sorted indices.
pub(super) fn ranges(indices: &[usize]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < indices.len() {
        let start = indices[i];
        while i + 1 < indices.len() && indices[i + 1] == indices[i] + 1 {
            i += 1;
        }
        out.push(match indices[i] {
            end if end == start => start.to_string(),
            end => format!("{start}-{end}"),
        });
        i += 1;
    }
    let shown: Vec<String> = out.iter().take(20).cloned().collect();
    match out.len().saturating_sub(20) {
        0 => shown.join(", "),
        n => format!("{}, … and {n} more ranges", shown.join(", ")),
    }
}

/// A JSON value for a message: compact, at most 60 characters.
fn shown(v: Option<&Value>) -> String {
    match v {
        Some(v) => clip(&v.to_string()),
        None => "absent".to_string(),
    }
}

/// The first place (a dotted path) where `got` differs from `want`, with both values (`None`:
/// equal).
pub fn differs(want: &Value, got: &Value) -> Option<String> {
    first_difference(want, got, "")
}

/// [`differs`] below `path`.
pub(super) fn first_difference(want: &Value, got: &Value, path: &str) -> Option<String> {
    // Keys and paths shown at most 60 characters (a part's keys are the user's text).
    let at = |key: &str| match path {
        "" => clip(key),
        p => clip(&format!("{p}.{}", clip(key))),
    };
    match (want, got) {
        (Value::Object(a), Value::Object(b)) => {
            let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
            keys.sort();
            keys.dedup();
            keys.into_iter().find_map(|k| match (a.get(k), b.get(k)) {
                (Some(x), Some(y)) => first_difference(x, y, &at(k)),
                (x, y) if x != y => Some(format!("{}: {}, not {}", at(k), shown(y), shown(x))),
                _ => None,
            })
        }
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => a
            .iter()
            .zip(b)
            .enumerate()
            .find_map(|(i, (x, y))| first_difference(x, y, &format!("{path}[{i}]"))),
        _ if want == got => None,
        _ => Some(format!(
            "{}: {}, not {}",
            clip(path),
            shown(Some(got)),
            shown(Some(want))
        )),
    }
}
