//! The EKF of spec §6 fed by the estimation stage of spec §4: per snapshot predict, gate every
//! link's estimates against the calibration (E4), associate the rest using the prediction
//! (`h_p(r̂⁻)`, `√S_pp`), then update with the links that kept a measurement (an absent link
//! skips its row; none = predict only).

use alloc::vec::Vec;

use crate::association::{select, AssociationRule, DelayEstimate, Selection};
use crate::calibration::Calibration;
use crate::ekf::{Ekf, MeasurementNoise, UpdateSummary};
use crate::error::Result;
use crate::model::Model;
use crate::motion::ConstantVelocity;

/// One step of [`GatedTracker::step`].
#[derive(Debug, Clone, PartialEq)]
pub struct GatedStep {
    /// The update's NIS and links used.
    pub summary: UpdateSummary,
    /// What gating and association made of the snapshot.
    pub selection: Selection,
}

/// An EKF whose measurements pass through gating and association.
#[derive(Debug, Clone)]
pub struct GatedTracker<'a> {
    /// The filter (state after the last step).
    pub ekf: Ekf,
    model: &'a Model,
    calibration: &'a Calibration,
    motion: ConstantVelocity,
    noise: MeasurementNoise<'a>,
    rule: AssociationRule,
}

impl<'a> GatedTracker<'a> {
    /// A tracker on `model` with one calibration entry per link (else `LengthMismatch`),
    /// associating under `rule`.
    pub fn new(
        ekf: Ekf,
        model: &'a Model,
        calibration: &'a Calibration,
        motion: ConstantVelocity,
        noise: MeasurementNoise<'a>,
        rule: AssociationRule,
    ) -> Result<GatedTracker<'a>> {
        calibration.check_links(model.link_count())?;
        Ok(GatedTracker {
            ekf,
            model,
            calibration,
            motion,
            noise,
            rule,
        })
    }

    /// Predict, gate and associate `snapshot` (`[p]` = link `p`'s estimates), update. On error
    /// the filter is left unchanged.
    pub fn step(&mut self, snapshot: &[Vec<DelayEstimate>]) -> Result<GatedStep> {
        let mut next = self.ekf;
        next.predict(&self.motion);
        let predictions = next.predicted_delays(self.model, self.noise)?;
        let selection = select(self.calibration, snapshot, Some(&predictions), self.rule)?;
        let summary = next.update(self.model, &selection.delays, self.noise, None)?;
        self.ekf = next;
        Ok(GatedStep { summary, selection })
    }
}
