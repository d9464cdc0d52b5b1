//! Output files of the CLI: the format from the extension, and the one writer every output file
//! goes through (issue 24, docs/cli.md "Output safety"):
//!
//! - the target is checked up front: an empty path, a symbolic link, a directory, a FIFO, a
//!   socket or a device is refused with an error naming the flag, before any work;
//! - each file is written into a temporary file with a random hidden name in the target's
//!   directory, created exclusively (`O_CREAT | O_EXCL`, by `tempfile`): nothing planted at a
//!   predictable name can be followed, and concurrent runs never share a temporary;
//! - the temporary is flushed and `fsync`ed, then renamed over the target (a new target is
//!   created without replacing anything that appeared in the meantime), so a reader sees the
//!   old file or the whole new one, never a torn one;
//! - a command with several outputs stages all of them in an [`OutputSet`] set and renames them
//!   only when every one was written; on any failure the temporaries are removed and nothing new
//!   is left. Two outputs naming one file are refused ([`check_distinct`]).

use std::fs::{File, Permissions};
use std::io::{BufWriter, Write};
use std::os::unix::fs::{FileTypeExt, PermissionsExt};
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;
use tempfile::NamedTempFile;

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

/// "cannot write" for `--flag` once the file was opened: a failed write (a full disk, a
/// file-size limit), exit status 1.
fn write_failed(flag: &str, path: &str, e: impl std::fmt::Display) -> CliError {
    CliError::output(format!("--{flag}: cannot write '{path}': {e}"))
}

/// What is at an output path now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Existing {
    /// Nothing: the file will be created.
    Nothing,
    /// A regular file: it will be replaced.
    File,
}

/// Refuses, naming `--flag`, an empty path and anything at `path` that an atomic write would
/// destroy instead of writing, or that would block or discard the data: a symbolic link (its
/// target would never be written), a directory, a FIFO (opening it waits for a reader), a
/// socket or a device (`/dev/null` would lose the data). A regular file (replaced) or a new path
/// is fine. Nothing is opened.
fn target_kind(flag: &str, path: &str) -> Result<Existing, CliError> {
    if path.is_empty() {
        return Err(CliError::usage(format!("--{flag}: the path is empty")));
    }
    let meta = match std::fs::symlink_metadata(path) {
        Ok(meta) => meta,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Existing::Nothing),
        Err(e) => return Err(cannot_write(flag, path, e)),
    };
    let kind = meta.file_type();
    if kind.is_file() {
        return Ok(Existing::File);
    }
    let what = if kind.is_symlink() {
        "a symbolic link"
    } else if kind.is_dir() {
        "a directory"
    } else if kind.is_fifo() {
        "a FIFO"
    } else if kind.is_socket() {
        "a socket"
    } else if kind.is_char_device() || kind.is_block_device() {
        "a device"
    } else {
        "not a regular file"
    };
    Err(CliError::usage(format!(
        "--{flag}: '{path}' is {what}, not a regular file; refusing to replace it (write to a new path or a regular file)"
    )))
}

/// The directory an output file is written in (`.` for a bare file name).
fn directory_of(path: &str) -> PathBuf {
    match Path::new(path).parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// A new temporary file for `path`: random hidden name in its directory, created exclusively;
/// permissions as a plain `File::create` (0666 less the umask), so the renamed output has the
/// same mode as before issue 24. Removed when dropped.
fn temporary_for(flag: &str, path: &str) -> Result<NamedTempFile, CliError> {
    tempfile::Builder::new()
        .prefix(".scatterloc-")
        .suffix(".tmp")
        .rand_bytes(12)
        .permissions(Permissions::from_mode(0o666))
        .tempfile_in(directory_of(path))
        .map_err(|e| cannot_write(flag, path, e))
}

/// Fails now, naming `--flag`, if `path` could not be written later: a refused kind of target
/// (see the module doc), a missing directory, no permission (a temporary file is created in
/// its directory and removed). Every command calls it for each output before its work starts.
pub fn check_writable(flag: &str, path: &str) -> Result<(), CliError> {
    target_kind(flag, path)?;
    temporary_for(flag, path).map(drop)
}

/// The file `path` names, to compare outputs: its directory made canonical (`.`, `..` and links
/// resolved) joined with its file name; the path as given when the directory cannot be resolved
/// (its own check then fails by name).
fn file_identity(path: &str) -> PathBuf {
    let p = Path::new(path);
    match (std::fs::canonicalize(directory_of(path)), p.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => p.to_path_buf(),
    }
}

/// Two output flags naming one file: exit status 2 naming both (one output would be lost).
fn same_file(first: &str, flag: &str, path: &str) -> CliError {
    CliError::usage(format!(
        "--{first} / --{flag}: both name the file '{path}'; give each output a path of its own"
    ))
}

/// Refuses, naming both flags, two of `outputs` (flag, path) that name one file (`--out a.json
/// --snapshots ./a.json`): the second would replace the first (issue 37). [`OutputSet`] refuses
/// the same when staging; commands call this with their other checks, before their work.
pub fn check_distinct(outputs: &[(&str, &str)]) -> Result<(), CliError> {
    let ids: Vec<PathBuf> = outputs.iter().map(|(_, p)| file_identity(p)).collect();
    for (i, (flag, path)) in outputs.iter().enumerate() {
        if let Some(j) = ids[..i].iter().position(|id| *id == ids[i]) {
            return Err(same_file(outputs[j].0, flag, path));
        }
    }
    Ok(())
}

/// One staged output: its temporary, and where it goes.
struct Staged {
    flag: String,
    path: String,
    /// The file it names ([`file_identity`]).
    identity: PathBuf,
    tmp: NamedTempFile,
}

/// The outputs of one command, staged as temporaries and renamed into place together by
/// [`OutputSet::commit`] once all were written. Dropping the set without committing removes every
/// temporary: a failed command leaves nothing new.
#[derive(Default)]
pub struct OutputSet {
    staged: Vec<Staged>,
}

impl OutputSet {
    /// An empty set.
    pub fn new() -> OutputSet {
        OutputSet::default()
    }

    /// Whether no file is staged.
    pub fn is_empty(&self) -> bool {
        self.staged.is_empty()
    }

    /// A new temporary for `path` (checked), filled by `write`, flushed and synced to disk. A
    /// path naming a file already staged (`same.json`, `./same.json`) is refused naming both
    /// flags ([`check_distinct`]).
    fn stage(
        &mut self,
        flag: &str,
        path: &str,
        write: impl FnOnce(&mut BufWriter<&File>) -> Result<(), CliError>,
    ) -> Result<(), CliError> {
        target_kind(flag, path)?;
        let identity = file_identity(path);
        if let Some(s) = self.staged.iter().find(|s| s.identity == identity) {
            return Err(same_file(&s.flag, flag, path));
        }
        let tmp = temporary_for(flag, path)?;
        {
            let mut w = BufWriter::new(tmp.as_file());
            write(&mut w)?;
            w.flush().map_err(|e| write_failed(flag, path, e))?;
        }
        tmp.as_file()
            .sync_all()
            .map_err(|e| write_failed(flag, path, e))?;
        self.staged.push(Staged {
            flag: flag.to_string(),
            path: path.to_string(),
            identity,
            tmp,
        });
        Ok(())
    }

    /// Stages `value` as compact JSON (and a newline) for `path`.
    pub fn json<T: Serialize>(
        &mut self,
        flag: &str,
        path: &str,
        value: &T,
    ) -> Result<(), CliError> {
        self.stage(flag, path, |w| {
            serde_json::to_writer(&mut *w, value).map_err(|e| write_failed(flag, path, e))?;
            w.write_all(b"\n").map_err(|e| write_failed(flag, path, e))
        })
    }

    /// Stages `bytes` as the whole file `path` (a recording).
    pub fn bytes(&mut self, flag: &str, path: &str, bytes: &[u8]) -> Result<(), CliError> {
        self.stage(flag, path, |w| {
            w.write_all(bytes).map_err(|e| write_failed(flag, path, e))
        })
    }

    /// Stages `figure` drawn as an SVG or PNG of `size` pixels for `path`. A PNG is drawn into
    /// memory and encoded into the temporary (the encoder plotters' own PNG files use, so the
    /// bytes are the same), never through a path.
    pub fn figure(
        &mut self,
        flag: &str,
        path: &str,
        format: Format,
        size: (u32, u32),
        figure: &impl Figure,
    ) -> Result<(), CliError> {
        let fail = |e: String| CliError::output(format!("--{flag}: drawing the figure: {e}"));
        match format {
            Format::Svg => {
                let mut svg = String::new();
                if let Some(own) = figure.svg(size) {
                    svg = own.map_err(|e| fail(e.to_string()))?;
                } else {
                    let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                    figure.draw(&root).map_err(|e| fail(e.to_string()))?;
                    root.present().map_err(|e| fail(e.to_string()))?;
                }
                self.stage(flag, path, |w| {
                    w.write_all(svg.as_bytes())
                        .map_err(|e| write_failed(flag, path, e))
                })
            }
            Format::Png => {
                let (width, height) = size;
                let mut rgb = vec![0u8; width as usize * height as usize * 3];
                {
                    let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
                    figure.draw(&root).map_err(|e| fail(e.to_string()))?;
                    root.present().map_err(|e| fail(e.to_string()))?;
                }
                self.stage(flag, path, |w| {
                    image::write_buffer_with_format(
                        w,
                        &rgb,
                        width,
                        height,
                        image::ColorType::Rgb8,
                        image::ImageOutputFormat::Png,
                    )
                    .map_err(|e| write_failed(flag, path, e))
                })
            }
            Format::Json => Err(fail("JSON is not a figure format".into())),
        }
    }

    /// Renames every staged temporary over its target. All targets are checked again first
    /// (a link, FIFO or directory that appeared meanwhile is refused before anything is
    /// renamed). A new target is created without replacing anything (`persist_noclobber`), an
    /// existing regular file is replaced atomically (`rename`, which never follows a link). If a
    /// rename still fails, the files this commit created are removed again.
    ///
    /// Across processes too (issue 37 item 9: concurrent runs into one directory left a mixed
    /// set): the targets' directories are locked (an exclusive `flock` on each directory, in a
    /// fixed order) while the set is renamed, so commits over the same files take turns and
    /// each leaves a whole set, the last one winning. A directory that cannot be opened or
    /// locked is renamed into without the lock (as before).
    pub fn commit(self) -> Result<(), CliError> {
        for s in &self.staged {
            target_kind(&s.flag, &s.path)?;
        }
        let _locks = lock_directories(self.staged.iter().map(|s| s.identity.as_path()));
        let mut created: Vec<String> = Vec::new();
        for (k, s) in self.staged.into_iter().enumerate() {
            if k > 0 {
                test_pause();
            }
            match persist(s.tmp, &s.flag, &s.path) {
                Ok(Existing::Nothing) => created.push(s.path),
                Ok(Existing::File) => {}
                Err(e) => {
                    for p in &created {
                        let _ = std::fs::remove_file(p);
                    }
                    return Err(e);
                }
            }
        }
        Ok(())
    }
}

/// The directories of `files` (deduplicated, sorted: every process takes them in the same
/// order), each opened and locked exclusively; the locks hold until the files are dropped.
fn lock_directories<'a>(files: impl Iterator<Item = &'a Path>) -> Vec<File> {
    let dirs: std::collections::BTreeSet<&Path> = files.filter_map(Path::parent).collect();
    dirs.into_iter()
        .filter_map(|d| File::open(d).ok().filter(|f| f.lock().is_ok()))
        .collect()
}

/// Debug builds only: sleeps `SCATTERLOC_TEST_COMMIT_PAUSE_MS` between two renames of a set,
/// so a test can make two commits overlap (`tests/cli/outputs.rs`).
fn test_pause() {
    if cfg!(debug_assertions) {
        if let Some(ms) = std::env::var("SCATTERLOC_TEST_COMMIT_PAUSE_MS")
            .ok()
            .and_then(|v| v.parse::<u64>().ok())
        {
            std::thread::sleep(std::time::Duration::from_millis(ms.min(10_000)));
        }
    }
}

/// Renames `tmp` to `path`: see [`OutputSet::commit`]. Returns what was there before.
fn persist(mut tmp: NamedTempFile, flag: &str, path: &str) -> Result<Existing, CliError> {
    let fail = |e: std::io::Error| write_failed(flag, path, e);
    // A concurrent writer may create the target between the check and the rename: then it is
    // a regular file and is replaced (the last writer wins, whole).
    for _ in 0..4 {
        match target_kind(flag, path)? {
            Existing::Nothing => match tmp.persist_noclobber(path) {
                Ok(_) => return Ok(Existing::Nothing),
                Err(e) if e.error.kind() == std::io::ErrorKind::AlreadyExists => tmp = e.file,
                // A file system without a no-replace rename or hard links (e.g. FAT on an old
                // kernel): the target was just checked to be absent, a plain rename then.
                Err(e) => {
                    return e
                        .file
                        .persist(path)
                        .map(|_| Existing::Nothing)
                        .map_err(|e| fail(e.error))
                }
            },
            Existing::File => {
                return tmp
                    .persist(path)
                    .map(|_| Existing::File)
                    .map_err(|e| fail(e.error))
            }
        }
    }
    Err(fail(std::io::Error::other(
        "the target kept changing during the write",
    )))
}

/// Writes `value` as compact JSON (and a newline) to `path`, atomically (one-file [`OutputSet`]).
pub fn write_json_file<T: Serialize>(flag: &str, path: &str, value: &T) -> Result<(), CliError> {
    let mut out = OutputSet::new();
    out.json(flag, path, value)?;
    out.commit()
}

/// Something drawable on any plotters backend (the CLI's SVG and PNG files).
pub trait Figure {
    /// Draws onto `root` (without `present()`).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError>;

    /// The figure's own SVG text of `size` px, when it has one (the map figure: its map as one
    /// embedded image); `None` draws [`Figure::draw`] through plotters' SVG backend.
    fn svg(&self, _size: (u32, u32)) -> Option<Result<String, ChartError>> {
        None
    }
}

/// Draws `figure` into an SVG or PNG file of `size` pixels at `path`, atomically (one-file
/// [`OutputSet`]).
pub fn write_figure(
    flag: &str,
    path: &str,
    format: Format,
    size: (u32, u32),
    figure: &impl Figure,
) -> Result<(), CliError> {
    let mut out = OutputSet::new();
    out.figure(flag, path, format, size, figure)?;
    out.commit()
}

/// A figure to write: its path and format (`--out`).
pub type FigureOut<'a> = Option<(&'a str, Format)>;

/// `--out` and `--json` of a result: formats checked, both writable.
pub fn result_outputs<'a>(
    out: Option<&'a str>,
    json: Option<&'a str>,
) -> Result<(FigureOut<'a>, Option<&'a str>), CliError> {
    let figure = match out {
        Some(p) => Some((p, Format::of("out", p, &[Format::Svg, Format::Png])?)),
        None => None,
    };
    let json = match json {
        Some(p) => Format::of("json", p, &[Format::Json]).map(|_| Some(p))?,
        None => None,
    };
    if let Some((p, _)) = figure {
        check_writable("out", p)?;
    }
    if let Some(p) = json {
        check_writable("json", p)?;
    }
    Ok((figure, json))
}
