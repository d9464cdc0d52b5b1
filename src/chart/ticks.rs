//! Colour-bar ticks: the labelled ticks of the shared [`crate::present::log_length_ticks`] (so the
//! figures and the page print the same labels), thinned to fit the bar, plus unlabelled minor
//! ticks at the other integer multiples of each decade.

use alloc::string::String;
use alloc::vec::Vec;

use crate::math::Real;
use crate::present::log_length_ticks;

/// A colour-bar tick: value in metres and its label (empty for a minor tick).
#[derive(Debug, Clone, PartialEq)]
pub struct BarTick {
    /// Value, m.
    pub value_m: Real,
    /// Label; empty for a minor tick.
    pub label: String,
}

/// Ticks for a log colour bar over `[min, max]` m with at most `max_labels` labels (≥ 2).
pub fn colorbar_ticks(min: Real, max: Real, max_labels: usize) -> Vec<BarTick> {
    let max_labels = max_labels.max(2);
    let mut major = log_length_ticks(min, max);
    if major.len() > max_labels {
        // Too many for the bar: keep the powers of ten, then every other one.
        let decades: Vec<_> = major
            .iter()
            .filter(|t| (t.value.log10() - t.value.log10().round()).abs() < 1e-9)
            .cloned()
            .collect();
        if decades.len() >= 2 {
            major = decades;
        }
    }
    while major.len() > max_labels {
        major = major.into_iter().step_by(2).collect();
    }
    let mut out: Vec<BarTick> = major
        .iter()
        .map(|t| BarTick {
            value_m: t.value,
            label: t.label.clone(),
        })
        .collect();
    // Minor ticks only when the labels are at most a decade apart (not for thinned decades or the
    // bare end points of a flat map).
    let dense = major.len() >= 2 && major.windows(2).all(|w| w[1].value <= 10.0001 * w[0].value);
    if dense && min > 0.0 && max > min {
        let (k0, k1) = (min.log10().floor() as i32, max.log10().ceil() as i32);
        for k in k0..=k1 {
            for m in 1..=9 {
                let v = m as Real * (10.0 as Real).powi(k);
                let inside = v >= min * (1.0 - 1e-9) && v <= max * (1.0 + 1e-9);
                let taken = major.iter().any(|t| (t.value - v).abs() <= 1e-9 * v);
                if inside && !taken {
                    out.push(BarTick {
                        value_m: v,
                        label: String::new(),
                    });
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests;
