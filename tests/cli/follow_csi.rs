//! `cir track --follow` on the CSI formats read as streams (issue 40 §3): each real file of
//! `tests/data/csi/` piped through standard input in chunks with pauses gives, chunk after chunk
//! (a line before the next chunk is written: a liveness check with a generous timeout, not a
//! timing assertion), the JSON lines whose times and states are those of the batch `cir track`
//! of the same file with the same flags; a truncated last record is a named error after the
//! lines already written; Ctrl-C stops a followed file (exit 130, the lines kept).
//!
//! On these captures (no one walks in them) the tracker starts no segment, in the batch run
//! and live alike: the states compared are `null` on both sides, so what the comparison pins
//! is the frames (their number after the conversion's drops), their times to the bit and the
//! events; the samples themselves are compared bit for bit with the whole-file conversion by the
//! core's tests (`edge/csi/stream/tests.rs`) and live = batch on a walk by `study/channel/live`.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use serde_json::Value;

use crate::common::cli::{interrupted, read_json, TempDir, BIN};

/// How long a line may take before the test calls the run stuck (a debug build, shared cores).
const LINE_TIMEOUT: Duration = Duration::from_secs(120);

/// The stream formats' real files, the `--format` value (`None`: left to the first bytes).
const FILES: [(&str, Option<&str>); 5] = [
    ("intel/example.dat", Some("intel5300")),
    ("nexmon/example_4366c0.pcap", Some("nexmon")),
    ("esp32/example_data.csv", None),
    ("feitcsi/VHT80_5500.csi", Some("feitcsi")),
    ("pico/picoscenes_iwl5300_example.csi", Some("picoscenes")),
];

/// Chunks each file is written in.
const CHUNKS: usize = 8;

fn data(name: &str) -> String {
    format!("{}/tests/data/csi/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn with_format(c: &mut Command, format: Option<&str>) {
    if let Some(f) = format {
        c.args(["--format", f]);
    }
}

/// The batch `cir track` of `file`: its TRACK.json.
fn batch(dir: &TempDir, file: &str, format: Option<&str>) -> Value {
    let out = dir.path("track.json");
    let mut c = Command::new(BIN);
    c.args([
        "cir",
        "track",
        "--scenario",
        &data("room.json"),
        "--cir",
        file,
    ])
    .args(["--out", &out]);
    with_format(&mut c, format);
    let st = c.output().unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    read_json(&out)
}

fn follow(cir: &str, format: Option<&str>) -> Command {
    let mut c = Command::new(BIN);
    c.args(["cir", "track", "--follow", "--scenario", &data("room.json")])
        .args(["--cir", cir]);
    with_format(&mut c, format);
    c
}

/// Lines of the child's stdout through a thread, so a read can time out.
fn lines(stdout: std::process::ChildStdout) -> mpsc::Receiver<String> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for l in BufReader::new(stdout).lines() {
            let Ok(l) = l else { break };
            if tx.send(l).is_err() {
                break;
            }
        }
    });
    rx
}

/// Line `k` against the batch track: its time to the bit, its state within 1e-12 (or both
/// `null`, the live run reporting a snapshot of a segment not yet confirmed as `searching`).
fn check_line(l: &str, k: usize, track: &Value, name: &str) {
    let v: Value = serde_json::from_str(l).unwrap_or_else(|e| panic!("{name}: {l}: {e}"));
    assert_eq!(v["snapshot"], k, "{name}: {l}");
    let t = track["t_s"][k].as_f64().unwrap();
    assert_eq!(
        v["t_s"].as_f64().unwrap().to_bits(),
        t.to_bits(),
        "{name} frame {k}"
    );
    let want = &track["states"][k];
    match (v["state"].as_array(), want.as_array()) {
        (Some(got), Some(want)) => {
            for (a, b) in got.iter().zip(want) {
                let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
                assert!(
                    (a - b).abs() <= 1e-12 * b.abs().max(1.0),
                    "{name} frame {k}: {a} {b}"
                );
            }
        }
        (None, _) => assert!(
            want.is_null() || v["event"] == "searching",
            "{name} frame {k}: live null, batch {want}"
        ),
        (Some(_), None) => panic!("{name} frame {k}: a live state where the batch has none"),
    }
}

/// Each file through a pipe in 8 chunks with pauses: after each chunk (but the last) at least
/// one new line comes before the next chunk is written (each chunk holds several records); the
/// end of input ends the run (exit 0); the lines are the batch run's frames, times and states.
#[test]
fn csi_on_stdin_in_chunks_gives_the_batch_track_line_by_line() {
    let dir = TempDir::new();
    for (name, format) in FILES {
        let file = data(name);
        let track = batch(&dir, &file, format);
        let frames = track["t_s"].as_array().unwrap().len();
        let bytes = std::fs::read(&file).unwrap();
        let mut child = follow("-", format)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let rx = lines(child.stdout.take().unwrap());
        let mut stdin = child.stdin.take().unwrap();
        let mut got: Vec<String> = Vec::new();
        let size = bytes.len().div_ceil(CHUNKS);
        for (i, chunk) in bytes.chunks(size).enumerate() {
            stdin.write_all(chunk).unwrap();
            stdin.flush().unwrap();
            if i + 1 < CHUNKS {
                let l = rx.recv_timeout(LINE_TIMEOUT).unwrap_or_else(|_| {
                    panic!("{name}: no line after chunk {i} before the next chunk")
                });
                got.push(l);
                // The lines of every frame this chunk completed.
                while let Ok(l) = rx.recv_timeout(Duration::from_millis(100)) {
                    got.push(l);
                }
            }
        }
        drop(stdin);
        let out = child.wait_with_output().unwrap();
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        got.extend(rx.iter());
        assert_eq!(got.len(), frames, "{name}");
        for (k, l) in got.iter().enumerate() {
            check_line(l, k, &track, name);
        }
        let summary: Value =
            serde_json::from_str(String::from_utf8_lossy(&out.stderr).trim()).unwrap();
        assert_eq!(summary["frames"], frames, "{name}");
    }
}

/// The file without its last bytes: the lines of the complete frames, then exit 2 with one
/// error naming the record cut short (the Intel log: 26 records of 395 bytes, the last cut).
#[test]
fn a_truncated_last_record_is_a_named_error_after_the_lines() {
    let dir = TempDir::new();
    for (name, format, frames, record) in [
        ("intel/example.dat", Some("intel5300"), 25, "record 25"),
        ("esp32/example_data.csv", None, usize::MAX, "record"),
        ("feitcsi/VHT80_5500.csi", Some("feitcsi"), 39, "record 39"),
    ] {
        let file = data(name);
        let mut bytes = std::fs::read(&file).unwrap();
        bytes.truncate(bytes.len() - 10);
        // The ESP32 CSV, its last line cut: the batch read skips that line, so the batch track
        // of the cut file is the reference (the binary formats' batch read refuses a cut file).
        let (track, frames) = if frames == usize::MAX {
            let cut = dir.path("cut.csv");
            std::fs::write(&cut, &bytes).unwrap();
            let track = batch(&dir, &cut, format);
            let n = track["t_s"].as_array().unwrap().len();
            (track, n)
        } else {
            (batch(&dir, &file, format), frames)
        };
        let mut child = follow("-", format)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut stdin = child.stdin.take().unwrap();
        stdin.write_all(&bytes).unwrap();
        drop(stdin);
        let out = child.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{name}");
        let text = String::from_utf8(out.stdout).unwrap();
        let got: Vec<&str> = text.lines().collect();
        assert_eq!(got.len(), frames, "{name}");
        for (k, l) in got.iter().enumerate() {
            check_line(l, k, &track, name);
        }
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(
            err.contains(record) && err.contains("truncated"),
            "{name}: {err}"
        );
    }
}

/// A followed CSI file has no end marker: the run waits at its end until Ctrl-C (exit 130),
/// every frame's line kept.
#[test]
fn ctrl_c_while_following_a_csi_file_keeps_the_lines() {
    let dir = TempDir::new();
    let file = data("intel/example.dat");
    let track = batch(&dir, &file, Some("intel5300"));
    let out = interrupted(
        &mut follow(&file, Some("intel5300")),
        "cir track --follow (CSI)",
    );
    assert_eq!(out.status.code(), Some(130));
    let text = String::from_utf8(out.stdout).unwrap();
    let got: Vec<&str> = text.lines().collect();
    assert_eq!(got.len(), 26, "{text}");
    for (k, l) in got.iter().enumerate() {
        check_line(l, k, &track, "intel");
    }
    assert!(String::from_utf8_lossy(&out.stderr).contains("Ctrl-C"));
}

/// `--format npz` cannot be followed; a CSI file of another format than `--format` is the
/// reader's named error.
#[test]
fn formats_that_cannot_stream_are_named() {
    let out = follow("-", Some("npz"))
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--format"));
    let mut child = follow("-", Some("feitcsi"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    stdin
        .write_all(&std::fs::read(data("esp32/example_data.csv")).unwrap())
        .unwrap();
    drop(stdin);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--cir"));
}
