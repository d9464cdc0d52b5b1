//! The trackers of `track --filter` and `montecarlo --filters` (issue 15) from their flags:
//! the library's [`scatterloc::track::FilterSettings`] (settings validated by the core, a
//! setting of a filter that is not run refused), its messages naming the flags.

use scatterloc::track::{FilterKind, FilterSettings};

use super::flags::with_flag;
use crate::cli::{self, FilterName};
use crate::failure::CliError;

/// The trackers `names` with `settings` (`flag` names the filter flag in messages). A UKF
/// setting without `ukf`, or a particle-filter setting without `pf`, is a usage error.
pub fn filter_kinds(
    names: &[FilterName],
    settings: &cli::FilterSettings,
    flag: &str,
) -> Result<Vec<FilterKind>, CliError> {
    let given = FilterSettings {
        ukf_alpha: settings.ukf_alpha,
        ukf_beta: settings.ukf_beta,
        ukf_kappa: settings.ukf_kappa,
        particles: settings.particles,
        roughening: settings.roughening,
        bootstrap: settings.pf_bootstrap,
    };
    let names: Vec<&str> = names.iter().map(|n| n.name()).collect();
    given
        .kinds(&names, flag, |_| flag.to_string())
        .map_err(|e| CliError::usage(with_flag(&e).unwrap_or_else(|| e.to_string())))
}
