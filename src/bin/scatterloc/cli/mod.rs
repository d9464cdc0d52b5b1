//! The command line of `scatterloc`, declared with clap (derive): the commands and their flags
//! with their help text (what each command does, its spec section, each flag's unit and
//! default), the value parsers that keep the messages of bad values, and [`parse`], which turns
//! every clap error into the CLI's one-line `error: …` with exit status 2 (help and version go
//! to stdout with status 0). The commands themselves are in `crate::cmd`.

mod cir;
mod error;
mod filters;
mod mtl;
mod plan;
mod scenario;
mod shard;
mod slurm;
mod study;
mod track;
mod values;

use std::ffi::OsString;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand, ValueEnum};

pub use cir::{
    CirCommand, CirConvertArgs, CirEstimateArgs, CirSimulateArgs, CirStreamArgs, CirTrackArgs,
    CsiArgs, FrontEndArgs, ReferenceName, SigmaSource, StaticsName,
};
pub use filters::{FilterName, FilterSettings};
pub use mtl::{MtlCommand, MtlLocateArgs, RocArgs, Table2Args};
pub use plan::PlanArgs;
pub use scenario::{CrlbArgs, CrlbMapArgs, DopplerArgs, LocateArgs, PresetArgs};
pub use shard::{MergeArgs, ShardArgs};
pub use slurm::{SlurmCommand, SubmitArgs};
pub use study::{MontecarloArgs, PcrlbArgs, StudyArgs};
pub use track::{CalibrateArgs, SimulateWalkArgs, TrackArgs};
pub use values::{
    Association, MtlModel, MultiMethod, RocExperiment, ShardSpec, Trajectory, WalkStart,
};

use crate::failure::CliError;

/// The top-level help's list of commands with their main flags, and the conventions.
const AFTER_HELP: &str = "\
Commands at a glance (`scatterloc help COMMAND` for every flag):
  scatterloc preset <NAME>
  scatterloc crlb --scenario FILE --at X,Y
  scatterloc crlb-map --scenario FILE --out OUT.{json,svg,png} [--nx N] [--ny N] [--x-min A]
                      [--x-max B] [--y-min C] [--y-max D] [--width PX] [--height PX] [--title TEXT]
  scatterloc locate --scenario FILE --delays FILE
  scatterloc track --scenario FILE --measurements FILE [--calibration FILE]
                   [--association spec|gated] [--out FIG.{svg,png} [--truth FILE]]
  scatterloc track --scenario FILE --measurements FILE --targets auto [--method pmb|gnn]
                   [--truth FILE] [--figure FIG.{svg,png}]
  scatterloc track --scenario FILE --detections D.jsonl [--process-noise Q] [the same flags]
  scatterloc calibrate --scenario FILE --snapshots FILE [--gap-s G] [--min-fraction F]
                       [--sigma-floor-s S] [--out OUT.json]
  scatterloc simulate-walk --scenario FILE --out-dir DIR [--duration S] [--dt T] [--seed N]
                           [--calibration-snapshots N] [--false-alarms F] [--process-noise Q]
                           [--start snapshot|truth] [--walkers N | --path X0,Y0,X1,Y1 ...]
  scatterloc cir simulate --scenario FILE --out-dir DIR [--scene FILE] [--walk POINTS]
                          [--duration S] [--dt T] [--seed N]
  scatterloc cir estimate --scenario FILE --cir REC.npz --out EST.json [--snapshots F]
                          [--measurements F] [--detections-out D.jsonl]
  scatterloc cir track --scenario FILE --calibration CAL.npz --cir REC.npz --out TRACK.json
                       [--figure F.{svg,png}] [--delays-figure D.{svg,png}] [--truth FILE]
                       [--filter ekf|ukf|pf]
  scatterloc cir convert IN OUT.npz [--format auto|intel5300|nexmon|picoscenes|feitcsi|esp32]
                         [--links rxR.txT=A:B,...] [--raw-gain]
  scatterloc montecarlo [--preset NAME | --scenario FILE] [--trajectory I|II|III|all]
                        [--runs N] [--noise-runs N] [--dt T] [--duration S] [--process-noise Q]
                        [--seed N] [--threads N] [--oracle-noise] [--out FIG.{svg,png}]
                        [--json OUT.json] [--shard I/N|env [--shards N] --json PART.json]
  scatterloc pcrlb --nominal [--preset NAME | --scenario FILE] [--trajectory I|II|III|all]
                   [--dt T] [--duration S] [--process-noise Q] [--json OUT.json] [--out FIG]
  scatterloc pcrlb [same flags without --nominal] [--runs N] [--seed N] [--threads N]
  scatterloc plan [--preset NAME | --scenario FILE] --move rx|tx|all|tx-boresight|NAME[,NAME..]
                  --objective mean|p90|max|coverage:T --roi X0,X1,Y0,Y1 [--bounds X0,X1,Y0,Y1]
                  [--allowed FILE] [--min-spacing M] [--grid N] [--budget EVALS] [--seed S]
                  --out plan.json [--figure F.{svg,png}]
  scatterloc mtl locate --network FILE --ranges FILE [--model icb|ppp|empirical]
                        [--te T] [--tb T|inf] [--b-max N|inf] [--n-min N] [--order 0,1,..]
                        [--p-u P | --p-d P --p-los P] [--lambda L] [--diameter D] [--exact]
                        [--table FILE | --cells N --scenes N --seed N] [--out OUT.json]
  scatterloc mtl table2 [--draws N] [--seed N] [--json OUT.json]
  scatterloc mtl roc --experiment va|vb|vc [--realizations N] [--seed N] [--threads N]
                     [--empirical] [--exact] [--out FIG.{svg,png}] [--json OUT.json]
                     [--shard I/N|env [--shards N] --json PART.json]
  scatterloc merge --json OUT.json [--out FIG.{svg,png}] PART...
  scatterloc slurm submit --shards N [--name NAME] [--dir DIR] [--json OUT.json]
                          [--out FIG] [--cpus-per-task N] -- montecarlo|mtl roc [flags]
  scatterloc completions bash|zsh|fish
  scatterloc help [COMMAND] | --help | -h | --version

FILE may be '-' for standard input. Units: metres, seconds, hertz; dB only where named.
Spec sections (§) are those of delay-localization.md; `mtl` cites multi-target.md, `plan`
filters-and-planning.md.
Exit status: 0 success, 2 bad input (one line on stderr naming the flag or field), 1 output
failure, 130 cancelled (Ctrl-C). Output files are written atomically (a temporary file renamed
into place).";

/// scatterloc: localize and track a scatterer from bistatic radio delays.
///
/// Scenarios (transmitters, receivers, radio link budget) as JSON; results as JSON on stdout,
/// figures as SVG or PNG. Spec: delay-localization.md (and multi-target.md for `mtl`).
#[derive(Debug, Parser)]
#[command(name = "scatterloc", version, after_help = AFTER_HELP)]
#[command(subcommand_required = true, arg_required_else_help = false)]
pub struct Cli {
    /// The command.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print a preset scenario as JSON (spec §9).
    ///
    /// The scenario file the other commands read: transmitters, receivers, links, radio
    /// (carrier, bandwidth, power, noise) and the area. sensors2019 is the [S] layout L4 (one Tx,
    /// four Rx); iclgnss2019 the [I] layout. Save it (`scatterloc preset sensors2019 > s.json`)
    /// and edit it to describe another setup.
    Preset(PresetArgs),
    /// The Cramér-Rao lower bound of a position fix at one point (spec §7).
    ///
    /// How well any unbiased estimator can locate a scatterer at X,Y from one snapshot of
    /// delays: sigma_x/sigma_y/RMSE bound (m), Fisher matrix (1/m^2), covariance, 1-sigma
    /// ellipse; per link the SNR (dB), delay std (s) and noise-free delay (s). Unbounded
    /// (singular Fisher matrix): "bounded": false and nulls.
    ///
    /// See also: preset (the scenario file), crlb-map (the bound over a grid), locate (a fix
    /// from measured delays).
    Crlb(CrlbArgs),
    /// Map the CRLB RMSE bound over a grid, as JSON, SVG or PNG (spec §7, figure §10).
    ///
    /// The bound of `crlb` at every cell centre of a grid (default 256 x 256 over the scenario's
    /// area_m; any edge may be overridden). .json: {x_m, y_m, rmse_bound_m[ny][nx]} with null
    /// for unbounded cells; .svg/.png: a figure with a log colour scale (width default 1000 px).
    /// Prints a one-line JSON summary {out, format, nx, ny, x_range_m, y_range_m, compute_ms,
    /// kernel, write_ms, min_m, max_m, unbounded_cells}; kernel is the CPU path the map ran on
    /// (portable, avx2, avx2-fast, avx512, avx512-fast; SCATTERLOC_MAP_PATH pins one).
    CrlbMap(CrlbMapArgs),
    /// Locate a scatterer from one snapshot of measured delays (Levenberg-Marquardt, spec §5).
    ///
    /// A weighted least-squares fix. Delays file: {"delays_s": [one per link in scenario link
    /// order, null = no measurement], "sigma_s": number | [per link], "initial_m": [x, y]
    /// (optional; default: best node of a 0.5 m grid over area_m)}. Prints {position_m,
    /// covariance_m2, cost, iterations, termination, converged, links_used, start_m}.
    Locate(LocateArgs),
    /// Track a moving scatterer with the EKF over a sequence of delays (spec §6; gating §4).
    ///
    /// Step n predicts by dt_s, then updates with steps[n-1]. Measurements file: {"dt_s": T,
    /// "process_noise": q (m^2/s^3), "initial_state": [x, y, vx, vy], "initial_covariance":
    /// [[4x4]], "sigma_s": number | [per link] (optional; default: link budget at the predicted
    /// position), "steps": [[one delay per link, null = missing], ..]}. Prints {t_s, states,
    /// covariances, nis (null: no link), links_used}, one entry per step.
    ///
    /// Instead of steps, "raw_steps": [[[[delay_s, amplitude], ..] per link] per step] (every
    /// estimate of the snapshot): each step is gated against --calibration FILE (E4: within 3
    /// sigma of a static cluster = discarded; no file: nothing is static) and associated (spec
    /// §4) with --association spec (default: one candidate is taken; of several the nearest to
    /// the prediction within 3 sigma, else the strongest) or gated (with a track only candidates
    /// within 3 sigma of the prediction; robust to false alarms and gate leaks). Adds
    /// {delays_used_s, choices, static_removed} per step and link.
    ///
    /// No track yet: "initial_snapshot" (one raw step at t0) instead of
    /// initial_state/initial_covariance: gated, strongest estimate per link, LM fix; the filter
    /// starts there at rest with sigma_v = 2 m/s per component ({start: {position_m,
    /// covariance_m2, termination, ..}}).
    ///
    /// --out: a figure of the filter's 1 sigma position sqrt(Pxx + Pyy) and the links used over
    /// time; --truth FILE ({t_s, states}, e.g. simulate-walk's truth.json) adds the error.
    ///
    /// --detections D.jsonl instead of --measurements: JSON lines of other tools' (or `cir
    /// estimate --detections-out`'s) detections, one per frame and link (docs/detections.md);
    /// the first frame is the initial_snapshot, the others the raw_steps, dt_s their spacing,
    /// process_noise --process-noise.
    Track(TrackArgs),
    /// Learn the static paths of the empty area from calibration snapshots (spec §4).
    ///
    /// The calibration stage: snapshots file {"snapshots": [[[delay_s, ..] per link] per
    /// snapshot]}. Per link: sort all delays, split where neighbours differ by more than G
    /// (default 1/B), drop clusters seen in fewer than F (0.5) of the snapshots, floor sigma at S
    /// (0.01/B). Prints {gap_s, min_fraction, sigma_floor_s, snapshot_count, links: [{clusters:
    /// [{mean_s, sigma_s, count, snapshots}]}]}: the --calibration file of `track`.
    Calibrate(CalibrateArgs),
    /// Write the input files of the synthetic measurement case (spec §9.6).
    ///
    /// A 1.4 m/s walk on a circle of 8 m about (12, 6) through the scenario, a static reflector
    /// at (6, 18), static paths jittering by 0.3 ns, echoes lost within 1/B of a static path
    /// (blind zone), F (0.5) false alarms per link and snapshot. Writes
    /// DIR/calibration_snapshots.json (N = 500, for calibrate), DIR/measurements.json (raw_steps
    /// for track; defaults 60 s, T = 0.1 s, q = 0.1; the start: the snapshot at t0 as
    /// initial_snapshot, or with --start truth the true state and P(t0) of spec §9.5) and
    /// DIR/truth.json {t_s, states, resolved[step][link]}. Prints a JSON summary.
    SimulateWalk(SimulateWalkArgs),
    /// Monte Carlo study of the EKF against the posterior CRLB ([S] Fig. 3; spec §8, §9.5).
    ///
    /// Draws truth trajectories from the prior of spec §9.4, tracks each with the EKF over
    /// several measurement-noise runs and compares the RMSE with the posterior CRLB. Defaults:
    /// paper scale, sensors2019, all three trajectories, 5000 trajectories x 50 noise runs, T =
    /// 2.048 ms, 10 s, q = 0.01, seed 1, all cores (0). Progress on stderr; Ctrl-C stops (exit
    /// 130, no files written).
    ///
    /// --json: {t_s, rmse_ekf_m, rmse_pcrlb_m, nees, runs, seed, trajectory, dt_s, noise_runs,
    /// trajectories, failed_runs, wall_time_s, ns_per_ekf_step, ..} (several trajectories:
    /// {"scenarios": [..]}); ns_per_ekf_step = wall x threads / (runs x steps). Prints a one-line
    /// summary with the values at 1, 2, 5 and 10 s (without --json and --out: the whole JSON
    /// document instead).
    ///
    /// --shard I/N: only the chunks [I*C/N, (I+1)*C/N) of the C = ceil(runs/16) chunks of 16
    /// trajectories, their sums written to the part file --json PART.json (no --out); `scatterloc
    /// merge` turns the parts into the result of the unsharded run.
    Montecarlo(MontecarloArgs),
    /// The posterior CRLB of tracking alone, without the EKF (spec §8; checks 9, 10).
    ///
    /// At the noise-free path (--nominal, check 9) or with E[F] over N truth trajectories
    /// (default 5000, check 10). Prints {t_s, rmse_pcrlb_m, trajectory, dt_s, nominal, ..}
    /// (several trajectories: {"scenarios": [..]}) unless --json/--out are given (then a
    /// one-line summary with the values at 1, 2, 5 and 10 s).
    Pcrlb(PcrlbArgs),
    /// Plan a network: move nodes to minimise the CRLB over a region (spec
    /// filters-and-planning.md §3).
    ///
    /// Moves the chosen nodes (--move; tx-boresight also turns the parabolic beams) to optimise
    /// an objective of the RMSE bound (spec §7) over the cells of an N x N grid over the ROI:
    /// mean, p90 (90th percentile; unbounded cells count as infinite) or max, minimised, or
    /// coverage:T, the fraction of cells with a bound <= T m, maximised. Moved nodes stay inside
    /// --bounds (default: area_m) and the --allowed polygons, and every pair of nodes at least
    /// --min-spacing apart. Seeded CMA-ES with restarts on a coarser grid (N/2 a side, at least
    /// 16), the best layouts re-scored on the N grid: `after` is never worse than
    /// `before` when the base layout keeps the constraints. Deterministic per seed. Progress on
    /// stderr; Ctrl-C stops (exit 130, no files written).
    ///
    /// --out plan.json: {scenario (the optimised scenario, for every command), objective {kind,
    /// label, maximised, before, after, unbounded_before, unbounded_after, roi, grid,
    /// search_grid}, history [{evaluations, best}], evaluations, seed, runs, termination, moved,
    /// paths [{name, transmitter, points}]}. --figure: the maps before and after side by side on
    /// one colour scale, the ROI and each moved node's path. Prints a one-line JSON summary {out,
    /// figure, objective, before, after, evaluations, runs, termination, moved, seed,
    /// wall_time_s}.
    Plan(PlanArgs),
    /// Several targets from range lists: locate, Table II, ROC (spec multi-target.md §4, §8).
    ///
    /// The multi-target method of spec multi-target.md: `mtl locate` (Algorithm 1, §4),
    /// `mtl table2` (Table II, §8) and `mtl roc` (the experiments V-A, V-B, V-C of §8).
    Mtl {
        /// The mtl command.
        #[command(subcommand)]
        command: MtlCommand,
    },
    /// From channel recordings to tracks: simulate, estimate, track (spec
    /// channel-estimation.md).
    ///
    /// The front end of [S] and [I]: `cir simulate` makes recordings (.npz, docs/recording.md)
    /// of a walk at the signal level, `cir estimate` finds each snapshot's paths (C5, C6), `cir
    /// track` runs the whole chain to a track (C7, E4, §4, §5, E7).
    Cir {
        /// The cir command.
        #[command(subcommand)]
        command: CirCommand,
    },
    /// Merge the part files of a sharded study into the unsharded run's result (spec §9.5).
    ///
    /// A study run with --shard I/N (montecarlo, mtl roc) writes the sufficient statistics of
    /// its shard to a part file (--json PART.json) instead of the result. `merge` checks that
    /// the parts are one study (same configuration, seed and scatterloc version) and cover every
    /// shard exactly once (missing, duplicate or foreign parts: exit 2, naming them), adds their
    /// sums exactly and writes the same JSON (--json) and figure (--out) as the unsharded run,
    /// equal to it bit for bit except the timing fields (wall_time_s, the sum over the parts;
    /// threads, the most of any part; ns_per_ekf_step, wall_ns_per_ekf_step). See
    /// docs/scale-out.md.
    Merge(MergeArgs),
    /// Run a sharded study on a Slurm cluster (docs/scale-out.md).
    Slurm {
        /// The Slurm command.
        #[command(subcommand)]
        command: SlurmCommand,
    },
    /// Print a shell completion script (bash, zsh or fish) on stdout.
    ///
    /// For example `scatterloc completions bash > ~/.local/share/bash-completion/completions/scatterloc`,
    /// `scatterloc completions zsh > "${fpath[1]}/_scatterloc"` or `scatterloc completions fish >
    /// ~/.config/fish/completions/scatterloc.fish`.
    Completions {
        /// The shell.
        #[arg(value_name = "SHELL")]
        shell: Shell,
    },
}

/// Shells of `scatterloc completions`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Shell {
    /// GNU Bash.
    Bash,
    /// Z shell.
    Zsh,
    /// fish.
    Fish,
}

/// The clap command: [`Cli`] with every flag's value allowed to start with `-` (`--x-min -5`,
/// `--ny -3` reaching the value check; as the former parser, the word after a flag is its value).
pub fn command() -> clap::Command {
    fn hyphen_values(cmd: clap::Command) -> clap::Command {
        let cmd = cmd.mut_args(|a| {
            if a.get_action().takes_values() && !a.is_positional() {
                a.allow_hyphen_values(true)
            } else {
                a
            }
        });
        let names: Vec<String> = cmd
            .get_subcommands()
            .map(|s| s.get_name().to_string())
            .collect();
        names
            .iter()
            .fold(cmd, |c, n| c.mut_subcommand(n, hyphen_values))
    }
    hyphen_values(Cli::command())
}

/// What parsing the command line gave.
// Built once and matched once: the size of the largest variant does not matter.
#[allow(clippy::large_enum_variant)]
pub enum Parsed {
    /// Run this command.
    Run(Cli),
    /// Help or the version was printed: exit status 0.
    Printed,
}

/// Parses the arguments (without the program name). Help and version are printed here; every
/// other clap error is one line naming the flag (exit status 2).
pub fn parse(argv: Vec<OsString>) -> Result<Parsed, CliError> {
    let mut cmd = command();
    let args = std::iter::once(OsString::from("scatterloc")).chain(argv.iter().cloned());
    let matches = match cmd.try_get_matches_from_mut(args) {
        Ok(m) => m,
        Err(e) => return error::handle(e, &cmd, &argv).map(|()| Parsed::Printed),
    };
    Cli::from_arg_matches(&matches)
        .map(Parsed::Run)
        .map_err(|e| CliError::usage(error::one_line(&e, &cmd, &argv)))
}

/// Writes the completion script for `shell` to stdout.
pub fn completions(shell: Shell) -> Result<(), CliError> {
    let shell = match shell {
        Shell::Bash => clap_complete::Shell::Bash,
        Shell::Zsh => clap_complete::Shell::Zsh,
        Shell::Fish => clap_complete::Shell::Fish,
    };
    let mut buf = Vec::new();
    clap_complete::generate(shell, &mut command(), "scatterloc", &mut buf);
    crate::stdout::write(&buf)
}
