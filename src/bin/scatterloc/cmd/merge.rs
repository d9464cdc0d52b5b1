//! `scatterloc merge`: the part files of a sharded study into the result of the unsharded run.
//! The files are read here, one at a time (each at most 256 MiB); the library checks them as
//! one set ([`scatterloc::study::PartSet::read`]: format version, one study, every shard
//! exactly once) before anything is written, then the study's merge reads each part's sums
//! again and checks them against their digest and the study (issue 24; the list is in
//! docs/scale-out.md, "What merge checks"). Each problem is one named error (exit status 2)
//! naming the part and the field, or the offending files or shards; the study's command
//! (`montecarlo`, `mtl roc`) then writes its usual outputs.

use scatterloc::study::PartSet;
use scatterloc::Error;

use super::io::read_input_named;
use crate::cli::MergeArgs;
use crate::failure::CliError;

/// Reads the part files of `merge`, one at a time (its errors as the library's, exit status
/// 2); stdin (`-`) is read once and kept, as it cannot be read again.
#[derive(Default)]
pub struct PartReader {
    stdin: Option<String>,
}

impl PartReader {
    /// The text of part file `path`.
    pub fn load(&mut self, path: &str) -> Result<String, Error> {
        let read = |p: &str| {
            read_input_named("merge: PART", p).map_err(|e| Error::PartSet { what: e.message })
        };
        if path != "-" {
            return read(path);
        }
        if self.stdin.is_none() {
            self.stdin = Some(read(path)?);
        }
        Ok(self.stdin.clone().unwrap_or_default())
    }
}

/// `scatterloc merge`.
pub fn merge(args: &MergeArgs) -> Result<(), CliError> {
    let mut reader = PartReader::default();
    let set = PartSet::read(&args.parts, &mut |p| reader.load(p))
        .map_err(|e| CliError::usage(e.to_string()))?;
    match set.study.as_str() {
        "montecarlo" => {
            super::montecarlo::merge_parts(&set, reader, &args.json, args.out.as_deref())
        }
        _ => super::mtl::merge_roc(&set, reader, &args.json, args.out.as_deref()),
    }
}
