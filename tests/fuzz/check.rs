//! The invariant of issue 12's fuzzing and the machinery around it: a case either succeeds with
//! finite outputs or fails with a named error (one non-empty line that names the input and is
//! not too long), within a time and memory budget.
//!
//! - In-process cases run under [`guarded`]: panics are caught (and classified, not printed), the
//!   wall time is measured against [`in_process_budget`], and a watchdog thread ends the whole
//!   test process (exit 3, naming the case) if one case runs past [`hard_limit`] — so a blow-up
//!   is a loud failure, never a hung CI job. Memory is bounded from outside (`scripts/fuzz.sh`
//!   runs the test binary under `prlimit --as`); a kind whose input declares sizes also checks
//!   the process's peak address space around each case ([`vm_peak_bytes`]), which counts a
//!   reservation whether or not a limit is set.
//! - CLI cases run the built binary under `prlimit --as` ([`cli_memory_bytes`]) and are killed
//!   after [`cli_time_limit`]; exit 0 must print JSON whose every `null` is documented, exit 2
//!   one `error: …` line naming a flag; 101 (panic), 134/SIGABRT (abort, out of memory), other
//!   signals and other codes are failures.

use std::collections::HashMap;
use std::fmt;
use std::io::Read;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::process::{Command, Stdio};
use std::sync::{Mutex, OnceLock};
use std::thread::{self, ThreadId};
use std::time::{Duration, Instant};

use serde_json::Value;

/// Longest accepted error message, bytes (one line; a temp file path is part of it).
pub const MAX_MESSAGE_BYTES: usize = 1000;

/// Names of internal quantities: an error naming one of them says the core failed on input it
/// accepted, instead of naming the input.
const INTERNAL_NAMES: &[&str] = &[
    "ekf.",
    "pcrlb.",
    "start_fix.",
    "grid_step_m",
    "blocking_vector",
    "polygons",
];

/// What went wrong in a failing case.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Class {
    /// A panic (in process) or exit 101 (CLI).
    Panic,
    /// SIGABRT or exit 134 without an allocation failure.
    Abort,
    /// Killed by another signal.
    Signal,
    /// An exit code other than 0, 2 (or 101/134).
    BadExit,
    /// `Ok`/exit 0 with a NaN, an infinity or an undocumented `null` in the output.
    NonFinite,
    /// An error that is empty, not one line, or (CLI) does not name a flag.
    UnnamedError,
    /// An error naming an internal quantity (`ekf.covariance`, …) instead of the input.
    InternalError,
    /// An error message longer than [`MAX_MESSAGE_BYTES`].
    LongMessage,
    /// Exit 0 with stdout that is not the documented JSON.
    BadOutput,
    /// Past the time budget (killed, for the CLI).
    OverTime,
    /// An allocation failure under the memory limit.
    OverMemory,
}

/// A failing case: its class and what was seen.
#[derive(Clone, Debug)]
pub struct Failure {
    pub class: Class,
    pub detail: String,
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}: {}", self.class, self.detail)
    }
}

/// A passing case: `Ok` with finite outputs, or a named error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    Ok,
    Err,
}

pub type Verdict = Result<Pass, Failure>;

pub fn fail(class: Class, detail: impl Into<String>) -> Failure {
    Failure {
        class,
        detail: detail.into(),
    }
}

/// `s` cut to `n` bytes (on a char boundary) with its length, for reports.
pub fn clip(s: &str, n: usize) -> String {
    if s.len() <= n {
        return s.to_string();
    }
    let mut end = n;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}… ({} bytes)", &s[..end], s.len())
}

fn env_f64(name: &str) -> Option<f64> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

/// Wall-time budget of one in-process case (`SCATTERLOC_FUZZ_BUDGET_S`; default 5 s optimised,
/// 60 s in a debug build): a multi-target case stopped by the work budget (250 000 candidates)
/// takes about 2.1 s optimised with the PPP models (8.5 µs each), about ten times that in debug.
pub fn in_process_budget() -> Duration {
    let d = if cfg!(debug_assertions) { 60.0 } else { 5.0 };
    Duration::from_secs_f64(env_f64("SCATTERLOC_FUZZ_BUDGET_S").unwrap_or(d))
}

/// After this long one in-process case ends the test process (`SCATTERLOC_FUZZ_HARD_S`, 120 s).
pub fn hard_limit() -> Duration {
    Duration::from_secs_f64(env_f64("SCATTERLOC_FUZZ_HARD_S").unwrap_or(120.0))
}

/// A CLI case is killed after this long (`SCATTERLOC_FUZZ_CLI_S`; default 15 s optimised, 60 s
/// debug).
pub fn cli_time_limit() -> Duration {
    // A case stopped by the multi-target work budget (250 000 candidates) takes up to about
    // 2.5 s in release with the PPP models (about 10 µs each); 15 s leaves room for a loaded machine.
    let d = if cfg!(debug_assertions) { 60.0 } else { 15.0 };
    Duration::from_secs_f64(env_f64("SCATTERLOC_FUZZ_CLI_S").unwrap_or(d))
}

/// Address-space limit of a CLI case (`SCATTERLOC_FUZZ_CLI_MB`, default 2048 MB).
pub fn cli_memory_bytes() -> u64 {
    (env_f64("SCATTERLOC_FUZZ_CLI_MB").unwrap_or(2048.0) * 1024.0 * 1024.0) as u64
}

// ------------------------------------------------------------------------------- messages

/// An error message (core `Display` or the CLI's stderr line without `error: `): one non-empty
/// line, at most [`MAX_MESSAGE_BYTES`], naming no internal quantity.
pub fn check_message(msg: &str) -> Verdict {
    let line = msg.strip_suffix('\n').unwrap_or(msg);
    if line.trim().is_empty() {
        return Err(fail(Class::UnnamedError, "empty error message"));
    }
    if line.contains('\n') {
        return Err(fail(
            Class::UnnamedError,
            format!(
                "error of {} lines: {}",
                line.lines().count(),
                clip(line, 300)
            ),
        ));
    }
    if line.len() > MAX_MESSAGE_BYTES {
        return Err(fail(
            Class::LongMessage,
            format!("error message of {} bytes: {}", line.len(), clip(line, 200)),
        ));
    }
    if let Some(n) = INTERNAL_NAMES.iter().find(|n| line.contains(*n)) {
        return Err(fail(
            Class::InternalError,
            format!("names the internal {n:?}: {line}"),
        ));
    }
    Ok(Pass::Err)
}

/// A core error: its `Display` must pass [`check_message`].
pub fn core_err(e: &scatterloc::Error) -> Verdict {
    check_message(&e.to_string())
}

// ------------------------------------------------------------------------------- finiteness

/// The first NaN or infinity in a `Debug` rendering (`NaN`, `inf`, `-inf` as whole tokens),
/// with context.
pub fn nonfinite_in_debug(what: &str, dbg: &str) -> Result<(), Failure> {
    let b = dbg.as_bytes();
    let word = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    for tok in ["NaN", "inf"] {
        let mut from = 0;
        while let Some(k) = dbg[from..].find(tok) {
            let i = from + k;
            let j = i + tok.len();
            let before_ok = i == 0 || !word(b[i - 1]);
            let after_ok = j >= b.len() || !word(b[j]);
            if before_ok && after_ok {
                let lo = dbg[..i].char_indices().rev().nth(80).map_or(0, |(p, _)| p);
                return Err(fail(
                    Class::NonFinite,
                    format!("{what}: {tok} in …{}", clip(&dbg[lo..], 160)),
                ));
            }
            from = j;
        }
    }
    Ok(())
}

/// `value` is finite.
pub fn finite(what: &str, value: f64) -> Result<(), Failure> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(fail(Class::NonFinite, format!("{what} = {value}")))
    }
}

/// Every `null` in a CLI's JSON output, as paths (`a.b[3].c`).
pub fn null_paths(v: &Value) -> Vec<String> {
    fn walk(v: &Value, here: &str, out: &mut Vec<String>) {
        match v {
            Value::Null => out.push(here.to_string()),
            Value::Array(a) => a
                .iter()
                .enumerate()
                .for_each(|(i, x)| walk(x, &format!("{here}[{i}]"), out)),
            Value::Object(m) => m.iter().for_each(|(k, x)| {
                let p = if here.is_empty() {
                    k.clone()
                } else {
                    format!("{here}.{k}")
                };
                walk(x, &p, out)
            }),
            _ => {}
        }
    }
    let mut out = vec![];
    walk(v, "", &mut out);
    out
}

// ------------------------------------------------------------------------------- in process

thread_local! {
    static IN_CASE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    static LAST_PANIC: std::cell::RefCell<String> = const { std::cell::RefCell::new(String::new()) };
}

type Running = Mutex<HashMap<ThreadId, (Instant, String)>>;

fn running() -> &'static Running {
    static RUNNING: OnceLock<Running> = OnceLock::new();
    static INIT: OnceLock<()> = OnceLock::new();
    INIT.get_or_init(|| {
        // Panics inside a case are recorded, not printed; others keep the default hook.
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if IN_CASE.with(|c| c.get()) {
                let loc = info
                    .location()
                    .map(|l| format!(" at {}:{}", l.file(), l.line()))
                    .unwrap_or_default();
                let msg = info
                    .payload()
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| info.payload().downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                LAST_PANIC.with(|p| *p.borrow_mut() = format!("{}{loc}", clip(&msg, 300)));
            } else {
                default(info);
            }
        }));
        // The watchdog: a case past the hard limit ends the process, naming it.
        thread::spawn(|| loop {
            thread::sleep(Duration::from_millis(500));
            let limit = hard_limit();
            let map = running().lock().unwrap_or_else(|e| e.into_inner());
            if let Some((t0, what)) = map.values().find(|(t0, _)| t0.elapsed() > limit) {
                eprintln!(
                    "\nfuzz watchdog: OverTime: one in-process case has run {:.0} s (> {:.0} s); \
                     stopping the test process. The case: {what}",
                    t0.elapsed().as_secs_f64(),
                    limit.as_secs_f64()
                );
                std::process::exit(3);
            }
        });
    });
    RUNNING.get_or_init(Default::default)
}

/// Runs an in-process case: catches a panic, enforces the time budget, registers the case
/// (`what`) with the watchdog.
pub fn guarded(what: &str, f: impl FnOnce() -> Verdict) -> Verdict {
    let reg = running();
    reg.lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(thread::current().id(), (Instant::now(), clip(what, 2000)));
    IN_CASE.with(|c| c.set(true));
    let t0 = Instant::now();
    let out = catch_unwind(AssertUnwindSafe(f));
    let dt = t0.elapsed();
    IN_CASE.with(|c| c.set(false));
    reg.lock()
        .unwrap_or_else(|e| e.into_inner())
        .remove(&thread::current().id());
    let v = match out {
        Ok(v) => v,
        Err(_) => {
            let msg = LAST_PANIC.with(|p| p.borrow().clone());
            return Err(fail(Class::Panic, format!("panicked: {msg}")));
        }
    };
    if dt > in_process_budget() {
        return Err(fail(
            Class::OverTime,
            format!(
                "took {:.2} s (budget {:.1} s); result {v:?}",
                dt.as_secs_f64(),
                in_process_budget().as_secs_f64()
            ),
        ));
    }
    v
}

// ------------------------------------------------------------------------------- the CLI

/// The binary under test.
pub const BIN: &str = env!("CARGO_BIN_EXE_scatterloc");

/// What the CLI printed.
pub struct CliRun {
    pub code: Option<i32>,
    pub signal: Option<i32>,
    pub timed_out: bool,
    pub stdout: String,
    pub stderr: String,
    pub elapsed: Duration,
}

/// Runs `scatterloc args…` under the memory limit, killed after the time limit.
pub fn run_cli(args: &[String]) -> CliRun {
    run_limited(BIN, args, &[])
}

/// Runs `program args…` (with `envs`) under the memory limit, killed after the time limit.
pub fn run_limited(program: &str, args: &[String], envs: &[(&str, &str)]) -> CliRun {
    use std::os::unix::process::ExitStatusExt;
    let mut child = Command::new("prlimit")
        .arg(format!("--as={}", cli_memory_bytes()))
        .arg("--")
        .arg(program)
        .args(args)
        .envs(envs.iter().copied())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn prlimit scatterloc");
    let reader = |mut r: Box<dyn Read + Send>, cap: u64| {
        thread::spawn(move || {
            let mut buf = Vec::new();
            // Keep at most `cap` bytes; drain the rest.
            let _ = r.by_ref().take(cap).read_to_end(&mut buf);
            let _ = std::io::copy(&mut r, &mut std::io::sink());
            String::from_utf8_lossy(&buf).into_owned()
        })
    };
    // stdout: a legitimate result can be tens of MB (20 000 track steps with covariances);
    // stderr: 4 MB (an echoed 1 MB input fits).
    let out = reader(Box::new(child.stdout.take().expect("stdout")), 256 << 20);
    let err = reader(Box::new(child.stderr.take().expect("stderr")), 4 << 20);
    let t0 = Instant::now();
    let limit = cli_time_limit();
    let mut nap = Duration::from_micros(200);
    let mut timed_out = false;
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if t0.elapsed() > limit {
            // Our own child, by its handle.
            let _ = child.kill();
            timed_out = true;
            break child.wait().expect("wait after kill");
        }
        thread::sleep(nap);
        nap = (nap * 2).min(Duration::from_millis(5));
    };
    let elapsed = t0.elapsed();
    CliRun {
        code: status.code(),
        signal: status.signal(),
        timed_out,
        stdout: out.join().unwrap_or_default(),
        stderr: err.join().unwrap_or_default(),
        elapsed,
    }
}

/// A limited run (CLI or child case) killed at the time limit, or out of memory under the
/// address-space limit.
fn over_limits(run: &CliRun) -> Result<(), Failure> {
    if run.timed_out {
        return Err(fail(
            Class::OverTime,
            format!(
                "killed after {:.1} s (limit {:.0} s)",
                run.elapsed.as_secs_f64(),
                cli_time_limit().as_secs_f64()
            ),
        ));
    }
    if run.stderr.contains("memory allocation of") {
        let first = clip(run.stderr.lines().next().unwrap_or(""), 300);
        return Err(fail(
            Class::OverMemory,
            format!(
                "allocation failure under {} MB: {first}",
                cli_memory_bytes() >> 20
            ),
        ));
    }
    Ok(())
}

/// The CLI invariant: exit 0 and JSON whose nulls `allow_null(path, doc)` accepts, or exit 2 and
/// one `error: …` line that names a flag; anything else is a failure.
pub fn check_cli(run: &CliRun, allow_null: &dyn Fn(&str, &Value) -> bool) -> Verdict {
    let first = |s: &str| clip(s.lines().next().unwrap_or(""), 300);
    over_limits(run)?;
    match (run.code, run.signal) {
        (Some(0), _) => {
            let doc: Value = match serde_json::from_str(&run.stdout) {
                Ok(v) => v,
                Err(e) => {
                    return Err(fail(
                        Class::BadOutput,
                        format!("exit 0, stdout not JSON ({e}): {}", clip(&run.stdout, 200)),
                    ))
                }
            };
            let bad: Vec<String> = null_paths(&doc)
                .into_iter()
                .filter(|p| !allow_null(p, &doc))
                .collect();
            if !bad.is_empty() {
                return Err(fail(
                    Class::NonFinite,
                    format!(
                        "exit 0 with undocumented null at {} ({} in all)",
                        bad.iter().take(6).cloned().collect::<Vec<_>>().join(", "),
                        bad.len()
                    ),
                ));
            }
            Ok(Pass::Ok)
        }
        (Some(2), _) => {
            if !run.stdout.is_empty() {
                return Err(fail(
                    Class::BadOutput,
                    format!("exit 2 with stdout {}", clip(&run.stdout, 200)),
                ));
            }
            let line = run.stderr.strip_suffix('\n').unwrap_or(&run.stderr);
            let Some(msg) = line.strip_prefix("error: ") else {
                return Err(fail(
                    Class::UnnamedError,
                    format!("stderr does not start with 'error: ': {}", clip(line, 300)),
                ));
            };
            check_message(line)?;
            if !msg.contains("--") {
                return Err(fail(
                    Class::UnnamedError,
                    format!("names no flag: {}", clip(line, 300)),
                ));
            }
            Ok(Pass::Err)
        }
        (Some(101), _) => Err(fail(
            Class::Panic,
            format!("exit 101: {}", first(&run.stderr)),
        )),
        (Some(134), _) | (None, Some(6)) => {
            Err(fail(Class::Abort, format!("abort: {}", first(&run.stderr))))
        }
        (None, Some(sig)) => Err(fail(
            Class::Signal,
            format!("signal {sig}: {}", first(&run.stderr)),
        )),
        (code, _) => Err(fail(
            Class::BadExit,
            format!("exit {code:?}: {}", first(&run.stderr)),
        )),
    }
}

/// A directory for one test thread's case files (reused case after case), removed at exit of
/// the thread's [`CaseDir`].
pub struct CaseDir(pub std::path::PathBuf);

impl CaseDir {
    pub fn new(kind: &str) -> CaseDir {
        let dir = std::env::temp_dir().join(format!(
            "scatterloc-fuzz-{}-{kind}-{:?}",
            std::process::id(),
            thread::current().id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("temp dir");
        CaseDir(dir)
    }

    pub fn write(&self, name: &str, text: &str) -> String {
        let p = self.0.join(name);
        std::fs::write(&p, text).expect("write case file");
        p.to_string_lossy().into_owned()
    }
}

impl Drop for CaseDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

// ------------------------------------------------------------------------------- child cases

/// Marker of the verdict line a child case prints.
const VERDICT: &str = "@@fuzz-verdict@@";

/// The child side of an in-process kind that runs its cases in child processes
/// ([`run_child`]). The child is this test binary re-run with the kind's own (parent) test as
/// the exact filter and `SCATTERLOC_FUZZ_CHILD` = kind, `SCATTERLOC_FUZZ_CHILD_FILE` = case: that
/// test calls this first. In a child (`SCATTERLOC_FUZZ_CHILD` set) it runs `run` on the case
/// text if `kind` is the one asked for, prints the verdict line and returns `true`: the test
/// returns without fuzzing. In a normal run it returns `false`. (There is no separate child
/// `#[test]`, which would pass in every normal run without testing anything.)
pub fn child_main(kind: &str, run: impl FnOnce(&str) -> Verdict) -> bool {
    let Ok(asked) = std::env::var("SCATTERLOC_FUZZ_CHILD") else {
        return false;
    };
    if asked != kind {
        return true;
    }
    let path = std::env::var("SCATTERLOC_FUZZ_CHILD_FILE").expect("case file");
    let text = std::fs::read_to_string(path).expect("read case");
    let line = match guarded(&text, || run(&text)) {
        Ok(Pass::Ok) => "ok".to_string(),
        Ok(Pass::Err) => "err".to_string(),
        Err(f) => format!("fail {:?} {}", f.class, f.detail.replace('\n', " ")),
    };
    println!("{VERDICT} {line}");
    true
}

/// Runs an in-process case in a child process of this test binary (its test `test_name`, the
/// kind's parent test, which hands it to [`child_main`]), so
/// that a run-away case is killed at the CLI time limit and bounded by the CLI memory limit.
pub fn run_child(kind: &str, test_name: &str, dir: &CaseDir, text: &str) -> Verdict {
    let file = dir.write("case.json", text);
    let exe = std::env::current_exe().expect("test binary");
    let args: Vec<String> = [
        test_name,
        "--exact",
        "--nocapture",
        "--test-threads=1",
        "-q",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let run = run_limited(
        &exe.to_string_lossy(),
        &args,
        &[
            ("SCATTERLOC_FUZZ_CHILD", kind),
            ("SCATTERLOC_FUZZ_CHILD_FILE", &file),
            ("RUST_BACKTRACE", "0"),
        ],
    );
    over_limits(&run)?;
    let Some(line) = run.stdout.lines().find_map(|l| l.strip_prefix(VERDICT)) else {
        return Err(fail(
            Class::Abort,
            format!(
                "child case ended without a verdict (exit {:?}, signal {:?}): {}",
                run.code,
                run.signal,
                clip(run.stderr.trim(), 300)
            ),
        ));
    };
    let line = line.trim();
    match line {
        "ok" => Ok(Pass::Ok),
        "err" => Ok(Pass::Err),
        _ => {
            let rest = line.strip_prefix("fail ").unwrap_or(line);
            let (class, detail) = rest.split_once(' ').unwrap_or((rest, ""));
            let class = [
                Class::Panic,
                Class::Abort,
                Class::Signal,
                Class::BadExit,
                Class::NonFinite,
                Class::UnnamedError,
                Class::InternalError,
                Class::LongMessage,
                Class::BadOutput,
                Class::OverTime,
                Class::OverMemory,
            ]
            .into_iter()
            .find(|c| format!("{c:?}") == class)
            .unwrap_or(Class::BadOutput);
            Err(fail(class, detail))
        }
    }
}

// ------------------------------------------------------------------------------- memory

/// The process's peak virtual memory size (`VmPeak` of `/proc/self/status`), bytes; `None`
/// where it cannot be read. A case whose call raises it by much reserved that much (an
/// allocation need not be touched to count), whatever the memory limit.
pub fn vm_peak_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmPeak:"))?;
    let kb: u64 = line
        .trim_start_matches("VmPeak:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb << 10)
}
