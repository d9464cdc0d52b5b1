//! Files the package writes (`write_recording`, `Scenario.save`): one atomic writer, with the
//! rules of the CLI's (`src/bin/scatterloc/cmd/output.rs`, docs/cli.md "Output safety"):
//!
//! - the target is checked first: an empty path, a symbolic link (its target would never be
//!   written), a directory, a FIFO, a socket or a device is refused by name
//!   (`ScatterlocError` naming the path argument); a regular file is replaced, a new path
//!   created;
//! - the bytes go into a temporary file with a random hidden name in the target's directory,
//!   created exclusively (`O_CREAT | O_EXCL`, by `tempfile`): nothing planted at a predictable
//!   name is followed, and concurrent writers never share a temporary;
//! - the temporary is flushed and `fsync`ed, then renamed over the target (a new target is
//!   created without replacing anything that appeared meanwhile), so a reader sees the old file
//!   or the whole new one, never a torn one; on any failure the temporary is removed and the
//!   target is left as it was.
//!
//! A failed write (a missing directory, no permission, a full disk) is the `OSError` of its
//! kind, naming the path.

use std::io::Write;
use std::path::{Path, PathBuf};

use pyo3::prelude::*;

use crate::errors::arg_error;

/// Why a file was not written.
pub enum WriteError {
    /// The target is of a kind the writer refuses (the module doc), with the reason.
    Refused(String),
    /// The file system's error.
    Io(std::io::Error),
}

impl From<std::io::Error> for WriteError {
    fn from(e: std::io::Error) -> WriteError {
        WriteError::Io(e)
    }
}

impl WriteError {
    /// As a Python exception: a refused target is a `ScatterlocError` naming `field`, an I/O
    /// failure the `OSError` of its kind (`FileNotFoundError`, `PermissionError`, …) naming
    /// `path`.
    pub fn into_py(self, field: &str, path: &Path) -> PyErr {
        match self {
            WriteError::Refused(why) => arg_error(field, why),
            WriteError::Io(e) => PyErr::from(std::io::Error::new(
                e.kind(),
                format!("cannot write '{}': {e}", path.display()),
            )),
        }
    }
}

/// Whether a regular file is at `path` (`false`: nothing, it will be created); anything else
/// is refused (the module doc). Nothing is opened, a link is not followed.
fn existing_file(path: &Path) -> Result<bool, WriteError> {
    let meta = match std::fs::symlink_metadata(path) {
        Ok(meta) => meta,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(false),
        Err(e) => return Err(e.into()),
    };
    let kind = meta.file_type();
    if kind.is_file() {
        return Ok(true);
    }
    let what = if kind.is_symlink() {
        "a symbolic link"
    } else if kind.is_dir() {
        "a directory"
    } else {
        special(&kind)
    };
    Err(WriteError::Refused(format!(
        "'{}' is {what}, not a regular file; refusing to replace it (write to a new path or a \
         regular file)",
        path.display()
    )))
}

/// The kind of a file that is neither a regular file, a link nor a directory.
#[cfg(unix)]
fn special(kind: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if kind.is_fifo() {
        "a FIFO"
    } else if kind.is_socket() {
        "a socket"
    } else if kind.is_char_device() || kind.is_block_device() {
        "a device"
    } else {
        "not a regular file"
    }
}

/// The kind of a file that is neither a regular file, a link nor a directory.
#[cfg(not(unix))]
fn special(_: &std::fs::FileType) -> &'static str {
    "not a regular file"
}

/// The directory a file is written in (`.` for a bare file name).
fn directory_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// A new temporary for `path`: a random hidden name in its directory, created exclusively;
/// permissions as a plain `File::create` (0666 less the umask). Removed when dropped.
fn temporary_for(path: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let mut b = tempfile::Builder::new();
    b.prefix(".scatterloc-").suffix(".tmp").rand_bytes(12);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    b.tempfile_in(directory_of(path))
}

/// Writes `bytes` as the whole file `path`, atomically (the module doc). Call it without the
/// GIL for large files; convert the error with [`WriteError::into_py`].
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    if path.as_os_str().is_empty() {
        return Err(WriteError::Refused("the path is empty".into()));
    }
    existing_file(path)?;
    let mut tmp = temporary_for(path)?;
    tmp.write_all(bytes)?;
    tmp.flush()?;
    tmp.as_file().sync_all()?;
    // A concurrent writer may create the target between the check and the rename: then it is
    // a regular file and is replaced (the last writer wins, whole).
    for _ in 0..4 {
        if existing_file(path)? {
            return tmp.persist(path).map(drop).map_err(|e| e.error.into());
        }
        match tmp.persist_noclobber(path) {
            Ok(_) => return Ok(()),
            Err(e) if e.error.kind() == std::io::ErrorKind::AlreadyExists => tmp = e.file,
            // A file system without a no-replace rename or hard links: the target was just
            // checked to be absent, a plain rename then.
            Err(e) => return e.file.persist(path).map(drop).map_err(|e| e.error.into()),
        }
    }
    Err(std::io::Error::other("the target kept changing during the write").into())
}

/// [`write_atomic`] without the GIL, its error as a Python exception naming `field` (the
/// path argument).
pub fn write_file(py: Python<'_>, field: &str, path: &Path, bytes: &[u8]) -> PyResult<()> {
    py.detach(|| write_atomic(path, bytes))
        .map_err(|e| e.into_py(field, path))
}
