//! `scatterloc slurm submit` (issue 28): a sharded study as a Slurm job array plus a merge job
//! that depends on it, submitted with the scripts of docs/scale-out.md — the same files
//! (`docs/slurm/*.sbatch`, compiled in), written to DIR/slurm/ so a user can read and re-run
//! them. The study is checked before anything is written or submitted: parsed as the CLI parses
//! it, then with the checks each shard makes before its run (issue 37).

use std::path::Path;
use std::process::Command;

use serde_json::json;

use scatterloc::math::MAX_SHARDS;

use super::flags::at_flag;
use super::io::emit_summary;
use super::output::{Format, OutputSet};
use super::{montecarlo, mtl};
use crate::cli::{self, MtlCommand, SubmitArgs};
use crate::failure::CliError;

/// The array script of docs/scale-out.md: one shard per task.
const SHARDS_SCRIPT: &str = include_str!("../../../../docs/slurm/shards.sbatch");
/// The merge script of docs/scale-out.md.
const MERGE_SCRIPT: &str = include_str!("../../../../docs/slurm/merge.sbatch");

/// Checks the study after `--` as its `shards` tasks of `threads` threads each, working in
/// `dir`, would check it before their runs, and returns its default name. Refused (exit 2,
/// naming the flag): what the CLI would not parse, the flags this command sets itself, and
/// what every shard would refuse (issue 37: `--runs 0`, a missing `--scenario`, a shard over
/// `--max-cpu-hours`, …), which was submitted as N failing tasks and a merge job pending
/// forever.
fn check_study(
    study: &[String],
    dir: &Path,
    shards: usize,
    threads: usize,
) -> Result<&'static str, CliError> {
    let bad = |m: String| CliError::usage(format!("slurm submit: the study after --: {m}"));
    let argv = std::iter::once("scatterloc".to_string()).chain(study.iter().cloned());
    let matches = cli::command()
        .try_get_matches_from(argv)
        .map_err(|e| bad(e.to_string().lines().next().unwrap_or("").to_string()))?;
    let mut parsed = <cli::Cli as clap::FromArgMatches>::from_arg_matches(&matches)
        .map_err(|e| bad(e.to_string()))?;
    let given = |shard: &cli::ShardArgs, json: bool, out: bool, threads: bool| {
        [
            ("--shard", shard.shard.is_some()),
            ("--shards", shard.shards.is_some()),
            ("--json", json),
            ("--out", out),
            ("--threads", threads),
        ]
        .into_iter()
        .find(|(_, g)| *g)
        .map(|(f, _)| f)
    };
    let (name, set) = match &parsed.command {
        cli::Command::Montecarlo(a) => (
            "montecarlo",
            given(
                &a.shard,
                a.json.is_some(),
                a.out.is_some(),
                a.threads.is_some(),
            ),
        ),
        cli::Command::Mtl {
            command: MtlCommand::Roc(a),
        } => (
            "mtl-roc",
            given(
                &a.shard,
                a.json.is_some(),
                a.out.is_some(),
                a.threads.is_some(),
            ),
        ),
        _ => {
            return Err(bad(format!(
                "'{}' is not a study that runs in shards (montecarlo or mtl roc)",
                study.join(" ")
            )))
        }
    };
    if let Some(flag) = set {
        return Err(bad(format!(
            "{flag} is set by slurm submit (--json/--out of the merged result go before --)"
        )));
    }
    // What each shard checks before its run (`bad`: the study's flags are named as they are).
    match &mut parsed.command {
        cli::Command::Montecarlo(a) => {
            as_the_tasks_read(&mut a.study.scenario, dir).map_err(|e| bad(e.message))?;
            montecarlo::check_shards(a, shards, threads).map_err(|e| bad(e.message))?;
        }
        cli::Command::Mtl {
            command: MtlCommand::Roc(a),
        } => {
            mtl::roc_config_of(a).map_err(|e| bad(e.message))?;
        }
        _ => {}
    }
    Ok(name)
}

/// `--scenario` of a study as its tasks read it: a relative path is DIR's (their working
/// directory, not this command's); standard input is refused (batch jobs have none).
fn as_the_tasks_read(scenario: &mut Option<String>, dir: &Path) -> Result<(), CliError> {
    match scenario.as_deref() {
        Some("-") => Err(CliError::usage(
            "--scenario: '-' (standard input) is not there for batch jobs; give the scenario \
             as a file",
        )),
        Some(p) if Path::new(p).is_relative() => {
            *scenario = Some(dir.join(p).display().to_string());
            Ok(())
        }
        _ => Ok(()),
    }
}

/// Refuses part files `DIR/parts/NAME-?????.json` left by an earlier run (issue 37): the merge
/// job reads every file of that pattern, so it would add them to the new ones or refuse the set.
fn check_no_parts(dir: &Path, name: &str) -> Result<(), CliError> {
    let parts = dir.join("parts");
    let entries = match std::fs::read_dir(&parts) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => {
            return Err(CliError::usage(format!(
                "--dir: cannot read {}: {e}",
                parts.display()
            )))
        }
    };
    let is_part = |file: &str| {
        file.strip_prefix(name)
            .and_then(|f| f.strip_prefix('-'))
            .and_then(|f| f.strip_suffix(".json"))
            .is_some_and(|index| index.chars().count() == 5)
    };
    let mut stale: Vec<String> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|f| is_part(f))
        .collect();
    stale.sort();
    match stale.first() {
        None => Ok(()),
        Some(first) => Err(CliError::usage(format!(
            "--dir: {} already holds {} part file(s) of '{name}' from an earlier run ({first}{}), \
             which the merge job would read with the new ones; remove them, or use another \
             --dir or --name",
            parts.display(),
            stale.len(),
            if stale.len() > 1 { ", …" } else { "" }
        ))),
    }
}

/// `text` quoted for a POSIX shell: in single quotes, each `'` in it as `'\''`.
fn shell_quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// Runs `sbatch --parsable ARGS` with `SCATTERLOC=exe` in its environment (exported to the
/// job by `--export=ALL`; inside `--export=…,SCATTERLOC=PATH` a comma of the path would split
/// it) and returns the job id (`123` of `123;cluster`).
fn sbatch(args: &[String], exe: &Path) -> Result<String, String> {
    let out = Command::new("sbatch")
        .env("SCATTERLOC", exe)
        .arg("--parsable")
        .args(args)
        .output()
        .map_err(|e| format!("sbatch: {e} (run this on a Slurm login node)"))?;
    if !out.status.success() {
        return Err(format!(
            "sbatch failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let id = text.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(format!("sbatch printed no job id: '{}'", text.trim()));
    }
    Ok(id)
}

/// `scatterloc slurm submit --shards N [...] -- STUDY...`.
pub fn slurm_submit(args: &SubmitArgs) -> Result<(), CliError> {
    let n = args.shards;
    if !(1..=MAX_SHARDS).contains(&n) {
        return Err(CliError::usage(format!(
            "--shards: {n} is outside the allowed range 1..={MAX_SHARDS}"
        )));
    }
    let cpus = args.cpus_per_task.unwrap_or(2);
    if !(1..=256).contains(&cpus) {
        return Err(CliError::usage(format!(
            "--cpus-per-task: {cpus} is outside the allowed range 1..=256"
        )));
    }
    let dir =
        std::path::absolute(args.dir.as_deref().unwrap_or(".")).map_err(|e| at_flag("dir", e))?;
    if !dir.is_dir() {
        return Err(CliError::usage(format!(
            "--dir: '{}' is not a directory",
            dir.display()
        )));
    }
    let study_name = check_study(&args.study, &dir, n, cpus)?;
    let name = args.name.clone().unwrap_or_else(|| study_name.to_string());
    if name.is_empty()
        || name.len() > 64
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
    {
        return Err(CliError::usage(format!(
            "--name: '{}' must be 1 to 64 characters of A-Z, a-z, 0-9, '-', '_', '.' (it names \
             files)",
            name.escape_debug()
        )));
    }
    let json_out = args.json.clone().unwrap_or_else(|| format!("{name}.json"));
    Format::of("json", &json_out, &[Format::Json])?;
    if let Some(out) = &args.out {
        Format::of("out", out, &[Format::Svg, Format::Png])?;
    }
    check_no_parts(&dir, &name)?;
    let dir_s = dir.display().to_string();
    let exe = std::env::current_exe()
        .map_err(|e| CliError::output(format!("the path of this binary: {e}")))?;

    // Slurm must be there before anything is written.
    match Command::new("sbatch").arg("--version").output() {
        Ok(o) if o.status.success() => {}
        Ok(o) => {
            return Err(CliError::output(format!(
                "sbatch --version failed ({}): {}",
                o.status,
                String::from_utf8_lossy(&o.stderr).trim()
            )))
        }
        Err(e) => {
            return Err(CliError::output(format!(
                "sbatch: {e} (run this on a Slurm login node)"
            )))
        }
    }

    // The docs' scripts, as files a user can read and re-run.
    let scripts = dir.join("slurm");
    std::fs::create_dir_all(&scripts)
        .map_err(|e| CliError::usage(format!("--dir: cannot create {}: {e}", scripts.display())))?;
    let shards_path = scripts.join("shards.sbatch").display().to_string();
    let merge_path = scripts.join("merge.sbatch").display().to_string();
    let mut files = OutputSet::new();
    files.bytes("dir", &shards_path, SHARDS_SCRIPT.as_bytes())?;
    files.bytes("dir", &merge_path, MERGE_SCRIPT.as_bytes())?;
    files.commit()?;

    let mut common = vec![format!("--chdir={dir_s}"), "--export=ALL".to_string()];
    if let Some(p) = &args.partition {
        common.push(format!("--partition={p}"));
    }
    let mut array = common.clone();
    array.push(format!("--array=0-{}", n - 1));
    array.push(format!("--job-name={name}-shards"));
    array.push(format!("--cpus-per-task={cpus}"));
    if let Some(t) = &args.time {
        array.push(format!("--time={t}"));
    }
    if let Some(m) = &args.mem {
        array.push(format!("--mem={m}"));
    }
    array.push(shards_path.clone());
    array.push(name.clone());
    array.push(n.to_string());
    array.extend(args.study.iter().cloned());
    let shards_job = sbatch(&array, &exe).map_err(CliError::output)?;

    let mut merge = common;
    merge.push(format!("--dependency=afterok:{shards_job}"));
    merge.push(format!("--job-name={name}-merge"));
    merge.push(merge_path.clone());
    merge.push(name.clone());
    merge.push("--json".into());
    merge.push(json_out.clone());
    if let Some(out) = &args.out {
        merge.push("--out".into());
        merge.push(out.clone());
    }
    let merge_job = sbatch(&merge, &exe).map_err(|e| {
        CliError::output(format!(
            "the array job {shards_job} was submitted, the merge job was not: {e}; submit it \
             with `SCATTERLOC={} sbatch {}` (or cancel the array: scancel {shards_job})",
            shell_quote(&exe.display().to_string()),
            merge
                .iter()
                .map(|a| shell_quote(a))
                .collect::<Vec<_>>()
                .join(" ")
        ))
    })?;

    let at = |p: &str| dir.join(p).display().to_string();
    emit_summary(
        &json!({
            "shards_job": shards_job,
            "merge_job": merge_job,
            "shards": n,
            "name": name,
            "dir": dir_s,
            "parts": at(&format!("parts/{name}-?????.json")),
            "json": at(&json_out),
            "out": args.out.as_deref().map(at),
            "shard_logs": at(&format!("shard-{shards_job}-*.log")),
            "merge_log": at(&format!("merge-{merge_job}.log")),
            "scripts": [shards_path, merge_path],
            "watch": format!("squeue -j {shards_job},{merge_job}"),
        })
        .to_string(),
    )
}
