//! Placeholder while the reader is written (issue 40).

use super::capture::CsiCapture;
use crate::error::{Error, Result};

/// Whether `bytes` look like this format.
pub fn sniff(_bytes: &[u8]) -> bool {
    false
}

/// Reads the file.
pub fn read(_bytes: &[u8]) -> Result<CsiCapture> {
    Err(Error::InvalidFile { field: "format".into(), reason: "feitcsi: reader not written yet".into() })
}
