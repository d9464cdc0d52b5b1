//! Flags of the tracking studies: `montecarlo` and `pcrlb` (spec §8, §9.5).

use clap::Args;

use super::filters::{filters, FilterList, FilterSettings};
use super::shard::ShardArgs;
use super::values::{finite, seed, whole, Trajectory};

/// The flags every study takes: the node layout, the trajectories and the time grid.
#[derive(Debug, Args)]
pub struct StudyArgs {
    /// Preset layout: sensors2019 or iclgnss2019 [default: sensors2019].
    #[arg(long, value_name = "NAME")]
    pub preset: Option<String>,
    /// Scenario JSON file ('-' = standard input) instead of --preset.
    #[arg(long, value_name = "FILE")]
    pub scenario: Option<String>,
    /// Trajectory of spec §9.4, or all three in turn [default: all].
    #[arg(
        long,
        value_name = "I|II|III|all",
        ignore_case = true,
        hide_possible_values = true
    )]
    pub trajectory: Option<Trajectory>,
    /// Step T, s [default: 2.048e-3, the paper's 2.048 ms].
    #[arg(long, value_name = "T", value_parser = finite)]
    pub dt: Option<f64>,
    /// Length of each track after t0, s [default: 10].
    #[arg(long, value_name = "S", value_parser = finite)]
    pub duration: Option<f64>,
    /// Process-noise intensity q of the constant-velocity model (E7), m^2/s^3 [default: 0.01].
    #[arg(long, value_name = "Q", value_parser = finite)]
    pub process_noise: Option<f64>,
}

/// `scatterloc montecarlo`.
#[derive(Debug, Args)]
pub struct MontecarloArgs {
    #[command(flatten)]
    pub study: StudyArgs,
    /// Truth trajectories drawn from the prior [default: 5000].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub runs: Option<usize>,
    /// Measurement-noise runs per trajectory [default: 50]; runs x noise-runs at most 10^7.
    #[arg(long, value_name = "N", value_parser = whole)]
    pub noise_runs: Option<usize>,
    /// Random seed [default: 1].
    #[arg(long, value_name = "N", value_parser = seed)]
    pub seed: Option<u64>,
    /// Worker threads, 0..=256, 0 = all cores [default: 0].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub threads: Option<usize>,
    /// The EKF's R from the link budget at the true position ("oracle") instead of at the
    /// prediction.
    #[arg(long)]
    pub oracle_noise: bool,
    /// Figure of the curves ([S] Fig. 3): .svg or .png.
    #[arg(long, value_name = "FIG.{svg,png}")]
    pub out: Option<String>,
    /// The curves as a .json file (with --shard: the part file).
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<String>,
    /// Trackers run on the same truth and measurements, in this order: ekf, ukf, pf, comma
    /// separated [default: ekf]. More than ekf adds "filters" to the JSON.
    #[arg(long, value_name = "LIST", value_parser = filters)]
    pub filters: Option<FilterList>,
    #[command(flatten)]
    pub settings: FilterSettings,
    #[command(flatten)]
    pub shard: ShardArgs,
    /// Refuse work predicted to take more than H CPU-hours [default: 24] (issue 24; the
    /// prediction and its calibration: docs/benchmarks.md "Cost model"); > 0.
    #[arg(long, value_name = "H", value_parser = finite)]
    pub max_cpu_hours: Option<f64>,
    /// Several people (1..=5, issue 41): N walkers (crossing, side by side, standing), the PMB
    /// tracker and the GNN baseline scored by GOSPA per scan against the known-association bound
    /// [default scenario: sensors2019 with a second transmitter; runs 100, dt 0.1, duration 10,
    /// process noise 0.5] (docs/multi-target.md).
    #[arg(long, value_name = "N", value_parser = whole)]
    pub targets: Option<usize>,
    /// With --doppler (issue 42): one filter (--filters, one name) tracks the same truths with
    /// and without the range rates of each scan's CPI (--cpi, --cpi-spacing-s,
    /// --range-rate-floor) against the PCRLB of each [defaults: dt 0.1, duration 3, process
    /// noise 1, runs 200] (docs/doppler.md "Monte Carlo"). --json: per trajectory the curves of
    /// both arms; --out: the position RMSE beside its bound, delays only and with Doppler.
    #[command(flatten)]
    pub doppler: super::DopplerArgs,
}

/// `scatterloc pcrlb`.
#[derive(Debug, Args)]
pub struct PcrlbArgs {
    /// The bound along the noise-free path (check 9) instead of E[F] over truth trajectories
    /// (check 10).
    #[arg(long)]
    pub nominal: bool,
    #[command(flatten)]
    pub study: StudyArgs,
    /// Truth trajectories of E[F] [default: 5000] (not with --nominal).
    #[arg(long, value_name = "N", value_parser = whole)]
    pub runs: Option<usize>,
    /// Random seed [default: 1] (not with --nominal).
    #[arg(long, value_name = "N", value_parser = seed)]
    pub seed: Option<u64>,
    /// Worker threads, 0..=256, 0 = all cores [default: 0] (not with --nominal).
    #[arg(long, value_name = "N", value_parser = whole)]
    pub threads: Option<usize>,
    /// Figure of the bound: .svg or .png.
    #[arg(long, value_name = "FIG.{svg,png}")]
    pub out: Option<String>,
    /// The curves as a .json file.
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<String>,
}
