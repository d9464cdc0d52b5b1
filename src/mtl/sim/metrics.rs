//! Detection metrics (M12) of spec `multi-target.md` §7: per realisation `N_D` (targets with an
//! estimate within `r_det`) and `N_FA` (estimates with no target within `r_det`); over
//! realisations `P_D = E[N_D/K]` and `P_FA = E[N_FA / max(K̂, 1)]`.

use crate::error::{Error, Result};
use crate::math::{Real, Vec2};

/// `N_D` and `N_FA` of one realisation (M12).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DetectionCounts {
    /// Targets `K`.
    pub targets: usize,
    /// Estimates `K̂`.
    pub estimates: usize,
    /// Targets with an estimate within `r_det`, `N_D`.
    pub detected: usize,
    /// Estimates with no target within `r_det`, `N_FA`.
    pub false_alarms: usize,
}

fn near(a: &Vec2, b: &Vec2, r: Real) -> bool {
    (a - b).norm_squared() <= r * r
}

/// `N_D` and `N_FA` (M12) for true `targets`, `estimates` and detection radius `r_det` (a
/// distance `≤ r_det` counts as within). One estimate may detect several targets.
pub fn count_detections(targets: &[Vec2], estimates: &[Vec2], r_det: Real) -> DetectionCounts {
    DetectionCounts {
        targets: targets.len(),
        estimates: estimates.len(),
        detected: targets
            .iter()
            .filter(|t| estimates.iter().any(|e| near(t, e, r_det)))
            .count(),
        false_alarms: estimates
            .iter()
            .filter(|e| !targets.iter().any(|t| near(t, e, r_det)))
            .count(),
    }
}

/// Running averages `P_D = E[N_D/K]`, `P_FA = E[N_FA / max(K̂, 1)]` (M12).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Metrics {
    realisations: usize,
    sum_detection: Real,
    sum_false_alarm: Real,
}

impl Metrics {
    /// No realisation yet.
    pub fn new() -> Metrics {
        Metrics::default()
    }

    /// Adds one realisation's counts; [`Error::SizeLimit`] (`targets`) when `K = 0` (then
    /// `N_D/K` is undefined).
    pub fn add_counts(&mut self, c: &DetectionCounts) -> Result<()> {
        if c.targets == 0 {
            return Err(Error::SizeLimit {
                field: "targets",
                value: 0,
                min: 1,
                max: usize::MAX,
            });
        }
        self.realisations += 1;
        self.sum_detection += c.detected as Real / c.targets as Real;
        self.sum_false_alarm += c.false_alarms as Real / c.estimates.max(1) as Real;
        Ok(())
    }

    /// Adds one realisation from positions ([`count_detections`]); returns its counts. Same
    /// error as [`Metrics::add_counts`].
    pub fn add(
        &mut self,
        targets: &[Vec2],
        estimates: &[Vec2],
        r_det: Real,
    ) -> Result<DetectionCounts> {
        let c = count_detections(targets, estimates, r_det);
        self.add_counts(&c)?;
        Ok(c)
    }

    /// Combines two accumulators (for parallel reductions; exact for any split).
    pub fn merge(&mut self, other: &Metrics) {
        self.realisations += other.realisations;
        self.sum_detection += other.sum_detection;
        self.sum_false_alarm += other.sum_false_alarm;
    }

    /// Realisations added.
    pub fn realisations(&self) -> usize {
        self.realisations
    }

    /// `P_D` (0 before any realisation).
    pub fn p_d(&self) -> Real {
        self.mean(self.sum_detection)
    }

    /// `P_FA` (0 before any realisation).
    pub fn p_fa(&self) -> Real {
        self.mean(self.sum_false_alarm)
    }

    fn mean(&self, sum: Real) -> Real {
        if self.realisations == 0 {
            0.0
        } else {
            sum / self.realisations as Real
        }
    }
}
