//! The scores of a multi-target run (issue 41 §1): GOSPA (`α = 2`) and its parts per step,
//! the cardinality error `|n̂ − n|`, and the label switches: for each true target, the label of
//! the estimate GOSPA pairs it with; a switch is a change of that label between two steps at
//! which it is paired.

use alloc::collections::BTreeMap;
use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{Real, Vec2};
use crate::track::multi::{TargetEstimate, Truth};
use crate::track::{gospa, GospaConfig};

/// One step's score.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepScore {
    /// GOSPA distance, m.
    pub gospa: Real,
    /// Localisation part, m^p.
    pub localisation: Real,
    /// Missed part, m^p.
    pub missed: Real,
    /// False part, m^p.
    pub false_: Real,
    /// `|n̂ − n|`.
    pub cardinality_error: usize,
}

/// A run's score.
#[derive(Debug, Clone, PartialEq)]
pub struct RunScore {
    /// Per step.
    pub steps: Vec<StepScore>,
    /// Label switches per true target (by its label).
    pub switches: BTreeMap<u64, usize>,
}

impl RunScore {
    /// `Σ_k d_k^p / K` (the mean of the p-th power GOSPA; its p-th root is the RMS GOSPA for
    /// `p = 2`).
    pub fn mean_gospa_p(&self, p: Real) -> Real {
        let n = self.steps.len().max(1) as Real;
        self.steps
            .iter()
            .map(|s| crate::math::pow(s.gospa, p))
            .sum::<Real>()
            / n
    }

    /// All switches.
    pub fn total_switches(&self) -> usize {
        self.switches.values().sum()
    }
}

/// The score of `estimates[k]` against `truth.steps[k]` (the shorter length of the two).
pub fn score_run(
    truth: &Truth,
    estimates: &[Vec<TargetEstimate>],
    config: &GospaConfig,
) -> Result<RunScore> {
    let mut steps = Vec::new();
    let mut last: BTreeMap<u64, u64> = BTreeMap::new();
    let mut switches: BTreeMap<u64, usize> = BTreeMap::new();
    for (targets, est) in truth.steps.iter().zip(estimates) {
        let x: Vec<Vec2> = targets.iter().map(|(_, s)| Vec2::new(s[0], s[1])).collect();
        let y: Vec<Vec2> = est
            .iter()
            .map(|e| Vec2::new(e.state[0], e.state[1]))
            .collect();
        let g = gospa(&x, &y, config)?;
        for &(i, j) in &g.pairs {
            let t = targets[i].0;
            let l = est[j].label;
            switches.entry(t).or_insert(0);
            if let Some(prev) = last.insert(t, l) {
                if prev != l {
                    *switches.entry(t).or_insert(0) += 1;
                }
            }
        }
        steps.push(StepScore {
            gospa: g.distance,
            localisation: g.localisation,
            missed: g.missed,
            false_: g.false_,
            cardinality_error: x.len().abs_diff(y.len()),
        });
    }
    Ok(RunScore { steps, switches })
}
