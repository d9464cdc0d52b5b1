//! Issue 37 ("Hardening III"), the command line's items: `slurm submit` checks the study as
//! its shards would (5) and submits safely (14: a comma in the binary's path, a resubmit hint
//! that pastes, an uncreatable `DIR/slurm`, stale parts); truth coordinates are range-checked
//! (10); two output flags naming one file (12) and two inputs on standard input (17) are
//! refused. Each bad input exits 2 with one stderr line naming the flag (or field).
#![cfg(not(target_arch = "wasm32"))]

use std::io::Write;
use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::{Command, Output, Stdio};

use serde_json::json;

use crate::cir::{scenario, simulate};
use crate::common::cli::{fails, fails_output, read_json, TempDir, BIN};

/// A stand-in `sbatch` for `slurm submit` (no Slurm here): `sbatch --version` prints a
/// version; each submission writes its arguments, one per line after a first line
/// `SCATTERLOC=<its environment's SCATTERLOC, or unset>`, to `log/N` (N = 0, 1, …) and prints
/// the job id 100 + N. With `FAKE_SBATCH_FAIL_MERGE` set, a submission with `--dependency`
/// (the merge job) is recorded, then fails as sbatch does.
struct FakeSbatch {
    dir: TempDir,
}

const FAKE_SBATCH: &str = r#"#!/bin/sh
if [ "$1" = --version ]; then echo 'slurm 23.11.4'; exit 0; fi
n=$(ls "$FAKE_SBATCH_LOG" | wc -l | tr -d ' ')
{ printf 'SCATTERLOC=%s\n' "${SCATTERLOC-unset}"; printf '%s\n' "$@"; } > "$FAKE_SBATCH_LOG/$n"
if [ -n "${FAKE_SBATCH_FAIL_MERGE-}" ]; then
  for a in "$@"; do
    case "$a" in --dependency=*) echo 'sbatch: error: Batch job submission failed' >&2; exit 1;; esac
  done
fi
echo "$((100 + n))"
"#;

impl FakeSbatch {
    fn new() -> FakeSbatch {
        let dir = TempDir::new();
        let script = dir.write_text("sbatch", FAKE_SBATCH);
        std::fs::set_permissions(&script, std::fs::Permissions::from_mode(0o755)).unwrap();
        std::fs::create_dir(dir.path("log")).unwrap();
        FakeSbatch { dir }
    }

    /// `cmd` with this `sbatch` first on PATH, its log, and no SCATTERLOC of the test's own.
    fn env<'a>(&self, cmd: &'a mut Command) -> &'a mut Command {
        let path = format!(
            "{}:{}",
            self.dir.0.display(),
            std::env::var("PATH").unwrap_or_default()
        );
        cmd.env("PATH", path)
            .env("FAKE_SBATCH_LOG", self.dir.path("log"))
            .env_remove("SCATTERLOC")
            .env_remove("FAKE_SBATCH_FAIL_MERGE")
    }

    /// Runs `bin args` with this `sbatch` (and `extra` variables).
    fn run(&self, bin: &str, args: &[&str], extra: &[(&str, &str)]) -> Output {
        let mut cmd = Command::new(bin);
        self.env(&mut cmd).args(args).envs(extra.iter().copied());
        cmd.output().expect("run scatterloc")
    }

    /// The recorded submissions, in order: each call's lines.
    fn calls(&self) -> Vec<Vec<String>> {
        (0..)
            .map(|n| self.dir.0.join("log").join(n.to_string()))
            .take_while(|p| p.exists())
            .map(|p| {
                std::fs::read_to_string(p)
                    .unwrap()
                    .lines()
                    .map(str::to_string)
                    .collect()
            })
            .collect()
    }
}

/// The `SCATTERLOC` a job of `call` sees, as sbatch computes it: the submitting environment
/// (`--export=ALL`), then each `NAME=VALUE` of the comma-separated `--export` list.
fn job_scatterloc(call: &[String]) -> Option<String> {
    let mut value = call[0]
        .strip_prefix("SCATTERLOC=")
        .filter(|v| *v != "unset")
        .map(str::to_string);
    for arg in &call[1..] {
        if let Some(list) = arg.strip_prefix("--export=") {
            for item in list.split(',') {
                if let Some(v) = item.strip_prefix("SCATTERLOC=") {
                    value = Some(v.to_string());
                }
            }
        }
    }
    value
}

/// `slurm submit --shards 4 --dir DIR STUDY...` arguments.
fn submit<'a>(dir: &'a str, study: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["slurm", "submit", "--shards", "4", "--dir", dir, "--"];
    args.extend_from_slice(study);
    args
}

/// Item 5: a study every shard would refuse is refused before anything is written or
/// submitted, naming the flag (it was submitted as N failing tasks and a merge job pending
/// forever). A relative `--scenario` is the jobs' working directory's (DIR), as the shards read
/// it; standard input, which batch jobs do not have, is refused.
#[test]
fn slurm_submit_refuses_a_study_its_shards_would_refuse() {
    let sbatch = FakeSbatch::new();
    let dir = TempDir::new();
    let d = dir.path("");
    let cases: [(&[&str], &[&str]); 8] = [
        (&["montecarlo", "--runs", "0"], &["--runs"]),
        (&["montecarlo", "--dt", "-1"], &["--dt"]),
        (
            &["montecarlo", "--scenario", "missing.json"],
            &["--scenario", "missing.json"],
        ),
        (
            &["montecarlo", "--scenario", "-"],
            &["--scenario", "standard input"],
        ),
        (
            &["montecarlo", "--preset", "nosuch"],
            &["--preset", "nosuch"],
        ),
        (
            &["montecarlo", "--max-cpu-hours", "0.0001"],
            &["--max-cpu-hours"],
        ),
        (
            &["mtl", "roc", "--experiment", "va", "--realizations", "0"],
            &["--realizations"],
        ),
        (
            &["mtl", "roc", "--experiment", "va", "--exact"],
            &["--exact"],
        ),
    ];
    for (study, needles) in cases {
        let args = submit(&d, study);
        let out = sbatch.run(BIN, &args, &[]);
        let err = fails_output(&args, &out, needles);
        assert!(err.contains("the study after --"), "{err}");
        assert!(sbatch.calls().is_empty(), "{args:?} submitted");
        assert!(dir.files().is_empty(), "{args:?}: {:?}", dir.files());
    }
    // A scenario file in DIR, named relative to it (from another working directory): accepted.
    let s = scenario(&dir);
    assert!(s.ends_with("s.json"));
    let args = submit(
        &d,
        &[
            "montecarlo",
            "--scenario",
            "s.json",
            "--runs",
            "16",
            "--noise-runs",
            "1",
        ],
    );
    let out = sbatch.run(BIN, &args, &[]);
    assert!(out.status.success(), "{out:?}");
    assert_eq!(sbatch.calls().len(), 2);
}

/// Item 14 (a): a comma in the binary's path split sbatch's `--export=ALL,SCATTERLOC=PATH`, so
/// the jobs ran another program. The jobs now see the whole path.
#[test]
fn slurm_submit_passes_a_binary_path_with_a_comma_whole() {
    let sbatch = FakeSbatch::new();
    let dir = TempDir::new();
    std::fs::create_dir(dir.path("a,b")).unwrap();
    let exe = dir.path("a,b/scatterloc");
    if std::fs::hard_link(BIN, &exe).is_err() {
        std::fs::copy(BIN, &exe).unwrap();
    }
    let work = dir.path("work");
    std::fs::create_dir(&work).unwrap();
    let out = sbatch.run(&exe, &submit(&work, &["montecarlo"]), &[]);
    assert!(out.status.success(), "{out:?}");
    let calls = sbatch.calls();
    assert_eq!(calls.len(), 2);
    for call in &calls {
        assert_eq!(
            job_scatterloc(call).as_deref(),
            Some(exe.as_str()),
            "{call:?}"
        );
    }
}

/// Item 14 (b): the `sbatch` line printed when the merge job could not be submitted pastes
/// into a shell as the same submission, even for a DIR with a space and a `'`.
#[test]
fn slurm_submit_resubmit_hint_pastes_into_a_shell() {
    let sbatch = FakeSbatch::new();
    let dir = TempDir::new();
    let work = dir.path("it's a dir");
    std::fs::create_dir(&work).unwrap();
    let out = sbatch.run(
        BIN,
        &submit(&work, &["montecarlo"]),
        &[("FAKE_SBATCH_FAIL_MERGE", "1")],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("the merge job was not"), "{err}");
    let hint = err
        .split_once("submit it with `")
        .and_then(|(_, rest)| rest.split_once("` (or cancel"))
        .map(|(hint, _)| hint)
        .unwrap_or_else(|| panic!("no hint in {err}"));
    let calls = sbatch.calls();
    assert_eq!(calls.len(), 2, "{calls:?}");
    let mut sh = Command::new("sh");
    let replay = sbatch.env(&mut sh).args(["-c", hint]).output().unwrap();
    assert!(replay.status.success(), "{hint}: {replay:?}");
    // The same submission (`--parsable`, for the job id, is the command's own).
    let calls: Vec<Vec<String>> = sbatch
        .calls()
        .into_iter()
        .map(|c| c.into_iter().filter(|a| a != "--parsable").collect())
        .collect();
    assert_eq!(calls.len(), 3, "{hint}");
    assert_eq!(calls[2], calls[1], "{hint}");
}

/// Item 14 (c), (d): an uncreatable `DIR/slurm` is bad input (exit 2 naming it; was exit 1);
/// part files of an earlier run in `DIR/parts`, which the merge job would read with the new
/// ones, are refused by name before anything is submitted. Another study's parts are not.
#[test]
fn slurm_submit_refuses_an_unusable_dir_by_name() {
    let sbatch = FakeSbatch::new();
    let dir = TempDir::new();
    let d = dir.path("");
    dir.write_text("slurm", "a file where the scripts' directory goes");
    let args = submit(&d, &["montecarlo"]);
    fails_output(&args, &sbatch.run(BIN, &args, &[]), &["--dir", "slurm"]);
    assert!(sbatch.calls().is_empty());

    let dir = TempDir::new();
    let d = dir.path("");
    std::fs::create_dir(dir.path("parts")).unwrap();
    dir.write_text("parts/montecarlo-00002.json", "{}");
    dir.write_text("parts/other-00000.json", "{}");
    let args = submit(&d, &["montecarlo"]);
    fails_output(
        &args,
        &sbatch.run(BIN, &args, &[]),
        &["--dir", "parts", "montecarlo-00002.json", "remove them"],
    );
    assert!(sbatch.calls().is_empty());
    assert_eq!(dir.files(), ["parts"]);
    let args = [
        "slurm",
        "submit",
        "--shards",
        "4",
        "--dir",
        &d,
        "--name",
        "mc",
        "--",
        "montecarlo",
    ];
    let out = sbatch.run(BIN, &args, &[]);
    assert!(out.status.success(), "{out:?}");
    assert_eq!(sbatch.calls().len(), 2);
}

/// Item 10: `cir track --truth` with states far outside the coordinate range gave
/// `median_m: 1e100` (exit 0), at 1e160 `"error": null`. Now a named error on the state.
#[test]
fn cir_track_refuses_truth_coordinates_out_of_range() {
    let dir = TempDir::new();
    let (scenario, sim) = simulate(&dir, "0.2", "0.02", "5");
    let rec = format!("{sim}/recording.npz");
    let truth = read_json(&format!("{sim}/truth.json"));
    let out = dir.path("t.json");
    for (i, v, field) in [
        (0, 1e100, "states[3][0]"),
        (1, 1e160, "states[3][1]"),
        (2, 1e7, "states[3][2]"),
    ] {
        let mut bad = truth.clone();
        bad["states"][3][i] = json!(v);
        let path = dir.write("bad-truth.json", &bad);
        fails(
            &[
                "cir",
                "track",
                "--scenario",
                &scenario,
                "--cir",
                &rec,
                "--truth",
                &path,
                "--out",
                &out,
            ],
            &["--truth", field, "out of range"],
        );
        assert!(!Path::new(&out).exists());
    }
}

/// Item 12: two output flags naming one file (also through `./` or a link to the directory)
/// wrote one output over the other. Refused by name; nothing is written.
#[test]
fn two_output_flags_naming_one_file_are_refused() {
    let dir = TempDir::new();
    let (scenario, sim) = simulate(&dir, "0.2", "0.02", "7");
    let rec = format!("{sim}/recording.npz");
    std::os::unix::fs::symlink(&dir.0, dir.path("link")).unwrap();
    let same = dir.path("same.json");
    let dotted = dir.path("./same.json");
    let linked = dir.path("link/same.json");
    for (flag, other) in [
        ("--snapshots", &same),
        ("--measurements", &dotted),
        ("--snapshots", &linked),
    ] {
        fails(
            &[
                "cir",
                "estimate",
                "--scenario",
                &scenario,
                "--cir",
                &rec,
                "--out",
                &same,
                flag,
                other,
            ],
            &["--out", flag, "same.json"],
        );
        assert!(!Path::new(&same).exists());
    }
    let fig = dir.path("f.svg");
    fails(
        &[
            "cir",
            "track",
            "--scenario",
            &scenario,
            "--cir",
            &rec,
            "--out",
            &dir.path("t.json"),
            "--figure",
            &fig,
            "--delays-figure",
            &fig,
        ],
        &["--figure", "--delays-figure", "f.svg"],
    );
    assert!(!Path::new(&fig).exists());
    assert!(!Path::new(&dir.path("t.json")).exists());
}

/// Item 17: two inputs on standard input (`--scenario - --cir -`) cannot both be read: refused
/// by name before anything is read, in every command with more than one input flag.
#[test]
fn two_inputs_on_standard_input_are_refused() {
    let dir = TempDir::new();
    let s = scenario(&dir);
    let o = dir.path("o.json");
    let cases: [(&[&str], [&str; 2]); 10] = [
        (
            &[
                "cir",
                "estimate",
                "--scenario",
                "-",
                "--cir",
                "-",
                "--out",
                &o,
            ],
            ["--scenario", "--cir"],
        ),
        (
            &[
                "cir",
                "estimate",
                "--scenario",
                &s,
                "--cir",
                "-",
                "--calibration",
                "-",
                "--out",
                &o,
            ],
            ["--cir", "--calibration"],
        ),
        (
            &[
                "cir",
                "track",
                "--scenario",
                "-",
                "--cir",
                "r.npz",
                "--truth",
                "-",
                "--out",
                &o,
            ],
            ["--scenario", "--truth"],
        ),
        (
            &[
                "cir",
                "simulate",
                "--scenario",
                "-",
                "--scene",
                "-",
                "--out-dir",
                &o,
            ],
            ["--scenario", "--scene"],
        ),
        (
            &["track", "--scenario", "-", "--measurements", "-"],
            ["--scenario", "--measurements"],
        ),
        (
            &[
                "track",
                "--scenario",
                &s,
                "--measurements",
                "-",
                "--out",
                "f.svg",
                "--truth",
                "-",
            ],
            ["--measurements", "--truth"],
        ),
        (
            &["calibrate", "--scenario", "-", "--snapshots", "-"],
            ["--scenario", "--snapshots"],
        ),
        (
            &["locate", "--scenario", "-", "--delays", "-"],
            ["--scenario", "--delays"],
        ),
        (
            &["mtl", "locate", "--network", "-", "--ranges", "-"],
            ["--network", "--ranges"],
        ),
        (
            &[
                "plan",
                "--scenario",
                "-",
                "--allowed",
                "-",
                "--move",
                "rx",
                "--objective",
                "mean",
                "--roi",
                "0,10,0,10",
                "--out",
                &o,
            ],
            ["--scenario", "--allowed"],
        ),
    ];
    for (args, [a, b]) in cases {
        fails(args, &[a, b, "standard input"]);
    }
    assert_eq!(dir.files(), ["s.json"]);
    // One input on standard input is fine.
    let mut child = Command::new(BIN)
        .args(["crlb", "--scenario", "-", "--at", "5,5"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let text = std::fs::read(&s).unwrap();
    child.stdin.take().unwrap().write_all(&text).unwrap();
    assert!(child.wait_with_output().unwrap().status.success());
}

/// Item 8: errors name the recording's array and file, and the flag at fault: a recording
/// scaled by 10³⁰⁰ (item 7: it gave `"noise_var": null` and exit 0) fails as `--cir PATH: cfr:`
/// (it said `noise_var`, the estimator's argument); `--statics clusters` without an empty area
/// as `--calibration: …` once (it said `--calibration: calibration: …`); `--extent-sigma-m
/// 1e300` by its flag (it was accepted and gave no track).
#[test]
fn errors_name_the_recordings_array_file_and_flag() {
    let dir = TempDir::new();
    let (scenario, sim) = simulate(&dir, "0.2", "0.02", "5");
    let rec = format!("{sim}/recording.npz");
    let mut r = scatterloc::npz::read_recording(&std::fs::read(&rec).unwrap()).unwrap();
    for v in r.samples.iter_mut() {
        *v *= 1e300;
    }
    let huge = dir.path("huge.npz");
    std::fs::write(&huge, scatterloc::npz::write_recording(&r).unwrap()).unwrap();
    let out = dir.path("o.json");
    let line = fails(
        &[
            "cir",
            "estimate",
            "--scenario",
            &scenario,
            "--cir",
            &huge,
            "--out",
            &out,
        ],
        &[&format!("--cir {huge}: cfr: "), "1e100"],
    );
    assert!(!line.contains("noise_var"), "{line}");
    let line = fails(
        &[
            "cir",
            "estimate",
            "--scenario",
            &scenario,
            "--cir",
            &rec,
            "--out",
            &out,
            "--statics",
            "clusters",
        ],
        &["--calibration: statics clusters"],
    );
    assert!(!line.contains("calibration: calibration"), "{line}");
    fails(
        &[
            "cir",
            "track",
            "--scenario",
            &scenario,
            "--cir",
            &rec,
            "--out",
            &out,
            "--extent-sigma-m",
            "1e300",
        ],
        &["--extent-sigma-m", "0 to 1e3 m"],
    );
    assert!(!Path::new(&out).exists());
}

/// Item 13: Ctrl-C during `cir simulate` takes effect at the next snapshot (exit 130, nothing
/// written), not after the whole simulation. The scene — 3900 point scatterers on 16 384
/// subcarriers for 63 snapshots, inside the truth's and the work's caps — takes over a minute
/// in a debug build (about a second per snapshot); `interrupted` sends SIGINT after 1.5 s and fails the test if the process
/// has not stopped 60 s later (before, it ran the whole simulation first).
#[test]
fn ctrl_c_stops_cir_simulate_within_a_snapshot() {
    use scatterloc::channel::{ChannelScene, PointScatterer};
    let dir = TempDir::new();
    let scenario = scenario(&dir);
    let mut scene = ChannelScene::hangar();
    scene.subcarriers = 16_384;
    scene.dt_s = 0.01;
    scene.duration_s = Some(0.62);
    scene.scatterers = (0..3900)
        .map(|i| PointScatterer {
            position_m: [1.0 + (i % 64) as f64 * 0.25, 1.0 + (i / 64) as f64 * 0.1],
            rcs_m2: 0.01,
        })
        .collect();
    let scene_file = dir.write("scene.json", &serde_json::to_value(&scene).unwrap());
    let out_dir = dir.path("sim");
    let out = crate::common::cli::interrupted(
        Command::new(BIN).args([
            "cir",
            "simulate",
            "--scenario",
            &scenario,
            "--scene",
            &scene_file,
            "--out-dir",
            &out_dir,
        ]),
        "cir simulate",
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(
        !Path::new(&out_dir).exists() || std::fs::read_dir(&out_dir).unwrap().next().is_none(),
        "nothing written"
    );
}
