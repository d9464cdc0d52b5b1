//! Experiment results: ROC points (M12) per curve and threshold, and the order-preserving sums
//! over realisations that make them independent of the thread count.

use alloc::string::String;
use alloc::vec::Vec;

use crate::math::Real;
use crate::mtl::experiment::{CurveSpec, Experiment, ExperimentConfig, RealisationCounts};
use crate::mtl::sim::DetectionCounts;

/// One point of a curve: the threshold and the metrics (M12) over all realisations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RocPoint {
    /// The swept threshold value.
    pub threshold: Real,
    /// `P_D = E[N_D/K]`.
    pub p_d: Real,
    /// `P_FA = E[N_FA/max(K̂, 1)]`.
    pub p_fa: Real,
    /// `Σ N_D`.
    pub detections: u64,
    /// `Σ N_FA`.
    pub false_alarms: u64,
    /// `Σ K̂`.
    pub estimates: u64,
}

/// A curve of the result.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// What produced it.
    pub spec: CurveSpec,
    /// Legend label.
    pub label: String,
    /// One point per sweep value.
    pub points: Vec<RocPoint>,
}

/// The result of an experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct ExperimentResult {
    /// Which experiment.
    pub experiment: Experiment,
    /// Realisations run.
    pub realisations: usize,
    /// Targets over all realisations.
    pub targets: u64,
    /// The curves.
    pub curves: Vec<Curve>,
    /// V-A: `(realisation, N_u, T_e)` triples where the size rule and Bayesian i.c.b returned
    /// different detections (spec check 6: none).
    pub disagreements: u64,
}

/// Per-curve, per-threshold sums over realisations, merged in realisation order.
#[derive(Debug, Clone, PartialEq)]
pub struct Tally {
    realisations: usize,
    targets: u64,
    disagreements: u64,
    /// `[curve][point]`.
    sums: Vec<Vec<PointSums>>,
}

impl Tally {
    /// Empty sums for `curves × points`.
    pub fn new(curves: usize, points: usize) -> Tally {
        Tally {
            realisations: 0,
            targets: 0,
            disagreements: 0,
            sums: alloc::vec![alloc::vec![PointSums::default(); points]; curves],
        }
    }

    /// Adds one realisation (call in realisation order for reproducible sums).
    pub fn add(&mut self, r: &RealisationCounts) {
        self.realisations += 1;
        self.targets += r.targets as u64;
        self.disagreements += r.disagreements;
        for (curve, counts) in self.sums.iter_mut().zip(&r.counts) {
            for (s, c) in curve.iter_mut().zip(counts) {
                add_counts(s, c);
            }
        }
    }

    /// Realisations added.
    pub fn realisations(&self) -> usize {
        self.realisations
    }

    /// The result of `cfg` from these sums.
    pub fn finish(&self, cfg: &ExperimentConfig) -> ExperimentResult {
        let n = self.realisations.max(1) as Real;
        let curves = cfg
            .curves()
            .into_iter()
            .zip(&self.sums)
            .map(|(spec, sums)| Curve {
                spec,
                label: spec.label(cfg),
                points: cfg
                    .sweep
                    .iter()
                    .zip(sums)
                    .map(|(&threshold, s)| RocPoint {
                        threshold,
                        p_d: s.detection_ratio / n,
                        p_fa: s.false_alarm_ratio / n,
                        detections: s.detections,
                        false_alarms: s.false_alarms,
                        estimates: s.estimates,
                    })
                    .collect(),
            })
            .collect();
        ExperimentResult {
            experiment: cfg.experiment,
            realisations: self.realisations,
            targets: self.targets,
            curves,
            disagreements: self.disagreements,
        }
    }
}

/// Sums of one curve point over realisations.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct PointSums {
    /// `Σ N_D/K`.
    detection_ratio: Real,
    /// `Σ N_FA/max(K̂, 1)`.
    false_alarm_ratio: Real,
    /// `Σ N_D`.
    detections: u64,
    /// `Σ N_FA`.
    false_alarms: u64,
    /// `Σ K̂`.
    estimates: u64,
}

fn add_counts(s: &mut PointSums, c: &DetectionCounts) {
    s.detection_ratio += c.detected as Real / c.targets.max(1) as Real;
    s.false_alarm_ratio += c.false_alarms as Real / c.estimates.max(1) as Real;
    s.detections += c.detected as u64;
    s.false_alarms += c.false_alarms as u64;
    s.estimates += c.estimates as u64;
}
