//! The proptest driver of one input kind: a fixed seed and RNG algorithm (deterministic CI),
//! the case count from the environment, regressions saved beside `tests/fuzz.rs`, per-kind
//! counts and time printed at the end, and the known-failure list of issue 12.

use std::collections::BTreeMap;
use std::time::Instant;

use proptest::strategy::Strategy;
use proptest::test_runner::{
    Config, FileFailurePersistence, RngAlgorithm, RngSeed, TestCaseError, TestError, TestRunner,
};

use super::check::{Class, Failure, Pass, Verdict};

/// A failure class the current code is known to have (issue 12), matched by kind, class and a
/// needle found in the failure's detail or in the case's mutation list. A match counts as
/// "known" (and passes) unless `SCATTERLOC_FUZZ_STRICT=1`. Remove an entry once fixed: the
/// summary line prints how often each one was seen.
pub struct Known {
    pub kind: &'static str,
    pub class: Class,
    /// Substrings, all of which must occur in "detail ‖ mutations" (empty: any).
    pub needles: &'static [&'static str],
    /// Substrings, one of which must occur too (empty: any).
    pub any_of: &'static [&'static str],
    /// The issue 12 item, in words.
    pub issue: &'static str,
}

/// Cases per kind: `SCATTERLOC_FUZZ_CASES` if set, else `default`.
pub fn cases(default: u32) -> u32 {
    std::env::var("SCATTERLOC_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn strict() -> bool {
    std::env::var("SCATTERLOC_FUZZ_STRICT").is_ok_and(|v| v == "1")
}

/// The seed: `SCATTERLOC_FUZZ_SEED` (default 12) mixed with the kind's name.
fn seed(kind: &str) -> u64 {
    let base: u64 = std::env::var("SCATTERLOC_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(12);
    kind.bytes().fold(base ^ 0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// One case as the kind's `run` sees it: the verdict and a description (the mutations).
pub struct Case {
    pub verdict: Verdict,
    pub what: String,
}

#[derive(Default)]
struct Stats {
    ok: u64,
    err: u64,
    known: BTreeMap<&'static str, u64>,
    /// Collect mode: per failure signature, the count and the shortest case seen.
    seen: BTreeMap<String, (u64, String)>,
}

/// `SCATTERLOC_FUZZ_COLLECT=1`: no case fails; every distinct failure (class and detail with
/// digits masked) is printed at the end with its count and shortest case, known or not.
fn collect() -> bool {
    std::env::var("SCATTERLOC_FUZZ_COLLECT").is_ok_and(|v| v == "1")
}

fn signature(f: &Failure) -> String {
    let masked: String = f
        .detail
        .chars()
        .map(|c| if c.is_ascii_digit() { '#' } else { c })
        .collect();
    let mut sig = format!("{:?}: {masked}", f.class);
    if sig.len() > 110 {
        let mut end = 110;
        while !sig.is_char_boundary(end) {
            end -= 1;
        }
        sig.truncate(end);
    }
    sig
}

/// Runs `run` on `cases(default_cases)` values of `strategy`, deterministic, and panics with the
/// shrunk case on an unknown failure.
pub fn fuzz<S: Strategy>(
    source_file: &'static str,
    kind: &'static str,
    default_cases: u32,
    known: &[Known],
    strategy: S,
    run: impl Fn(&S::Value) -> Case,
) {
    let n = cases(default_cases);
    let config = Config {
        cases: n,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(seed(kind)),
        failure_persistence: Some(Box::new(FileFailurePersistence::SourceParallel(
            "proptest-regressions",
        ))),
        source_file: Some(source_file),
        max_shrink_iters: 400,
        max_shrink_time: 120_000,
        max_global_rejects: 0,
        ..Config::default()
    };
    let stats = std::cell::RefCell::new(Stats::default());
    let t0 = Instant::now();
    let mut runner = TestRunner::new(config);
    let result = runner.run(&strategy, |v| {
        let case = run(&v);
        let mut s = stats.borrow_mut();
        match case.verdict {
            Ok(Pass::Ok) => s.ok += 1,
            Ok(Pass::Err) => s.err += 1,
            Err(f) if collect() => {
                let hay = format!("{} ‖ {}", f.detail, case.what);
                let tag = match known.iter().find(|k| {
                    (k.kind == "*" || k.kind == kind)
                        && k.class == f.class
                        && k.needles.iter().all(|n| hay.contains(n))
                        && (k.any_of.is_empty() || k.any_of.iter().any(|n| hay.contains(n)))
                }) {
                    Some(k) => format!("known ({})", k.issue),
                    None => "UNKNOWN".to_string(),
                };
                let e = s
                    .seen
                    .entry(format!("{tag} {}", signature(&f)))
                    .or_insert((0, String::new()));
                e.0 += 1;
                let this = report(&f, &case.what);
                if e.1.is_empty() || this.len() < e.1.len() {
                    e.1 = this;
                }
            }
            Err(f) => {
                let hay = format!("{} ‖ {}", f.detail, case.what);
                let k = known.iter().find(|k| {
                    (k.kind == "*" || k.kind == kind)
                        && k.class == f.class
                        && k.needles.iter().all(|n| hay.contains(n))
                        && (k.any_of.is_empty() || k.any_of.iter().any(|n| hay.contains(n)))
                });
                match k {
                    Some(k) if !strict() => *s.known.entry(k.issue).or_default() += 1,
                    _ => return Err(TestCaseError::fail(report(&f, &case.what))),
                }
            }
        }
        Ok(())
    });
    let s = stats.into_inner();
    let secs = t0.elapsed().as_secs_f64();
    let mut line = format!(
        "fuzz {kind:<20} {n:>6} cases {:>7.1} s ({:.2} ms/case): {} ok, {} named errors",
        secs,
        1e3 * secs / (s.ok + s.err + s.known.values().sum::<u64>()).max(1) as f64,
        s.ok,
        s.err
    );
    for (issue, c) in &s.known {
        line.push_str(&format!("; known failure ×{c}: {issue}"));
    }
    for (sig, (c, example)) in &s.seen {
        line.push_str(&format!("\n  [{kind}] ×{c} {sig}\n{example}"));
    }
    eprintln!("{line}");
    match result {
        Ok(()) => {}
        Err(TestError::Fail(reason, _)) => {
            panic!("fuzz {kind}: a case breaks the invariant (shrunk):\n{reason}")
        }
        Err(TestError::Abort(reason)) => panic!("fuzz {kind}: aborted: {reason}"),
    }
}

fn report(f: &Failure, what: &str) -> String {
    format!("  failure: {f}\n  case:    {what}")
}
