//! The invariants of a Monte Carlo part's sums (issue 24): what [`crate::track::StudySums`]
//! of a shard's chunks can hold, checked by [`crate::study::MonteCarloStudy::merge`] before
//! they are added. The list is in the documentation of [`crate::study::PartSet`].

use alloc::format;
use alloc::string::String;
use core::ops::Range;

use crate::math::ExactSum;
use crate::track::{MonteCarloConfig, StudySums};

/// Relative tolerance of the Fisher sums' positive semi-definiteness: each trajectory's
/// `F = Σ w g gᵀ` is PSD; its entries are rounded sums of up to 10⁶ links' terms and the
/// chunks' plain sums, so `F₁₂² − F₁₁ F₂₂` may exceed 0 by a few ulps of `F₁₁ F₂₂`.
const PSD_TOLERANCE: f64 = 1e-9;

/// Checks the sums `entries` (one per filter, `sums[first + f]` of the part) of one
/// trajectory of configuration `cfg` over `chunks`; the error names the field
/// (`sums[3].nees[17]: -3.2 is negative`).
pub fn check_sums(
    cfg: &MonteCarloConfig,
    chunks: &Range<usize>,
    first: usize,
    entries: &[StudySums],
) -> Result<(), String> {
    let trajectories = cfg.trajectories_in(chunks);
    let runs = trajectories * cfg.noise_runs;
    for (f, s) in entries.iter().enumerate() {
        let at = |field: &str| format!("sums[{}].{field}", first + f);
        for (name, len) in [
            ("squared_error", s.squared_error.len()),
            ("nees", s.nees.len()),
            ("fisher", s.fisher.len()),
        ] {
            if len != cfg.steps + 1 {
                return Err(format!(
                    "{}: {len} entries, not the {} of {} steps",
                    at(name),
                    cfg.steps + 1,
                    cfg.steps
                ));
            }
        }
        if s.trajectories != trajectories {
            return Err(format!(
                "{}: {}, not the {trajectories} trajectories of chunks [{}, {})",
                at("trajectories"),
                s.trajectories,
                chunks.start,
                chunks.end
            ));
        }
        if s.runs.checked_add(s.failed_runs) != Some(runs) {
            return Err(format!(
                "{}: {} failed + {} counted is not the {runs} runs of chunks [{}, {}) \
                 ({trajectories} trajectories × {} noise runs)",
                at("failed_runs"),
                s.failed_runs,
                s.runs,
                chunks.start,
                chunks.end,
                cfg.noise_runs
            ));
        }
        for (name, list) in [("squared_error", &s.squared_error), ("nees", &s.nees)] {
            for (n, v) in list.iter().enumerate() {
                check_run_sum(&at(&format!("{name}[{n}]")), v, s.runs)?;
            }
        }
        let mut any = false;
        for (n, m) in s.fisher.iter().enumerate() {
            let field = at(&format!("fisher[{n}]"));
            let [f11, f21, f12, f22] = [0, 1, 2, 3].map(|i| m[i].value());
            if let Some(v) = [f11, f21, f12, f22].into_iter().find(|v| !v.is_finite()) {
                return Err(format!("{field}: {v} is not finite"));
            }
            if f11 < 0.0 || f22 < 0.0 {
                return Err(format!(
                    "{field}: diagonal [{f11}, {f22}] is negative (a sum of Fisher information)"
                ));
            }
            if f21 != f12 {
                return Err(format!("{field}: not symmetric (F21 = {f21}, F12 = {f12})"));
            }
            let scale = f11.max(f22);
            if scale > 0.0 {
                let (a, b, c) = (f11 / scale, f22 / scale, f12 / scale);
                if c * c > a * b * (1.0 + PSD_TOLERANCE) {
                    return Err(format!(
                        "{field}: not positive semi-definite (F12² = {} > F11·F22 = {})",
                        f12 * f12,
                        f11 * f22
                    ));
                }
            } else if f12 != 0.0 {
                return Err(format!(
                    "{field}: not positive semi-definite (zero diagonal, F12 = {f12})"
                ));
            }
            let zero = f11 == 0.0 && f22 == 0.0;
            if n == 0 && !zero {
                return Err(format!("{field}: not zero (step 0 has no measurement)"));
            }
            if s.trajectories == 0 && !zero {
                return Err(format!("{field}: not zero, but no trajectory was counted"));
            }
            any |= n > 0 && !zero;
        }
        if s.trajectories > 0 && cfg.steps > 0 && !any {
            return Err(format!(
                "{}: zero at every step, but {} trajectories were counted",
                at("fisher"),
                s.trajectories
            ));
        }
        // The truth is the same for every filter: its trajectories and Fisher sums too.
        let lead = &entries[0];
        if f > 0 && (s.fisher != lead.fisher) {
            let n = s
                .fisher
                .iter()
                .zip(&lead.fisher)
                .position(|(a, b)| a != b)
                .unwrap_or(0);
            return Err(format!(
                "{}: not the Fisher sum of sums[{first}] (the same trajectories)",
                at(&format!("fisher[{n}]"))
            ));
        }
    }
    Ok(())
}

/// A sum over runs (`squared_error[n]`, `nees[n]`) of `runs` counted runs: finite, ≥ 0, zero
/// for no run and not zero for some (a squared error or NEES of exactly 0 has probability 0).
fn check_run_sum(field: &str, v: &ExactSum, runs: usize) -> Result<(), String> {
    let x = v.value();
    if !x.is_finite() {
        return Err(format!("{field}: {x} is not finite"));
    }
    if x < 0.0 {
        return Err(format!("{field}: {x} is negative"));
    }
    if runs == 0 && x != 0.0 {
        return Err(format!("{field}: {x}, but no run was counted (must be 0)"));
    }
    if runs > 0 && x == 0.0 {
        return Err(format!("{field}: 0, but {runs} runs were counted"));
    }
    Ok(())
}
