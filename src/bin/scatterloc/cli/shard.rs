//! Flags of scale-out (issue 13 §4): `--shard I/N|env` and `--shards N` of the long studies
//! (`montecarlo`, `mtl roc`), and `scatterloc merge`.

use clap::Args;

use super::values::{shard_spec, whole, ShardSpec};

/// Running one shard of a study (flattened into `montecarlo` and `mtl roc`).
#[derive(Debug, Args)]
pub struct ShardArgs {
    /// Run only shard I of N (0-based) and write its part file to --json PART.json, for
    /// `scatterloc merge`. env: I and N from SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT
    /// (Slurm job array, --array=0-(N-1)), or JOB_COMPLETION_INDEX (Kubernetes Indexed Job)
    /// with --shards N.
    #[arg(long, value_name = "I/N|env", value_parser = shard_spec)]
    pub shard: Option<ShardSpec>,
    /// The number of shards N for --shard env: needed with JOB_COMPLETION_INDEX, and with Slurm
    /// when SLURM_ARRAY_TASK_COUNT is not set.
    #[arg(long, value_name = "N", value_parser = whole)]
    pub shards: Option<usize>,
}

/// `scatterloc merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The merged result: the same JSON as the unsharded run.
    #[arg(long, value_name = "OUT.json")]
    pub json: String,
    /// The figure of the unsharded run: .svg or .png.
    #[arg(long, value_name = "FIG.{svg,png}")]
    pub out: Option<String>,
    /// The part files of every shard (any order; '-' = standard input, once).
    #[arg(value_name = "PART", required = true, num_args = 1..)]
    pub parts: Vec<String>,
}
