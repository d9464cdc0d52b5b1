//! Flags of `scatterloc slurm submit` (issue 28): a sharded study as a Slurm job array and a
//! merge job that waits for it.

use clap::{Args, Subcommand};

use super::values::whole;

/// `scatterloc slurm …`.
#[derive(Debug, Subcommand)]
pub enum SlurmCommand {
    /// Submit a study in shards: a Slurm job array and a dependent merge job (docs/scale-out.md).
    ///
    /// Writes the scripts of docs/scale-out.md (DIR/slurm/shards.sbatch, merge.sbatch),
    /// submits `--array=0-(N-1)` of `shards.sbatch NAME N STUDY...` and a merge job with
    /// `--dependency=afterok` on it, both with DIR as their working directory and this binary as
    /// SCATTERLOC. The study (after `--`) is `montecarlo …` or `mtl roc …` without --shard,
    /// --shards, --json, --out and --threads (set here); it is checked as each shard checks it
    /// (a relative --scenario is DIR's) before anything is written or submitted. Prints the job
    /// ids and where the parts, the logs and the result will be.
    Submit(SubmitArgs),
}

/// `scatterloc slurm submit`.
#[derive(Debug, Args)]
pub struct SubmitArgs {
    /// Number of shards N (array tasks), 1..=100000.
    #[arg(long, value_name = "N", value_parser = whole)]
    pub shards: usize,
    /// The study's name: parts/NAME-IIIII.json, the job names [default: the study, e.g.
    /// montecarlo or mtl-roc].
    #[arg(long, value_name = "NAME")]
    pub name: Option<String>,
    /// The jobs' working directory (on a file system every node sees) [default: .].
    #[arg(long, value_name = "DIR")]
    pub dir: Option<String>,
    /// The merged result, relative to DIR [default: NAME.json].
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<String>,
    /// The merged figure (.svg or .png), relative to DIR [default: none].
    #[arg(long, value_name = "FIG.{svg,png}")]
    pub out: Option<String>,
    /// CPUs per array task (the study's --threads) [default: 2].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub cpus_per_task: Option<usize>,
    /// Time limit per array task, as sbatch --time takes it [default: the script's, 01:00:00].
    #[arg(long, value_name = "TIME")]
    pub time: Option<String>,
    /// Memory per array task, as sbatch --mem takes it [default: the script's, 1G].
    #[arg(long, value_name = "MEM")]
    pub mem: Option<String>,
    /// The Slurm partition [default: the cluster's default].
    #[arg(long, value_name = "NAME")]
    pub partition: Option<String>,
    /// The study: `montecarlo [flags]` or `mtl roc [flags]` (after `--`).
    #[arg(last = true, required = true, value_name = "STUDY")]
    pub study: Vec<String>,
}
