//! Output files of the CLI: the format from the extension, atomic writes (a temporary file in the
//! same directory, renamed into place, so an interrupted or failed run leaves nothing
//! half-written) and SVG/PNG figures drawn by any [`Figure`].

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;

use scatterloc::chart::ChartError;

use crate::failure::CliError;

/// File format, from the extension of the path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// `.json`
    Json,
    /// `.svg`
    Svg,
    /// `.png`
    Png,
}

impl Format {
    /// The format of `path` for `--flag`, which accepts the formats in `allowed`.
    pub fn of(flag: &str, path: &str, allowed: &[Format]) -> Result<Format, CliError> {
        let names: Vec<String> = allowed.iter().map(|f| format!(".{}", f.name())).collect();
        let expected = names.join(", ");
        let ext = Path::new(path)
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let format = match ext.as_deref() {
            Some("json") => Format::Json,
            Some("svg") => Format::Svg,
            Some("png") => Format::Png,
            Some(e) => {
                return Err(CliError::usage(format!(
                    "--{flag}: unknown extension '.{e}' (use {expected})"
                )))
            }
            None => {
                return Err(CliError::usage(format!(
                    "--{flag}: '{path}' has no extension (use {expected})"
                )))
            }
        };
        if allowed.contains(&format) {
            Ok(format)
        } else {
            Err(CliError::usage(format!(
                "--{flag}: '.{}' is not accepted here (use {expected})",
                format.name()
            )))
        }
    }

    /// `json`, `svg` or `png`.
    pub fn name(self) -> &'static str {
        match self {
            Format::Json => "json",
            Format::Svg => "svg",
            Format::Png => "png",
        }
    }
}

/// "cannot write" for `--flag`: bad input (a path that cannot be created), exit status 2.
pub fn cannot_write(flag: &str, path: &str, e: impl std::fmt::Display) -> CliError {
    CliError::usage(format!("--{flag}: cannot write '{path}': {e}"))
}

/// `dir/stem.tmp.ext` beside `path` (the extension is kept: the PNG encoder picks the format
/// from it).
fn temporary_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
    let name = match (stem, path.extension()) {
        (Some(stem), Some(ext)) => format!("{stem}.tmp.{}", ext.to_string_lossy()),
        (Some(stem), None) => format!("{stem}.tmp"),
        _ => ".scatterloc.tmp".to_string(),
    };
    path.with_file_name(name)
}

/// Refuses, naming `--flag`, an empty path and anything at `path` that an atomic write would
/// destroy instead of writing: a symbolic link (its target would never be written), a device,
/// a FIFO, a socket or a directory. A regular file (replaced) or a new path is fine.
pub fn check_target(flag: &str, path: &str) -> Result<(), CliError> {
    if path.is_empty() {
        return Err(CliError::usage(format!("--{flag}: the path is empty")));
    }
    let meta = match std::fs::symlink_metadata(path) {
        Ok(meta) => meta,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(cannot_write(flag, path, e)),
    };
    let kind = meta.file_type();
    if kind.is_file() {
        return Ok(());
    }
    let what = if kind.is_symlink() {
        "a symbolic link"
    } else if kind.is_dir() {
        "a directory"
    } else {
        "a device, FIFO or socket"
    };
    Err(CliError::usage(format!(
        "--{flag}: '{path}' is {what}, not a regular file; refusing to replace it (write to a new path or a regular file)"
    )))
}

/// Fails now, naming `--flag`, if `path` could not be written later (see [`check_target`];
/// missing directory, no permission): creates and removes its temporary file. For long runs,
/// before they start.
pub fn check_writable(flag: &str, path: &str) -> Result<(), CliError> {
    check_target(flag, path)?;
    let tmp = temporary_path(Path::new(path));
    std::fs::File::create(&tmp).map_err(|e| cannot_write(flag, path, e))?;
    let _ = std::fs::remove_file(&tmp);
    Ok(())
}

/// Writes `path` atomically: `write` fills the temporary file beside it, which is then renamed
/// over `path`; on any failure the temporary file is removed and `path` is untouched.
pub fn write_atomic(
    flag: &str,
    path: &str,
    write: impl FnOnce(&Path) -> Result<(), CliError>,
) -> Result<(), CliError> {
    check_target(flag, path)?;
    let tmp = temporary_path(Path::new(path));
    // Fail early, with the target's name, when the directory is missing or not writable.
    std::fs::File::create(&tmp).map_err(|e| cannot_write(flag, path, e))?;
    let done = write(&tmp).and_then(|()| {
        std::fs::rename(&tmp, path).map_err(|e| CliError::output(format!("--{flag}: {e}")))
    });
    if done.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    done
}

/// Writes `value` as compact JSON (and a newline) to `path`, atomically.
pub fn write_json_file<T: Serialize>(flag: &str, path: &str, value: &T) -> Result<(), CliError> {
    write_atomic(flag, path, |tmp| {
        let fail = |e: &dyn std::fmt::Display| cannot_write(flag, path, e);
        let file = std::fs::File::create(tmp).map_err(|e| fail(&e))?;
        let mut w = BufWriter::new(file);
        serde_json::to_writer(&mut w, value).map_err(|e| fail(&e))?;
        w.write_all(b"\n")
            .and_then(|()| w.flush())
            .map_err(|e| fail(&e))
    })
}

/// Something drawable on any plotters backend (the CLI's SVG and PNG files).
pub trait Figure {
    /// Draws onto `root` (without `present()`).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError>;
}

/// Draws `figure` into an SVG or PNG file of `size` pixels at `path`, atomically.
pub fn write_figure(
    flag: &str,
    path: &str,
    format: Format,
    size: (u32, u32),
    figure: &impl Figure,
) -> Result<(), CliError> {
    let fail = |e: String| CliError::output(format!("--{flag}: drawing the figure: {e}"));
    write_atomic(flag, path, |tmp| match format {
        Format::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                figure.draw(&root).map_err(|e| fail(e.to_string()))?;
                root.present().map_err(|e| fail(e.to_string()))?;
            }
            std::fs::write(tmp, svg).map_err(|e| cannot_write(flag, path, e))
        }
        Format::Png => {
            let root = BitMapBackend::new(tmp, size).into_drawing_area();
            figure.draw(&root).map_err(|e| fail(e.to_string()))?;
            root.present().map_err(|e| cannot_write(flag, path, e))
        }
        Format::Json => Err(fail("JSON is not a figure format".into())),
    })
}
