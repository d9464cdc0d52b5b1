//! The estimation stage of spec §4: per snapshot, every link's full list of delay estimates
//! `τ̂^full_kl` (S5, I6) is gated against the calibration (E4: static estimates are discarded),
//! and the remaining candidates are associated to the one mobile scatterer (S6, I7).
//!
//! Association rule (spec §4 **\[choice\]**): if one candidate remains take it; if several remain,
//! take the one nearest the filter's predicted delay when its normalised innovation
//! `|τ̂ − h_p(r̂⁻)|/√S_pp` is ≤ 3, else (in particular with no track yet) the one of largest
//! amplitude. A link with no candidate is absent from `τ̂` at that time (the filter skips it).
//! That rule assumes the papers' unique scatterer: a lone false alarm is taken however far from
//! the prediction, which derails the track. [`AssociationRule::Gated`] is the clutter-safe
//! variant: with a track only a candidate inside the innovation gate is taken.

use alloc::format;
use alloc::vec::Vec;

pub use crate::channel::DelayEstimate;
use crate::error::{check_len, limits, Error, Result};
use crate::math::Real;
use crate::track::gating::Calibration;
use crate::track::PredictedDelay;

/// Gate on the normalised innovation of the nearest candidate (spec §4).
pub const INNOVATION_GATE: Real = 3.0;

/// Largest number of delay estimates accepted for one link in one snapshot.
pub const MAX_ESTIMATES_PER_LINK: usize = 10_000;

/// How a link's measurement was chosen in one snapshot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Choice {
    /// No candidate remained after gating: the link is absent.
    Absent,
    /// Exactly one candidate remained.
    Single,
    /// Several remained; the nearest to the prediction passed the innovation gate.
    Nearest,
    /// Several remained; no track yet, or the nearest failed the gate: the largest amplitude.
    Strongest,
}

impl Choice {
    /// A short lower-case name (`absent`, `single`, `nearest`, `strongest`).
    pub fn name(self) -> &'static str {
        match self {
            Choice::Absent => "absent",
            Choice::Single => "single",
            Choice::Nearest => "nearest",
            Choice::Strongest => "strongest",
        }
    }
}

/// Which association rule to apply (JSON: `"spec"`, `"gated"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AssociationRule {
    /// The spec's rule (§4 **\[choice\]**), for a unique scatterer without clutter: one candidate is
    /// always taken; of several, the nearest if it passes the innovation gate, else the largest
    /// amplitude.
    #[default]
    Spec,
    /// For clutter (false alarms): with a track, a candidate is taken only if it passes the
    /// innovation gate (the nearest of those that do), else the link is absent; without a track
    /// as [`AssociationRule::Spec`].
    Gated,
}

impl AssociationRule {
    /// `spec` or `gated`.
    pub fn name(self) -> &'static str {
        match self {
            AssociationRule::Spec => "spec",
            AssociationRule::Gated => "gated",
        }
    }

    /// The rule named `name` (`spec`, `gated`), else [`Error::InvalidFile`] of `field`.
    pub fn named(field: &str, name: &str) -> Result<AssociationRule> {
        match name {
            "spec" => Ok(AssociationRule::Spec),
            "gated" => Ok(AssociationRule::Gated),
            _ => Err(Error::InvalidFile {
                field: field.into(),
                reason: format!("\"{}\" is not one of gated, spec", crate::error::Clip(name)),
            }),
        }
    }
}

/// The association of one link's non-static candidates under `rule`: the index chosen (into
/// `candidates`) and how. Ties go to the earlier candidate.
pub fn associate(
    candidates: &[DelayEstimate],
    prediction: Option<&PredictedDelay>,
    rule: AssociationRule,
) -> (Option<usize>, Choice) {
    if candidates.is_empty() {
        return (None, Choice::Absent);
    }
    let single = candidates.len() == 1;
    // The candidate nearest the prediction and whether it passes the innovation gate.
    let nearest = prediction.map(|pred| {
        let i = argmin(candidates, |c| pred.normalized_innovation(c.delay_s));
        (
            i,
            pred.normalized_innovation(candidates[i].delay_s) <= INNOVATION_GATE,
        )
    });
    match (rule, nearest) {
        (AssociationRule::Gated, Some((i, true))) if single => (Some(i), Choice::Single),
        (AssociationRule::Gated, Some((_, false))) => (None, Choice::Absent),
        _ if single => (Some(0), Choice::Single),
        (_, Some((i, true))) => (Some(i), Choice::Nearest),
        _ => (
            Some(argmin(candidates, |c| -c.amplitude)),
            Choice::Strongest,
        ),
    }
}

/// Index of the smallest key, the first one on ties.
fn argmin(c: &[DelayEstimate], key: impl Fn(&DelayEstimate) -> Real) -> usize {
    let mut best = 0;
    for i in 1..c.len() {
        if key(&c[i]) < key(&c[best]) {
            best = i;
        }
    }
    best
}

/// One snapshot after gating and association.
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    /// Per link the associated delay (s), `None` = absent: the filter's measurement vector.
    pub delays: Vec<Option<Real>>,
    /// Per link how it was chosen.
    pub choices: Vec<Choice>,
    /// Per link the number of estimates discarded as static (E4).
    pub static_removed: Vec<usize>,
    /// Per link the estimator's σ of the associated delay (C5), s, when it gave one.
    pub sigmas: Vec<Option<Real>>,
}

/// Gates one snapshot (`estimates[p]` = link `p`'s list) against `calibration` and associates
/// each link under `rule` (with the filter's predictions when a track exists). Errors: wrong link count
/// (`LengthMismatch`), a delay outside `0 < delay ≤ 1 s` (`InvalidDelay`) or amplitude (`NonFinite`), too
/// many estimates on a link (`SizeLimit`).
pub fn select(
    calibration: &Calibration,
    estimates: &[Vec<DelayEstimate>],
    predictions: Option<&[PredictedDelay]>,
    rule: AssociationRule,
) -> Result<Selection> {
    let n = calibration.link_count();
    check_len("estimates", n, estimates.len())?;
    if let Some(p) = predictions {
        check_len("predictions", n, p.len())?;
    }
    let mut out = Selection {
        delays: Vec::with_capacity(n),
        choices: Vec::with_capacity(n),
        static_removed: Vec::with_capacity(n),
        sigmas: Vec::with_capacity(n),
    };
    let mut kept = Vec::new();
    for (link, list) in estimates.iter().enumerate() {
        if list.len() > MAX_ESTIMATES_PER_LINK {
            return Err(Error::SizeLimit {
                field: "delay estimates per link and snapshot",
                value: list.len(),
                min: 0,
                max: MAX_ESTIMATES_PER_LINK,
            });
        }
        kept.clear();
        for (i, e) in list.iter().enumerate() {
            if !limits::DELAY_S.contains(e.delay_s) {
                return Err(Error::InvalidDelay {
                    link,
                    value: e.delay_s,
                });
            }
            if !e.amplitude.is_finite() {
                return Err(Error::NonFinite {
                    field: format!("estimates[{link}][{i}].amplitude"),
                });
            }
            if !calibration.links[link].is_static(e.delay_s) {
                kept.push(*e);
            }
        }
        let (index, choice) = associate(&kept, predictions.map(|p| &p[link]), rule);
        out.delays.push(index.map(|i| kept[i].delay_s));
        out.sigmas.push(index.and_then(|i| kept[i].sigma_s));
        out.choices.push(choice);
        out.static_removed.push(list.len() - kept.len());
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
