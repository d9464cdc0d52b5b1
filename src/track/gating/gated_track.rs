//! Any filter of the seam ([`Filter`]: the EKF of spec §6, the UKF or the particle filter of
//! `filters-and-planning.md` §1–2, or a [`crate::track::Tracker`] holding one) fed by the
//! estimation stage of spec §4: per snapshot predict, gate every link's estimates against the
//! calibration (E4), associate the rest using the filter's own prediction (`ẑ_p`, `√S_pp`:
//! the EKF's from its Jacobian, the UKF's from its sigma points, the particle filter's from its
//! weighted particles), then update with the links that kept a measurement (an absent link
//! skips its row; none = predict only).
//!
//! Without a track yet (the measurement case of spec §9.6 starts with "LM at t₀ = 0"),
//! [`start_from_snapshot`] gates the first snapshot, associates with no prediction (the
//! largest amplitude per link) and fixes the position with Levenberg–Marquardt (§5) to start
//! the filter.

use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::localize::{locate, DelayMeasurements, LmConfig, LmReport};
use crate::math::{Mat4, Real, Vec4};
use crate::measure::Model;
use crate::scenario::Area;
use crate::track::gating::Calibration;
use crate::track::gating::{select, AssociationRule, DelayEstimate, Selection};
use crate::track::{ConstantVelocity, Filter};
use crate::track::{Ekf, MeasurementNoise, UpdateSummary};

/// One step of [`GatedTracker::step`].
#[derive(Debug, Clone, PartialEq)]
pub struct GatedStep {
    /// The update's NIS and links used.
    pub summary: UpdateSummary,
    /// What gating and association made of the snapshot.
    pub selection: Selection,
    /// Per link the σ its delay was weighted with in the update, s (the estimator's where it
    /// was used, else the tracker's noise at the predicted position); `None` for an absent link.
    pub sigmas_s: Vec<Option<Real>>,
}

/// A filter (by default the EKF) whose measurements pass through gating and association.
#[derive(Debug, Clone)]
pub struct GatedTracker<'a, F: Filter = Ekf> {
    /// The filter (state after the last step).
    pub filter: F,
    model: &'a Model,
    calibration: &'a Calibration,
    motion: ConstantVelocity,
    noise: MeasurementNoise<'a>,
    rule: AssociationRule,
    estimate_sigmas: bool,
    gate_sigma_s: Option<Real>,
}

impl<'a, F: Filter> GatedTracker<'a, F> {
    /// A tracker of `filter` on `model` with one calibration entry per link (else
    /// `LengthMismatch`), associating under `rule`.
    pub fn new(
        filter: F,
        model: &'a Model,
        calibration: &'a Calibration,
        motion: ConstantVelocity,
        noise: MeasurementNoise<'a>,
        rule: AssociationRule,
    ) -> Result<GatedTracker<'a, F>> {
        calibration.check_links(model.link_count())?;
        Ok(GatedTracker {
            filter,
            model,
            calibration,
            motion,
            noise,
            rule,
            estimate_sigmas: true,
            gate_sigma_s: None,
        })
    }

    /// Whether an associated delay that carries the estimator's own σ (C5) is weighted with it
    /// (the default; `false`: always the tracker's `noise`). A fixed `noise`
    /// ([`MeasurementNoise::Fixed`]) always wins: a file that fixes `sigma_s` means it.
    pub fn with_estimate_sigmas(mut self, on: bool) -> Self {
        self.estimate_sigmas = on;
        self
    }

    /// A floor of every link's measurement σ in the innovation gate of the association (s):
    /// the gate then holds an extended scatterer's spread (`None`: the tracker's noise, E8).
    pub fn with_gate_sigma(mut self, sigma_s: Option<Real>) -> Self {
        self.gate_sigma_s = sigma_s;
        self
    }

    /// The motion model of the next [`GatedTracker::step`] (a recording's snapshots need not be
    /// uniform in time).
    pub fn set_motion(&mut self, motion: ConstantVelocity) {
        self.motion = motion;
    }

    /// Predict, gate and associate `snapshot` (`[p]` = link `p`'s estimates), update. On error
    /// the filter is left unchanged.
    pub fn step(&mut self, snapshot: &[Vec<DelayEstimate>]) -> Result<GatedStep> {
        let mut next = self.filter.clone();
        next.predict(&self.motion);
        let predictions = match self.gate_sigma_s {
            Some(g) => {
                let r = next.position();
                let floor: Vec<Real> = (0..self.model.link_count())
                    .map(|p| self.noise.sigma(self.model, p, r).max(g))
                    .collect();
                next.predicted_delays(self.model, MeasurementNoise::Fixed(&floor))?
            }
            None => next.predicted_delays(self.model, self.noise)?,
        };
        let selection = select(self.calibration, snapshot, Some(&predictions), self.rule)?;
        let own = self.estimate_sigmas && !matches!(self.noise, MeasurementNoise::Fixed(_));
        // The estimator's σ where it gave one (and `own`), else the tracker's noise at the
        // prediction; only for the links that have a delay.
        let r = next.position();
        let sigmas_s: Vec<Option<Real>> = (0..self.model.link_count())
            .map(|p| {
                selection.delays[p].map(|_| match selection.sigmas[p] {
                    Some(s) if own => s,
                    _ => self.noise.sigma(self.model, p, r),
                })
            })
            .collect();
        let summary = if own && selection.sigmas.iter().any(Option::is_some) {
            // Absent links' rows are skipped: their σ is never read.
            let fixed: Vec<Real> = sigmas_s.iter().map(|s| s.unwrap_or(1.0)).collect();
            next.update(
                self.model,
                &selection.delays,
                MeasurementNoise::Fixed(&fixed),
            )?
        } else {
            next.update(self.model, &selection.delays, self.noise)?
        };
        self.filter = next;
        Ok(GatedStep {
            summary,
            selection,
            sigmas_s,
        })
    }
}

/// Standard deviation of each velocity component when the filter starts from a snapshot fix
/// (the fix says nothing about velocity), m/s: spec §9.6 **\[choice\]**, walking speeds.
pub const START_SPEED_SIGMA_MPS: Real = 2.0;

/// The start of a track from one snapshot: the filter and how it was made.
#[derive(Debug, Clone, PartialEq)]
pub struct StartFix {
    /// `x̂(t₀) = [r̂, 0, 0]`, `P(t₀) = diag(cov(r̂), σ_v², σ_v²)`.
    pub ekf: Ekf,
    /// Gating and association of the snapshot (no track: the largest amplitude per link).
    pub selection: Selection,
    /// The LM fix (second pass, weighted with `σ_p` from E8 at the first pass's fix).
    pub report: LmReport,
}

/// Starts a track from `snapshot` at `t₀`: gate (E4), associate without a prediction, then LM
/// (§5) from the best node of the 0.5 m grid over `area` — first unweighted, then with
/// `σ_p(r̂₁)` from the link budget (E8) — and the filter at the fix with velocity zero and
/// per-component velocity σ `speed_sigma_mps`. Errors: those of [`select`], fewer than 3 links
/// left (`TooFewLinks`), a singular fix (`NotPositiveDefinite` of `start_fix.covariance`), a
/// speed σ that is not finite and `> 0`.
pub fn start_from_snapshot(
    model: &Model,
    calibration: &Calibration,
    snapshot: &[Vec<DelayEstimate>],
    area: &Area,
    speed_sigma_mps: Real,
) -> Result<StartFix> {
    if !(speed_sigma_mps.is_finite() && speed_sigma_mps > 0.0) {
        return Err(Error::NotPositive {
            field: "start_speed_sigma_mps".into(),
            value: speed_sigma_mps,
        });
    }
    calibration.check_links(model.link_count())?;
    let selection = select(calibration, snapshot, None, AssociationRule::Spec)?;
    let cfg = LmConfig::default();
    let uniform = alloc::vec![1e-9; model.link_count()];
    let m = DelayMeasurements {
        delays_s: &selection.delays,
        sigmas_s: &uniform,
    };
    let first = locate(&model.network, &m, &cfg, None, area)?;
    let sigmas = model.sigma_delays(first.position);
    let m = DelayMeasurements {
        delays_s: &selection.delays,
        sigmas_s: &sigmas,
    };
    let report = locate(&model.network, &m, &cfg, Some(first.position), area)?;
    let singular = || Error::NotPositiveDefinite {
        field: "start_fix.covariance".into(),
    };
    let c = report.covariance_m2.ok_or_else(singular)?;
    let v2 = speed_sigma_mps * speed_sigma_mps;
    let mut p = Mat4::zeros();
    p.fixed_view_mut::<2, 2>(0, 0).copy_from(&c);
    p[(2, 2)] = v2;
    p[(3, 3)] = v2;
    let state = Vec4::new(report.position.x, report.position.y, 0.0, 0.0);
    let ekf = Ekf::new(state, p).map_err(|_| singular())?;
    Ok(StartFix {
        ekf,
        selection,
        report,
    })
}
