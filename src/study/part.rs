//! The part file of a sharded study (issue 13 §4) and the checks that make a set of them one
//! study: a sharded run writes its configuration, seed, shard, timing and sufficient statistics
//! ([`crate::track::StudySums`], [`crate::mtl::experiment::Tally`]) instead of its result, and
//! [`PartSet::check`] reads the parts back as one set before anything is merged — every one a
//! part file of this format version, all of one study (same software version, study kind and
//! configuration, seed included), every shard of one count present exactly once, each
//! consistent with its index. Each problem is one named error that lists the offending files.
//!
//! Part file (JSON, format `scatterloc-part`, version 1):
//! `{"format": "scatterloc-part", "version": 1, "software": "scatterloc 0.1.0", "study":
//! "montecarlo" | "mtl-roc", "config": {…}, "shard": {"index": I, "count": N, "unit": "chunks" |
//! "realisations", "range": [a, b], "total": C}, "timing": {"threads": T, "wall_time_s": [..]},
//! "sums": …}`. The shard covers the units `[a, b)` = [`Shard::range`] of `C`.
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
//! // … read back as one set, in shard order.
//! let set = PartSet::check(&texts).unwrap();
//! assert_eq!(set.study, "montecarlo");
//! assert_eq!(set.parts[1].shard.range, [2, 5]);
//! let sums: Vec<usize> = set.parts[1].sums().unwrap();
//! assert_eq!(sums, [1]);
//! // A set with a shard missing is refused, naming it.
//! let err = PartSet::check(&texts[..1]).unwrap_err();
//! assert!(err.to_string().contains("missing parts: shard 1 of 2"));
//! ```

use alloc::collections::BTreeMap;
use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::error::{Error, Result};
use crate::math::Shard;

/// The `format` of a part file.
pub const PART_FORMAT: &str = "scatterloc-part";
/// The `version` of the part format this build reads and writes.
pub const PART_VERSION: u64 = 1;

/// Study kinds and the unit their shards split.
const STUDIES: [(&str, &str); 2] = [("montecarlo", "chunks"), ("mtl-roc", "realisations")];

/// The `software` of a part file: parts of one study must come from the same build version.
pub fn software() -> String {
    format!("scatterloc {}", env!("CARGO_PKG_VERSION"))
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

/// A part file as written (serialize it, e.g. with `serde_json::to_string`).
#[derive(Debug, Serialize)]
pub struct PartFile<'a, C: Serialize, S: Serialize + ?Sized> {
    format: &'static str,
    version: u64,
    software: String,
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
            format: PART_FORMAT,
            version: PART_VERSION,
            software: software(),
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

/// A part file as read (its configuration and sums still JSON values).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PartIn {
    /// `format` and `version`, checked before the fields are read.
    #[serde(rename = "format")]
    _format: serde::de::IgnoredAny,
    #[serde(rename = "version")]
    _version: serde::de::IgnoredAny,
    software: String,
    study: String,
    config: Value,
    shard: ShardDoc,
    timing: Timing,
    sums: Value,
}

/// One checked part of a [`PartSet`].
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// The name the part was given under (its path).
    pub path: String,
    /// The study's configuration (the same in every part of a set).
    pub config: Value,
    /// Which shard.
    pub shard: ShardDoc,
    /// Its run time.
    pub timing: Timing,
    /// Its sums (the study's type, as JSON).
    pub sums: Value,
}

impl Part {
    /// The sums as `T`; sums that do not parse make the part inconsistent
    /// ([`Error::InconsistentPart`]).
    pub fn sums<T: serde::de::DeserializeOwned>(&self) -> Result<T> {
        T::deserialize(&self.sums).map_err(|e| inconsistent(&self.path, format!("sums: {e}")))
    }
}

/// The parts of one study, checked as a set, in shard order.
#[derive(Debug, Clone, PartialEq)]
pub struct PartSet {
    /// The study kind: `montecarlo` or `mtl-roc`.
    pub study: String,
    /// The parts, one per shard, in shard order.
    pub parts: Vec<Part>,
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
    let text = match v {
        Some(v) => v.to_string(),
        None => "absent".to_string(),
    };
    match text.char_indices().nth(60) {
        Some((i, _)) => format!("{}…", &text[..i]),
        None => text,
    }
}

/// The first place (a dotted path) where `got` differs from `want`, with both values (`None`:
/// equal).
pub fn differs(want: &Value, got: &Value) -> Option<String> {
    first_difference(want, got, "")
}

/// [`differs`] below `path`.
fn first_difference(want: &Value, got: &Value, path: &str) -> Option<String> {
    let at = |key: &str| match path {
        "" => key.to_string(),
        p => format!("{p}.{key}"),
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
            "{path}: {}, not {}",
            shown(Some(got)),
            shown(Some(want))
        )),
    }
}

/// Reads one part file's text: the format and version first, then the fields.
fn read_part(text: &str) -> core::result::Result<PartIn, String> {
    let value: Value = serde_json::from_str(text).map_err(|e| format!("invalid JSON: {e}"))?;
    let format = value.get("format").and_then(Value::as_str);
    let version = value.get("version").and_then(Value::as_u64);
    if format != Some(PART_FORMAT) {
        return Err(format!(
            "format {}, not \"{PART_FORMAT}\"",
            shown(value.get("format"))
        ));
    }
    if version != Some(PART_VERSION) {
        return Err(format!(
            "version {}, this scatterloc reads version {PART_VERSION}",
            shown(value.get("version"))
        ));
    }
    let part: PartIn = serde_json::from_value(value).map_err(|e| e.to_string())?;
    match STUDIES.iter().find(|(s, _)| *s == part.study) {
        None => Err(format!(
            "study \"{}\" is not montecarlo or mtl-roc",
            part.study.escape_debug()
        )),
        Some((_, unit)) if part.shard.unit != *unit => Err(format!(
            "shard.unit \"{}\" is not \"{unit}\" (study {})",
            part.shard.unit.escape_debug(),
            part.study
        )),
        Some(_) => Ok(part),
    }
}

impl PartSet {
    /// Reads and checks `files` (`(path, text)` of each part file) as one set: the study kind
    /// and the parts in shard order. Errors: [`Error::PartSet`] (not part files, foreign
    /// parts, shard counts that disagree, duplicate or missing shards; each lists the files)
    /// or [`Error::InconsistentPart`] (a part that is not the shard it says it is).
    pub fn check(files: &[(String, String)]) -> Result<PartSet> {
        // Every file is a part of this format.
        let mut read = Vec::new();
        let mut bad = Vec::new();
        for (path, text) in files {
            match read_part(text) {
                Ok(p) => read.push((path.clone(), p)),
                Err(why) => bad.push(format!("{path} ({why})")),
            }
        }
        if !bad.is_empty() {
            return Err(set_error(format!(
                "merge: not scatterloc part files (format \"{PART_FORMAT}\", version {PART_VERSION}): {}",
                listed(&bad)
            )));
        }
        // One study: the identity shared by the most parts (the first such part's on a tie).
        let identity = |p: &PartIn| serde_json::json!({"software": p.software, "study": p.study, "config": p.config});
        let mut votes: BTreeMap<String, (usize, usize)> = BTreeMap::new();
        for (i, (_, p)) in read.iter().enumerate() {
            let e = votes.entry(identity(p).to_string()).or_insert((0, i));
            e.0 += 1;
        }
        let (_, &(_, first)) = votes
            .iter()
            .max_by_key(|(_, &(n, first))| (n, core::cmp::Reverse(first)))
            .ok_or_else(|| set_error("merge: no part files given".into()))?;
        let reference = identity(&read[first].1);
        let foreign: Vec<String> = read
            .iter()
            .filter_map(|(path, p)| {
                first_difference(&reference, &identity(p), "").map(|d| format!("{path} ({d})"))
            })
            .collect();
        if !foreign.is_empty() {
            return Err(set_error(format!(
                "merge: foreign parts, not of the study of {} ({}, {}): {}",
                read[first].0,
                read[first].1.study,
                read[first].1.software,
                listed(&foreign)
            )));
        }
        // One shard count.
        let mut counts: BTreeMap<usize, Vec<&str>> = BTreeMap::new();
        for (path, p) in &read {
            counts.entry(p.shard.count).or_default().push(path);
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
        let count = read[0].1.shard.count;
        // Each part is the shard it says it is.
        for (path, p) in &read {
            let s = &p.shard;
            let Some(shard) = Shard::new(s.index, s.count) else {
                return Err(inconsistent(
                    path,
                    format!("shard {} of {} does not exist", s.index, s.count),
                ));
            };
            let r = shard.range(s.total);
            if s.range != [r.start, r.end] || s.total != read[0].1.shard.total {
                return Err(inconsistent(
                    path,
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
                        read[0].1.shard.total
                    ),
                ));
            }
        }
        // Every shard exactly once.
        let mut by_index: BTreeMap<usize, Vec<&str>> = BTreeMap::new();
        for (path, p) in &read {
            by_index.entry(p.shard.index).or_default().push(path);
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
        if !problems.is_empty() {
            return Err(set_error(problems.join("; ")));
        }
        let study = read[0].1.study.clone();
        let mut parts: Vec<Part> = read
            .into_iter()
            .map(|(path, p)| Part {
                path,
                config: p.config,
                shard: p.shard,
                timing: p.timing,
                sums: p.sums,
            })
            .collect();
        parts.sort_by_key(|p| p.shard.index);
        Ok(PartSet { study, parts })
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
