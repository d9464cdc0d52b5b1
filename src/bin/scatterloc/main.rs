//! `scatterloc`: command-line front end of the scatterloc core — presets, the CRLB at a point,
//! CRLB maps (JSON, SVG, PNG) and Levenberg–Marquardt fixes from measured delays.
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
#[cfg(not(target_arch = "wasm32"))]
mod map_cmd;

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
  scatterloc help | --help | -h      Show this text.
  scatterloc --version               Show the version.

FILE may be '-' for standard input. Units: metres, seconds, hertz; dB only where named.
Exit status: 0 success, 2 bad input (one line on stderr naming the field), 1 output failure.
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
            "missing subcommand (preset, crlb, crlb-map, locate, help)",
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
        other => Err(CliError::usage(format!(
            "unknown subcommand '{}' (expected preset, crlb, crlb-map, locate or help)",
            if other.is_empty() {
                first.to_string_lossy()
            } else {
                other.into()
            }
        ))),
    }
}
