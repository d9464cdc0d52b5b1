//! One part file read back: its top level in one pass (each field's JSON text, unknown and
//! repeated keys), then the format and version, and every header field checked on its own
//! (the list is on [`super::PartSet`]); the sums are kept as text for the merge.

use alloc::format;
use alloc::string::{String, ToString};

use serde::de::{MapAccess, Visitor};
use serde::Deserialize;
use serde_json::value::RawValue;
use serde_json::Value;
use sha2::{Digest, Sha256};

use super::digest::walk;
use super::format::{
    ShardDoc, Timing, MAX_PART_CONFIG_BYTES, MAX_TIMING_ENTRIES, PART_FORMAT, PART_VERSION, STUDIES,
};
use super::message::{clip, parse_at, shown_raw};

/// The top-level fields of a part file, in order.
const FIELDS: [&str; 9] = [
    "format", "version", "software", "study", "config", "shard", "timing", "digest", "sums",
];

/// A part file's top level as read in one pass: each field's JSON text (nothing parsed or
/// allocated for the values), and the first unknown or repeated key.
struct RawPart<'a> {
    fields: [Option<&'a RawValue>; 9],
    problem: Option<String>,
}

impl<'de> Deserialize<'de> for RawPart<'de> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> core::result::Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawPart<'de>;
            fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
                f.write_str("a part file (a JSON object)")
            }
            fn visit_map<A: MapAccess<'de>>(
                self,
                mut map: A,
            ) -> core::result::Result<RawPart<'de>, A::Error> {
                let mut part = RawPart {
                    fields: [None; 9],
                    problem: None,
                };
                while let Some(key) = map.next_key::<alloc::borrow::Cow<'de, str>>()? {
                    let value: &'de RawValue = map.next_value()?;
                    match FIELDS.iter().position(|f| *f == key) {
                        Some(i) if part.fields[i].is_none() => part.fields[i] = Some(value),
                        Some(_) => {
                            part.problem
                                .get_or_insert_with(|| format!("duplicate field `{key}`"));
                        }
                        None => {
                            part.problem.get_or_insert_with(|| {
                                format!(
                                    "unknown field `{}`, expected one of {}",
                                    clip(&key.escape_debug().to_string()),
                                    FIELDS.join(", ")
                                )
                            });
                        }
                    }
                }
                Ok(part)
            }
        }
        d.deserialize_map(V)
    }
}

/// A part file's fields, the large ones still text of the file.
struct PartIn<'a> {
    software: String,
    study: String,
    config: &'a RawValue,
    shard: ShardDoc,
    timing: &'a RawValue,
    digest: String,
    sums: &'a RawValue,
}

/// A part's header, checked on its own.
pub(super) struct Header<'a> {
    software: String,
    pub(super) study: String,
    config: Value,
    pub(super) shard: ShardDoc,
    pub(super) timing: Timing,
    pub(super) digest: String,
    pub(super) sums: &'a RawValue,
}

impl Header<'_> {
    /// What makes parts one study: software, study kind and configuration.
    pub(super) fn identity(&self) -> Value {
        serde_json::json!({"software": self.software, "study": self.study, "config": self.config})
    }
}

/// The SHA-256 of a canonical JSON value (object keys sorted).
pub(super) fn key_of(v: &Value) -> [u8; 32] {
    Sha256::digest(v.to_string().as_bytes()).into()
}

/// Why a file is not a part file of this build.
pub(super) enum NotPart {
    /// A part file of another format version.
    Version(String),
    /// Anything else.
    Other(String),
}

/// Reads one part file's text: the format and version first, then the fields, each checked
/// on its own.
pub(super) fn read_part<'a>(text: &'a str) -> core::result::Result<Header<'a>, NotPart> {
    let other = NotPart::Other;
    let raw: RawPart = serde_json::from_str(text).map_err(|e| {
        other(match e.classify() {
            serde_json::error::Category::Data => format!("not a part file: {e}"),
            _ => format!("invalid JSON: {e}"),
        })
    })?;
    let [format, version, software, study, config, shard, timing, digest, sums] = raw.fields;
    if format.map(|f| f.get().trim()) != Some(&format!("\"{PART_FORMAT}\"")[..]) {
        return Err(other(format!(
            "format {}, not \"{PART_FORMAT}\"",
            shown_raw(format)
        )));
    }
    match version.map(|v| serde_json::from_str::<u64>(v.get())) {
        Some(Ok(PART_VERSION)) => {}
        Some(Ok(v)) => return Err(NotPart::Version(v.to_string())),
        _ => {
            return Err(other(format!(
                "version {}, this scatterloc reads version {PART_VERSION}",
                shown_raw(version)
            )))
        }
    }
    if let Some(problem) = raw.problem {
        return Err(other(problem));
    }
    let field = |i: usize, v: Option<&'a RawValue>| {
        v.ok_or_else(|| NotPart::Other(format!("missing field `{}`", FIELDS[i])))
    };
    let (software, study, config) = (field(2, software)?, field(3, study)?, field(4, config)?);
    let (shard, timing, digest, sums) = (
        field(5, shard)?,
        field(6, timing)?,
        field(7, digest)?,
        field(8, sums)?,
    );
    let software: String = parse_at("software", software.get()).map_err(other)?;
    let study: String = parse_at("study", study.get()).map_err(other)?;
    let shard: ShardDoc = parse_at("shard", shard.get()).map_err(other)?;
    let digest: String = parse_at("digest", digest.get()).map_err(other)?;
    let part = PartIn {
        software,
        study,
        config,
        shard,
        timing,
        digest,
        sums,
    };
    let (study, unit) = match STUDIES.iter().find(|(s, _)| *s == part.study) {
        Some(&(s, u)) => (s, u),
        None => {
            return Err(other(format!(
                "study \"{}\" is not montecarlo or mtl-roc",
                clip(&part.study.escape_debug().to_string())
            )))
        }
    };
    if part.shard.unit != unit {
        return Err(other(format!(
            "shard.unit \"{}\" is not \"{unit}\" (study {study})",
            clip(&part.shard.unit.escape_debug().to_string())
        )));
    }
    let config = part.config.get();
    if config.len() > MAX_PART_CONFIG_BYTES {
        return Err(other(format!(
            "config: {} bytes, more than the {} MiB a study's configuration takes",
            config.len(),
            MAX_PART_CONFIG_BYTES >> 20
        )));
    }
    let config: Value = serde_json::from_str(config).map_err(|e| other(format!("config: {e}")))?;
    walk("timing", part.timing.get(), MAX_TIMING_ENTRIES).map_err(other)?;
    let timing: Timing = parse_at("timing", part.timing.get()).map_err(other)?;
    if timing.threads == 0 {
        return Err(other("timing.threads: 0, not a thread count ≥ 1".into()));
    }
    if let Some((i, w)) = timing
        .wall_time_s
        .iter()
        .enumerate()
        .find(|(_, w)| !(w.is_finite() && **w >= 0.0))
    {
        return Err(other(format!(
            "timing.wall_time_s[{i}]: {w} is not a wall time (finite, ≥ 0 s)"
        )));
    }
    let hex = part.digest.strip_prefix("sha256:").unwrap_or("");
    if hex.len() != 64
        || !hex
            .bytes()
            .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
    {
        return Err(other(format!(
            "digest \"{}\" is not sha256: and 64 lowercase hex digits",
            clip(&part.digest.escape_debug().to_string())
        )));
    }
    Ok(Header {
        software: part.software,
        study: part.study,
        config,
        shard: part.shard,
        timing,
        digest: part.digest,
        sums: part.sums,
    })
}
