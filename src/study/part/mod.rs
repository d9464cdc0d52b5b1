//! The part file of a sharded study (issue 13 §4, issue 24) and the checks that make a set of
//! them one study: a sharded run writes its configuration, seed, shard, timing and sufficient
//! statistics ([`crate::track::StudySums`], [`crate::mtl::experiment::Tally`]) instead of its
//! result, with a digest of those sums ([`PartFile`], `format.rs`; the digest's canonical token
//! walk in `digest.rs`); [`PartSet::read`] reads the parts back as one set before anything is
//! merged — every one a part file of this format version (its header read and checked field by
//! field in `header.rs`), all of one study (same software version, study kind and
//! configuration, seed included), every shard of one count present exactly once, each
//! consistent with its index (`set.rs`) — and the study's `merge`
//! ([`crate::study::MonteCarloStudy::merge`], [`crate::study::RocStudy::merge`]) reads each
//! part's sums again, one file at a time, and checks them against their digest and against
//! the study before adding them ([`Part::read_sums`]). Each problem is one named error that
//! names the file and the field ([`crate::Error::PartSet`] for the set,
//! [`crate::Error::InconsistentPart`] for one part; the message helpers in `message.rs`). The
//! format and the full list of checks are documented on [`PartFile`] and [`PartSet`].

mod digest;
mod format;
mod header;
mod message;
mod set;

pub use digest::sums_digest;
pub use format::{
    software, PartFile, ShardDoc, Timing, MAX_PART_CONFIG_BYTES, MAX_TIMING_ENTRIES, PART_FORMAT,
    PART_VERSION,
};
pub use message::{differs, inconsistent};
pub use set::{load_sums, merged_timing, Part, PartSet};

#[cfg(test)]
mod tests;
