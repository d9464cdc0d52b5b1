//! The trackers of `track --filter` and `montecarlo --filters` (issue 15) from their flags:
//! settings validated by the core (messages name the flag), settings of a filter that is not
//! run rejected (exit status 2).

use scatterloc::track::{FilterKind, PfConfig, UkfParams};

use super::flags::with_flag;
use crate::cli::{FilterName, FilterSettings};
use crate::failure::CliError;

/// A core error of the filter settings with the flag in place of the field.
fn settings_error(e: scatterloc::Error) -> CliError {
    CliError::usage(with_flag(&e).unwrap_or_else(|| e.to_string()))
}

/// The trackers `names` with `settings` (`flag` names the filter flag in messages). A UKF
/// setting without `ukf`, or a particle-filter setting without `pf`, is a usage error.
pub fn filter_kinds(
    names: &[FilterName],
    settings: &FilterSettings,
    flag: &str,
) -> Result<Vec<FilterKind>, CliError> {
    let ukf_given = [
        ("--ukf-alpha", settings.ukf_alpha.is_some()),
        ("--ukf-beta", settings.ukf_beta.is_some()),
        ("--ukf-kappa", settings.ukf_kappa.is_some()),
    ];
    let pf_given = [
        ("--particles", settings.particles.is_some()),
        ("--roughening", settings.roughening.is_some()),
        ("--pf-bootstrap", settings.pf_bootstrap),
    ];
    let unused = |given: &[(&str, bool)], name: &str| -> Result<(), CliError> {
        match given.iter().find(|(_, g)| *g) {
            Some((f, _)) => Err(CliError::usage(format!(
                "{f}: only for the {name} filter ({flag} does not include {name})"
            ))),
            None => Ok(()),
        }
    };
    if !names.contains(&FilterName::Ukf) {
        unused(&ukf_given, "ukf")?;
    }
    if !names.contains(&FilterName::Pf) {
        unused(&pf_given, "pf")?;
    }
    let defaults = UkfParams::default();
    let ukf = UkfParams {
        alpha: settings.ukf_alpha.unwrap_or(defaults.alpha),
        beta: settings.ukf_beta.unwrap_or(defaults.beta),
        kappa: settings.ukf_kappa.unwrap_or(defaults.kappa),
    };
    let pf = PfConfig {
        particles: settings.particles.unwrap_or(PfConfig::default().particles),
        roughening: settings.roughening,
        regularized: !settings.pf_bootstrap,
    };
    names
        .iter()
        .map(|n| match n {
            FilterName::Ekf => Ok(FilterKind::Ekf),
            FilterName::Ukf => ukf
                .validate()
                .map(|_| FilterKind::Ukf(ukf))
                .map_err(settings_error),
            FilterName::Pf => pf
                .validate()
                .map(|_| FilterKind::Pf(pf))
                .map_err(settings_error),
        })
        .collect()
}
