//! Running one shard of a study (issue 13 §4): `--shard I/N|env` resolved against the batch
//! system's variables, and the writing of the part file a sharded run writes instead of its
//! result ([`scatterloc::study::PartFile`], whose format is documented in the library), which
//! `scatterloc merge` (`super::merge`) checks and adds up exactly.

use serde::Serialize;

use scatterloc::math::{Shard, MAX_SHARDS};
use scatterloc::study::{PartFile, ShardDoc};

use super::io::emit_summary;
use super::output::{check_writable, write_json_file, Format};
use crate::cli::{ShardArgs, ShardSpec};
use crate::failure::CliError;

/// The shard of a run from `--shard` and `--shards` (`None`: the whole study). `--shard env`
/// reads the process environment ([`from_env`]).
pub fn resolve(args: &ShardArgs) -> Result<Option<Shard>, CliError> {
    match (args.shard, args.shards) {
        (None, Some(_)) => Err(CliError::usage(
            "--shards: only with --shard env (the count of --shard I/N is N)",
        )),
        (None, None) => Ok(None),
        (Some(ShardSpec::Given(_)), Some(_)) => Err(CliError::usage(
            "--shards: only with --shard env (the count of --shard I/N is N)",
        )),
        (Some(ShardSpec::Given(s)), None) => Ok(Some(s)),
        (Some(ShardSpec::Env), shards) => {
            from_env(shards, |name| std::env::var(name).ok()).map(Some)
        }
    }
}

/// `--shard env`: the index and count from a Slurm job array (`SLURM_ARRAY_TASK_ID`, and
/// `--shards N` or else `SLURM_ARRAY_TASK_COUNT`) or a Kubernetes Indexed Job
/// (`JOB_COMPLETION_INDEX` and `--shards N`); `var` looks a variable up. Errors name the
/// variable or flag.
pub fn from_env(
    shards: Option<usize>,
    var: impl Fn(&str) -> Option<String>,
) -> Result<Shard, CliError> {
    let bad = |msg: String| CliError::usage(format!("--shard env: {msg}"));
    let number = |name: &str, text: &str| {
        text.trim().parse::<usize>().map_err(|_| {
            bad(format!(
                "{name}='{}' is not a whole number",
                text.escape_debug()
            ))
        })
    };
    let slurm = var("SLURM_ARRAY_TASK_ID");
    let k8s = var("JOB_COMPLETION_INDEX");
    let (source, index, count) =
        match (slurm, k8s) {
            (Some(_), Some(_)) => return Err(bad(
                "both SLURM_ARRAY_TASK_ID and JOB_COMPLETION_INDEX are set; unset the one that \
                 does not belong to this job"
                    .into(),
            )),
            (Some(id), None) => {
                let index = number("SLURM_ARRAY_TASK_ID", &id)?;
                // `--shards N` is the study's count and wins: a re-submission of some of the
                // array's tasks (`sbatch --array=7,12-13`, issue 28) has a smaller
                // SLURM_ARRAY_TASK_COUNT than the study's shard count.
                let count = match (shards, var("SLURM_ARRAY_TASK_COUNT")) {
                    (Some(n), _) => n,
                    (None, Some(c)) => number("SLURM_ARRAY_TASK_COUNT", &c)?,
                    (None, None) => {
                        return Err(bad(
                            "SLURM_ARRAY_TASK_COUNT is not set; give the number of \
                                        shards with --shards N"
                                .into(),
                        ))
                    }
                };
                ("SLURM_ARRAY_TASK_ID", index, count)
            }
            (None, Some(i)) => {
                let index = number("JOB_COMPLETION_INDEX", &i)?;
                let count = shards.ok_or_else(|| {
                    bad("JOB_COMPLETION_INDEX needs --shards N (the Job's completions)".into())
                })?;
                ("JOB_COMPLETION_INDEX", index, count)
            }
            (None, None) => {
                return Err(bad(
                    "neither SLURM_ARRAY_TASK_ID (Slurm job array) nor JOB_COMPLETION_INDEX \
                 (Kubernetes Indexed Job) is set"
                        .into(),
                ))
            }
        };
    if !(1..=MAX_SHARDS).contains(&count) {
        return Err(bad(format!(
            "the shard count {count} is outside the allowed range 1..={MAX_SHARDS}"
        )));
    }
    Shard::new(index, count).ok_or_else(|| {
        bad(format!(
            "{source}={index} is not below the shard count {count} (shards are 0-based: \
             sbatch --array=0-{}; a re-submitted task of a larger array needs the study's \
             count: --shards N)",
            count - 1
        ))
    })
}

/// The part file of a sharded run: `--json` is required (the part), `--out` is refused (the
/// figure needs every shard: `scatterloc merge --out`). Checked before the run.
pub fn part_path(json: Option<&str>, out: Option<&str>) -> Result<String, CliError> {
    if out.is_some() {
        return Err(CliError::usage(
            "--out: a sharded run (--shard) writes a part file, not a figure; draw the figure \
             with `scatterloc merge --json OUT.json --out FIG PART...`",
        ));
    }
    let path = json.ok_or_else(|| {
        CliError::usage(
            "--shard: a sharded run needs --json PART.json (the part file for `scatterloc merge`)",
        )
    })?;
    Format::of("json", path, &[Format::Json])?;
    check_writable("json", path)?;
    Ok(path.to_string())
}

/// Writes the part file `part` to `path` (atomically) and prints the one-line summary
/// `{part, study, shard, …extra}`.
pub fn write_part<C: Serialize, S: Serialize + ?Sized, E: Serialize>(
    path: &str,
    part: &PartFile<C, S>,
    extra: &E,
) -> Result<(), CliError> {
    let (study, shard, timing) = (part.study(), part.shard(), part.timing());
    write_json_file("json", path, part)?;
    #[derive(Serialize)]
    struct Line<'a, E: Serialize> {
        part: &'a str,
        study: &'a str,
        shard: &'a ShardDoc,
        #[serde(flatten)]
        extra: &'a E,
        wall_time_s: f64,
        threads: usize,
    }
    let line = Line {
        part: path,
        study,
        shard,
        extra,
        wall_time_s: timing.wall_time_s.iter().sum(),
        threads: timing.threads,
    };
    let text = serde_json::to_string(&line)
        .map_err(|e| CliError::output(format!("encoding JSON: {e}")))?;
    emit_summary(&text)
}
