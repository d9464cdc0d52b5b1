//! `scatterloc merge`: the part files of a sharded study (`super::shard`) into the result of the
//! unsharded run. The parts are read and checked as a set — every one a part file of this
//! format version, all of one study (same software version, study kind and configuration,
//! seed included), every shard of one count present exactly once, each consistent with its
//! index — before anything is written; each problem is one named error (exit status 2) that
//! lists the offending files or shards. The study's own code (`montecarlo`, `mtl roc`) then adds
//! the sums exactly and writes its usual outputs.

use std::collections::BTreeMap;

use serde::Deserialize;
use serde_json::Value;

use scatterloc::math::Shard;

use super::io::read_input_named;
use super::shard::{ShardDoc, Timing, PART_FORMAT, PART_VERSION};
use crate::cli::MergeArgs;
use crate::failure::CliError;

/// Study kinds and the unit their shards split.
const STUDIES: [(&str, &str); 2] = [("montecarlo", "chunks"), ("mtl-roc", "realisations")];

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

/// One checked part of the set.
#[derive(Debug)]
pub struct Part {
    /// The path given on the command line.
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

/// `scatterloc merge`.
pub fn merge(args: &MergeArgs) -> Result<(), CliError> {
    let (study, parts) = read_set(&args.parts)?;
    match study.as_str() {
        "montecarlo" => super::montecarlo::merge_parts(&parts, &args.json, args.out.as_deref()),
        _ => super::mtl::merge_roc(&parts, &args.json, args.out.as_deref()),
    }
}

/// A part that does not fit the set: `merge: inconsistent part PATH: what`.
pub fn inconsistent(path: &str, what: impl std::fmt::Display) -> CliError {
    CliError::usage(format!("merge: inconsistent part {path}: {what}"))
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

/// Reads one part file: the format and version first, then the fields.
fn read_part(path: &str) -> Result<Result<PartIn, String>, CliError> {
    let text = read_input_named("merge: PART", path)?;
    let value: Value = match serde_json::from_str(&text) {
        Ok(v) => v,
        Err(e) => return Ok(Err(format!("invalid JSON: {e}"))),
    };
    let format = value.get("format").and_then(Value::as_str);
    let version = value.get("version").and_then(Value::as_u64);
    if format != Some(PART_FORMAT) {
        return Ok(Err(format!(
            "format {}, not \"{PART_FORMAT}\"",
            shown(value.get("format"))
        )));
    }
    if version != Some(PART_VERSION) {
        return Ok(Err(format!(
            "version {}, this scatterloc reads version {PART_VERSION}",
            shown(value.get("version"))
        )));
    }
    let part: PartIn = match serde_json::from_value(value) {
        Ok(p) => p,
        Err(e) => return Ok(Err(e.to_string())),
    };
    match STUDIES.iter().find(|(s, _)| *s == part.study) {
        None => Ok(Err(format!(
            "study \"{}\" is not montecarlo or mtl-roc",
            part.study.escape_debug()
        ))),
        Some((_, unit)) if part.shard.unit != *unit => Ok(Err(format!(
            "shard.unit \"{}\" is not \"{unit}\" (study {})",
            part.shard.unit.escape_debug(),
            part.study
        ))),
        Some(_) => Ok(Ok(part)),
    }
}

/// Reads and checks the parts as one set; returns the study kind and the parts in shard order.
fn read_set(paths: &[String]) -> Result<(String, Vec<Part>), CliError> {
    // Every file is a part of this format.
    let mut read = Vec::new();
    let mut bad = Vec::new();
    for path in paths {
        match read_part(path)? {
            Ok(p) => read.push((path.clone(), p)),
            Err(why) => bad.push(format!("{path} ({why})")),
        }
    }
    if !bad.is_empty() {
        return Err(CliError::usage(format!(
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
        .max_by_key(|(_, &(n, first))| (n, std::cmp::Reverse(first)))
        .ok_or_else(|| CliError::usage("merge: no part files given"))?;
    let reference = identity(&read[first].1);
    let foreign: Vec<String> = read
        .iter()
        .filter_map(|(path, p)| {
            first_difference(&reference, &identity(p), "").map(|d| format!("{path} ({d})"))
        })
        .collect();
    if !foreign.is_empty() {
        return Err(CliError::usage(format!(
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
        return Err(CliError::usage(format!(
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
        return Err(CliError::usage(problems.join("; ")));
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
    Ok((study, parts))
}

/// The sums of `part` as `T`; a part whose sums do not parse is inconsistent.
pub fn sums_of<T: serde::de::DeserializeOwned>(part: &Part) -> Result<T, CliError> {
    T::deserialize(&part.sums).map_err(|e| inconsistent(&part.path, format!("sums: {e}")))
}

/// The merged run time: the wall times added (per entry), the most threads of any part, and
/// the thread time `Σ wall · threads` per entry.
pub fn merged_timing(parts: &[Part], entries: usize) -> Result<(Timing, Vec<f64>), CliError> {
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
