//! `scatterloc`: command-line front end of the scatterloc core — presets, the CRLB at a point,
//! CRLB maps (JSON, SVG, PNG), Levenberg–Marquardt fixes from measured delays, the EKF tracker
//! (spec §6) and its Monte Carlo evaluation against the posterior CRLB (§8, §9.5, [S] Fig. 3).
//!
//! Results are JSON on stdout. Bad input exits with status 2 and one line on stderr that names the
//! offending flag or field; nothing panics on bad input. Native only: for wasm32 targets (which
//! `wasm-pack test` also builds bins for) `main` is empty.

#[cfg(target_arch = "wasm32")]
fn main() {}

#[cfg(not(target_arch = "wasm32"))]
mod args;
#[cfg(not(target_arch = "wasm32"))]
mod commands;
#[cfg(not(target_arch = "wasm32"))]
mod gating_cmd;
#[cfg(not(target_arch = "wasm32"))]
mod map_cmd;
#[cfg(not(target_arch = "wasm32"))]
mod mc_cmd;
#[cfg(not(target_arch = "wasm32"))]
mod mtl_cmd;
#[cfg(not(target_arch = "wasm32"))]
mod output;
#[cfg(not(target_arch = "wasm32"))]
mod report;
#[cfg(not(target_arch = "wasm32"))]
mod study;
#[cfg(not(target_arch = "wasm32"))]
mod track_cmd;
#[cfg(not(target_arch = "wasm32"))]
mod track_fig;

/// Usage text (`scatterloc help`).
#[cfg(not(target_arch = "wasm32"))]
pub const USAGE: &str = "\
scatterloc — localize a scatterer from bistatic delays (spec: delay-localization.md)

USAGE:
  scatterloc preset <NAME>
      Print a preset scenario as JSON. NAME: sensors2019 | iclgnss2019
  scatterloc crlb --scenario FILE --at X,Y
      CRLB at one point: sigma_x/sigma_y/RMSE bound (m), Fisher matrix (1/m^2), covariance,
      1-sigma ellipse; per link the SNR (dB), delay std (s) and noise-free delay (s).
      Unbounded (singular Fisher matrix): \"bounded\": false and nulls.
  scatterloc crlb-map --scenario FILE --out OUT.{json,svg,png}
                      [--nx N] [--ny N] [--x-min A] [--x-max B] [--y-min C] [--y-max D]
                      [--width PX] [--height PX] [--title TEXT]
      RMSE-bound map over a grid of cell centres (default 256 x 256 over the scenario's
      area_m; any bound may be overridden). .json: {x_m, y_m, rmse_bound_m[ny][nx]} with
      null for unbounded cells; .svg/.png: figure (log colour scale, width default 1000 px).
      Prints a one-line JSON summary.
  scatterloc locate --scenario FILE --delays FILE
      Levenberg-Marquardt fix. Delays file: {\"delays_s\": [one per link in scenario link
      order, null = no measurement], \"sigma_s\": number | [per link], \"initial_m\": [x, y]
      (optional; default: best node of a 0.5 m grid over area_m)}.
  scatterloc track --scenario FILE --measurements FILE [--calibration FILE]
                   [--association spec|gated] [--out FIG.{svg,png} [--truth FILE]]
      EKF (spec 6): step n predicts by dt_s, then updates with steps[n-1]. Measurements file:
      {\"dt_s\": T, \"process_noise\": q (m^2/s^3), \"initial_state\": [x, y, vx, vy],
      \"initial_covariance\": [[4x4]], \"sigma_s\": number | [per link] (optional; default: link
      budget at the predicted position), \"steps\": [[one delay per link, null = missing], ..]}.
      Prints {t_s, states, covariances, nis (null: no link), links_used}, one entry per step.
      Instead of steps, \"raw_steps\": [[[[delay_s, amplitude], ..] per link] per step] (every
      estimate of the snapshot): each step is gated against --calibration FILE (E4: within
      3 sigma of a static cluster = discarded; no file: nothing is static) and associated
      (spec 4) with --association spec (default: one candidate is taken; of several the
      nearest to the prediction within 3 sigma, else the strongest) or gated (with a track only
      candidates within 3 sigma of the prediction; robust to false alarms and gate leaks).
      Adds {delays_used_s, choices, static_removed} per step and link. No track yet:
      \"initial_snapshot\" (one raw step at t0) instead of initial_state/initial_covariance:
      gated, strongest estimate per link, LM fix; the filter starts there at rest with
      sigma_v = 2 m/s per component ({start: {position_m, covariance_m2, termination, ..}}).
      --out: a figure of the filter's 1 sigma position sqrt(Pxx + Pyy) and the links used over
      time; --truth FILE ({t_s, states}, e.g. simulate-walk's truth.json) adds the error.
  scatterloc calibrate --scenario FILE --snapshots FILE [--gap-s G] [--min-fraction F]
                       [--sigma-floor-s S] [--out OUT.json]
      Calibration stage (spec 4) of the empty area: {\"snapshots\": [[[delay_s, ..] per link]
      per snapshot]}. Per link: sort all delays, split where neighbours differ by more than
      G (default 1/B), drop clusters seen in fewer than F (0.5) of the snapshots, floor sigma
      at S (0.01/B). Prints {gap_s, min_fraction, sigma_floor_s, snapshot_count, links:
      [{clusters: [{mean_s, sigma_s, count, snapshots}]}]} (the --calibration file of track).
  scatterloc simulate-walk --scenario FILE --out-dir DIR [--duration S] [--dt T] [--seed N]
                           [--calibration-snapshots N] [--false-alarms F] [--process-noise Q]
                           [--start snapshot|truth]
      The synthetic measurement case (spec 9.6): a 1.4 m/s walk on a circle of 8 m about
      (12, 6) through the scenario, a static reflector at (6, 18), static paths jittering by
      0.3 ns, echoes lost within 1/B of a static path (blind zone), F (0.5) false alarms per
      link and snapshot. Writes DIR/calibration_snapshots.json (N = 500, for calibrate),
      DIR/measurements.json (raw_steps for track; defaults 60 s, T = 0.1 s, q = 0.1; the
      start: the snapshot at t0 as initial_snapshot, or with --start truth the true state
      and P(t0) of spec 9.5) and DIR/truth.json {t_s, states, resolved[step][link]}.
  scatterloc montecarlo [--preset NAME | --scenario FILE] [--trajectory I|II|III|all]
                        [--runs N] [--noise-runs N] [--dt T] [--duration S] [--process-noise Q]
                        [--seed N] [--threads N] [--oracle-noise] [--out FIG.{svg,png}]
                        [--json OUT.json]
      EKF RMSE against the posterior CRLB ([S] Fig. 3, spec 9.5). Defaults: paper scale,
      sensors2019, all three trajectories, 5000 trajectories x 50 noise runs, T = 2.048 ms,
      10 s, q = 0.01, seed 1, all cores (0). Progress on stderr; Ctrl-C stops (exit 130, no
      files written). --json: {t_s, rmse_ekf_m, rmse_pcrlb_m, nees, runs, seed, trajectory,
      dt_s, noise_runs, trajectories, failed_runs, wall_time_s, ns_per_ekf_step, ..} (several
      trajectories: {\"scenarios\": [..]}); ns_per_ekf_step = wall x threads / (runs x steps).
      Prints a one-line summary with the values at 1, 2, 5 and 10 s (without --json and
      --out: the whole JSON document instead).
  scatterloc pcrlb --nominal [--preset NAME | --scenario FILE] [--trajectory I|II|III|all]
                   [--dt T] [--duration S] [--process-noise Q] [--json OUT.json] [--out FIG]
  scatterloc pcrlb [same flags without --nominal] [--runs N] [--seed N] [--threads N]
      Posterior CRLB alone (spec 8): at the noise-free path (--nominal, check 9) or with
      E[F] over N truth trajectories (default 5000, check 10). {t_s, rmse_pcrlb_m, trajectory,
      dt_s, nominal, ..}; on stdout unless --json/--out are given (then a summary).
  scatterloc mtl locate --network FILE --ranges FILE [--model icb|ppp|empirical]
                        [--te T] [--tb T|inf] [--b-max N|inf] [--n-min N] [--order 0,1,..]
                        [--p-u P | --p-d P --p-los P] [--lambda L] [--diameter D] [--exact]
                        [--table FILE | --cells N --scenes N --seed N] [--out OUT.json]
      Multi-target localization (spec multi-target.md, Algorithm 1). Network file:
      {\"tx\": [[x, y], ..], \"rx\": [[x, y], ..], \"region\": {\"min_m\": [x, y], \"max_m\": [x, y]}
      (optional), \"c_sigma_m\": 0.1 (optional)}. Ranges file: {\"ranges_m\": [[r, ..] per TRP]},
      TRP m (0-based) = TX m mod N_t, RX m div N_t. Models: icb (p_u, or 1 - p_d p_LoS^2;
      default p_d = p_LoS = 0.9), ppp (lambda 0.03, D 0.6 m, p_d 0.9; --exact: M11), empirical
      (--table: EmpiricalTable JSON, else trained on the network from --lambda/--diameter).
      Defaults T_e = 3, T_b = 20, B_max = 16, n_min = 3. Prints {model, t_e, t_b, count,
      targets: [{position_m, matching: [[trp, mpc], ..], j, l_b, g: [0/1 per TRP], family}]}.
  scatterloc mtl table2 [--draws N] [--seed N] [--json OUT.json]
      Table II: DP-count distribution at target points, \"True\" from the generator (V-B
      defaults, default 100000 draws) and i.c.b Binomial(9, 1 - 0.5329), next to the paper.
  scatterloc mtl roc --experiment va|vb|vc [--realizations N] [--seed N] [--threads N]
                     [--empirical] [--exact] [--out FIG.{svg,png}] [--json OUT.json]
      The experiments of spec 8: va = Fig. 3 ROC over T_e (size rule vs Bayesian i.c.b),
      vb = Fig. 4 ROC over T_b (PPP vs i.c.b), vc = Fig. 5 1 - P_D vs T_b (Bayesian vs genie).
      --empirical adds the empirical model (vb, vc); --exact uses (M11) for PPP. Default 100
      realisations, seed 1. Progress on stderr; Ctrl-C stops (exit 130, no files written).
      Prints a summary table; --json: {config, curves: [{method, label, points: [{threshold,
      p_d, p_fa, detections, false_alarms, estimates}]}], disagreements, ..}.
  scatterloc help | --help | -h      Show this text.
  scatterloc --version               Show the version.

FILE may be '-' for standard input. Units: metres, seconds, hertz; dB only where named.
Exit status: 0 success, 2 bad input (one line on stderr naming the field), 1 output failure,
130 cancelled (Ctrl-C). Output files are written atomically (a temporary file renamed into place).
";

/// A failure to report: one line on stderr and an exit status.
#[cfg(not(target_arch = "wasm32"))]
#[derive(Debug)]
pub struct CliError {
    /// The message (a single line).
    pub message: String,
    /// Process exit status.
    pub code: i32,
}

#[cfg(not(target_arch = "wasm32"))]
impl CliError {
    /// Bad input: exit status 2.
    pub fn usage(message: impl Into<String>) -> CliError {
        CliError {
            message: message.into(),
            code: 2,
        }
    }

    /// Failure to write results: exit status 1.
    pub fn output(message: impl Into<String>) -> CliError {
        CliError {
            message: message.into(),
            code: 1,
        }
    }
}

#[cfg(not(target_arch = "wasm32"))]
fn main() {
    let argv: Vec<std::ffi::OsString> = std::env::args_os().skip(1).collect();
    let code = match run(&argv) {
        Ok(()) => 0,
        Err(e) => {
            // One line, whatever the underlying library put into the message.
            let line = e.message.replace(['\n', '\r'], " ");
            eprintln!("error: {line}");
            e.code
        }
    };
    std::process::exit(code);
}

#[cfg(not(target_arch = "wasm32"))]
fn run(argv: &[std::ffi::OsString]) -> Result<(), CliError> {
    let Some(first) = argv.first() else {
        return Err(CliError::usage(
            "missing subcommand (preset, crlb, crlb-map, locate, track, calibrate, simulate-walk, \
             montecarlo, pcrlb, mtl, help)",
        ));
    };
    let rest = &argv[1..];
    match first.to_str().unwrap_or("") {
        "help" | "--help" | "-h" => commands::emit(USAGE.trim_end()),
        "--version" | "-V" => commands::emit(&format!("scatterloc {}", env!("CARGO_PKG_VERSION"))),
        "preset" => commands::preset(rest),
        "crlb" => commands::crlb(rest),
        "crlb-map" => map_cmd::crlb_map(rest),
        "locate" => commands::locate(rest),
        "track" => track_cmd::track(rest),
        "calibrate" => gating_cmd::calibrate(rest),
        "simulate-walk" => gating_cmd::simulate_walk(rest),
        "montecarlo" => mc_cmd::montecarlo(rest),
        "pcrlb" => mc_cmd::pcrlb(rest),
        "mtl" => mtl_cmd::mtl(rest),
        other => Err(CliError::usage(format!(
            "unknown subcommand '{}' (expected preset, crlb, crlb-map, locate, track, \
             calibrate, simulate-walk, montecarlo, pcrlb, mtl or help)",
            if other.is_empty() {
                first.to_string_lossy()
            } else {
                other.into()
            }
        ))),
    }
}
