//! `scatterloc merge`: the part files of a sharded study into the result of the unsharded run.
//! The files are read here; the library checks them as one set
//! ([`scatterloc::study::PartSet::check`]: format version, one study, every shard exactly once)
//! before anything is written, each problem one named error (exit status 2) that lists the
//! offending files or shards; the study's command (`montecarlo`, `mtl roc`) then adds the sums
//! exactly and writes its usual outputs.

use scatterloc::study::PartSet;

use super::io::read_input_named;
use crate::cli::MergeArgs;
use crate::failure::CliError;

/// `scatterloc merge`.
pub fn merge(args: &MergeArgs) -> Result<(), CliError> {
    let files = args
        .parts
        .iter()
        .map(|path| Ok((path.clone(), read_input_named("merge: PART", path)?)))
        .collect::<Result<Vec<_>, CliError>>()?;
    let set = PartSet::check(&files).map_err(|e| CliError::usage(e.to_string()))?;
    match set.study.as_str() {
        "montecarlo" => super::montecarlo::merge_parts(&set.parts, &args.json, args.out.as_deref()),
        _ => super::mtl::merge_roc(&set.parts, &args.json, args.out.as_deref()),
    }
}
