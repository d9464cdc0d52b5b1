//! Flags of the trackers (issue 15): `--filter` (`track`), `--filters` (`montecarlo`) and the
//! settings of the UKF and the particle filter they share.

use clap::{Args, ValueEnum};

use super::values::finite;
use super::values::whole;

/// A tracker: the EKF (spec §6), the UKF or the bootstrap particle filter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FilterName {
    /// The extended Kalman filter.
    Ekf,
    /// The unscented Kalman filter.
    Ukf,
    /// The bootstrap (SIR) particle filter.
    Pf,
}

impl FilterName {
    /// `ekf`, `ukf` or `pf`.
    pub fn name(self) -> &'static str {
        match self {
            FilterName::Ekf => "ekf",
            FilterName::Ukf => "ukf",
            FilterName::Pf => "pf",
        }
    }
}

/// `ekf,ukf,pf`: one or more distinct filter names, in the order given.
fn filter_list(v: &str) -> Result<Vec<FilterName>, String> {
    let mut out = Vec::new();
    for part in v.split(',') {
        let f = FilterName::from_str(part.trim(), true)
            .map_err(|_| format!("unknown filter '{}' (expected ekf, ukf or pf)", part.trim()))?;
        if out.contains(&f) {
            return Err(format!("filter '{}' given twice", f.name()));
        }
        out.push(f);
    }
    Ok(out)
}

/// The list of filter names as a value of `--filters`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FilterList(pub Vec<FilterName>);

/// Parses `--filters`.
pub fn filters(v: &str) -> Result<FilterList, String> {
    filter_list(v).map(FilterList)
}

/// Settings of the UKF and the particle filter (flattened into `track` and `montecarlo`). A
/// setting of a filter that is not run is an error (exit status 2) naming the flag.
#[derive(Debug, Args)]
pub struct FilterSettings {
    /// Particles of the particle filter, 1..=1000000 [default: 1000].
    #[arg(long, value_name = "N", value_parser = whole)]
    pub particles: Option<usize>,
    /// Roughening constant c of the particle filter, 0..=10 [default: off].
    #[arg(long, value_name = "C", value_parser = finite)]
    pub roughening: Option<f64>,
    /// The particle filter as the plain bootstrap SIR (no first-update proposal, no kernel
    /// after resampling) [default: the regularised particle filter].
    #[arg(long)]
    pub pf_bootstrap: bool,
    /// UKF sigma-point spread alpha, 1e-4 <= alpha <= 1 (Wan & van der Merwe) [default: 1].
    #[arg(long, value_name = "A", value_parser = finite)]
    pub ukf_alpha: Option<f64>,
    /// UKF beta, 0..=10 [default: 2].
    #[arg(long, value_name = "B", value_parser = finite)]
    pub ukf_beta: Option<f64>,
    /// UKF kappa, 4 + kappa > 0, |kappa| <= 100 [default: 0].
    #[arg(long, value_name = "K", value_parser = finite)]
    pub ukf_kappa: Option<f64>,
}
