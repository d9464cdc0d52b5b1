//! `scatterloc`: command-line front end of the scatterloc core — presets, the CRLB at a point,
//! CRLB maps (JSON, SVG, PNG), Levenberg–Marquardt fixes from measured delays, the EKF tracker
//! (spec §6) and its Monte Carlo evaluation against the posterior CRLB (§8, §9.5, [S] Fig. 3),
//! network planning (`plan`), the multi-target method (`mtl`), and the merge of sharded studies
//! (`merge`).
//!
//! `cli` declares the command line (clap), `cmd` runs the commands, `failure` holds their one
//! error type ([`CliError`](failure::CliError)). Results are JSON on stdout.
//! Bad input exits with status 2 and one line on stderr that names the offending flag or field;
//! nothing panics on bad input. Native only: for wasm32 targets (which `wasm-pack test` also
//! builds bins for) `main` is empty.

#[cfg(target_arch = "wasm32")]
fn main() {}

#[cfg(not(target_arch = "wasm32"))]
mod cli;
#[cfg(not(target_arch = "wasm32"))]
mod cmd;
#[cfg(not(target_arch = "wasm32"))]
mod failure;
#[cfg(not(target_arch = "wasm32"))]
mod stdout;

#[cfg(not(target_arch = "wasm32"))]
use failure::CliError;

#[cfg(not(target_arch = "wasm32"))]
fn main() {
    // A write past the file-size limit (`ulimit -f`) then fails with EFBIG, which the output
    // writer reports (removing its temporaries), instead of SIGXFSZ killing the process and
    // leaving them behind (issue 24). A handler that does nothing, installed without unsafe code.
    let _ = signal_hook::flag::register(
        signal_hook::consts::SIGXFSZ,
        std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false)),
    );
    let argv: Vec<std::ffi::OsString> = std::env::args_os().skip(1).collect();
    let result = cli::parse(argv).and_then(|parsed| match parsed {
        cli::Parsed::Run(args) => run(args.command),
        cli::Parsed::Printed => Ok(()),
    });
    let code = match result {
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

/// Runs one command.
#[cfg(not(target_arch = "wasm32"))]
fn run(command: cli::Command) -> Result<(), CliError> {
    use cli::{CirCommand, Command, MtlCommand};
    match command {
        Command::Preset(a) => cmd::preset(&a),
        Command::Crlb(a) => cmd::crlb(&a),
        Command::CrlbMap(a) => cmd::crlb_map(&a),
        Command::Locate(a) => cmd::locate(&a),
        Command::Track(a) => cmd::track(&a),
        Command::Calibrate(a) => cmd::calibrate(&a),
        Command::SimulateWalk(a) => cmd::simulate_walk(&a),
        Command::Montecarlo(a) => cmd::montecarlo(&a),
        Command::Pcrlb(a) => cmd::pcrlb(&a),
        Command::Plan(a) => cmd::plan(&a),
        Command::Mtl { command } => match command {
            MtlCommand::Locate(a) => cmd::mtl_locate(&a),
            MtlCommand::Table2(a) => cmd::mtl_table2(&a),
            MtlCommand::Roc(a) => cmd::mtl_roc(&a),
        },
        Command::Cir { command } => match command {
            CirCommand::Simulate(a) => cmd::cir_simulate(&a),
            CirCommand::Estimate(a) => cmd::cir_estimate(&a),
            CirCommand::Track(a) if a.follow => cmd::cir_track_follow(&a),
            CirCommand::Track(a) => cmd::cir_track(&a),
            CirCommand::Convert(a) => cmd::cir_convert(&a),
            CirCommand::Stream(a) => cmd::cir_stream(&a),
        },
        Command::Merge(a) => cmd::merge(&a),
        Command::Slurm { command } => match command {
            cli::SlurmCommand::Submit(a) => cmd::slurm_submit(&a),
        },
        Command::Completions { shell } => cli::completions(shell),
    }
}
