//! Helpers of the CLI tests (`cli.rs`, `cli/`): a temporary
//! directory, running the binary, and the "exit 2 + one stderr line naming the field" contract
//! for bad input.

use std::path::PathBuf;
use std::process::{Command, Output, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use serde_json::Value;

/// The binary under test.
pub const BIN: &str = env!("CARGO_BIN_EXE_scatterloc");
/// The fast profile of spec §9.5 with small counts.
pub const FAST: [&str; 6] = ["--runs", "64", "--noise-runs", "2", "--dt", "0.1"];

/// A fresh directory under the system temp dir, removed on drop.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new() -> TempDir {
        static N: AtomicUsize = AtomicUsize::new(0);
        let n = N.fetch_add(1, Ordering::SeqCst);
        let dir = std::env::temp_dir().join(format!("scatterloc-trk-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    pub fn path(&self, name: &str) -> String {
        self.0.join(name).to_string_lossy().into_owned()
    }

    /// Writes `v` as JSON to `name`; returns the path.
    pub fn write(&self, name: &str, v: &Value) -> String {
        self.write_text(name, &v.to_string())
    }

    /// Writes `text` to `name`; returns the path.
    pub fn write_text(&self, name: &str, text: &str) -> String {
        let p = self.path(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    /// File names in the directory, sorted.
    pub fn files(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

pub fn run(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .output()
        .expect("run scatterloc")
}

/// Runs, expects success and one line of JSON on stdout without NaN.
pub fn ok_json_line(args: &[&str]) -> Value {
    let out = run(args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(stdout.lines().count(), 1, "{stdout}");
    ok_json_output(args, &out)
}

/// Runs, expects success and JSON (any layout) on stdout without NaN.
pub fn ok_json(args: &[&str]) -> Value {
    ok_json_output(args, &run(args))
}

fn ok_json_output(args: &[&str], out: &Output) -> Value {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{args:?} failed: {err}");
    assert!(
        !stdout.contains("NaN") && !stdout.contains("inf"),
        "{stdout}"
    );
    serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{e}: {stdout}"))
}

/// Runs, expects exit status 2, empty stdout and exactly one newline-terminated stderr line
/// containing every needle; returns that line.
pub fn fails(args: &[&str], needles: &[&str]) -> String {
    fails_output(args, &run(args), needles)
}

/// [`fails`] for an `out` already run (e.g. with environment variables set).
pub fn fails_output(args: &[&str], out: &Output, needles: &[&str]) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{args:?}: stderr {err}");
    assert!(out.stdout.is_empty(), "{args:?}: stdout not empty");
    assert_eq!(err.lines().count(), 1, "{args:?}: not one line: {err:?}");
    assert!(err.ends_with('\n'));
    for n in needles {
        assert!(err.contains(n), "{args:?}: {err:?} lacks {n:?}");
    }
    err
}

pub fn read_json(path: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

pub fn floats(v: &Value) -> Vec<f64> {
    let a = v.as_array().unwrap_or_else(|| panic!("not an array: {v}"));
    a.iter().map(|x| x.as_f64().unwrap()).collect()
}

/// Starts `cmd` (stdout and stderr captured), sends it SIGINT as Ctrl-C does after 1.5 s (time
/// to install the handler and start, in a debug build on a possibly busy machine; the shell's
/// built-in `kill`, no extra package), waits up to 60 s for it to stop and returns its output.
/// Panics, naming `what`, if it does not stop.
pub fn interrupted(cmd: &mut Command, what: &str) -> Output {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run scatterloc");
    std::thread::sleep(Duration::from_millis(1500));
    let kill = Command::new("sh")
        .args(["-c", &format!("kill -INT {}", child.id())])
        .status();
    assert!(kill.unwrap().success());
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("{what} did not stop after SIGINT");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}
