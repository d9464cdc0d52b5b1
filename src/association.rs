//! The estimation stage of spec §4: per snapshot, every link's full list of delay estimates
//! `τ̂^full_kl` (S5, I6) is gated against the calibration (E4: static estimates are discarded),
//! and the remaining candidates are associated to the one mobile scatterer (S6, I7).
//!
//! Association rule (spec §4 **[choice]**): if one candidate remains take it; if several remain,
//! take the one nearest the EKF-predicted delay when its normalised innovation
//! `|τ̂ − h_p(r̂⁻)|/√S_pp` is ≤ 3, else (in particular with no track yet) the one of largest
//! amplitude. A link with no candidate is absent from `τ̂` at that time (the EKF skips its row).
//! That rule assumes the papers' unique scatterer: a lone false alarm is taken however far from
//! the prediction, which derails the track. [`AssociationRule::Gated`] is the clutter-safe
//! variant: with a track only a candidate inside the innovation gate is taken.

use alloc::format;
use alloc::vec::Vec;

use crate::calibration::Calibration;
use crate::ekf::PredictedDelay;
use crate::error::{Error, Result};
use crate::math::Real;

/// Gate on the normalised innovation of the nearest candidate (spec §4).
pub const INNOVATION_GATE: Real = 3.0;

/// Largest number of delay estimates accepted for one link in one snapshot.
pub const MAX_ESTIMATES_PER_LINK: usize = 10_000;

/// One entry of a parameter estimator's per-snapshot list: a delay and its amplitude.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DelayEstimate {
    /// `τ̂`, s.
    pub delay_s: Real,
    /// Amplitude `|α̂|` (any linear unit; only compared within a link).
    pub amplitude: Real,
}

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

/// Which association rule to apply.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AssociationRule {
    /// The spec's rule (§4 **[choice]**), for a unique scatterer without clutter: one candidate is
    /// always taken; of several, the nearest if it passes the innovation gate, else the largest
    /// amplitude.
    #[default]
    Spec,
    /// For clutter (false alarms): with a track, a candidate is taken only if it passes the
    /// innovation gate (the nearest of those that do), else the link is absent; without a track
    /// as [`AssociationRule::Spec`].
    Gated,
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
    /// Per link the associated delay (s), `None` = absent: the EKF's measurement vector.
    pub delays: Vec<Option<Real>>,
    /// Per link how it was chosen.
    pub choices: Vec<Choice>,
    /// Per link the number of estimates discarded as static (E4).
    pub static_removed: Vec<usize>,
}

/// Gates one snapshot (`estimates[p]` = link `p`'s list) against `calibration` and associates
/// each link under `rule` (with the filter's predictions when a track exists). Errors: wrong link count
/// (`LengthMismatch`), a non-finite delay (`NonFiniteDelay`) or amplitude (`NonFinite`), too
/// many estimates on a link (`SizeLimit`).
pub fn select(
    calibration: &Calibration,
    estimates: &[Vec<DelayEstimate>],
    predictions: Option<&[PredictedDelay]>,
    rule: AssociationRule,
) -> Result<Selection> {
    let n = calibration.link_count();
    if estimates.len() != n {
        return Err(Error::LengthMismatch {
            field: "estimates",
            expected: n,
            found: estimates.len(),
        });
    }
    if let Some(p) = predictions {
        if p.len() != n {
            return Err(Error::LengthMismatch {
                field: "predictions",
                expected: n,
                found: p.len(),
            });
        }
    }
    let mut out = Selection {
        delays: Vec::with_capacity(n),
        choices: Vec::with_capacity(n),
        static_removed: Vec::with_capacity(n),
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
            if !e.delay_s.is_finite() {
                return Err(Error::NonFiniteDelay { link });
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
        out.choices.push(choice);
        out.static_removed.push(list.len() - kept.len());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::AssociationRule::{Gated, Spec};
    use super::*;
    use crate::calibration::{LinkCalibration, StaticCluster};
    use alloc::vec;

    fn est(delay_ns: Real, amplitude: Real) -> DelayEstimate {
        DelayEstimate {
            delay_s: delay_ns * 1e-9,
            amplitude,
        }
    }

    fn pred(delay_ns: Real, sigma_ns: Real) -> PredictedDelay {
        PredictedDelay {
            delay_s: delay_ns * 1e-9,
            innovation_sigma_s: sigma_ns * 1e-9,
        }
    }

    #[test]
    fn the_association_rule_of_spec_section_4() {
        let c = [est(50.0, 1.0), est(70.0, 3.0), est(90.0, 2.0)];
        assert_eq!(associate(&[], None, Spec), (None, Choice::Absent));
        // One candidate is taken even far from the prediction.
        assert_eq!(
            associate(&c[..1], Some(&pred(100.0, 1.0)), Spec),
            (Some(0), Choice::Single)
        );
        // No track: the largest amplitude.
        assert_eq!(associate(&c, None, Spec), (Some(1), Choice::Strongest));
        // Nearest within 3σ of the prediction (|89 − 90|/1 = 1).
        assert_eq!(
            associate(&c, Some(&pred(89.0, 1.0)), Spec),
            (Some(2), Choice::Nearest)
        );
        // Just inside the gate (2.99σ) passes; just beyond it (3.01σ) falls back to the amplitude.
        assert_eq!(
            associate(&c, Some(&pred(47.01, 1.0)), Spec),
            (Some(0), Choice::Nearest)
        );
        assert_eq!(
            associate(&c, Some(&pred(46.99, 1.0)), Spec),
            (Some(1), Choice::Strongest)
        );
        // Gated: a lone or nearest candidate only inside the gate; no track: as the spec's.
        assert_eq!(
            associate(&c[..1], Some(&pred(100.0, 1.0)), Gated),
            (None, Choice::Absent)
        );
        assert_eq!(
            associate(&c[..1], Some(&pred(52.0, 1.0)), Gated),
            (Some(0), Choice::Single)
        );
        assert_eq!(
            associate(&c, Some(&pred(46.99, 1.0)), Gated),
            (None, Choice::Absent)
        );
        assert_eq!(
            associate(&c, Some(&pred(89.0, 1.0)), Gated),
            (Some(2), Choice::Nearest)
        );
        assert_eq!(associate(&c, None, Gated), (Some(1), Choice::Strongest));
    }

    #[test]
    fn select_gates_then_associates_per_link() {
        let cluster = |mean_ns: Real, sigma_ns: Real| StaticCluster {
            mean_s: mean_ns * 1e-9,
            sigma_s: sigma_ns * 1e-9,
            count: 10,
            snapshots: 10,
        };
        let cal = Calibration {
            links: vec![
                LinkCalibration {
                    clusters: vec![cluster(40.0, 0.1), cluster(60.0, 0.1)],
                },
                LinkCalibration::default(),
            ],
        };
        let raw = vec![
            vec![est(40.05, 9.0), est(55.0, 1.0), est(60.29, 9.0)],
            vec![],
        ];
        let s = select(&cal, &raw, None, Spec).unwrap();
        assert_eq!(s.delays, vec![Some(55.0e-9), None]);
        assert_eq!(s.choices, vec![Choice::Single, Choice::Absent]);
        assert_eq!(s.static_removed, vec![2, 0]);
        // Bad input is named.
        let bad = vec![vec![est(Real::NAN, 1.0)], vec![]];
        assert_eq!(
            select(&cal, &bad, None, Spec).unwrap_err(),
            Error::NonFiniteDelay { link: 0 }
        );
        let bad = vec![vec![], vec![est(50.0, Real::INFINITY)]];
        assert_eq!(
            select(&cal, &bad, None, Spec).unwrap_err().to_string(),
            "estimates[1][0].amplitude: not a finite number"
        );
        assert!(matches!(
            select(&cal, &raw[..1], None, Spec),
            Err(Error::LengthMismatch {
                expected: 2,
                found: 1,
                ..
            })
        ));
        assert!(matches!(
            select(&cal, &raw, Some(&[pred(1.0, 1.0)]), Spec),
            Err(Error::LengthMismatch {
                field: "predictions",
                ..
            })
        ));
    }
}
