//! Flags of the channel front end `cir simulate|estimate|track` (issues 25, 36; spec
//! channel-estimation.md, C1–C11).

use clap::{Args, Subcommand, ValueEnum};

use super::filters::{FilterName, FilterSettings};
use super::values::{finite, probability, seed, whole, Association, MultiMethod, TargetsMode};

/// `scatterloc cir SUBCOMMAND`.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Subcommand)]
pub enum CirCommand {
    /// Simulate channel recordings of a walk at the signal level (C1, C3; [S] §5.3).
    ///
    /// The scene (walls with first- and second-order reflections, point scatterers, a walking
    /// person as an extended, fluctuating scatterer with double reflections off the walls and
    /// shadowing) on the scenario's links and radio, thermal noise from the link budget.
    /// Writes DIR/recording.npz (the walk), DIR/calibration.npz (the empty area), DIR/truth.json
    /// {t_s, states, paths} and DIR/scene.json (the scene used). Prints a JSON summary.
    Simulate(CirSimulateArgs),
    /// Estimate every snapshot's paths of a recording (C5, C6, C9, C10).
    ///
    /// The static channel is dealt with first (--statics: the empty area's background
    /// subtracted at the signal level, C9, or its clusters gated, C7); then per link and
    /// snapshot a bounded greedy ML with refinement and a CFAR stop, seeded by the link's path
    /// tracks; delays absolute or relative to each link's direct path (--delay-reference, C10).
    /// --out EST.json: {t_s, links, estimates [snapshot][link] [{delay_s, amplitude, sigma_s,
    /// snr_db, track, confirmed}], noise_var, front_end (settings, bounds reached, alignment)}.
    /// --snapshots and --measurements also write the forms `calibrate --snapshots` and `track
    /// --measurements` read.
    Estimate(CirEstimateArgs),
    /// Track a person through a recording: estimate, gate, start, filter, lose and restart.
    ///
    /// Estimates the recording as `cir estimate` does, gates what is left of the static
    /// channel (E4), associates (§4) and tracks in segments (C11): a start from hypotheses
    /// confirmed over the following snapshots, a loss on innovations, misses or leaving the
    /// area, then a new start. --out TRACK.json: {t_s, states (null outside segments),
    /// covariances, links_used, delays_used_s, sigmas_used_s, choices, static_removed, start,
    /// segments [{first, last, end, …}], front_end, calibration, error (with --truth)}.
    /// With --targets auto: several people, every snapshot's estimates a scan of the
    /// multi-target tracker (docs/multi-target.md); --out TRACK.json: {method, settings, t_s,
    /// targets [scan][{label, state, covariance, existence}], tracks [{label, first_scan, …}],
    /// static_removed, extent_sigma_m, score (with --truth: cir simulate's truth.json with
    /// `others`)}.
    Track(CirTrackArgs),
    /// Convert a Wi-Fi CSI tool's file to a recording (.npz, docs/recording.md).
    ///
    /// Reads Intel 5300 (.dat), Nexmon (pcap), PicoScenes (.csi), FeitCSI (.csi) and ESP32
    /// (CSV) files; puts the reported subcarriers on a uniform grid with a mask (P[n] = 0 where
    /// no subcarrier is reported: null, DC, guard, grouped-out); applies the gain the format
    /// reports (RSSI/AGC); maps antenna pairs to the scenario's links (--links). Prints what it
    /// found: format, device, frames, bandwidth, antennas, subcarriers, dropped frames, notes.
    Convert(CirConvertArgs),
    /// Write a recording (.npz, frequency responses) as a frame stream (docs/recording.md,
    /// "Streaming frames"), the input of `cir track --follow`: a JSON header line, then one
    /// frame per snapshot (samples as float32), then the end marker, on standard output.
    Stream(CirStreamArgs),
}

/// `scatterloc cir stream`.
#[derive(Debug, Args)]
pub struct CirStreamArgs {
    /// The recording (.npz with a `cfr` array); the stream goes to standard output.
    #[arg(value_name = "REC.npz")]
    pub input: String,
    /// Write the recording this many times, each copy's times after the previous copy's by
    /// its span plus one mean step (a long stream for benchmarks) [default: 1].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub repeat: Option<usize>,
    /// Leave out the end marker (a stream that stops as if its writer were still running).
    #[arg(long)]
    pub no_end: bool,
}

/// `scatterloc cir convert`.
#[derive(Debug, Args)]
pub struct CirConvertArgs {
    /// The CSI file ('-' = standard input).
    #[arg(value_name = "IN")]
    pub input: String,
    /// The recording to write (.npz).
    #[arg(value_name = "OUT.npz")]
    pub output: String,
    #[command(flatten)]
    pub csi: CsiArgs,
}

/// How a recording file is read: `.npz` or a CSI tool's file (`cir convert`, `cir estimate`,
/// `cir track`).
#[derive(Debug, Args)]
pub struct CsiArgs {
    /// The file's format [default: auto, by its first bytes].
    #[arg(long, value_name = "FORMAT", value_parser = [
        "auto", "npz", "intel5300", "nexmon", "picoscenes", "feitcsi", "esp32",
    ])]
    pub format: Option<String>,
    /// Which antenna pair of a CSI file is which link of the scenario: rxR.txT=A:B,… (receive
    /// antenna R and transmit antenna T → transmitter A, receiver B), e.g. rx0.tx0=0:0,rx1.tx0=0:1
    /// [default: every pair, rxR.txT → transmitter T, receiver R].
    #[arg(long, value_name = "MAP")]
    pub links: Option<String>,
    /// Keep the CSI as written: do not apply the RSSI/AGC gain the format reports.
    #[arg(long)]
    pub raw_gain: bool,
    /// Keep every subcarrier the file reports, also those no frame occupies (by default the
    /// 20 MHz blocks 20 dB below the strongest, and tones 30 dB below the median, are left out).
    #[arg(long)]
    pub all_subcarriers: bool,
}

/// `scatterloc cir simulate`.
#[derive(Debug, Args)]
pub struct CirSimulateArgs {
    /// Scenario JSON file ('-' = standard input).
    #[arg(long, value_name = "FILE")]
    pub scenario: String,
    /// Directory for recording.npz, calibration.npz, truth.json and scene.json (created if
    /// missing).
    #[arg(long, value_name = "DIR")]
    pub out_dir: String,
    /// Scene JSON file (walls, scatterers, body, walk; see docs/recording.md) [default: the
    /// hangar scene of docs/reproduction.md].
    #[arg(long, value_name = "FILE")]
    pub scene: Option<String>,
    /// Waypoints of the walk "x,y x,y ..." (m; at least two), replacing the scene's.
    #[arg(long, value_name = "POINTS")]
    pub walk: Option<String>,
    /// Walking speed, m/s, replacing the scene's.
    #[arg(long, value_name = "V", value_parser = finite)]
    pub speed: Option<f64>,
    /// Length of the walk, s [default: the scene's].
    #[arg(long, value_name = "S", value_parser = finite)]
    pub duration: Option<f64>,
    /// Snapshot interval, s [default: 0.002048, the sounder of [S]].
    #[arg(long, value_name = "T", value_parser = finite)]
    pub dt: Option<f64>,
    /// Length of the calibration recording of the empty area, s [default: 1].
    #[arg(long, value_name = "S", value_parser = finite)]
    pub calibration_duration: Option<f64>,
    /// Random seed [default: 1].
    #[arg(long, value_name = "N", value_parser = seed)]
    pub seed: Option<u64>,
}

/// How static paths are removed (`--statics`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum StaticsName {
    /// Subtract the background (the empty area's mean, or a recursive mean) at the signal
    /// level and estimate the residual (C9).
    Background,
    /// Estimate every full response and gate the empty area's clusters (C7, [S]'s way).
    Clusters,
}

/// Which delays the tracker reads (`--delay-reference`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ReferenceName {
    /// Absolute delays (a sounder with a common clock).
    Absolute,
    /// Delays relative to each link's direct path (Wi-Fi CSI, free-running UWB anchors; C10).
    Los,
}

/// Parses `T0,T1` (seconds, finite).
fn time_range(text: &str) -> Result<[f64; 2], String> {
    let (a, b) = text
        .split_once(',')
        .ok_or_else(|| format!("'{text}' is not T0,T1 (seconds)"))?;
    let num = |v: &str| {
        v.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{v}' is not a finite number"))
    };
    Ok([num(a)?, num(b)?])
}

/// The front end's flags shared by `cir estimate` and `cir track`.
#[derive(Debug, Args)]
pub struct FrontEndArgs {
    /// How static paths are removed: background (C9; the default) or clusters (C7).
    #[arg(long, value_name = "background|clusters")]
    pub statics: Option<StaticsName>,
    /// Delays absolute (a common clock) or relative to each link's direct path (C10) [default:
    /// the recording's `synchronized` flag, absolute without one].
    #[arg(long, value_name = "absolute|los")]
    pub delay_reference: Option<ReferenceName>,
    /// Time constant of the recursive background, s, used without a recording of the empty
    /// area [default: 10].
    #[arg(long, value_name = "S", value_parser = finite)]
    pub background_time: Option<f64>,
    /// The snapshots of the recording between T0 and T1 (s) are the empty area (instead of
    /// --calibration).
    #[arg(long, value_name = "T0,T1", value_parser = time_range)]
    pub calibration_range: Option<[f64; 2]>,
    /// Most paths per snapshot and link (C5) [default: the estimator's].
    #[arg(long, value_name = "K", value_parser = whole)]
    pub max_paths: Option<usize>,
    /// Design false-alarm probability per snapshot of the CFAR stop (C5) [default: the
    /// estimator's].
    #[arg(long, value_name = "P", value_parser = finite)]
    pub pfa: Option<f64>,
    /// Worker threads (0 = all cores) [default: 0].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub threads: Option<usize>,
    /// Each scan a CPI of N consecutive snapshots: the paths are estimated in its middle
    /// snapshot and each path's range rate read from its phase over the CPI (issue 42; a
    /// recording made in bursts, e.g. `cir simulate` with the scene's `cpi`) [default: 1, no
    /// Doppler].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub cpi_snapshots: Option<usize>,
    /// Floor on each range rate's σ, m/s (a body's limbs do not move at one velocity)
    /// [default: 0.1].
    #[arg(long, value_name = "M/S", value_parser = finite)]
    pub range_rate_floor: Option<f64>,
    #[command(flatten)]
    pub csi: CsiArgs,
}

/// `scatterloc cir estimate`.
#[derive(Debug, Args)]
pub struct CirEstimateArgs {
    /// Scenario JSON file ('-' = standard input).
    #[arg(long, value_name = "FILE")]
    pub scenario: String,
    /// The recording (.npz, docs/recording.md, or a CSI tool's file: see --format).
    #[arg(long, value_name = "REC.npz")]
    pub cir: String,
    /// The estimates (.json).
    #[arg(long, value_name = "EST.json")]
    pub out: String,
    /// Recording of the empty area (.npz): its background is subtracted (C9) or its clusters
    /// gated (C7) [default: a recursive background learnt from the recording itself].
    #[arg(long, value_name = "CAL.npz")]
    pub calibration: Option<String>,
    /// Also write the delays in the form `calibrate --snapshots` reads.
    #[arg(long, value_name = "FILE.json")]
    pub snapshots: Option<String>,
    /// Also write the estimates as `track --measurements` reads them (raw_steps [delay,
    /// amplitude, sigma], the first snapshot as initial_snapshot; uniform snapshot times only).
    #[arg(long, value_name = "FILE.json")]
    pub measurements: Option<String>,
    /// Also write the estimates as detections, JSON lines (docs/detections.md; `track
    /// --detections` reads them): per snapshot and recorded link the delays (s), SNR (dB) and
    /// sigma (s).
    #[arg(long, value_name = "D.jsonl")]
    pub detections_out: Option<String>,
    /// Process-noise intensity q written to --measurements, m^2/s^3 [default: 1].
    #[arg(long, value_name = "Q", value_parser = finite)]
    pub process_noise: Option<f64>,
    #[command(flatten)]
    pub front_end: FrontEndArgs,
}

/// How `cir track` weights each delay.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SigmaSource {
    /// The estimator's own sigma (C4 at the fitted SNR).
    Estimator,
    /// The link budget's sigma at the prediction (E8).
    Budget,
}

/// `scatterloc cir track`.
#[derive(Debug, Args)]
pub struct CirTrackArgs {
    /// Scenario JSON file ('-' = standard input).
    #[arg(long, value_name = "FILE")]
    pub scenario: String,
    /// Recording of the empty area (.npz): its background is subtracted (C9) or its clusters
    /// gated (C7) [default: a recursive background learnt from the recording itself].
    #[arg(long, value_name = "CAL.npz")]
    pub calibration: Option<String>,
    /// Recording of the walk (.npz); with --follow a frame stream (docs/recording.md,
    /// "Streaming frames") in a file that grows, or '-' for standard input [--follow default: -].
    #[arg(long, value_name = "REC.npz", required_unless_present = "follow")]
    pub cir: Option<String>,
    /// The track (.json).
    #[arg(
        long,
        value_name = "TRACK.json",
        required_unless_present = "follow",
        conflicts_with = "follow"
    )]
    pub out: Option<String>,
    /// Track as frames arrive: read --cir as a frame stream (a file followed as it grows,
    /// until its end marker; or standard input) and write one JSON line per frame on stdout as
    /// soon as it is computed: {t_s, state, covariance, segment, links_used, delays_s,
    /// snapshot, event, end, dropped_hypotheses}. Ctrl-C: exit 130, the lines written kept.
    #[arg(long, conflicts_with_all = ["figure", "delays_figure", "truth", "calibration_range", "threads"])]
    pub follow: bool,
    /// The track on the map, the position error over time and its CDF (.svg or .png; with
    /// --truth).
    #[arg(long, value_name = "F.{svg,png}")]
    pub figure: Option<String>,
    /// [S] Fig. 4 per link: path length against time, the response's magnitude, the
    /// estimates, the static clusters, the truth (.svg or .png).
    #[arg(long, value_name = "D.{svg,png}")]
    pub delays_figure: Option<String>,
    /// Truth file (cir simulate's truth.json): adds the error to TRACK.json and the figures.
    #[arg(long, value_name = "FILE")]
    pub truth: Option<String>,
    /// The tracker: ekf, ukf or pf [default: ekf].
    #[arg(
        long,
        value_name = "ekf|ukf|pf",
        ignore_case = true,
        hide_possible_values = true
    )]
    pub filter: Option<FilterName>,
    /// Process-noise intensity q of the CV model, m^2/s^3 [default: 1, a walk with turns].
    #[arg(long, value_name = "Q", value_parser = finite)]
    pub process_noise: Option<f64>,
    /// Delay weights [default: estimator].
    #[arg(long, value_name = "estimator|budget")]
    pub sigma: Option<SigmaSource>,
    /// The scatterer's extent as path length, m, added in quadrature to each estimate's sigma
    /// (--sigma estimator) [default: 0.2, a person].
    #[arg(long, value_name = "M", value_parser = finite)]
    pub extent_sigma_m: Option<f64>,
    /// Association rule [default: gated].
    #[arg(long, value_name = "RULE")]
    pub association: Option<Association>,
    /// Seed of the particle filter's particles [default: 1] (--filter pf only).
    #[arg(long, value_name = "N", value_parser = seed)]
    pub seed: Option<u64>,
    /// Several people: `auto` tracks every person the estimates show, with births, deaths and
    /// a stable label per person (docs/multi-target.md) [--extent-sigma-m default: 0.3].
    #[arg(
        long,
        value_name = "auto",
        ignore_case = true,
        conflicts_with = "follow"
    )]
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
    /// Detection probability of a person per link and snapshot [default: 0.7, the front end's
    /// on simulated recordings] (--targets auto).
    #[arg(long, value_name = "P", value_parser = probability)]
    pub detection_probability: Option<f64>,
    /// Mean clutter delays per link and snapshot [default: 4.5] (--targets auto).
    #[arg(long, value_name = "N", value_parser = finite)]
    pub clutter: Option<f64>,
    /// Width of the delay window clutter is spread over, ns [default: 175] (--targets auto).
    #[arg(long, value_name = "NS", value_parser = finite)]
    pub clutter_window_ns: Option<f64>,
    /// Expected new people per snapshot over the scenario's area [default: 0.01] (--targets
    /// auto).
    #[arg(long, value_name = "R", value_parser = finite)]
    pub birth_rate: Option<f64>,
    /// GOSPA cut-off c of the score against --truth, m [default: 1] (--targets auto).
    #[arg(long, value_name = "M", value_parser = finite)]
    pub gospa_c: Option<f64>,
    #[command(flatten)]
    pub settings: FilterSettings,
    #[command(flatten)]
    pub front_end: FrontEndArgs,
}
