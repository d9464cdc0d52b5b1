//! The one map from the core's field names to the CLI's flags: a core error that names a field
//! a flag sets ([`scatterloc::Error::field`]) is reported with the flag in its place, so every
//! command's messages name what the user typed; and the one form of an error about the file a
//! flag named ([`in_file`], [`at_flag`]).

use std::fmt::Display;

use scatterloc::Error;

use crate::failure::CliError;

/// Core field → flag.
const FLAGS: [(&str, &str); 61] = [
    // Tracking studies (`montecarlo`, `pcrlb`, `track`).
    ("runs", "--runs"),
    ("noise_runs", "--noise-runs"),
    ("runs*noise_runs", "--runs × --noise-runs"),
    ("steps", "--duration / --dt (steps)"),
    ("dt_s", "--dt"),
    ("process_noise", "--process-noise"),
    ("threads", "--threads"),
    // The trackers' settings.
    ("ukf_alpha", "--ukf-alpha"),
    ("ukf_beta", "--ukf-beta"),
    ("ukf_kappa", "--ukf-kappa"),
    ("particles", "--particles"),
    ("roughening", "--roughening"),
    ("bootstrap", "--pf-bootstrap"),
    // The multi-target method (`mtl`).
    ("t_e", "--te"),
    ("t_b", "--tb"),
    ("b_max", "--b-max"),
    ("n_min", "--n-min"),
    ("max_candidates", "--max-candidates"),
    ("order", "--order"),
    ("p_u", "--p-u"),
    ("p_d", "--p-d"),
    ("p_los", "--p-los"),
    ("lambda", "--lambda"),
    ("diameter", "--diameter"),
    ("scenes", "--scenes"),
    ("nx", "--cells"),
    ("ny", "--cells"),
    ("nx*ny*patterns", "--cells"),
    ("realisations", "--realizations"),
    ("draws", "--draws"),
    ("empirical", "--empirical"),
    ("exact", "--exact"),
    ("filters", "--filters"),
    // The channel front end and a recording's track (`cir`).
    ("max_paths", "--max-paths"),
    ("p_fa", "--pfa"),
    ("pfa", "--pfa"),
    ("background_time_s", "--background-time"),
    ("cpi_snapshots", "--cpi-snapshots"),
    ("range_rate_floor_mps", "--range-rate-floor"),
    ("calibration_range_s", "--calibration-range"),
    ("extent_sigma_m", "--extent-sigma-m"),
    ("filter", "--filter"),
    ("seed", "--seed"),
    ("statics", "--statics"),
    // The simulator (`cir simulate`).
    ("walk", "--walk"),
    ("speed_mps", "--speed"),
    ("duration_s", "--duration"),
    ("calibration_duration_s", "--calibration-duration"),
    // The planner (`plan`; `allowed` names its file there).
    ("roi", "--roi"),
    ("bounds", "--bounds"),
    ("move", "--move"),
    ("min_spacing", "--min-spacing"),
    ("objective", "--objective"),
    ("grid", "--grid"),
    ("budget", "--budget"),
    // The clusterer (`calibrate`).
    ("calibration.gap_s", "--gap-s"),
    ("calibration.min_fraction", "--min-fraction"),
    ("calibration.sigma_floor_s", "--sigma-floor-s"),
    // The §9.6 walk (`simulate-walk`).
    ("calibration_snapshots", "--calibration-snapshots"),
    ("false_alarms", "--false-alarms"),
    (
        "walk_estimates",
        "--duration/--dt/--false-alarms/--calibration-snapshots",
    ),
];

/// The flag that sets core field `field`.
pub fn flag_of(field: &str) -> Option<&'static str> {
    FLAGS
        .iter()
        .find(|(f, _)| *f == field)
        .map(|(_, flag)| *flag)
}

/// `e`'s message with its field replaced by the flag that sets it (`None`: `e` names no field
/// a flag sets).
pub fn with_flag(e: &Error) -> Option<String> {
    let field = e.field()?;
    let flag = flag_of(field)?;
    Some(e.to_string().replacen(field, flag, 1))
}

/// A usage error about the file `--flag PATH` named: `--flag PATH: e`.
pub fn in_file(flag: &str, path: &str, e: impl Display) -> CliError {
    CliError::usage(format!("--{flag} {path}: {e}"))
}

/// A usage error about what `--flag` gave (a file read before, a value): `--flag: e`.
pub fn at_flag(flag: &str, e: impl Display) -> CliError {
    CliError::usage(format!("--{flag}: {e}"))
}

/// `e`'s message with the leading `prefix` of its field replaced by `by` (field `calibration`,
/// `calibration: no direct path`, `by` = `--calibration CAL.npz` → `--calibration CAL.npz: no
/// direct path`; field `response`, `by` = `cir` → `cir: …`); `None` when `e` names no field
/// that starts with `prefix`. `Display` starts with the field ([`Error::field`]).
pub fn renamed(e: &Error, prefix: &str, by: &str) -> Option<String> {
    e.field()?.strip_prefix(prefix)?;
    let text = e.to_string();
    let after = text.get(prefix.len()..)?;
    Some(match after.strip_prefix(": ") {
        Some(reason) => format!("{by}: {reason}"),
        None => format!("{by}{after}"),
    })
}
