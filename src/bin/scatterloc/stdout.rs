//! Checked writes to standard output (issue 24: a closed stdout gave exit status 0 with nothing
//! written). A leaf module: `cli` (help, completions) and `cmd` (results) write through it.
//!
//! Rust's `std::io::stdout` reports success for a write that fails with `EBADF` (a descriptor
//! opened read-only, e.g. `1</dev/null`), and the runtime reopens a closed descriptor 1 (`>&-`)
//! on `/dev/null` before `main`, read-write. Here stdout is written through a duplicate of
//! descriptor 1 as a plain [`File`], so every error (`EBADF`, `EPIPE`, `ENOSPC`) is reported,
//! and the runtime's stand-in for a closed stdout (`/dev/null` open for reading and writing) is
//! refused where stdout carries a command's result ([`write`]); a summary line beside output
//! files ([`write_summary`]) is written to it like to any `/dev/null`, so a daemon's or
//! Python's `subprocess.DEVNULL` stdout (also `/dev/null` read-write) does not fail a run whose
//! results went to files. An explicit `>/dev/null` (write-only) is honoured.

use std::fs::File;
use std::io::{Read, Write};
use std::os::fd::AsFd;
use std::os::unix::fs::MetadataExt;

use crate::failure::CliError;

/// The failure for a stdout problem (exit status 1).
fn failed(e: impl std::fmt::Display) -> CliError {
    CliError::output(format!("stdout: {e}"))
}

/// Whether `f` is the runtime's `/dev/null` standing in for a closed descriptor 1: the null
/// device, open for reading (an explicit `>/dev/null` is write-only).
fn is_closed_stand_in(f: &File) -> bool {
    let (Ok(meta), Ok(null)) = (f.metadata(), std::fs::metadata("/dev/null")) else {
        return false;
    };
    if !std::os::unix::fs::FileTypeExt::is_char_device(&meta.file_type())
        || meta.rdev() != null.rdev()
    {
        return false;
    }
    // Reading the null device returns at once (end of file) when it is open for reading.
    let mut byte = [0u8; 1];
    let mut reader = f;
    reader.read(&mut byte).is_ok()
}

/// Descriptor 1 as a file; with `result`, refused when it is closed (see the module doc).
fn open(result: bool) -> Result<File, CliError> {
    let fd = std::io::stdout()
        .as_fd()
        .try_clone_to_owned()
        .map_err(failed)?;
    let f = File::from(fd);
    if result && is_closed_stand_in(&f) {
        return Err(failed(
            "standard output is closed (results are written there; redirect it to a file or /dev/null)",
        ));
    }
    Ok(f)
}

/// Writes a command's result `bytes` to stdout and flushes; any failure, a closed stdout
/// included, is an error naming stdout.
pub fn write(bytes: &[u8]) -> Result<(), CliError> {
    put(bytes, true)
}

/// Writes a summary line (the results went to files) to stdout and flushes; a write error
/// (`EBADF`, `EPIPE`, `ENOSPC`) is an error naming stdout, the runtime's `/dev/null` stand-in
/// for a closed stdout is not.
pub fn write_summary(bytes: &[u8]) -> Result<(), CliError> {
    put(bytes, false)
}

/// Descriptor 1 for a stream of result lines (`cir track --follow`), refused when closed as
/// [`write`] does; each `write_all` on it goes out at once (no buffer of ours).
pub fn result_stream() -> Result<File, CliError> {
    open(true)
}

/// Writes `bytes` to descriptor 1 ([`open`] with `result`) and flushes.
fn put(bytes: &[u8], result: bool) -> Result<(), CliError> {
    let mut f = open(result)?;
    f.write_all(bytes).and_then(|()| f.flush()).map_err(failed)
}
