//! Reading the part files of `scatterloc merge` for the library ([`PartReader`]): one file at
//! a time, each at most 256 MiB, stdin (`-`) once. `merge` reads the set through it, then hands
//! it to the study's command (`montecarlo`, `mtl roc`), whose merge reads each part's sums
//! again through it.

use scatterloc::Error;

use super::io::read_input_named;

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
