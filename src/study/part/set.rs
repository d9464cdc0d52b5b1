//! A set of part files read and checked as one study ([`PartSet::read`]: one study, one shard
//! count, every shard exactly once, each the shard it says), each part's sums read again and
//! checked against its digest when merged ([`Part::read_sums`], [`load_sums`]), and the merged
//! run time ([`merged_timing`]).

use alloc::collections::BTreeMap;
use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use serde::Serialize;
use serde_json::Value;

use super::digest::{hex, walk};
use super::format::{software, ShardDoc, Timing, PART_FORMAT, PART_VERSION};
use super::header::{key_of, read_part, NotPart};
use super::message::{clip, first_difference, inconsistent, listed, parse_at, ranges, set_error};
use crate::error::Result;
use crate::math::Shard;

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
///
/// # What is checked (issue 24)
///
/// Every part, when the set is read:
/// - `format` is `scatterloc-part` and `version` is [`PART_VERSION`] (a set all of one other
///   version gets one error naming that version); the fields are exactly those of
///   [`PartFile`](super::PartFile);
/// - `study` is `montecarlo` or `mtl-roc`, `shard.unit` its unit; `shard` is the shard
///   `index` of `count` of `total` units ([`Shard::range`]), `total` the same in every part;
/// - `config` at most [`MAX_PART_CONFIG_BYTES`](super::MAX_PART_CONFIG_BYTES) of JSON, `timing`
///   at most [`MAX_TIMING_ENTRIES`](super::MAX_TIMING_ENTRIES) entries; `timing.threads` ≥ 1;
///   every `timing.wall_time_s[i]` finite and ≥ 0; `digest` is `sha256:` and 64 lowercase hex
///   digits.
///
/// The set: one study (software, study, config), one shard count, every shard exactly once.
///
/// Every part's sums, when merged (the study rebuilt from `config` gives the bounds):
/// - no array longer than the study implies (checked while parsing, before anything is
///   allocated for it: [`Part::read_sums`]); the digest matches the sums (corruption,
///   truncation, an edit); the types exact (counts are whole numbers ≥ 0);
/// - Monte Carlo, per entry `sums[k·F + f]` (trajectory `k`, filter `f` of `F`): `steps + 1`
///   entries per list; `trajectories` = the trajectories of the shard's chunks; `runs +
///   failed_runs` = trajectories × noise runs; every `squared_error[n]` and `nees[n]` finite
///   and ≥ 0, zero when no run counted and non-zero when one did; `fisher[n]` finite,
///   symmetric (`F₂₁ = F₁₂` exactly: every addend is), with a diagonal ≥ 0 and positive
///   semi-definite (`F₁₂² ≤ F₁₁ F₂₂`, relative 10⁻⁹ for rounding), `fisher[0]` zero, all zero
///   when no trajectory counted and not all zero when one did; the Fisher sums and trajectory
///   count are the same for every filter of a trajectory (they come from the truth alone);
/// - ROC ([`crate::mtl::experiment::Tally::check`]): `realisations` = the shard's; `curves ×
///   points` as the experiment's; per point `detections ≤ targets`, `false_alarms ≤
///   estimates`, the ratio sums finite, in `[0, realisations]`, zero when their count is;
///   `disagreements ≤ realisations × curves × points`.
///
/// Memory: [`PartSet::read`] and the merges hold one part file's text at a time (the CLI
/// caps each at 256 MiB, [`crate::error::limits::MAX_INPUT_BYTES`]), the reference
/// configuration, and per part a few hundred bytes; the sums of one part are at most what
/// its configuration implies (the merged sums' size).
///
/// ```
/// use scatterloc::math::Shard;
/// use scatterloc::study::{PartFile, PartSet, ShardDoc, Timing};
///
/// // Two shards of a study of 5 units, written as a sharded run writes them …
/// let texts: Vec<(String, String)> = (0..2)
///     .map(|i| {
///         let shard = ShardDoc::new(Shard::new(i, 2).unwrap(), "chunks", 5);
///         let timing = Timing { threads: 1, wall_time_s: vec![0.5] };
///         let (config, sums) = (serde_json::json!({"seed": 1}), [i]);
///         let part = PartFile::new("montecarlo", &config, &shard, &timing, &sums);
///         (format!("part{i}.json"), serde_json::to_string(&part).unwrap())
///     })
///     .collect();
/// // … read back as one set, in shard order …
/// let set = PartSet::check(&texts).unwrap();
/// assert_eq!(set.study, "montecarlo");
/// assert_eq!(set.parts[1].shard.range, [2, 5]);
/// // … and the sums of one part, checked against its digest (arrays of at most 8 entries).
/// let sums: Vec<usize> = set.parts[1].read_sums(&texts[1].1, 8).unwrap();
/// assert_eq!(sums, [1]);
/// // A set with a shard missing is refused, naming it.
/// let err = PartSet::check(&texts[..1]).unwrap_err();
/// assert!(err.to_string().contains("missing parts: shard 1 of 2"));
/// // An edited sum no longer matches its digest.
/// let edited = texts[1].1.replace("\"sums\":[1]", "\"sums\":[2]");
/// let err = set.parts[1].read_sums::<Vec<usize>>(&edited, 8).unwrap_err();
/// assert!(err.to_string().contains("part1.json: sums do not match their digest"));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct PartSet {
    /// The study kind: `montecarlo` or `mtl-roc`.
    pub study: String,
    /// The study's configuration (the same in every part).
    pub config: Value,
    /// The parts, one per shard, in shard order.
    pub parts: Vec<Part>,
}

impl Part {
    /// The sums of this part as `T`, from `text`, the part file read again: the header must be
    /// the one checked ([`PartSet::read`]), no array of the sums longer than `max_len` (checked
    /// in a first pass that allocates nothing for the sums, which also computes their digest),
    /// the digest the part's, and the sums must parse as `T` (errors name the field). Each
    /// problem is [`crate::Error::InconsistentPart`].
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

impl PartSet {
    /// Reads and checks the part files `paths` as one set, one file at a time through `load`
    /// (the file's text; its errors are returned as they are): the study kind, its
    /// configuration and the parts' headers in shard order (the sums are read again by the
    /// study's merge, [`Part::read_sums`]). Errors: [`crate::Error::PartSet`] (not part files
    /// of this version, foreign parts, shard counts that disagree, duplicate or missing shards;
    /// each lists the files) or [`crate::Error::InconsistentPart`] (a part that is not the
    /// shard it says it is).
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
