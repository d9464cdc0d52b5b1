//! `scatterloc merge`: the part files of a sharded study into the result of the unsharded run.
//! The files are read one at a time (each at most 256 MiB, `parts`); the library checks them as
//! one set ([`scatterloc::study::PartSet::read`]: format version, one study, every shard
//! exactly once) before anything is written, then the study's merge reads each part's sums
//! again and checks them against their digest and the study (issue 24; the list is in
//! docs/scale-out.md, "What merge checks"). Each problem is one named error (exit status 2)
//! naming the part and the field, or the offending files or shards; the study's command
//! (`montecarlo`, `mtl roc`) then writes its usual outputs.

use scatterloc::study::PartSet;

use super::parts::PartReader;
use crate::cli::MergeArgs;
use crate::failure::CliError;

/// `scatterloc merge`.
pub fn merge(args: &MergeArgs) -> Result<(), CliError> {
    let mut reader = PartReader::default();
    let set = PartSet::read(&args.parts, &mut |p| reader.load(p))
        .map_err(|e| CliError::usage(e.to_string()))?;
    match set.study.as_str() {
        "montecarlo" => {
            super::montecarlo::merge_parts(&set, reader, &args.json, args.out.as_deref())
        }
        "multi-target" => {
            super::multi_study::merge_multi(&set, reader, &args.json, args.out.as_deref())
        }
        _ => super::mtl::merge_roc(&set, reader, &args.json, args.out.as_deref()),
    }
}
