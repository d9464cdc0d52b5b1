//! End-to-end tests of scale-out (issue 13 §4): sharded `montecarlo` and `mtl roc` runs as
//! separate processes, merged in shuffled order with `scatterloc merge`, equal the unsharded run
//! bit for bit (timing fields aside) for any shard count; bad part sets are named errors that
//! write nothing; `--shard env` reads Slurm and Kubernetes variables; Ctrl-C of a sharded run
//! writes nothing.
#![cfg(not(target_arch = "wasm32"))]

use crate::common;

use std::process::{Child, Command, Output, Stdio};

use serde_json::Value;

use common::cli::{fails, fails_output, interrupted, ok_json_line, read_json, TempDir, BIN};

/// The fields that may differ between a merged and an unsharded result.
const TIMING: [&str; 4] = [
    "wall_time_s",
    "ns_per_ekf_step",
    "wall_ns_per_ekf_step",
    "threads",
];

/// The batch systems' variables `--shard env` reads (removed from every child by default).
const SHARD_VARS: [&str; 3] = [
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_COUNT",
    "JOB_COMPLETION_INDEX",
];

/// A small fast-profile Monte Carlo study: 64 trajectories (4 chunks) × 2 noise runs, T = 0.1 s,
/// 3 s, all three trajectories.
const MC: [&str; 9] = [
    "montecarlo",
    "--runs",
    "64",
    "--noise-runs",
    "2",
    "--dt",
    "0.1",
    "--duration",
    "3",
];

/// A small V-A experiment: 8 realisations.
const ROC: [&str; 6] = ["mtl", "roc", "--experiment", "va", "--realizations", "8"];

/// `args` without the batch variables, plus `env`.
fn command(args: &[&str], env: &[(&str, &str)]) -> Command {
    let mut c = Command::new(BIN);
    c.args(args);
    for v in SHARD_VARS {
        c.env_remove(v);
    }
    for (k, v) in env {
        c.env(k, v);
    }
    c
}

fn run_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    command(args, env).output().expect("run scatterloc")
}

/// `study` followed by `extra`.
fn with(study: &[&str], extra: &[&str]) -> Vec<String> {
    study.iter().chain(extra).map(|s| s.to_string()).collect()
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// The JSON document without the timing fields, as canonical text (equal text ⇔ equal values,
/// bit for bit: serde_json prints the shortest representation that round-trips).
fn without_timing(v: &Value) -> String {
    fn strip(v: &Value) -> Value {
        match v {
            Value::Object(m) => Value::Object(
                m.iter()
                    .filter(|(k, _)| !TIMING.contains(&k.as_str()))
                    .map(|(k, x)| (k.clone(), strip(x)))
                    .collect(),
            ),
            Value::Array(a) => Value::Array(a.iter().map(strip).collect()),
            x => x.clone(),
        }
    }
    strip(v).to_string()
}

/// Runs `study` sharded `count` ways, every shard a separate process started in the order
/// `order` (all running at once, one thread each), and returns the part paths in `order`.
fn run_shards(
    dir: &TempDir,
    study: &[&str],
    tag: &str,
    count: usize,
    order: &[usize],
) -> Vec<String> {
    let children: Vec<(String, Child, Vec<String>)> = order
        .iter()
        .map(|&i| {
            let path = dir.path(&format!("{tag}-part{i}of{count}.json"));
            let shard = format!("{i}/{count}");
            let args = with(
                study,
                &["--threads", "1", "--shard", &shard, "--json", &path],
            );
            let child = command(&strs(&args), &[])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("spawn a shard");
            (path, child, args)
        })
        .collect();
    children
        .into_iter()
        .map(|(path, child, args)| {
            let out = child.wait_with_output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(out.status.success(), "{args:?}: {err}");
            let line: Value = serde_json::from_slice(&out.stdout).unwrap();
            assert_eq!(line["part"], Value::from(path.as_str()));
            path
        })
        .collect()
}

/// `scatterloc merge --json OUT [--out FIG] PARTS…`; returns the merged JSON.
fn merge(out: &str, fig: Option<&str>, parts: &[String]) -> Value {
    let mut args = vec!["merge".to_string(), "--json".into(), out.into()];
    if let Some(f) = fig {
        args.extend(["--out".to_string(), f.to_string()]);
    }
    args.extend(parts.iter().cloned());
    let out_ = run_env(&strs(&args), &[]);
    assert!(
        out_.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out_.stderr)
    );
    read_json(out)
}

#[test]
fn montecarlo_four_shard_processes_merge_to_the_unsharded_run() {
    let dir = TempDir::new();
    let (whole, fig) = (dir.path("whole.json"), dir.path("whole.svg"));
    let summary = ok_json_line(&strs(&with(&MC, &["--json", &whole, "--out", &fig])));
    assert_eq!(summary["scenarios"].as_array().unwrap().len(), 3);
    let parts = run_shards(&dir, &MC, "mc", 4, &[2, 0, 3, 1]);
    // Every part holds its shard: 4 chunks in 4 shards, one each.
    let p = read_json(&parts[0]);
    assert_eq!(
        (&p["format"], &p["version"], &p["study"]),
        (
            &Value::from("scatterloc-part"),
            &Value::from(2),
            &Value::from("montecarlo")
        )
    );
    assert_eq!(p["shard"]["index"], 2);
    assert_eq!(p["shard"]["range"], serde_json::json!([2, 3]));
    assert_eq!(p["config"]["seed"], 1);
    assert_eq!(p["config"]["scenario"]["name"], "sensors2019");
    assert_eq!(p["sums"].as_array().unwrap().len(), 3);
    assert_eq!(p["sums"][1]["trajectories"], 16);

    let (merged, merged_fig) = (dir.path("merged.json"), dir.path("merged.svg"));
    let shuffled = [&parts[3], &parts[1], &parts[0], &parts[2]].map(|s| s.clone());
    let m = merge(&merged, Some(&merged_fig), &shuffled);
    let w = read_json(&whole);
    assert_eq!(without_timing(&m), without_timing(&w));
    assert!(m["scenarios"][0]["wall_time_s"].as_f64().unwrap() > 0.0);
    assert_eq!(
        std::fs::read(&merged_fig).unwrap(),
        std::fs::read(&fig).unwrap(),
        "the same figure"
    );
    assert!(
        dir.files().iter().all(|f| !f.contains(".tmp")),
        "{:?}",
        dir.files()
    );
}

#[test]
fn roc_four_shard_processes_merge_to_the_unsharded_run() {
    let dir = TempDir::new();
    let (whole, fig) = (dir.path("whole.json"), dir.path("whole.svg"));
    let out = run_env(&strs(&with(&ROC, &["--json", &whole, "--out", &fig])), &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let parts = run_shards(&dir, &ROC, "roc", 4, &[1, 3, 0, 2]);
    let p = read_json(&parts[1]);
    assert_eq!(p["study"], "mtl-roc");
    assert_eq!(p["shard"]["range"], serde_json::json!([6, 8]));
    assert_eq!(p["sums"]["realisations"], 2);
    let (merged, merged_fig) = (dir.path("merged.json"), dir.path("merged.svg"));
    let shuffled = [&parts[2], &parts[0], &parts[3], &parts[1]].map(|s| s.clone());
    let m = merge(&merged, Some(&merged_fig), &shuffled);
    let w = read_json(&whole);
    assert_eq!(without_timing(&m), without_timing(&w));
    assert_eq!(m["realisations"], 8);
    assert_eq!(
        std::fs::read(&merged_fig).unwrap(),
        std::fs::read(&fig).unwrap()
    );
}

#[test]
fn merged_result_does_not_depend_on_the_shard_count() {
    let dir = TempDir::new();
    // 48 trajectories: 3 chunks; 5 shards leave two of them empty.
    let study = [
        "montecarlo",
        "--trajectory",
        "II",
        "--runs",
        "48",
        "--noise-runs",
        "2",
        "--dt",
        "0.1",
        "--duration",
        "3",
    ];
    let whole = dir.path("whole.json");
    ok_json_line(&strs(&with(&study, &["--json", &whole])));
    let want = without_timing(&read_json(&whole));
    for (count, order) in [(1, vec![0]), (3, vec![2, 0, 1]), (5, vec![4, 1, 3, 0, 2])] {
        let parts = run_shards(&dir, &study, "n", count, &order);
        if count == 5 {
            let empty = read_json(&parts[3]);
            assert_eq!(empty["shard"]["range"], serde_json::json!([0, 0]));
            assert_eq!(empty["sums"][0]["runs"], 0);
        }
        let m = merge(&dir.path(&format!("merged{count}.json")), None, &parts);
        assert_eq!(without_timing(&m), want, "{count} shards");
    }
}

/// The part set of the bad-set tests: a Monte Carlo study (32 trajectories, 2 chunks) in 3
/// shards (one empty).
const SMALL: [&str; 11] = [
    "montecarlo",
    "--trajectory",
    "I",
    "--runs",
    "32",
    "--noise-runs",
    "1",
    "--dt",
    "0.1",
    "--duration",
    "1",
];

#[test]
fn bad_part_sets_are_named_errors_that_write_nothing() {
    let dir = TempDir::new();
    let parts = run_shards(&dir, &SMALL, "ok", 3, &[0, 1, 2]);
    let part = |path: &str, extra: &[&str]| {
        let args = with(&SMALL, &[extra, &["--json", path][..]].concat());
        ok_json_line(&strs(&args));
        path.to_string()
    };
    let seed = part(&dir.path("seed2.json"), &["--seed", "2", "--shard", "1/3"]);
    let config = part(
        &dir.path("oracle.json"),
        &["--oracle-noise", "--shard", "1/3"],
    );
    let of_two = part(&dir.path("of2.json"), &["--shard", "1/2"]);
    let whole = part(&dir.path("whole.json"), &[]);
    let mut v = read_json(&parts[1]);
    v["version"] = Value::from(3);
    let v2 = dir.write("v2.json", &v);
    let mut v = read_json(&parts[1]);
    v["shard"]["range"] = serde_json::json!([0, 2]);
    let tampered = dir.write("tampered.json", &v);
    let garbage = dir.write_text("garbage.json", "{\"format\": ");
    let before = dir.files();

    let (out, fig) = (dir.path("out.json"), dir.path("fig.svg"));
    let merge_fails = |given: &[&String], needles: &[&str]| {
        let mut args = vec!["merge", "--json", &out, "--out", &fig];
        args.extend(given.iter().map(|s| s.as_str()));
        let err = fails(&args, needles);
        assert_eq!(dir.files(), before, "nothing written: {err}");
        err
    };
    let [p0, p1, p2] = [&parts[0], &parts[1], &parts[2]];
    merge_fails(&[p2, p0], &["merge: missing parts", "shard 1 of 3"]);
    merge_fails(&[p0], &["merge: missing parts", "shards 1-2 of 3"]);
    merge_fails(
        &[p1, p0, p2, p1],
        &["merge: duplicate parts", "shard 1 in", "part1of3.json"],
    );
    // Duplicates and missing shards at once: both named.
    merge_fails(
        &[p0, p0],
        &["duplicate parts", "shard 0 in", "missing parts", "1-2 of 3"],
    );
    merge_fails(
        &[p0, &seed, p2],
        &[
            "merge: foreign parts",
            "seed2.json",
            "config.seed: 2, not 1",
        ],
    );
    merge_fails(
        &[&config, p0, p2],
        &[
            "merge: foreign parts",
            "oracle.json",
            "config.oracle_noise: true, not false",
        ],
    );
    merge_fails(
        &[p0, &of_two, p2],
        &[
            "merge: the parts disagree on the shard count",
            "2 shards: ",
            "of2.json",
        ],
    );
    merge_fails(
        &[p0, &whole, p2],
        &[
            "merge: not scatterloc part files",
            "whole.json",
            "format absent",
        ],
    );
    merge_fails(
        &[p0, &v2, &garbage, p2],
        &[
            "merge: not scatterloc part files",
            "v2.json (version 3",
            "garbage.json (invalid JSON",
        ],
    );
    merge_fails(
        &[p0, &tampered, p2],
        &[
            "merge: inconsistent part",
            "tampered.json",
            "shard.range [0, 2]",
        ],
    );
    let missing = dir.path("nope.json");
    merge_fails(&[p0, &missing], &["merge: PART", "nope.json"]);
    // A good set still merges.
    merge(&out, None, &[p2.clone(), p0.clone(), p1.clone()]);
}

#[test]
fn sharded_runs_refuse_bad_flags() {
    let dir = TempDir::new();
    let part = dir.path("p.json");
    let args = |extra: &[&str]| with(&SMALL, extra);
    let bad = [
        (
            args(&["--shard", "0/2"]),
            vec!["--shard", "--json PART.json"],
        ),
        (
            args(&["--shard", "0/2", "--json", &part, "--out", "f.svg"]),
            vec!["--out", "scatterloc merge"],
        ),
        (
            args(&["--shard", "2/2", "--json", &part]),
            vec!["--shard", "'2/2'", "I/N"],
        ),
        (
            args(&["--shard", "0/0", "--json", &part]),
            vec!["--shard", "'0/0'"],
        ),
        (
            args(&["--shard", "0/100001", "--json", &part]),
            vec!["--shard", "100000"],
        ),
        (
            args(&["--shard", "a/b", "--json", &part]),
            vec!["--shard", "'a/b'"],
        ),
        (
            args(&["--shard", "0/2", "--shards", "2", "--json", &part]),
            vec!["--shards", "--shard env"],
        ),
        (args(&["--shards", "2", "--json", &part]), vec!["--shards"]),
        (
            args(&["--shard", "0/2", "--json", &dir.path("p.svg")]),
            vec!["--json", ".svg"],
        ),
    ];
    for (a, needles) in &bad {
        fails(&strs(a), needles);
    }
    let roc = with(&ROC, &["--shard", "0/2", "--out", "f.svg", "--json", &part]);
    fails(&strs(&roc), &["--out", "scatterloc merge"]);
    assert!(dir.files().is_empty(), "{:?}", dir.files());
}

#[test]
fn shard_env_reads_slurm_and_kubernetes_variables() {
    let dir = TempDir::new();
    let explicit = run_shards(&dir, &SMALL, "explicit", 3, &[1, 2]);
    let env_run = |name: &str, env: &[(&str, &str)], extra: &[&str]| {
        let path = dir.path(name);
        let args = with(
            &SMALL,
            &[&["--shard", "env", "--json", &path][..], extra].concat(),
        );
        let out = run_env(&strs(&args), env);
        assert!(
            out.status.success(),
            "{env:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        read_json(&path)
    };
    let same_as = |v: &Value, part: &str| {
        let want = read_json(part);
        assert_eq!(v["shard"], want["shard"]);
        assert_eq!(v["config"], want["config"]);
        assert_eq!(v["sums"], want["sums"]);
    };
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "1"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    same_as(&env_run("slurm.json", &slurm, &[]), &explicit[0]);
    let slurm_n = env_run(
        "slurm-n.json",
        &[("SLURM_ARRAY_TASK_ID", "2")],
        &["--shards", "3"],
    );
    same_as(&slurm_n, &explicit[1]);
    let k8s = env_run(
        "k8s.json",
        &[("JOB_COMPLETION_INDEX", "2")],
        &["--shards", "3"],
    );
    same_as(&k8s, &explicit[1]);

    let fails_env = |env: &[(&str, &str)], extra: &[&str], needles: &[&str]| {
        let path = dir.path("never.json");
        let args = with(
            &SMALL,
            &[&["--shard", "env", "--json", &path][..], extra].concat(),
        );
        fails_output(&strs(&args), &run_env(&strs(&args), env), needles);
    };
    fails_env(
        &[],
        &[],
        &["--shard env", "SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"],
    );
    fails_env(
        &[("JOB_COMPLETION_INDEX", "0")],
        &[],
        &["JOB_COMPLETION_INDEX", "--shards"],
    );
    fails_env(
        &[("JOB_COMPLETION_INDEX", "x1")],
        &["--shards", "3"],
        &["JOB_COMPLETION_INDEX='x1'", "whole number"],
    );
    fails_env(
        &[("JOB_COMPLETION_INDEX", "3")],
        &["--shards", "3"],
        &["JOB_COMPLETION_INDEX=3", "below the shard count 3"],
    );
    fails_env(
        &[("SLURM_ARRAY_TASK_ID", "0")],
        &[],
        &["SLURM_ARRAY_TASK_COUNT", "--shards"],
    );
    fails_env(
        &[
            ("SLURM_ARRAY_TASK_ID", "20"),
            ("SLURM_ARRAY_TASK_COUNT", "20"),
        ],
        &[],
        &["SLURM_ARRAY_TASK_ID=20", "--array=0-19"],
    );
    // A re-submitted task of a 3-shard array (`sbatch --array=2`: SLURM_ARRAY_TASK_COUNT=1)
    // with the study's count is that shard (issue 28); without it, a named error.
    let resubmitted = env_run(
        "resubmitted.json",
        &[
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "1"),
        ],
        &["--shards", "3"],
    );
    same_as(&resubmitted, &explicit[1]);
    fails_env(
        &[
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "1"),
        ],
        &[],
        &["SLURM_ARRAY_TASK_ID=2", "shard count 1", "--shards N"],
    );
    fails_env(
        &[("JOB_COMPLETION_INDEX", "0")],
        &["--shards", "100001"],
        &["1..=100000"],
    );
    fails_env(
        &[("JOB_COMPLETION_INDEX", "0"), ("SLURM_ARRAY_TASK_ID", "0")],
        &[],
        &["both"],
    );
    assert!(!dir.files().contains(&"never.json".to_string()));
}

#[test]
fn ctrl_c_stops_a_sharded_run_without_writing_its_part() {
    let dir = TempDir::new();
    let part = dir.path("part.json");
    let args = [
        "montecarlo",
        "--trajectory",
        "I",
        "--runs",
        "5000000",
        "--noise-runs",
        "1",
        "--dt",
        "0.1",
        "--shard",
        "0/2",
        "--json",
        &part,
    ];
    let out = interrupted(&mut command(&args, &[]), "the sharded run");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(out.stdout.is_empty());
    assert!(err.contains("cancelled"), "{err}");
    assert!(dir.files().is_empty(), "{:?}", dir.files());
}

/// Sets the digest of part `v` to that of its sums: an edit that keeps the part
/// self-consistent, so only the range checks refuse it.
fn redigest(v: &mut Value) {
    v["digest"] = Value::from(scatterloc::study::sums_digest(&v["sums"]).unwrap());
}

/// Issue 24: parts whose sums are impossible, corrupted, truncated or of another version are
/// named errors (exit status 2) naming the part and the field, and write nothing.
#[test]
fn tampered_parts_are_named_errors_that_write_nothing() {
    let dir = TempDir::new();
    let parts = run_shards(&dir, &SMALL, "ok", 2, &[0, 1]);
    let roc = run_shards(&dir, &ROC, "roc", 2, &[0, 1]);
    let good = read_json(&parts[1]);
    let edit = |name: &str, f: &dyn Fn(&mut Value), redo: bool| {
        let mut v = good.clone();
        f(&mut v);
        if redo {
            redigest(&mut v);
        }
        dir.write(name, &v)
    };
    let negative = edit(
        "neg.json",
        &|v| v["sums"][0]["squared_error"][3] = serde_json::json!([-3.2]),
        true,
    );
    let nan_nees = edit(
        "nan.json",
        &|v| v["sums"][0]["nees"][2] = serde_json::json!("nan"),
        true,
    );
    let failed = edit(
        "failed.json",
        &|v| v["sums"][0]["failed_runs"] = serde_json::json!(5),
        true,
    );
    let asym = edit(
        "asym.json",
        &|v| v["sums"][0]["fisher"][1][1] = serde_json::json!([-7.0]),
        true,
    );
    let corrupt = edit(
        "corrupt.json",
        &|v| v["sums"][0]["squared_error"][3] = serde_json::json!([1.0]),
        false,
    );
    let wall = edit(
        "wall.json",
        &|v| v["timing"]["wall_time_s"][0] = serde_json::json!(-1.0),
        false,
    );
    let text = std::fs::read_to_string(&parts[1]).unwrap();
    let truncated = dir.write_text("trunc.json", &text[..text.len() * 2 / 3]);
    let mut old = Vec::new();
    for (i, p) in parts.iter().enumerate() {
        let mut v = read_json(p);
        v["version"] = Value::from(1);
        v.as_object_mut().unwrap().remove("digest");
        old.push(dir.write(&format!("old{i}.json"), &v));
    }
    let mut r = read_json(&roc[1]);
    r["sums"]["sums"][0][0]["detection_ratio"] = serde_json::json!([-0.83]);
    redigest(&mut r);
    let pd = dir.write("pd.json", &r);
    let before = dir.files();
    let (out, fig) = (dir.path("out.json"), dir.path("fig.svg"));
    let merge_fails = |given: &[&String], needles: &[&str]| {
        let mut args = vec!["merge", "--json", &out, "--out", &fig];
        args.extend(given.iter().map(|s| s.as_str()));
        let err = fails(&args, needles);
        assert_eq!(dir.files(), before, "nothing written: {err}");
    };
    let p0 = &parts[0];
    let bad = "merge: inconsistent part";
    merge_fails(
        &[p0, &negative],
        &[bad, "neg.json: sums[0].squared_error[3]: -3.2 is negative"],
    );
    merge_fails(
        &[p0, &nan_nees],
        &[bad, "nan.json: sums[0].nees[2]: NaN is not finite"],
    );
    merge_fails(
        &[p0, &failed],
        &[
            bad,
            "failed.json: sums[0].failed_runs: 5 failed + 16 counted",
        ],
    );
    merge_fails(
        &[p0, &asym],
        &[bad, "asym.json: sums[0].fisher[1]: not symmetric"],
    );
    merge_fails(
        &[p0, &corrupt],
        &[bad, "corrupt.json: sums do not match their digest"],
    );
    merge_fails(
        &[p0, &wall],
        &["wall.json (timing.wall_time_s[0]: -1 is not a wall time"],
    );
    merge_fails(&[p0, &truncated], &["trunc.json (invalid JSON: EOF"]);
    merge_fails(
        &[&old[0], &old[1]],
        &[
            "merge: the parts are of part format version 1",
            "reads version 2",
        ],
    );
    merge_fails(
        &[&roc[0], &pd],
        &[bad, "pd.json: sums.sums[0][0].detection_ratio: -0.83"],
    );
    // The untouched sets still merge, a part from stdin too (read once: merge reads a part
    // twice, for the set and for its sums).
    merge(&out, None, &[parts[1].clone(), parts[0].clone()]);
    merge(&dir.path("roc.json"), None, &roc);
    let piped = dir.path("piped.json");
    let o = command(&["merge", "--json", &piped, &parts[0], "-"], &[])
        .stdin(std::fs::File::open(&parts[1]).unwrap())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        without_timing(&read_json(&piped)),
        without_timing(&read_json(&out))
    );
}

/// Issue 24: a 229 MiB part (under the 256 MiB input cap) padded with a long array of sums
/// is refused with a named error under a 4 GB address-space limit (it took 7.7 GB and aborted
/// before). `merge` holds one part's text at a time and checks array lengths before
/// allocating them.
#[test]
fn a_padded_part_is_a_named_error_within_the_memory_cap() {
    let dir = TempDir::new();
    let parts = run_shards(&dir, &SMALL, "ok", 2, &[0, 1]);
    let text = std::fs::read_to_string(&parts[1]).unwrap();
    // 229 MiB of empty exact sums in the first squared-error list.
    let at = text.find("\"squared_error\":[").unwrap() + "\"squared_error\":[".len();
    let pad = "[],".repeat((229 << 20) / 3);
    let padded = format!("{}{pad}{}", &text[..at], &text[at..]);
    let big = dir.write_text("big.json", &padded);
    drop((padded, pad, text));
    let out = dir.path("out.json");
    let script = format!(
        "ulimit -v 4000000; exec {BIN} merge --json {out} {} {big}",
        parts[0]
    );
    let o = Command::new("sh").args(["-c", &script]).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("merge: inconsistent part")
            && err.contains("big.json: sums[0].squared_error: more than 64 entries"),
        "{err}"
    );
    assert!(!std::path::Path::new(&out).exists());
}

/// `slurm submit` checks the study and finds `sbatch` before it writes or submits anything
/// (issue 28); the submissions themselves are tested on a real Slurm cluster by
/// tests/deploy/test_slurm.py.
#[test]
fn slurm_submit_refuses_bad_input_before_anything() {
    let dir = TempDir::new();
    let d = dir.path("");
    let cases: [(&[&str], &[&str]); 6] = [
        (
            &["--", "crlb-map", "--scenario", "s.json", "--out", "m.png"],
            &["slurm submit", "not a study that runs in shards"],
        ),
        (
            &["--", "montecarlo", "--json", "x.json"],
            &["--json is set by slurm submit"],
        ),
        (
            &["--", "mtl", "roc", "--experiment", "va", "--threads", "2"],
            &["--threads is set by slurm submit"],
        ),
        (
            &["--", "montecarlo", "--runz", "3"],
            &["the study after --", "--runz"],
        ),
        (
            &["--name", "../x", "--", "montecarlo"],
            &["--name", "'../x'"],
        ),
        (&["--json", "x.txt", "--", "montecarlo"], &["--json"]),
    ];
    for (extra, needles) in cases {
        let args: Vec<&str> = ["slurm", "submit", "--shards", "4", "--dir", &d]
            .into_iter()
            .chain(extra.iter().copied())
            .collect();
        fails_output(&args, &run_env(&args, &[]), needles);
    }
    // No sbatch on PATH: exit 1 naming it, nothing written.
    let args = [
        "slurm",
        "submit",
        "--shards",
        "4",
        "--dir",
        &d,
        "--",
        "montecarlo",
    ];
    let out = run_env(&args, &[("PATH", "")]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("sbatch"));
    assert!(dir.files().is_empty(), "{:?}", dir.files());
}
