//! Running one shard of a study (issue 13 §4): `--shard I/N|env` resolved against the batch
//! system's variables, and the part file a sharded run writes instead of its result — the
//! study's full configuration and seed, the shard, its timing and the sufficient statistics
//! ([`scatterloc::track::StudySums`], [`scatterloc::mtl::experiment::Tally`]), which
//! `scatterloc merge` (`super::merge`) adds up exactly.
//!
//! Part file (JSON, format `scatterloc-part`, version 1):
//! `{"format": "scatterloc-part", "version": 1, "software": "scatterloc 0.1.0", "study":
//! "montecarlo" | "mtl-roc", "config": {…}, "shard": {"index": I, "count": N, "unit": "chunks" |
//! "realisations", "range": [a, b], "total": C}, "timing": {"threads": T, "wall_time_s": [..]},
//! "sums": …}`. The shard covers the units `[a, b)` = [`Shard::range`] of `C`.

use serde::{Deserialize, Serialize};

use scatterloc::math::{Shard, MAX_SHARDS};

use super::io::emit;
use super::output::{check_writable, write_json_file, Format};
use crate::cli::{ShardArgs, ShardSpec};
use crate::failure::CliError;

/// The `format` of a part file.
pub const PART_FORMAT: &str = "scatterloc-part";
/// The `version` of the part format this build reads and writes.
pub const PART_VERSION: u64 = 1;

/// The `software` of a part file: parts of one study must come from the same build version.
pub fn software() -> String {
    format!("scatterloc {}", env!("CARGO_PKG_VERSION"))
}

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
/// `SLURM_ARRAY_TASK_COUNT` or `--shards N`) or a Kubernetes Indexed Job
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
                let count =
                    match (var("SLURM_ARRAY_TASK_COUNT"), shards) {
                        (Some(c), shards) => {
                            let c = number("SLURM_ARRAY_TASK_COUNT", &c)?;
                            if shards.is_some_and(|n| n != c) {
                                return Err(bad(format!(
                                    "--shards {} disagrees with SLURM_ARRAY_TASK_COUNT={c}",
                                    shards.unwrap_or(0)
                                )));
                            }
                            c
                        }
                        (None, Some(n)) => n,
                        (None, None) => return Err(bad(
                            "SLURM_ARRAY_TASK_COUNT is not set; give the number of shards with \
                         --shards N"
                                .into(),
                        )),
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
             sbatch --array=0-{})",
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

/// Where a shard lies in its study.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardDoc {
    /// `I`, 0-based.
    pub index: usize,
    /// `N`.
    pub count: usize,
    /// What the study is split into: `chunks` (Monte Carlo) or `realisations` (ROC).
    pub unit: String,
    /// The units `[a, b)` of this shard.
    pub range: [usize; 2],
    /// The study's units `C`.
    pub total: usize,
}

impl ShardDoc {
    /// Shard `shard` of a study of `total` `unit`s.
    pub fn new(shard: Shard, unit: &str, total: usize) -> ShardDoc {
        let r = shard.range(total);
        ShardDoc {
            index: shard.index(),
            count: shard.count(),
            unit: unit.to_string(),
            range: [r.start, r.end],
            total,
        }
    }
}

/// Run time of a part (or of the merged study).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Timing {
    /// Worker threads used.
    pub threads: usize,
    /// Wall time, s, one per entry of `sums` (Monte Carlo: per trajectory).
    pub wall_time_s: Vec<f64>,
}

/// A part file as written.
#[derive(Serialize)]
struct PartOut<'a, C: Serialize, S: Serialize> {
    format: &'static str,
    version: u64,
    software: String,
    study: &'a str,
    config: &'a C,
    shard: &'a ShardDoc,
    timing: &'a Timing,
    sums: &'a S,
}

/// Writes the part file `path` (atomically) and prints the one-line summary `{part, study,
/// shard, …extra}`.
pub fn write_part<C: Serialize, S: Serialize, E: Serialize>(
    path: &str,
    study: &str,
    config: &C,
    shard: &ShardDoc,
    timing: &Timing,
    sums: &S,
    extra: &E,
) -> Result<(), CliError> {
    let part = PartOut {
        format: PART_FORMAT,
        version: PART_VERSION,
        software: software(),
        study,
        config,
        shard,
        timing,
        sums,
    };
    write_json_file("json", path, &part)?;
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
    emit(&text)
}
