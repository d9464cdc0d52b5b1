//! The part file of a sharded study (issue 13 §4, issue 24) and the checks that make a set of
//! them one study: a sharded run writes its configuration, seed, shard, timing and sufficient
//! statistics ([`crate::track::StudySums`], [`crate::mtl::experiment::Tally`]) instead of its
//! result, with a digest of those sums; [`PartSet::read`] reads the parts back as one set
//! before anything is merged — every one a part file of this format version, all of one study
//! (same software version, study kind and configuration, seed included), every shard of one
//! count present exactly once, each consistent with its index — and the study's `merge`
//! ([`crate::study::MonteCarloStudy::merge`], [`crate::study::RocStudy::merge`]) reads each
//! part's sums again, one file at a time, and checks them against their digest and against
//! the study before adding them. Each problem is one named error that names the file and the
//! field ([`Error::PartSet`] for the set, [`Error::InconsistentPart`] for one part).
//!
//! Part file (JSON, format `scatterloc-part`, version 2):
//! `{"format": "scatterloc-part", "version": 2, "software": "scatterloc 0.1.0", "study":
//! "montecarlo" | "mtl-roc", "config": {…}, "shard": {"index": I, "count": N, "unit": "chunks" |
//! "realisations", "range": [a, b], "total": C}, "timing": {"threads": T, "wall_time_s": [..]},
//! "digest": "sha256:…", "sums": …}`. The shard covers the units `[a, b)` = [`Shard::range`] of
//! `C`. `digest` is the SHA-256 of the sums' JSON as a canonical token stream
//! ([`sums_digest`]): the same sums give the same digest, so it does not depend on the thread
//! count, and a part reformatted (e.g. by `jq -S .`) keeps it. Version 1 (without a digest) is
//! refused with a named error.
//!
//! # What is checked (issue 24)
//!
//! Every part, when the set is read:
//! - `format` is `scatterloc-part` and `version` is [`PART_VERSION`] (a set all of one other
//!   version gets one error naming that version); the fields are exactly those above;
//! - `study` is `montecarlo` or `mtl-roc`, `shard.unit` its unit; `shard` is the shard
//!   `index` of `count` of `total` units ([`Shard::range`]), `total` the same in every part;
//! - `config` at most [`MAX_PART_CONFIG_BYTES`] of JSON, `timing` at most
//!   [`MAX_TIMING_ENTRIES`] entries; `timing.threads` ≥ 1; every `timing.wall_time_s[i]`
//!   finite and ≥ 0; `digest` is `sha256:` and 64 lowercase hex digits.
//!
//! The set: one study (software, study, config), one shard count, every shard exactly once.
//!
//! Every part's sums, when merged (the study rebuilt from `config` gives the bounds):
//! - no array longer than the study implies (checked while parsing, before anything is
//!   allocated for it: [`Part::read_sums`]); the digest matches the sums (corruption,
//!   truncation, an edit); the types exact (counts are whole numbers ≥ 0);
//! - the digest matches the sums (corruption, truncation, an edit);
//! - Monte Carlo, per entry `sums[k·F + f]` (trajectory `k`, filter `f` of `F`): `steps + 1`
//!   entries per list; `trajectories` = the trajectories of the shard's chunks; `runs +
//!   failed_runs` = trajectories × noise runs; every `squared_error[n]` and `nees[n]` finite
//!   and ≥ 0, zero when no run counted and non-zero when one did; `fisher[n]` finite,
//!   symmetric (`F₂₁ = F₁₂` exactly: every addend is), with a diagonal ≥ 0 and positive
//!   semi-definite (`F₁₂² ≤ F₁₁ F₂₂`, relative 10⁻⁹ for rounding), `fisher[0]` zero, all zero
//!   when no trajectory counted and not all zero when one did; the Fisher sums and trajectory
//!   count are the same for every filter of a trajectory (they come from the truth alone);
//! - ROC ([`crate::mtl::experiment::Tally::check`]): `realisations` = the shard's; `curves ×
//!   points` as the experiment's; per point `detections ≤ targets`, `false_alarms ≤
//!   estimates`, the ratio sums finite, in `[0, realisations]`, zero when their count is;
//!   `disagreements ≤ realisations × curves × points`.
//!
//! Memory: [`PartSet::read`] and the merges hold one part file's text at a time (the CLI
//! caps each at 256 MiB, [`crate::error::limits::MAX_INPUT_BYTES`]), the reference
//! configuration, and per part a few hundred bytes; the sums of one part are at most what
//! its configuration implies (the merged sums' size).
//!
//! ```
//! use scatterloc::math::Shard;
//! use scatterloc::study::{PartFile, PartSet, ShardDoc, Timing};
//!
//! // Two shards of a study of 5 units, written as a sharded run writes them …
//! let texts: Vec<(String, String)> = (0..2)
//!     .map(|i| {
//!         let shard = ShardDoc::new(Shard::new(i, 2).unwrap(), "chunks", 5);
//!         let timing = Timing { threads: 1, wall_time_s: vec![0.5] };
//!         let (config, sums) = (serde_json::json!({"seed": 1}), [i]);
//!         let part = PartFile::new("montecarlo", &config, &shard, &timing, &sums);
//!         (format!("part{i}.json"), serde_json::to_string(&part).unwrap())
//!     })
//!     .collect();
//! // … read back as one set, in shard order …
//! let set = PartSet::check(&texts).unwrap();
//! assert_eq!(set.study, "montecarlo");
//! assert_eq!(set.parts[1].shard.range, [2, 5]);
//! // … and the sums of one part, checked against its digest (arrays of at most 8 entries).
//! let sums: Vec<usize> = set.parts[1].read_sums(&texts[1].1, 8).unwrap();
//! assert_eq!(sums, [1]);
//! // A set with a shard missing is refused, naming it.
//! let err = PartSet::check(&texts[..1]).unwrap_err();
//! assert!(err.to_string().contains("missing parts: shard 1 of 2"));
//! // An edited sum no longer matches its digest.
//! let edited = texts[1].1.replace("\"sums\":[1]", "\"sums\":[2]");
//! let err = set.parts[1].read_sums::<Vec<usize>>(&edited, 8).unwrap_err();
//! assert!(err.to_string().contains("part1.json: sums do not match their digest"));
//! ```

use alloc::collections::BTreeMap;
use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use serde::de::{DeserializeSeed, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;
use serde_json::Value;
use sha2::{Digest, Sha256};

use crate::error::{Error, Result};
use crate::math::Shard;

/// The `format` of a part file.
pub const PART_FORMAT: &str = "scatterloc-part";
/// The `version` of the part format this build reads and writes (2: with `digest`, issue 24).
pub const PART_VERSION: u64 = 2;
/// Largest `config` of a part file, bytes of JSON: 4 MiB. The largest legitimate one, a
/// scenario of 4096 + 4096 nodes ([`crate::error::limits::MAX_NODES`]) with its links, is
/// below 2 MiB; the configuration is parsed into a JSON tree (up to ~16× its text).
pub const MAX_PART_CONFIG_BYTES: usize = 4 << 20;
/// Most entries of a part's `timing.wall_time_s` (one per trajectory: at most 3).
pub const MAX_TIMING_ENTRIES: usize = 16;

/// Study kinds and the unit their shards split.
const STUDIES: [(&str, &str); 2] = [("montecarlo", "chunks"), ("mtl-roc", "realisations")];

/// The `software` of a part file: parts of one study must come from the same build version.
pub fn software() -> String {
    format!("scatterloc {}", env!("CARGO_PKG_VERSION"))
}

/// The `digest` of a part file with sums `sums`: `sha256:` and the hex SHA-256 of their JSON
/// as a canonical token stream (structure, strings, numbers by type and bits; not the layout
/// or the key order, so a reformatted part keeps its digest). Errors are serde_json's (sums
/// that do not serialize).
pub fn sums_digest<S: Serialize + ?Sized>(sums: &S) -> core::result::Result<String, String> {
    let text = serde_json::to_string(sums).map_err(|e| format!("encoding the sums: {e}"))?;
    walk("sums", &text, usize::MAX).map(|d| hex(&d))
}

/// Where a shard lies in its study.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardDoc {
    /// `I`, 0-based.
    pub index: usize,
    /// `N`.
    pub count: usize,
    /// What the study is split into: `chunks` (Monte Carlo) or `realisations` (ROC).
    pub unit: String,
    /// The units `[a, b)` of this shard.
    pub range: [usize; 2],
    /// The study's units `C`.
    pub total: usize,
}

impl ShardDoc {
    /// Shard `shard` of a study of `total` `unit`s.
    pub fn new(shard: Shard, unit: &str, total: usize) -> ShardDoc {
        let r = shard.range(total);
        ShardDoc {
            index: shard.index(),
            count: shard.count(),
            unit: unit.to_string(),
            range: [r.start, r.end],
            total,
        }
    }
}

/// Run time of a part (or of the merged study).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Timing {
    /// Worker threads used.
    pub threads: usize,
    /// Wall time, s, one per entry of `sums` (Monte Carlo: per trajectory).
    pub wall_time_s: Vec<f64>,
}

/// A part file as written (serialize it, e.g. with `serde_json::to_string`; serializing
/// computes its `digest`, [`sums_digest`]).
#[derive(Debug)]
pub struct PartFile<'a, C: Serialize, S: Serialize + ?Sized> {
    study: &'a str,
    config: &'a C,
    shard: &'a ShardDoc,
    timing: &'a Timing,
    sums: &'a S,
}

impl<'a, C: Serialize, S: Serialize + ?Sized> PartFile<'a, C, S> {
    /// The part of shard `shard` of study kind `study` (`montecarlo` or `mtl-roc`) with its
    /// configuration, timing and sums, of this format version and software.
    pub fn new(
        study: &'a str,
        config: &'a C,
        shard: &'a ShardDoc,
        timing: &'a Timing,
        sums: &'a S,
    ) -> PartFile<'a, C, S> {
        PartFile {
            study,
            config,
            shard,
            timing,
            sums,
        }
    }

    /// The study kind.
    pub fn study(&self) -> &str {
        self.study
    }

    /// The shard.
    pub fn shard(&self) -> &ShardDoc {
        self.shard
    }

    /// The timing.
    pub fn timing(&self) -> &Timing {
        self.timing
    }
}

impl<C: Serialize, S: Serialize + ?Sized> Serialize for PartFile<'_, C, S> {
    fn serialize<Z: serde::Serializer>(&self, z: Z) -> core::result::Result<Z::Ok, Z::Error> {
        #[derive(Serialize)]
        struct Out<'b, C: Serialize, S: Serialize + ?Sized> {
            format: &'static str,
            version: u64,
            software: String,
            study: &'b str,
            config: &'b C,
            shard: &'b ShardDoc,
            timing: &'b Timing,
            digest: String,
            sums: &'b S,
        }
        let digest = sums_digest(self.sums).map_err(serde::ser::Error::custom)?;
        Out {
            format: PART_FORMAT,
            version: PART_VERSION,
            software: software(),
            study: self.study,
            config: self.config,
            shard: self.shard,
            timing: self.timing,
            digest,
            sums: self.sums,
        }
        .serialize(z)
    }
}

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
struct Header<'a> {
    software: String,
    study: String,
    config: Value,
    shard: ShardDoc,
    timing: Timing,
    digest: String,
    sums: &'a RawValue,
}

impl Header<'_> {
    /// What makes parts one study: software, study kind and configuration.
    fn identity(&self) -> Value {
        serde_json::json!({"software": self.software, "study": self.study, "config": self.config})
    }
}

/// The SHA-256 of a canonical JSON value (object keys sorted).
fn key_of(v: &Value) -> [u8; 32] {
    Sha256::digest(v.to_string().as_bytes()).into()
}

/// One checked part of a [`PartSet`]: its header (the sums are read again when merged,
/// [`Part::read_sums`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// The name the part was given under (its path).
    pub path: String,
    /// Which shard.
    pub shard: ShardDoc,
    /// Its run time.
    pub timing: Timing,
    /// Its `digest`.
    pub digest: String,
    /// SHA-256 of its identity (software, study, configuration).
    identity: [u8; 32],
}

/// The parts of one study, checked as a set, in shard order.
#[derive(Debug, Clone, PartialEq)]
pub struct PartSet {
    /// The study kind: `montecarlo` or `mtl-roc`.
    pub study: String,
    /// The study's configuration (the same in every part).
    pub config: Value,
    /// The parts, one per shard, in shard order.
    pub parts: Vec<Part>,
}

/// Why a file is not a part file of this build.
enum NotPart {
    /// A part file of another format version.
    Version(String),
    /// Anything else.
    Other(String),
}

/// Raw JSON text for a message: at most 60 characters.
fn shown_raw(v: Option<&RawValue>) -> String {
    match v {
        Some(v) => clip(v.get().trim()),
        None => "absent".to_string(),
    }
}

/// At most 60 characters of `text`, then `…`.
fn clip(text: &str) -> String {
    match text.char_indices().nth(60) {
        Some((i, _)) => format!("{}…", &text[..i]),
        None => text.to_string(),
    }
}

/// Walks the JSON text `raw` once without allocating for its values: checks that no array
/// (nested at any depth) has more than `max` entries, and returns the SHA-256 of its values
/// as a canonical token stream (the value's structure, strings, numbers by type and bits;
/// an object's entries in any order — whitespace, layout and key order do not count; an
/// object of more than `max` keys is refused too). The error
/// names the path under `what` (`sums[0].squared_error: more than 11 entries …`).
fn walk(what: &str, raw: &str, max: usize) -> core::result::Result<[u8; 32], String> {
    struct Shape<'h> {
        max: usize,
        h: &'h mut Sha256,
    }
    impl<'de> DeserializeSeed<'de> for Shape<'_> {
        type Value = ();
        fn deserialize<D: serde::Deserializer<'de>>(
            self,
            d: D,
        ) -> core::result::Result<(), D::Error> {
            d.deserialize_any(self)
        }
    }
    impl<'de> Visitor<'de> for Shape<'_> {
        type Value = ();
        fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
            f.write_str("any JSON value")
        }
        fn visit_bool<E>(self, v: bool) -> core::result::Result<(), E> {
            self.h.update([b'b', v as u8]);
            Ok(())
        }
        fn visit_i64<E>(self, v: i64) -> core::result::Result<(), E> {
            self.h.update([b'i']);
            self.h.update(v.to_le_bytes());
            Ok(())
        }
        fn visit_u64<E>(self, v: u64) -> core::result::Result<(), E> {
            self.h.update([b'u']);
            self.h.update(v.to_le_bytes());
            Ok(())
        }
        fn visit_f64<E>(self, v: f64) -> core::result::Result<(), E> {
            self.h.update([b'f']);
            self.h.update(v.to_bits().to_le_bytes());
            Ok(())
        }
        fn visit_str<E>(self, v: &str) -> core::result::Result<(), E> {
            self.h.update([b's']);
            self.h.update((v.len() as u64).to_le_bytes());
            self.h.update(v.as_bytes());
            Ok(())
        }
        fn visit_unit<E>(self) -> core::result::Result<(), E> {
            self.h.update([b'n']);
            Ok(())
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> core::result::Result<(), A::Error> {
            let Shape { max, h } = self;
            h.update([b'[']);
            let mut n = 0usize;
            while seq.next_element_seed(Shape { max, h: &mut *h })?.is_some() {
                n += 1;
                if n > max {
                    return Err(serde::de::Error::custom(format!(
                        "more than {max} entries (the most the study's configuration implies)"
                    )));
                }
            }
            h.update([b']']);
            Ok(())
        }
        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> core::result::Result<(), A::Error> {
            // Each entry hashed on its own, the entries' hashes sorted: key order does not
            // count (a tool that sorts keys keeps the digest).
            let Shape { max, h } = self;
            let mut entries: Vec<[u8; 32]> = Vec::new();
            loop {
                let mut e = Sha256::new();
                if map.next_key_seed(Shape { max, h: &mut e })?.is_none() {
                    break;
                }
                map.next_value_seed(Shape { max, h: &mut e })?;
                entries.push(e.finalize().into());
                if entries.len() > max {
                    return Err(serde::de::Error::custom(format!(
                        "more than {max} keys (the most the study's configuration implies)"
                    )));
                }
            }
            entries.sort_unstable();
            h.update([b'{']);
            for e in &entries {
                h.update(e);
            }
            h.update([b'}']);
            Ok(())
        }
    }
    let mut h = Sha256::new();
    let mut de = serde_json::Deserializer::from_str(raw);
    let mut track = serde_path_to_error::Track::new();
    Shape { max, h: &mut h }
        .deserialize(serde_path_to_error::Deserializer::new(&mut de, &mut track))
        .map_err(|e| at_path(what, &track.path().to_string(), e))?;
    Ok(h.finalize().into())
}

/// `sha256:` and 64 hex digits.
fn hex(d: &[u8; 32]) -> String {
    let mut s = String::from("sha256:");
    for b in d {
        s.push_str(&format!("{b:02x}"));
    }
    s
}

/// Reads one part file's text: the format and version first, then the fields, each checked
/// on its own.
fn read_part<'a>(text: &'a str) -> core::result::Result<Header<'a>, NotPart> {
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

impl Part {
    /// The sums of this part as `T`, from `text`, the part file read again: the header must be
    /// the one checked ([`PartSet::read`]), no array of the sums longer than `max_len` (checked
    /// in a first pass that allocates nothing for the sums, which also computes their digest),
    /// the digest the part's, and the sums must parse as `T` (errors name the field). Each problem is [`Error::InconsistentPart`].
    pub fn read_sums<T: serde::de::DeserializeOwned + Serialize>(
        &self,
        text: &str,
        max_len: usize,
    ) -> Result<T> {
        let header = read_part(text).map_err(|e| match e {
            NotPart::Version(v) => inconsistent(&self.path, format!("version {v}")),
            NotPart::Other(why) => inconsistent(&self.path, why),
        })?;
        if header.shard != self.shard
            || header.timing != self.timing
            || header.digest != self.digest
            || key_of(&header.identity()) != self.identity
        {
            return Err(inconsistent(
                &self.path,
                "the file changed while it was merged (read again for its sums)",
            ));
        }
        let raw = header.sums.get();
        let digest = walk("sums", raw, max_len).map_err(|e| inconsistent(&self.path, e))?;
        let digest = hex(&digest);
        if digest != self.digest {
            return Err(inconsistent(
                &self.path,
                format!(
                    "sums do not match their digest (the file was corrupted, truncated or \
                     edited after it was written): digest {}, the sums hash to {}",
                    clip(&self.digest),
                    clip(&digest)
                ),
            ));
        }
        let sums: T = parse_at("sums", raw).map_err(|e| inconsistent(&self.path, e))?;
        Ok(sums)
    }
}

/// Reads `part`'s text for the merge: `load` (errors as they are), then [`Part::read_sums`].
pub fn load_sums<T: serde::de::DeserializeOwned + Serialize>(
    part: &Part,
    max_len: usize,
    load: &mut dyn FnMut(&str) -> Result<String>,
) -> Result<T> {
    let text = load(&part.path)?;
    part.read_sums(&text, max_len)
}

/// Distinct studies whose configuration [`PartSet::read`] keeps to name the difference.
const KEPT: usize = 10;

/// `sums` or `timing` followed by a serde path (`[0].runs`, `.threads`) and the message.
fn at_path(what: &str, path: &str, inner: impl core::fmt::Display) -> String {
    match path {
        "" | "." => format!("{what}: {inner}"),
        p if p.starts_with('[') => format!("{what}{p}: {inner}"),
        p => format!("{what}.{p}: {inner}"),
    }
}

/// `raw` as `T`, errors naming the field under `what` (`sums[0].runs: invalid value: …`).
fn parse_at<T: serde::de::DeserializeOwned>(
    what: &str,
    raw: &str,
) -> core::result::Result<T, String> {
    let mut de = serde_json::Deserializer::from_str(raw);
    serde_path_to_error::deserialize(&mut de)
        .map_err(|e| at_path(what, &e.path().to_string(), e.into_inner()))
}

impl PartSet {
    /// Reads and checks the part files `paths` as one set, one file at a time through `load`
    /// (the file's text; its errors are returned as they are): the study kind, its
    /// configuration and the parts' headers in shard order (the sums are read again by the
    /// study's merge, [`Part::read_sums`]). Errors: [`Error::PartSet`] (not part files of this
    /// version, foreign parts, shard counts that disagree, duplicate or missing shards; each
    /// lists the files) or [`Error::InconsistentPart`] (a part that is not the shard it says it
    /// is).
    pub fn read(paths: &[String], load: &mut dyn FnMut(&str) -> Result<String>) -> Result<PartSet> {
        // Every file is a part of this format; one identity Value is kept per study seen.
        let mut read: Vec<Part> = Vec::new();
        let mut studies: BTreeMap<[u8; 32], (usize, usize, String, Value)> = BTreeMap::new();
        let mut bad = Vec::new();
        let mut versions: BTreeMap<String, usize> = BTreeMap::new();
        for path in paths {
            let text = load(path)?;
            match read_part(&text) {
                Ok(h) => {
                    let identity = h.identity();
                    let key = key_of(&identity);
                    // At most KEPT configurations are held (the rest: compared by digest only).
                    let keep = studies.len() < KEPT;
                    let e = studies.entry(key).or_insert_with(|| {
                        let identity = if keep { identity } else { Value::Null };
                        (0, read.len(), h.study.clone(), identity)
                    });
                    e.0 += 1;
                    read.push(Part {
                        path: path.clone(),
                        shard: h.shard,
                        timing: h.timing,
                        digest: h.digest,
                        identity: key,
                    });
                }
                Err(NotPart::Version(v)) => {
                    *versions.entry(v.clone()).or_default() += 1;
                    bad.push(format!(
                        "{path} (version {v}, this scatterloc reads version {PART_VERSION})"
                    ));
                }
                Err(NotPart::Other(why)) => bad.push(format!("{path} ({why})")),
            }
        }
        if !bad.is_empty() {
            if let (true, Some((v, _))) = (
                read.is_empty() && versions.len() == 1,
                versions.iter().next(),
            ) {
                if versions[v] == paths.len() {
                    return Err(set_error(format!(
                        "merge: the parts are of part format version {v}; this scatterloc ({}) \
                         reads version {PART_VERSION}: merge them with the build that wrote \
                         them, or run the shards again with this one",
                        software()
                    )));
                }
            }
            return Err(set_error(format!(
                "merge: not scatterloc part files (format \"{PART_FORMAT}\", version {PART_VERSION}): {}",
                listed(&bad)
            )));
        }
        // One study: the identity shared by the most parts (the first such part's on a tie).
        let (&reference, _) = studies
            .iter()
            .max_by_key(|(_, (n, first, ..))| (*n, core::cmp::Reverse(*first)))
            .ok_or_else(|| set_error("merge: no part files given".into()))?;
        if studies.len() > 1 {
            let (_, first, study, want) = &studies[&reference];
            let foreign: Vec<String> = read
                .iter()
                .filter(|p| p.identity != reference)
                .map(|p| {
                    let got = &studies[&p.identity].3;
                    let d = first_difference(want, got, "").unwrap_or_default();
                    format!("{} ({d})", p.path)
                })
                .collect();
            return Err(set_error(format!(
                "merge: foreign parts, not of the study of {} ({study}, {}): {}",
                read[*first].path,
                want["software"].as_str().unwrap_or(""),
                listed(&foreign)
            )));
        }
        let (_, _, study, identity) = studies
            .remove(&reference)
            .ok_or_else(|| set_error("merge: no part files given".into()))?;
        let config = match identity {
            Value::Object(mut m) => m.remove("config").unwrap_or(Value::Null),
            _ => Value::Null,
        };
        check_set(&read)?;
        read.sort_by_key(|p| p.shard.index);
        Ok(PartSet {
            study,
            config,
            parts: read,
        })
    }

    /// [`PartSet::read`] of part files held in memory: `(path, text)` of each.
    pub fn check(files: &[(String, String)]) -> Result<PartSet> {
        let paths: Vec<String> = files.iter().map(|(p, _)| p.clone()).collect();
        let mut next = 0;
        PartSet::read(&paths, &mut |_| {
            let text = files[next].1.clone();
            next += 1;
            Ok(text)
        })
    }
}

/// The shards of parts of one study: one count, each the shard it says, each exactly once.
fn check_set(read: &[Part]) -> Result<()> {
    let Some(first) = read.first() else {
        return Err(set_error("merge: no part files given".into()));
    };
    // One shard count.
    let mut counts: BTreeMap<usize, Vec<&str>> = BTreeMap::new();
    for p in read {
        counts.entry(p.shard.count).or_default().push(&p.path);
    }
    if counts.len() > 1 {
        let items: Vec<String> = counts
            .iter()
            .map(|(n, files)| format!("{n} shards: {}", files.join(", ")))
            .collect();
        return Err(set_error(format!(
            "merge: the parts disagree on the shard count: {}",
            listed(&items)
        )));
    }
    let count = first.shard.count;
    // Each part is the shard it says it is.
    for p in read {
        let s = &p.shard;
        let Some(shard) = Shard::new(s.index, s.count) else {
            return Err(inconsistent(
                &p.path,
                format!("shard {} of {} does not exist", s.index, s.count),
            ));
        };
        let r = shard.range(s.total);
        if s.range != [r.start, r.end] || s.total != first.shard.total {
            return Err(inconsistent(
                &p.path,
                format!(
                    "shard.range [{}, {}] of {} {} is not shard {} of {} ([{}, {}] of {})",
                    s.range[0],
                    s.range[1],
                    s.total,
                    s.unit,
                    s.index,
                    s.count,
                    r.start,
                    r.end,
                    first.shard.total
                ),
            ));
        }
    }
    // Every shard exactly once.
    let mut by_index: BTreeMap<usize, Vec<&str>> = BTreeMap::new();
    for p in read {
        by_index.entry(p.shard.index).or_default().push(&p.path);
    }
    let duplicates: Vec<String> = by_index
        .iter()
        .filter(|(_, files)| files.len() > 1)
        .map(|(i, files)| format!("shard {i} in {}", files.join(", ")))
        .collect();
    let missing: Vec<usize> = (0..count).filter(|i| !by_index.contains_key(i)).collect();
    let mut problems = Vec::new();
    if !duplicates.is_empty() {
        problems.push(format!(
            "merge: duplicate parts (shards of {count}): {}",
            listed(&duplicates)
        ));
    }
    if !missing.is_empty() {
        problems.push(format!(
            "merge: missing parts: shard{} {} of {count} ({} of {count} given)",
            if missing.len() == 1 { "" } else { "s" },
            ranges(&missing),
            by_index.len()
        ));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(set_error(problems.join("; ")))
    }
}

/// A part that does not fit its set: `merge: inconsistent part PATH: what`.
pub fn inconsistent(path: &str, what: impl core::fmt::Display) -> Error {
    Error::InconsistentPart {
        path: path.to_string(),
        what: what.to_string(),
    }
}

/// A set of files that is not one study's complete set of parts.
fn set_error(what: String) -> Error {
    Error::PartSet { what }
}

/// At most 10 items joined with `; `, then how many more.
fn listed(items: &[String]) -> String {
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
fn ranges(indices: &[usize]) -> String {
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
fn first_difference(want: &Value, got: &Value, path: &str) -> Option<String> {
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

/// The merged run time: the wall times added (per entry), the most threads of any part, and
/// the thread time `Σ wall · threads` per entry. A part with another number of entries than
/// `entries` is inconsistent.
pub fn merged_timing(parts: &[Part], entries: usize) -> Result<(Timing, Vec<f64>)> {
    let mut wall = vec![0.0; entries];
    let mut thread_s = vec![0.0; entries];
    let mut threads = 0;
    for p in parts {
        if p.timing.wall_time_s.len() != entries {
            return Err(inconsistent(
                &p.path,
                format!(
                    "timing.wall_time_s has {} entries, not {entries}",
                    p.timing.wall_time_s.len()
                ),
            ));
        }
        threads = threads.max(p.timing.threads);
        for (k, &w) in p.timing.wall_time_s.iter().enumerate() {
            wall[k] += w;
            thread_s[k] += w * p.timing.threads as f64;
        }
    }
    Ok((
        Timing {
            threads,
            wall_time_s: wall,
        },
        thread_s,
    ))
}
