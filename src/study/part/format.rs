//! The part file as written: its format name and version, the bounds of its `config` and
//! `timing`, the study kinds and their units, the shard and timing records ([`ShardDoc`],
//! [`Timing`]) and the writer [`PartFile`], whose serialization computes the digest.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use super::digest::sums_digest;
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
pub(super) const STUDIES: [(&str, &str); 3] = [
    ("montecarlo", "chunks"),
    ("mtl-roc", "realisations"),
    ("multi-target", "runs"),
];

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

/// A part file as written (serialize it, e.g. with `serde_json::to_string`; serializing
/// computes its `digest`, [`sums_digest`]).
///
/// Part file (JSON, format `scatterloc-part`, version 2):
/// `{"format": "scatterloc-part", "version": 2, "software": "scatterloc 0.1.0", "study":
/// "montecarlo" | "mtl-roc", "config": {…}, "shard": {"index": I, "count": N, "unit": "chunks" |
/// "realisations", "range": [a, b], "total": C}, "timing": {"threads": T, "wall_time_s": [..]},
/// "digest": "sha256:…", "sums": …}`. The shard covers the units `[a, b)` = [`Shard::range`] of
/// `C`. `digest` is the SHA-256 of the sums' JSON as a canonical token stream
/// ([`sums_digest`]): the same sums give the same digest, so it does not depend on the thread
/// count, and a part reformatted (e.g. by `jq -S .`) keeps it. Version 1 (without a digest) is
/// refused with a named error.
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
