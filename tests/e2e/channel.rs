//! Issues 26 §1 and 36: the channel view's worker against the CLI. The CLI simulates a
//! 300-snapshot, 4-link, 241-subcarrier recording of the hangar walk (`cir simulate`), estimates
//! it (`cir estimate`, with its calibration recording) and tracks it (`cir track`, with the
//! calibration recording and the truth, and again without a calibration: the background learnt
//! from the recording); the page loads the same files through `www/js/channel-job.js` (its
//! worker runs the core's `ChannelJob`), and its `EST.json` and both `TRACK.json` equal the CLI's
//! files: the same keys, lengths, strings, booleans and nulls, every number within `EST_TOL` /
//! `TRACK_TOL` = 1e-12 relative (the counts of numbers not bit-equal and the largest difference
//! are printed). The page's timings (reading the files, estimating the statics and paths,
//! tracking, in the worker) are printed for both jobs (target: 0.5 s for the chain). Bad files
//! and settings through the same path give named errors: a zip bomb (a member declaring more
//! than the page's cap, and one that inflates past what it declares), a wrong array shape, a
//! file over the size cap, statics "clusters" without an empty area, an unknown setting. Stop
//! rejects the running job and the next job runs.

use std::io::Write;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use fantoccini::Client;
use serde_json::Value;

use scatterloc::error::limits::MAX_PAGE_RECORDING_BYTES;
use scatterloc::npz::read_recording;

use super::ui::temp_dir;
use super::{console_errors, js, open, with_browser};

const BIN: &str = env!("CARGO_BIN_EXE_scatterloc");

/// Runs the CLI with `args`; panics with its stderr unless it succeeds.
pub(super) fn cli(args: &[&str]) -> Vec<u8> {
    let out = Command::new(BIN).args(args).output().unwrap();
    assert!(
        out.status.success(),
        "scatterloc {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

fn unbase64(s: &str) -> Vec<u8> {
    let val = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    };
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    for q in s.as_bytes().chunks(4) {
        let pad = q.iter().filter(|&&c| c == b'=').count();
        let n = q.iter().fold(0u32, |n, &c| {
            n << 6 | if c == b'=' { 0 } else { val(c) as u32 }
        });
        let b = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&b[..3 - pad]);
    }
    out
}

/// A recording's times, links, samples (re, im) and noise variances as JSON, for [`compare`].
fn recording_value(r: &scatterloc::channel::Recording) -> Value {
    serde_json::json!({
        "t_s": r.t_s,
        "links": r.links,
        "layout": r.layout.array(),
        "samples": r.samples.iter().flat_map(|c| [c.re, c.im]).collect::<Vec<f64>>(),
        "noise_var": r.noise_var,
    })
}

pub(super) fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for (i, shift) in [18, 12, 6, 0].into_iter().enumerate() {
            if i <= c.len() {
                s.push(A[(n >> shift & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// The CLI's files of the test: (scenario text, recording, calibration, truth text, EST.json
/// and TRACK.json with the calibration, TRACK.json without one).
struct Files {
    scenario: String,
    recording: Vec<u8>,
    calibration: Vec<u8>,
    truth: String,
    estimates: Value,
    track: Value,
    track_learnt: Value,
}

fn cli_files(dir: &Path) -> Files {
    let p = |n: &str| dir.join(n).to_string_lossy().into_owned();
    let scenario = String::from_utf8(cli(&["preset", "sensors2019"])).unwrap();
    std::fs::write(p("s.json"), &scenario).unwrap();
    // 5.98 s at 20 ms: snapshots at 0, 0.02, …, 5.98 s = 300.
    let sim = cli(&[
        "cir",
        "simulate",
        "--scenario",
        &p("s.json"),
        "--out-dir",
        &p("sim"),
        "--duration",
        "5.98",
        "--dt",
        "0.02",
        "--calibration-duration",
        "0.4",
        "--seed",
        "1",
    ]);
    let summary: Value = serde_json::from_slice(&sim).unwrap();
    assert_eq!(summary["snapshots"], 300, "{summary}");
    assert_eq!(summary["links"], 4, "{summary}");
    assert_eq!(summary["subcarriers"], 241, "{summary}");
    let (rec, cal, truth) = (
        p("sim/recording.npz"),
        p("sim/calibration.npz"),
        p("sim/truth.json"),
    );
    cli(&[
        "cir",
        "estimate",
        "--scenario",
        &p("s.json"),
        "--calibration",
        &cal,
        "--cir",
        &rec,
        "--out",
        &p("est.json"),
    ]);
    cli(&[
        "cir",
        "track",
        "--scenario",
        &p("s.json"),
        "--cir",
        &rec,
        "--truth",
        &truth,
        "--out",
        &p("track-learnt.json"),
    ]);
    cli(&[
        "cir",
        "track",
        "--scenario",
        &p("s.json"),
        "--calibration",
        &cal,
        "--cir",
        &rec,
        "--truth",
        &truth,
        "--out",
        &p("track.json"),
    ]);
    let json = |f: &str| serde_json::from_slice(&std::fs::read(p(f)).unwrap()).unwrap();
    Files {
        scenario,
        recording: std::fs::read(&rec).unwrap(),
        calibration: std::fs::read(&cal).unwrap(),
        truth: std::fs::read_to_string(&truth).unwrap(),
        estimates: json("est.json"),
        track: json("track.json"),
        track_learnt: json("track-learnt.json"),
    }
}

/// Relative tolerances of the page's numbers against the CLI's: 1e-12, as the issue asks. The
/// page's wasm and the native CLI run the same code in the same order, and the core's elementary
/// functions are the `libm` crate's on both (`crate::math`): the platform's `sin`/`cos`/`ln`/`exp`
/// (glibc natively, Rust's musl port in wasm) differ in the last bit, which the estimator's fits
/// carried to 9.6e-10 and the start fix's LM iterations to 1.1e-7 (measured 2026-12-04 before
/// the change).
const EST_TOL: f64 = 1e-12;
/// See [`EST_TOL`].
pub(super) const TRACK_TOL: f64 = 1e-12;

/// What [`compare`] found.
pub(super) struct Diff {
    /// The relative tolerance.
    tol: f64,
    /// Mismatches beyond `tol` and structural ones (keys, lengths, strings, nulls).
    errors: Vec<String>,
    /// Numbers compared.
    numbers: usize,
    /// Numbers not bit-equal.
    inexact: usize,
    /// Numbers beyond 1e-12 relative.
    beyond_1e12: usize,
    /// Largest relative difference.
    max_rel: f64,
}

impl Diff {
    pub(super) fn new(tol: f64) -> Diff {
        Diff {
            tol,
            errors: Vec::new(),
            numbers: 0,
            inexact: 0,
            beyond_1e12: 0,
            max_rel: 0.0,
        }
    }
}

/// Compares `a` (the page's) and `b` (the CLI's) at `path`: numbers within `d.tol` relative
/// (of the larger magnitude; exact for 0), everything else (keys, lengths, strings, booleans,
/// nulls) equal.
pub(super) fn compare(path: &str, a: &Value, b: &Value, d: &mut Diff) {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            d.numbers += 1;
            if x != y {
                d.inexact += 1;
                let rel = (x - y).abs() / x.abs().max(y.abs());
                d.max_rel = d.max_rel.max(rel);
                if rel > 1e-12 {
                    d.beyond_1e12 += 1;
                }
                if rel > d.tol {
                    d.errors.push(format!("{path}: page {x:e}, CLI {y:e}"));
                }
            }
        }
        (Value::Array(x), Value::Array(y)) => {
            if x.len() != y.len() {
                d.errors
                    .push(format!("{path}: page {} entries, CLI {}", x.len(), y.len()));
                return;
            }
            for (i, (x, y)) in x.iter().zip(y).enumerate() {
                compare(&format!("{path}[{i}]"), x, y, d);
            }
        }
        (Value::Object(x), Value::Object(y)) => {
            let (kx, ky): (Vec<_>, Vec<_>) = (x.keys().collect(), y.keys().collect());
            if kx != ky {
                d.errors
                    .push(format!("{path}: page keys {kx:?}, CLI keys {ky:?}"));
                return;
            }
            for (k, v) in x {
                compare(&format!("{path}.{k}"), v, &y[k], d);
            }
        }
        _ => {
            if a != b {
                d.errors.push(format!("{path}: page {a}, CLI {b}"));
            }
        }
    }
}

/// Asserts that `d` found no mismatch and prints its counts.
pub(super) fn check(what: &str, d: &Diff) {
    println!(
        "{what}: {} numbers, {} not bit-equal, {} beyond 1e-12 relative, largest relative \
         difference {:.2e}",
        d.numbers, d.inexact, d.beyond_1e12, d.max_rel
    );
    assert!(
        d.errors.is_empty(),
        "{what}: {} differences beyond {:e} or structural, first: {:?}",
        d.errors.len(),
        d.tol,
        &d.errors[..d.errors.len().min(10)]
    );
}

/// Starts `jobs.start(files, settings)` in the page (the module imported once into
/// `window.__ch`); the outcome lands in `window.__chOut` ({state: 'done', r} or {state:
/// 'error', message, stopped}). `files` are (recording, calibration) as base64 or a script
/// expression, so a test can hand over a file built in the page.
pub(super) async fn start_job(
    c: &Client,
    scenario: &str,
    recording_b64: &str,
    calibration_b64: &str,
    truth: Option<&str>,
    settings: &str,
) -> Result<(), String> {
    c.execute(
        "const [scenario, rec, cal, truth, settings] = arguments; \
         const b = (s) => Uint8Array.from(atob(s), (ch) => ch.charCodeAt(0)); \
         window.__chOut = { state: 'running', progress: [] }; \
         (async () => { \
           if (!window.__ch) { \
             const m = await import('/js/channel-job.js'); \
             window.__ch = { m, jobs: new m.ChannelJobs() }; \
           } \
           const out = window.__chOut; \
           const files = { scenario, recording: rec === 'BIG' ? new Uint8Array(window.__big) : b(rec), \
             calibration: cal ? b(cal) : null, truth }; \
           try { \
             const r = await window.__ch.jobs.start(files, JSON.parse(settings), \
               (p) => out.progress.push(p)); \
             Object.assign(out, { state: 'done', r }); \
           } catch (e) { \
             Object.assign(out, { state: 'error', message: String(e.message), \
               stopped: e instanceof window.__ch.m.ChannelStopped }); \
           } \
         })();",
        vec![
            Value::from(scenario),
            Value::from(recording_b64),
            Value::from(calibration_b64),
            truth.map_or(Value::Null, Value::from),
            Value::from(settings),
        ],
    )
    .await
    .map_err(|e| format!("start_job: {e}"))?;
    Ok(())
}

/// Waits for the job's outcome (`window.__chOut` once not running).
pub(super) async fn outcome(c: &Client, within: Duration) -> Result<Value, String> {
    let t0 = Instant::now();
    loop {
        let o = js(
            c,
            "const o = window.__chOut; return o && o.state !== 'running' ? \
             { state: o.state, message: o.message || null, stopped: !!o.stopped, \
               progress: o.progress.length, \
               last: o.progress.length ? o.progress[o.progress.length - 1] : null, \
               r: o.r ? { summary: o.r.summary, timings: o.r.timings, ms: o.r.ms, \
                 wallMs: o.r.wallMs, estimates: o.r.estimates, track: o.r.track, \
                 figure_len: o.r.figure.length, errors: o.r.errors } : null } : null",
        )
        .await?;
        if !o.is_null() {
            return Ok(o);
        }
        if t0.elapsed() > within {
            return Err("the channel job did not finish in time".into());
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// The message of a job expected to fail.
async fn failure(c: &Client, scenario: &str, rec: &str, cal: &str) -> Result<String, String> {
    failure_with(c, scenario, rec, cal, "{}").await
}

/// The message of a job with `settings` expected to fail.
async fn failure_with(
    c: &Client,
    scenario: &str,
    rec: &str,
    cal: &str,
    settings: &str,
) -> Result<String, String> {
    start_job(c, scenario, rec, cal, None, settings).await?;
    let o = outcome(c, Duration::from_secs(60)).await?;
    if o["state"] != "error" {
        return Err(format!("expected an error, got {o}"));
    }
    Ok(o["message"].as_str().unwrap_or_default().to_string())
}

/// An uncompressed-size-patched one-member zip: the member `name` holds `len` zero bytes
/// (deflated), its headers declare `declared` bytes.
fn zip_bomb(name: &str, len: usize, declared: Option<u32>) -> Vec<u8> {
    let mut w = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    w.start_file(name, opts).unwrap();
    let zeros = vec![0u8; 1 << 20];
    for _ in 0..len >> 20 {
        w.write_all(&zeros).unwrap();
    }
    let mut z = w.finish().unwrap().into_inner();
    if let Some(size) = declared {
        let find = |z: &[u8], sig: &[u8]| z.windows(4).position(|w| w == sig).unwrap();
        let local = find(&z, b"PK\x03\x04");
        z[local + 22..local + 26].copy_from_slice(&size.to_le_bytes());
        let central = find(&z, b"PK\x01\x02");
        z[central + 24..central + 28].copy_from_slice(&size.to_le_bytes());
    }
    z
}

/// A `.npy` file (version 1.0) of dtype `descr`, `shape` text and raw `data`.
fn npy(descr: &str, shape: &str, data: &[u8]) -> Vec<u8> {
    let mut h = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + h.len() + 1) % 64 != 0 {
        h.push(' ');
    }
    h.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(h.len() as u16).to_le_bytes());
    out.extend_from_slice(h.as_bytes());
    out.extend_from_slice(data);
    out
}

/// A stored (uncompressed) zip of `members`.
fn npz(members: &[(&str, Vec<u8>)]) -> Vec<u8> {
    let mut w = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let opts =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    for (name, data) in members {
        w.start_file(*name, opts).unwrap();
        w.write_all(data).unwrap();
    }
    w.finish().unwrap().into_inner()
}

/// Prints a job's timings (`r`: the page's result) as the report quotes them.
fn print_timings(what: &str, r: &Value) {
    let t = &r["timings"];
    let ms = |k: &str| t[k].as_f64().unwrap();
    let chain = ms("parse_ms") + ms("estimate_ms") + ms("track_ms");
    println!(
        "channel view, 300 snapshots × 4 links × 241 subcarriers, {what}, in the worker: parse \
         {:.0} ms, statics + paths {:.0} ms, track {:.0} ms → parse + estimation + tracking \
         {chain:.0} ms (target ≤ 500 ms); delay figure {:.0} ms; worker total {:.0} ms, start() \
         to result {:.0} ms",
        ms("parse_ms"),
        ms("estimate_ms"),
        ms("track_ms"),
        ms("figure_ms"),
        r["ms"].as_f64().unwrap(),
        r["wallMs"].as_f64().unwrap(),
    );
}

#[test]
#[ignore = "needs chromedriver, headless Chromium and the wasm package (www/pkg)"]
fn channel_view_worker_equals_the_cli() {
    let dir = temp_dir("channel");
    let f = cli_files(&dir);
    let (rec64, cal64) = (base64(&f.recording), base64(&f.calibration));
    // A member declaring 300 MiB (over the page's 256 MiB cap; 300 kB compressed), and one
    // declaring 1000 bytes that inflates to 64 MiB.
    let declared_bomb = zip_bomb("cfr.npy", 300 << 20, None);
    assert!(declared_bomb.len() < 1 << 20, "{}", declared_bomb.len());
    let lying_bomb = zip_bomb("cfr.npy", 64 << 20, Some(1000));
    // t_s of shape (2, 2).
    let wrong = npz(&[("t_s.npy", npy("<f8", "(2, 2)", &[0u8; 32]))]);
    with_browser(async |c, port, _| {
        open(c, port).await?;
        // The page's estimates and track.
        start_job(c, &f.scenario, &rec64, &cal64, Some(&f.truth), "{}").await?;
        let o = outcome(c, Duration::from_secs(600)).await?;
        if o["state"] != "done" {
            return Err(format!("the channel job failed: {o}"));
        }
        let r = &o["r"];
        let est: Value = serde_json::from_str(r["estimates"].as_str().unwrap()).unwrap();
        let track: Value = serde_json::from_str(r["track"].as_str().unwrap()).unwrap();
        let (mut de, mut dt) = (Diff::new(EST_TOL), Diff::new(TRACK_TOL));
        compare("EST", &est, &f.estimates, &mut de);
        compare("TRACK", &track, &f.track, &mut dt);
        check("EST.json", &de);
        check("TRACK.json", &dt);
        let (n_est, n_track) = (de.numbers, dt.numbers);
        // Not trivially small (with the background subtracted, about 22 000 and 9 600 on
        // 2026-12-06: fewer paths per snapshot than the 30 000 of the full responses).
        assert!(n_est > 10_000 && n_track > 5_000, "{n_est} {n_track}");
        assert!(track["start"].is_object(), "the track never started");
        assert!(
            track["error"]["median_m"].as_f64().unwrap() < 0.5,
            "{}",
            track["error"]
        );
        assert_eq!(r["summary"]["snapshots"], 300);
        assert_eq!(r["summary"]["samples_per_link"], 241);
        assert!(
            o["progress"].as_u64().unwrap() > 0,
            "no progress reported: {o}"
        );
        assert!(r["figure_len"].as_u64().unwrap() > 1000);
        assert_eq!(r["summary"]["calibration"]["source"], "file");
        print_timings("with the 21-snapshot calibration recording", r);
        // The pictures on the page's main thread from the worker's texts: the SVG by the CLI's
        // chart code names every link's panel; the overlay of the last snapshot is the track's.
        let fig = c
            .execute(
                "const [scenario] = arguments; return (async () => { const o = window.__chOut.r; \
                 const w = await import('/pkg/scatterloc.js'); \
                 const f = new w.ChannelFigures(scenario, o.figure, o.errors, o.track); \
                 const canvas = document.createElement('canvas'); \
                 canvas.width = 900; canvas.height = 600; \
                 f.draw_delays(canvas, 'Delays', ''); f.draw_errors(canvas, 'Errors', ''); \
                 const res = { n: f.snapshot_count(), size: Array.from(f.delays_size()), \
                   svg: f.delays_svg(0, 0, 'Delays', ''), errors_svg: f.errors_svg(0, 0, 'E', '').length, \
                   last: f.overlay(f.snapshot_count() - 1), first: f.overlay(0) }; \
                 try { f.overlay(f.snapshot_count()); res.out = null; } catch (e) { res.out = e.message; } \
                 f.free(); return res; })();",
                vec![Value::from(f.scenario.as_str())],
            )
            .await
            .map_err(|e| format!("ChannelFigures: {e}"))?;
        assert_eq!(fig["n"], 300);
        assert_eq!(fig["size"], serde_json::json!([1400, 900]));
        let svg = fig["svg"].as_str().unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("Tx → Rx1") && svg.contains("Tx → Rx4"));
        assert!(fig["errors_svg"].as_u64().unwrap() > 1000);
        let last = &fig["last"];
        let states = track["states"].as_array().unwrap();
        let with_state = states.iter().filter(|x| !x.is_null()).count();
        // One run of positions per segment, together every state of the track.
        let runs = last["track_m"].as_array().unwrap();
        assert_eq!(runs.len(), track["segments"].as_array().unwrap().len());
        let points: usize = runs.iter().map(|r| r.as_array().unwrap().len()).sum();
        assert_eq!(points, with_state);
        assert_eq!(last["state"], states[299]);
        assert_eq!(last["links_used"], track["links_used"][299]);
        let used = track["delays_used_s"][299].as_array().unwrap();
        let links = last["links"].as_array().unwrap();
        assert_eq!(links.len(), used.iter().filter(|d| !d.is_null()).count());
        for l in links {
            assert_eq!(l["delay_s"], used[l["link"].as_u64().unwrap() as usize]);
            assert!(l["ellipse"]["a"].as_f64().unwrap() > 0.0, "{l}");
        }
        assert!(last["sigma_ellipse"]["a"].as_f64().unwrap() > 0.0, "{last}");
        assert!(
            fig["out"]
                .as_str()
                .unwrap()
                .starts_with("snapshot: 300 is outside"),
            "{}",
            fig["out"]
        );
        // The simulator in the worker writes the CLI's files, byte for byte.
        c.execute(
            "const [scenario] = arguments; window.__sim = null; \
             window.__ch.jobs.simulate(scenario, { duration_s: 5.98, dt_s: 0.02, \
               calibration_duration_s: 0.4, seed: 1 }) \
               .then((s) => { window.__sim = s; }, (e) => { window.__sim = { error: e.message }; });",
            vec![Value::from(f.scenario.as_str())],
        )
        .await
        .map_err(|e| format!("simulate: {e}"))?;
        let t0 = Instant::now();
        let sim = loop {
            let s = js(
                c,
                "const s = window.__sim; if (!s) return null; if (s.error) return s; \
                 const h = (b) => { let t = ''; for (let i = 0; i < b.length; i += 32768) \
                   t += String.fromCharCode(...b.subarray(i, i + 32768)); return btoa(t); }; \
                 return { rec: h(s.recording), cal: h(s.calibration), truth: s.truth, \
                   summary: s.summary };",
            )
            .await?;
            if !s.is_null() {
                break s;
            }
            if t0.elapsed() > Duration::from_secs(120) {
                return Err("simulate did not finish".into());
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        };
        assert!(sim["error"].is_null(), "{sim}");
        for (what, page, cli) in [
            ("recording.npz", &sim["rec"], &f.recording),
            ("calibration.npz", &sim["cal"], &f.calibration),
        ] {
            let page = read_recording(&unbase64(page.as_str().unwrap())).unwrap();
            let cli = read_recording(cli).unwrap();
            println!(
                "{what} (page simulator): {}",
                if page == cli {
                    "bit-equal"
                } else {
                    "not bit-equal"
                }
            );
            let (p, q) = (recording_value(&page), recording_value(&cli));
            let mut d = Diff::new(EST_TOL);
            compare(what, &p, &q, &mut d);
            check(&format!("{what} (page simulator)"), &d);
        }
        let truth: Value = serde_json::from_str(sim["truth"].as_str().unwrap()).unwrap();
        let cli_truth: Value = serde_json::from_str(&f.truth).unwrap();
        let mut d = Diff::new(EST_TOL);
        compare("truth", &truth, &cli_truth, &mut d);
        check("truth.json (page simulator)", &d);
        assert_eq!(sim["summary"]["snapshots"], 300);
        // Without a calibration: the background learnt from the recording, as `cir track`
        // without --calibration.
        start_job(c, &f.scenario, &rec64, "", Some(&f.truth), "{}").await?;
        let o = outcome(c, Duration::from_secs(600)).await?;
        if o["state"] != "done" {
            return Err(format!("the channel job without a calibration failed: {o}"));
        }
        let r = &o["r"];
        assert_eq!(r["summary"]["calibration"]["source"], "none");
        assert_eq!(r["summary"]["calibration"]["snapshots"], 0);
        let learnt: Value = serde_json::from_str(r["track"].as_str().unwrap()).unwrap();
        let mut dl = Diff::new(TRACK_TOL);
        compare("TRACK", &learnt, &f.track_learnt, &mut dl);
        check("TRACK.json without a calibration", &dl);
        assert!(
            learnt["segments"].as_array().is_some_and(|s| !s.is_empty()),
            "no segment: {}",
            learnt["segments"]
        );
        print_timings(
            "without a calibration (background learnt from the recording)",
            r,
        );
        // Stop: the running job rejects with ChannelStopped, the next one runs. Stopped at once
        // (the whole job takes ≈ 0.3 s now: a fixed wait would race its end).
        start_job(c, &f.scenario, &rec64, &cal64, None, "{}").await?;
        js(c, "window.__ch.jobs.stop()").await?;
        let o = outcome(c, Duration::from_secs(10)).await?;
        assert!(o["state"] == "error" && o["stopped"] == true, "{o}");
        // Named errors through the same path.
        let m = failure(c, &f.scenario, &base64(&declared_bomb), &cal64).await?;
        assert!(
            m.starts_with("recording: cfr: 314572800 is outside the allowed range 0..=268435456"),
            "{m}"
        );
        let m = failure(c, &f.scenario, &base64(&lying_bomb), &cal64).await?;
        assert!(
            m.starts_with("recording: cfr: the member inflates to more than its declared 1000"),
            "{m}"
        );
        let m = failure(c, &f.scenario, &rec64, &base64(&wrong)).await?;
        assert!(
            m.starts_with("calibration: t_s: wrong shape (2, 2), expected (S,)"),
            "{m}"
        );
        js(
            c,
            &format!(
                "window.__big = new ArrayBuffer({});",
                MAX_PAGE_RECORDING_BYTES + 1
            ),
        )
        .await?;
        let m = failure(c, &f.scenario, "BIG", &cal64).await?;
        assert!(
            m.starts_with(&format!(
                "recording: {} is outside the allowed range 0..={MAX_PAGE_RECORDING_BYTES}",
                MAX_PAGE_RECORDING_BYTES + 1
            )),
            "{m}"
        );
        js(c, "window.__big = null;").await?;
        // Settings: statics "clusters" needs an empty area (the core's error, named by it); an
        // unknown setting is refused.
        let m = failure_with(c, &f.scenario, &rec64, "", r#"{"statics": "clusters"}"#).await?;
        assert!(m.starts_with("calibration: statics clusters:"), "{m}");
        let m = failure_with(c, &f.scenario, &rec64, &cal64, r#"{"colour": 1}"#).await?;
        assert!(
            m.starts_with("settings: invalid JSON:") && m.contains("colour"),
            "{m}"
        );
        let errors = console_errors(c).await?;
        assert!(errors.is_empty(), "console errors: {errors:?}");
        Ok(())
    });
    let _ = std::fs::remove_dir_all(&dir);
}
