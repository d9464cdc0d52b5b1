//! Issue 24, "Outputs" and "Small": the one output writer of the CLI (docs/cli.md, "Output
//! safety"). Concurrent writers never tear a file, planted links and FIFOs are refused (never
//! followed, never blocking), multi-file outputs are all-or-nothing (also on a full file-size
//! limit), names are capped, and stdout errors are not exit 0. Each case is one of the issue's
//! reproductions on main at 3026b0e.
#![cfg(not(target_arch = "wasm32"))]

use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::common;

use common::cli::{fails, ok_json, run, TempDir, BIN, FAST};
use scatterloc::scenario::presets;

/// The flags of a small, fast plan (tests/cli/plan.rs): move the receivers, p90 over the area.
const PLAN: [&str; 10] = [
    "--grid",
    "16",
    "--move",
    "rx",
    "--objective",
    "p90",
    "--roi",
    "-7.5,30,-10,26",
    "--budget",
    "100",
];

fn preset_file(dir: &TempDir) -> String {
    dir.write_text("s.json", &presets::sensors2019().to_json())
}

/// `value` without its timing fields (wall times, thread counts and the ns-per-step figures
/// differ between runs; every other number is deterministic).
fn without_timing(v: &Value) -> Value {
    match v {
        Value::Object(m) => Value::Object(
            m.iter()
                .filter(|(k, _)| {
                    !(k.contains("wall")
                        || k.contains("_ms")
                        || k.contains("ns_per")
                        || *k == "threads")
                })
                .map(|(k, v)| (k.clone(), without_timing(v)))
                .collect(),
        ),
        Value::Array(a) => Value::Array(a.iter().map(without_timing).collect()),
        other => other.clone(),
    }
}

/// Runs `args` with stdout and stderr captured, killing it after `limit` (a FIFO target used to
/// block forever): panics naming `what` if it had to be killed.
fn run_bounded(args: &[&str], limit: Duration, what: &str) -> Output {
    let mut child = Command::new(BIN)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run scatterloc");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what}: still running after {limit:?} (blocked?)");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Files in `dir` other than `keep`: what a run left behind (temporaries included: they are
/// hidden `.scatterloc-*.tmp` files, listed too).
fn new_files(dir: &TempDir, keep: &[&str]) -> Vec<String> {
    dir.files()
        .into_iter()
        .filter(|f| !keep.contains(&f.as_str()))
        .collect()
}

/// The three commands of the issue writing `out` (`{}` in the arguments).
fn writers(scenario: &str, out: &str) -> Vec<(&'static str, Vec<String>)> {
    let s = scenario.to_string();
    let o = out.to_string();
    let mut mc: Vec<String> = ["montecarlo", "--trajectory", "I", "--json", &o]
        .iter()
        .map(|x| x.to_string())
        .collect();
    mc.extend(FAST.iter().map(|x| x.to_string()));
    vec![
        (
            "crlb-map",
            vec![
                "crlb-map".into(),
                "--scenario".into(),
                s.clone(),
                "--out".into(),
                o.clone(),
            ],
        ),
        ("montecarlo", mc),
        (
            "plan",
            ["plan", "--scenario", &s, "--out", &o]
                .iter()
                .chain(PLAN.iter())
                .map(|x| x.to_string())
                .collect(),
        ),
    ]
}

/// Issue: two processes writing the same `--out`/`--json` gave invalid JSON in 7 of 10
/// (crlb-map), 1 of 6 (montecarlo) and 1 of 10 (plan) trials. Now each writes its own exclusive
/// temporary and renames it: the file is always one whole run's output, and no temporary is
/// left.
#[test]
fn concurrent_writers_never_tear_the_output() {
    let dir = TempDir::new();
    let scenario = preset_file(&dir);
    let out = dir.path("out.json");
    for (name, args) in writers(&scenario, &out) {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let out_ok = run(&a);
        assert!(out_ok.status.success(), "{name}: {:?}", out_ok);
        let want = without_timing(&common::cli::read_json(&out));
        for trial in 0..3 {
            std::fs::remove_file(&out).unwrap();
            let children: Vec<_> = (0..2)
                .map(|_| {
                    Command::new(BIN)
                        .args(&a)
                        .stdout(Stdio::null())
                        .stderr(Stdio::piped())
                        .spawn()
                        .unwrap()
                })
                .collect();
            for c in children {
                let o = c.wait_with_output().unwrap();
                assert!(
                    o.status.success(),
                    "{name} trial {trial}: {}",
                    String::from_utf8_lossy(&o.stderr)
                );
            }
            let text = std::fs::read_to_string(&out).unwrap();
            let got: Value = serde_json::from_str(&text)
                .unwrap_or_else(|e| panic!("{name} trial {trial}: torn JSON: {e}"));
            assert_eq!(without_timing(&got), want, "{name} trial {trial}");
            assert_eq!(
                new_files(&dir, &["s.json", "out.json"]),
                Vec::<String>::new()
            );
        }
    }
}

/// Issue: a symlink planted at the predictable temporary `NAME.tmp` was followed (its target
/// overwritten with the map) and a link at the target to `/dev/null` gave exit 0 with the data
/// lost. Now links at the old temporary names are left alone (their targets unchanged), and a
/// link at the target itself is a named error (exit 2) that writes nothing.
#[test]
fn planted_links_are_never_followed() {
    let dir = TempDir::new();
    let scenario = preset_file(&dir);
    let victim = dir.write_text("victim.txt", "precious");
    for planted in ["m.tmp.json", "m.tmp", "m.json.tmp", ".m.json.tmp"] {
        std::os::unix::fs::symlink(&victim, dir.path(planted)).unwrap();
    }
    let out = dir.path("m.json");
    ok_json(&[
        "crlb-map",
        "--scenario",
        &scenario,
        "--out",
        &out,
        "--nx",
        "8",
        "--ny",
        "8",
    ]);
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    let meta = std::fs::symlink_metadata(&out).unwrap();
    assert!(meta.file_type().is_file(), "m.json is not a regular file");
    assert_eq!(
        common::cli::read_json(&out)["x_m"]
            .as_array()
            .unwrap()
            .len(),
        8
    );

    // A link at the target: to the victim, and to /dev/null (the data would be lost).
    for (link, to) in [("l.png", victim.as_str()), ("null.png", "/dev/null")] {
        let p = dir.path(link);
        std::os::unix::fs::symlink(to, &p).unwrap();
        fails(
            &[
                "crlb-map",
                "--scenario",
                &scenario,
                "--out",
                &p,
                "--nx",
                "8",
                "--ny",
                "8",
            ],
            &["--out", link, "symbolic link", "refusing"],
        );
        let plan = dir.path("plan.json");
        fails(
            &[
                &[
                    "plan",
                    "--scenario",
                    &scenario,
                    "--out",
                    &plan,
                    "--figure",
                    &p,
                ][..],
                &PLAN,
            ]
            .concat(),
            &["--figure", link, "symbolic link"],
        );
        assert!(!std::path::Path::new(&plan).exists(), "plan.json written");
        assert!(std::fs::symlink_metadata(&p)
            .unwrap()
            .file_type()
            .is_symlink());
    }
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    let left: Vec<String> = new_files(&dir, &[])
        .into_iter()
        .filter(|f| f.starts_with(".scatterloc-"))
        .collect();
    assert!(left.is_empty(), "temporaries left: {left:?}");
}

/// Issue: a FIFO as `--out` blocked forever (opening it waits for a reader). Every output flag
/// now refuses a FIFO (and a device) up front with a named error, within seconds.
#[test]
fn fifo_and_device_targets_are_refused_without_blocking() {
    let dir = TempDir::new();
    let scenario = preset_file(&dir);
    let fifo = dir.path("f.json");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let snaps = dir.path("walk/calibration_snapshots.json");
    let walk = dir.path("walk");
    let limit = Duration::from_secs(60);
    // (A device such as /dev/null has no extension: `calibrate --out /dev/null` is refused as
    // a device in basics.rs.)
    {
        let (target, what) = (fifo.as_str(), "a FIFO");
        let cases: Vec<(Vec<&str>, &str)> = vec![
            (
                vec!["crlb-map", "--scenario", &scenario, "--out", target],
                "--out",
            ),
            (
                [
                    &["plan", "--scenario", &scenario, "--out", target][..],
                    &PLAN,
                ]
                .concat(),
                "--out",
            ),
            (
                vec![
                    "montecarlo",
                    "--trajectory",
                    "I",
                    "--json",
                    target,
                    "--runs",
                    "4",
                    "--dt",
                    "0.1",
                ],
                "--json",
            ),
        ];
        for (args, flag) in cases {
            let o = run_bounded(&args, limit, &format!("{args:?}"));
            common::cli::fails_output(&args, &o, &[flag, what, "refusing"]);
        }
    }
    // calibrate --out and simulate-walk's files.
    ok_json(&[
        "simulate-walk",
        "--scenario",
        &scenario,
        "--out-dir",
        &walk,
        "--duration",
        "2",
    ]);
    let args = [
        "calibrate",
        "--scenario",
        &scenario,
        "--snapshots",
        &snaps,
        "--out",
        &fifo,
    ];
    let o = run_bounded(&args, limit, "calibrate");
    common::cli::fails_output(&args, &o, &["--out", "a FIFO"]);
    let fifo_dir = TempDir::new();
    let made = Command::new("mkfifo")
        .arg(fifo_dir.path("truth.json"))
        .status()
        .unwrap();
    assert!(made.success());
    let d = fifo_dir.0.to_string_lossy().into_owned();
    let args = [
        "simulate-walk",
        "--scenario",
        &scenario,
        "--out-dir",
        &d,
        "--duration",
        "2",
    ];
    let o = run_bounded(&args, limit, "simulate-walk");
    common::cli::fails_output(&args, &o, &["--out-dir", "truth.json", "a FIFO"]);
    assert_eq!(fifo_dir.files(), vec!["truth.json".to_string()]);
}

/// Issue: `simulate-walk` into a directory where `truth.json` is a symlink exited 2 after
/// writing `calibration_snapshots.json` and `measurements.json`. Now every target is checked
/// before the work: exit 2 naming the file, nothing written, the link's target not created.
#[test]
fn simulate_walk_with_a_planted_truth_link_writes_nothing() {
    let dir = TempDir::new();
    let scenario = preset_file(&dir);
    let out = TempDir::new();
    let target = dir.path("elsewhere.json");
    std::os::unix::fs::symlink(&target, out.path("truth.json")).unwrap();
    let d = out.0.to_string_lossy().into_owned();
    fails(
        &[
            "simulate-walk",
            "--scenario",
            &scenario,
            "--out-dir",
            &d,
            "--duration",
            "2",
        ],
        &["--out-dir", "truth.json", "symbolic link"],
    );
    assert_eq!(out.files(), vec!["truth.json".to_string()]);
    assert!(!std::path::Path::new(&target).exists());
}

/// Runs `args` under `ulimit -f blocks` (512-byte blocks in POSIX sh): a write past it fails
/// with EFBIG (SIGXFSZ, which would kill the process and leave the temporaries, is handled).
fn run_with_file_limit(blocks: u32, args: &[&str]) -> Output {
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    Command::new("sh")
        .args([
            "-c",
            &format!("ulimit -f {blocks} && exec '{BIN}' {}", quoted.join(" ")),
        ])
        .output()
        .unwrap()
}

/// Issue: on a full disk `simulate-walk` left `calibration_snapshots.json`, and `plan --figure`
/// wrote the figure without `plan.json`. Now (a file-size limit standing in for the full disk)
/// the run fails with exit 1 naming the file, and leaves nothing: no output, no temporary.
#[test]
fn a_full_disk_leaves_nothing() {
    let dir = TempDir::new();
    let scenario = preset_file(&dir);
    let out = TempDir::new();
    let d = out.0.to_string_lossy().into_owned();
    // 64 KiB: the measurements are larger, the calibration snapshots (500 × 4 links) smaller.
    let o = run_with_file_limit(
        128,
        &[
            "simulate-walk",
            "--scenario",
            &scenario,
            "--out-dir",
            &d,
            "--duration",
            "20",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--out-dir") && err.contains("File too large"),
        "{err}"
    );
    assert_eq!(out.files(), Vec::<String>::new());

    // plan: the PNG figure (tens of KiB) fails; plan.json (a few KiB) would fit.
    let plan = dir.path("plan.json");
    let fig = dir.path("plan.png");
    let o = run_with_file_limit(
        16,
        &[
            &[
                "plan",
                "--scenario",
                &scenario,
                "--out",
                &plan,
                "--figure",
                &fig,
            ][..],
            &PLAN,
        ]
        .concat(),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--figure") && err.contains("File too large"),
        "{err}"
    );
    assert_eq!(new_files(&dir, &["s.json"]), Vec::<String>::new());
}

/// Issue: a 100 MB node or scenario name made `crlb-map --out m.png` and `plan --figure` run for
/// minutes. Names are capped at 256 bytes (`limits::MAX_NAME_BYTES`) in the core's scenario
/// validation: a named error before any work (the cap's message is the proof; how long it took is
/// not asserted: tests do not time the wall clock, issue 39).
#[test]
fn long_names_are_a_named_error_before_any_work() {
    let dir = TempDir::new();
    let mut s: Value = serde_json::from_str(&presets::sensors2019().to_json()).unwrap();
    s["transmitters"][0]["name"] = Value::String("T".repeat(10 << 20));
    let node = dir.write("node.json", &s);
    let mut s: Value = serde_json::from_str(&presets::sensors2019().to_json()).unwrap();
    s["name"] = Value::String("S".repeat(100 << 20));
    let big = dir.write("name.json", &s);
    let png = dir.path("m.png");
    fails(
        &["crlb-map", "--scenario", &node, "--out", &png],
        &["transmitters[0].name", "10485760 bytes long, at most 256"],
    );
    let plan = dir.path("plan.json");
    fails(
        &[
            &["plan", "--scenario", &big, "--out", &plan, "--figure", &png][..],
            &PLAN,
        ]
        .concat(),
        &["name: 104857600 bytes long, at most 256"],
    );
    assert_eq!(
        new_files(&dir, &["node.json", "name.json"]),
        Vec::<String>::new()
    );
    // 256 bytes is still fine.
    let mut s: Value = serde_json::from_str(&presets::sensors2019().to_json()).unwrap();
    s["receivers"][1]["name"] = Value::String("R".repeat(256));
    let ok = dir.write("ok.json", &s);
    ok_json(&[
        "crlb-map",
        "--scenario",
        &ok,
        "--out",
        &dir.path("ok-map.json"),
        "--nx",
        "4",
        "--ny",
        "4",
    ]);
    s["receivers"][1]["name"] = Value::String("R".repeat(257));
    let bad = dir.write("bad.json", &s);
    fails(
        &["crlb", "--scenario", &bad, "--at", "1,1"],
        &["receivers[1].name", "257 bytes long"],
    );
}

/// Issue ("Small"): `calibrate --out cal.txt` wrote JSON; `simulate-walk` exited 1 when it
/// could not create its directory. Now the extension rule of every output flag, and exit 2.
#[test]
fn calibrate_extension_and_walk_directory_exit_codes() {
    let dir = TempDir::new();
    let scenario = preset_file(&dir);
    let walk = dir.path("walk");
    ok_json(&[
        "simulate-walk",
        "--scenario",
        &scenario,
        "--out-dir",
        &walk,
        "--duration",
        "2",
    ]);
    let snaps = format!("{walk}/calibration_snapshots.json");
    let txt = dir.path("cal.txt");
    fails(
        &[
            "calibrate",
            "--scenario",
            &scenario,
            "--snapshots",
            &snaps,
            "--out",
            &txt,
        ],
        &["--out", "unknown extension '.txt'", ".json"],
    );
    assert!(!std::path::Path::new(&txt).exists());
    let file = dir.write_text("plain", "x");
    fails(
        &[
            "simulate-walk",
            "--scenario",
            &scenario,
            "--out-dir",
            &format!("{file}/sub"),
            "--duration",
            "2",
        ],
        &["--out-dir", "cannot create"],
    );
}

/// Issue ("Small"): a closed stdout (`>&-`) gave exit 0 with nothing written. Now a closed
/// stdout, a read-only one (EBADF) and a closed pipe (EPIPE) exit 1 with a stderr line naming
/// stdout; an explicit `>/dev/null` still succeeds.
#[test]
fn stdout_errors_are_not_exit_0() {
    for redirect in [">&-", "1</dev/null"] {
        let o = Command::new("sh")
            .args(["-c", &format!("exec '{BIN}' preset sensors2019 {redirect}")])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{redirect}: {err}");
        assert!(err.starts_with("error: stdout:"), "{redirect}: {err}");
    }
    // A closed pipe: the reader is gone before the map is written.
    let dir = TempDir::new();
    let scenario = preset_file(&dir);
    let mut child = Command::new(BIN)
        .args([
            "crlb-map",
            "--scenario",
            &scenario,
            "--out",
            &dir.path("m.json"),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("stdout:") && err.contains("Broken pipe"),
        "{err}"
    );
    let o = Command::new(BIN)
        .args(["preset", "sensors2019"])
        .stdout(Stdio::null())
        .output()
        .unwrap();
    assert!(o.status.success());
    // `/dev/null` read-write (a daemon's descriptors, Python's `subprocess.DEVNULL`) is the
    // runtime's stand-in for a closed stdout: refused for a result, accepted for the summary
    // line of a run whose result went to a file.
    let o = Command::new("sh")
        .args([
            "-c",
            &format!("exec '{BIN}' preset sensors2019 1<>/dev/null"),
        ])
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let out = dir.path("rw.json");
    let o = Command::new("sh")
        .args([
            "-c",
            &format!("exec '{BIN}' crlb-map --scenario '{scenario}' --out '{out}' 1<>/dev/null"),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let map: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert!(map.is_object());
}

/// Issue 37 item 9: two `cir simulate` runs into one `--out-dir` (different `--dt`), their
/// commits made to overlap (debug builds pause between two renames of a set when
/// `SCATTERLOC_TEST_COMMIT_PAUSE_MS` is set; 900 and 250 ms here): the four files are one
/// run's, whole — never the recording of one beside the truth of the other. Without the
/// directory lock the renames interleave (4 of 30 concurrent pairs in the issue; with these
/// pauses round 0 already left the recording of one run beside the other's files).
#[test]
fn concurrent_multi_file_commits_leave_one_whole_set() {
    let dir = TempDir::new();
    let scenario = preset_file(&dir);
    let out = TempDir::new();
    let d = out.0.to_string_lossy().into_owned();
    for round in 0..2 {
        // The slow committer first, the fast one 300 ms later: the fast one's first rename
        // lands after the slow one's, its last before the slow one's last.
        let children: Vec<_> = [("0.02", "900", 0), ("0.025", "250", 300)]
            .iter()
            .map(|(dt, pause, after)| {
                std::thread::sleep(Duration::from_millis(*after));
                Command::new(BIN)
                    .args([
                        "cir",
                        "simulate",
                        "--scenario",
                        &scenario,
                        "--out-dir",
                        &d,
                        "--duration",
                        "0.5",
                        "--dt",
                        dt,
                    ])
                    .env("SCATTERLOC_TEST_COMMIT_PAUSE_MS", pause)
                    .stdout(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for c in children {
            let o = c.wait_with_output().unwrap();
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        }
        let json = |name: &str| -> Value {
            serde_json::from_str(&std::fs::read_to_string(out.path(name)).unwrap()).unwrap()
        };
        let spacing = |t: &[f64]| t[1] - t[0];
        let scene_dt = json("scene.json")["dt_s"].as_f64().unwrap();
        let truth_t: Vec<f64> = serde_json::from_value(json("truth.json")["t_s"].clone()).unwrap();
        let npz_dt = |name: &str| {
            let bytes = std::fs::read(out.path(name)).unwrap();
            spacing(&scatterloc::npz::read_recording(&bytes).unwrap().t_s)
        };
        let dts = [
            scene_dt,
            spacing(&truth_t),
            npz_dt("recording.npz"),
            npz_dt("calibration.npz"),
        ];
        assert!(
            dts.iter().all(|v| (v - dts[0]).abs() < 1e-9),
            "round {round}: a mixed set, dt of scene, truth, recording, calibration: {dts:?}"
        );
    }
}
