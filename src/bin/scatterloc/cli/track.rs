//! Flags of the tracking commands: `track`, `calibrate`, `simulate-walk`.

use clap::Args;

use super::filters::{FilterName, FilterSettings};
use super::scenario::DopplerArgs;
use super::values::{
    finite, probability, seed, whole, Association, MultiMethod, TargetsMode, WalkStart,
};

/// `scatterloc track`.
#[derive(Debug, Args)]
pub struct TrackArgs {
    /// Scenario JSON file ('-' = standard input).
    #[arg(long, value_name = "FILE")]
    pub scenario: String,
    /// Measurements JSON file ('-' = standard input): dt_s, process_noise, the start, and steps
    /// or raw_steps (see above). Give this or --detections.
    #[arg(long, value_name = "FILE")]
    pub measurements: Option<String>,
    /// Detections, JSON lines ('-' = standard input; docs/detections.md): per frame and link
    /// {timestamp, tx, rx, unit, delay, snr, sigma, doppler}; the first frame starts the track
    /// (as initial_snapshot), the others are its raw_steps. Give this or --measurements.
    #[arg(long, value_name = "D.jsonl")]
    pub detections: Option<String>,
    /// Process-noise intensity q of the track over --detections, m^2/s^3 [default: 1, as
    /// `cir estimate --measurements` writes].
    #[arg(long, value_name = "Q", value_parser = finite)]
    pub process_noise: Option<f64>,
    /// Static paths from `scatterloc calibrate` (raw_steps only); estimates within 3 sigma of a
    /// static cluster are discarded (E4) [default: none, nothing is static].
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<String>,
    /// Association rule of raw_steps (spec §4) [default: spec].
    #[arg(long, value_name = "RULE")]
    pub association: Option<Association>,
    /// Figure of the 1 sigma position uncertainty and the links used over time (.svg or .png).
    #[arg(long, value_name = "FIG.{svg,png}")]
    pub out: Option<String>,
    /// Truth file {t_s, states} (e.g. simulate-walk's truth.json): adds the position error to
    /// the --out figure.
    #[arg(long, value_name = "FILE")]
    pub truth: Option<String>,
    /// The tracker: ekf, ukf or pf [default: ekf]. ukf and pf take the plain form only (steps,
    /// initial_state and initial_covariance; not raw_steps).
    #[arg(
        long,
        value_name = "ekf|ukf|pf",
        ignore_case = true,
        hide_possible_values = true
    )]
    pub filter: Option<FilterName>,
    /// Seed of the particle filter's particles [default: 1] (--filter pf only).
    #[arg(long, value_name = "N", value_parser = seed)]
    pub seed: Option<u64>,
    #[command(flatten)]
    pub settings: FilterSettings,
    /// The range rates' CPI (issue 42; docs/doppler.md D5): with --doppler the rates of the
    /// measurements file (range_rates_mps) take their sigma from the CPI of --cpi,
    /// --cpi-spacing-s and --range-rate-floor instead of the file's cpi (a file that fixes
    /// range_rate_sigma_mps is refused). Without --doppler: the file's cpi, else these defaults.
    #[command(flatten)]
    pub doppler: DopplerArgs,
    /// Ignore the range rates of the measurements file: the delay-only track (the output's
    /// doppler.used is false).
    #[arg(long)]
    pub no_doppler: bool,
    /// Refuse work predicted to take more than H CPU-hours [default: 24] (issue 24; the
    /// prediction and its calibration: docs/benchmarks.md "Cost model"); > 0.
    #[arg(long, value_name = "H", value_parser = finite)]
    pub max_cpu_hours: Option<f64>,
    /// Several targets: `auto` tracks every target the raw_steps show, with births, deaths and
    /// a stable label per target (docs/multi-target.md); prints labelled tracks.
    #[arg(long, value_name = "auto", ignore_case = true)]
    pub targets: Option<TargetsMode>,
    /// The multi-target tracker: pmb (belief propagation) or gnn (baseline) [default: pmb]
    /// (--targets auto only).
    #[arg(
        long,
        value_name = "pmb|gnn",
        ignore_case = true,
        hide_possible_values = true
    )]
    pub method: Option<MultiMethod>,
    /// Detection probability of a target per link and scan [default: 0.9] (--targets auto).
    #[arg(long, value_name = "P", value_parser = probability)]
    pub detection_probability: Option<f64>,
    /// Mean clutter delays per link and scan [default: 5] (--targets auto).
    #[arg(long, value_name = "N", value_parser = finite)]
    pub clutter: Option<f64>,
    /// Width of the delay window clutter is spread over, ns [default: 60] (--targets auto).
    #[arg(long, value_name = "NS", value_parser = finite)]
    pub clutter_window_ns: Option<f64>,
    /// Expected new targets per scan over the scenario's area [default: 0.01] (--targets auto).
    #[arg(long, value_name = "R", value_parser = finite)]
    pub birth_rate: Option<f64>,
    /// GOSPA cut-off c of the score against --truth, m [default: 1] (--targets auto).
    #[arg(long, value_name = "M", value_parser = finite)]
    pub gospa_c: Option<f64>,
    /// Map of the labelled tracks at the last scan, with the --truth paths if given (.svg or
    /// .png; the page's "Several people" figure) (--targets auto).
    #[arg(long, value_name = "FIG.{svg,png}")]
    pub figure: Option<String>,
}

/// `scatterloc calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Scenario JSON file ('-' = standard input).
    #[arg(long, value_name = "FILE")]
    pub scenario: String,
    /// Snapshots JSON file ('-' = standard input): {"snapshots": [[[delay_s, ..] per link] per
    /// snapshot]}.
    #[arg(long, value_name = "FILE")]
    pub snapshots: String,
    /// Clusterer gap G, s: sorted delays further apart than G start a new cluster
    /// [default: 1/B of the scenario's bandwidth].
    #[arg(long, value_name = "G", value_parser = finite)]
    pub gap_s: Option<f64>,
    /// Least fraction F of the snapshots a cluster must be seen in to count as static
    /// [default: 0.5].
    #[arg(long, value_name = "F", value_parser = finite)]
    pub min_fraction: Option<f64>,
    /// Floor of a cluster's sigma, s [default: 0.01/B].
    #[arg(long, value_name = "S", value_parser = finite)]
    pub sigma_floor_s: Option<f64>,
    /// Write the calibration to this .json file instead of standard output.
    #[arg(long, value_name = "OUT.json")]
    pub out: Option<String>,
}

/// `scatterloc simulate-walk`.
#[derive(Debug, Args)]
pub struct SimulateWalkArgs {
    /// Scenario JSON file ('-' = standard input).
    #[arg(long, value_name = "FILE")]
    pub scenario: String,
    /// Directory for calibration_snapshots.json, measurements.json and truth.json (created if
    /// missing).
    #[arg(long, value_name = "DIR")]
    pub out_dir: String,
    /// Length of the walk, s [default: 60, one loop].
    #[arg(long, value_name = "S", value_parser = finite)]
    pub duration: Option<f64>,
    /// Step T between snapshots, s [default: 0.1].
    #[arg(long, value_name = "T", value_parser = finite)]
    pub dt: Option<f64>,
    /// Random seed [default: 1].
    #[arg(long, value_name = "N", value_parser = seed)]
    pub seed: Option<u64>,
    /// Calibration snapshots of the empty area, 1..=100000 [default: 500].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub calibration_snapshots: Option<usize>,
    /// Mean number of false alarms per link and snapshot [default: 0.5].
    #[arg(long, value_name = "F", value_parser = finite)]
    pub false_alarms: Option<f64>,
    /// Process-noise intensity q written to measurements.json, m^2/s^3 [default: 0.1].
    #[arg(long, value_name = "Q", value_parser = finite)]
    pub process_noise: Option<f64>,
    /// How measurements.json starts the filter [default: snapshot].
    #[arg(long, value_name = "HOW")]
    pub start: Option<WalkStart>,
    /// Several people (1..=5; issue 41): two crossing, two side by side, one standing still a
    /// while; writes measurements.json (raw_steps with --false-alarms clutter delays per link,
    /// default 5) and truth.json ({t_s, targets}) for `track --targets auto` [default
    /// duration: 10 s].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub walkers: Option<usize>,
    /// Detection probability per link and scan of --walkers [default: 0.9].
    #[arg(long, value_name = "P", value_parser = probability)]
    pub detection_probability: Option<f64>,
    /// A drawn walker path, m (repeatable, 1..=5): one walker walks the straight line from
    /// (x0, y0) to (x1, y1) at constant velocity over the run, instead of the planned walkers
    /// of --walkers; implies --walkers = the number of paths (a different --walkers is refused).
    #[arg(
        long = "path",
        value_name = "X0,Y0,X1,Y1",
        value_parser = walker_path,
        allow_hyphen_values = true
    )]
    pub path: Vec<[f64; 4]>,
}

/// `--path x0,y0,x1,y1`: four finite numbers, comma-separated.
pub fn walker_path(v: &str) -> Result<[f64; 4], String> {
    let parts: Vec<&str> = v.split(',').collect();
    let bad = || format!("expected x0,y0,x1,y1 (four finite numbers, m), got '{v}'");
    if parts.len() != 4 {
        return Err(bad());
    }
    let mut out = [0.0; 4];
    for (o, p) in out.iter_mut().zip(&parts) {
        *o = finite(p).map_err(|_| bad())?;
    }
    Ok(out)
}
