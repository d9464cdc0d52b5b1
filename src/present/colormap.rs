//! The log colour scale of CRLB maps, shared by the page (RGBA buffer) and the CLI figures, so
//! both show the same colours for the same values.

use alloc::vec::Vec;

use crate::error::{check_len, Result};
use crate::math::{log10, Real};
use crate::present::{colorbar_ticks, Tick};

/// Colour of unbounded (∞) or missing cells: neutral grey.
pub const UNBOUNDED_RGB: [u8; 3] = [72, 72, 80];

/// The colours of the links (their iso-delay ellipses; the multi-target view's TRPs) over the
/// map: link `i` takes entry `i mod 8`. The page draws with them and the map figure's overlays
/// ([`crate::chart::MapOverlay`]) too. Colour-blind safe: the Okabe–Ito palette (M. Okabe and
/// K. Ito, "Color Universal Design", 2008), its black replaced by an off-white (the overlays lie
/// on a dark map) and its dark blue last (the least visible on the map's dark end).
pub const LINK_RGB: [[u8; 3]; 8] = [
    [86, 180, 233],  // sky blue
    [230, 159, 0],   // orange
    [0, 158, 115],   // bluish green
    [240, 228, 66],  // yellow
    [204, 121, 167], // reddish purple
    [213, 94, 0],    // vermillion
    [244, 244, 240], // off-white (for Okabe–Ito's black)
    [0, 114, 178],   // blue
];

/// Control points of the perceptually ordered "viridis" map (dark = small error = good).
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// Colour at `t ∈ [0, 1]` (clamped; NaN → grey).
pub fn viridis(t: Real) -> [u8; 3] {
    if t.is_nan() {
        return UNBOUNDED_RGB;
    }
    let t = t.clamp(0.0, 1.0) * (VIRIDIS.len() - 1) as Real;
    let i = (t as usize).min(VIRIDIS.len() - 2);
    let f = t - i as Real;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |k: usize| (a[k] as Real + f * (b[k] as Real - a[k] as Real) + 0.5) as u8;
    [mix(0), mix(1), mix(2)]
}

/// A logarithmic scale from `min` to `max` (both > 0), mapping values to colours.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogScale {
    /// Value at the dark end, m.
    pub min: Real,
    /// Value at the bright end, m.
    pub max: Real,
}

impl LogScale {
    /// The scale from `min` to `max`; `None` unless both are finite and `0 < min < max`.
    pub fn new(min: Real, max: Real) -> Option<LogScale> {
        (min.is_finite() && max.is_finite() && min > 0.0 && max > min)
            .then_some(LogScale { min, max })
    }

    /// The scale spanning the finite positive values of `values`, widened to at least one decade
    /// ratio of 1.01 so a flat map still has a valid scale. `None` if no value is finite and > 0.
    pub fn spanning(values: &[Real]) -> Option<LogScale> {
        let (mut lo, mut hi) = (Real::INFINITY, 0.0 as Real);
        for &v in values {
            if v.is_finite() && v > 0.0 {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        if !lo.is_finite() {
            return None;
        }
        if hi < lo * 1.01 {
            hi = lo * 1.01;
        }
        Some(LogScale { min: lo, max: hi })
    }

    /// Position of `v` on the scale in [0, 1] (NaN for non-finite or non-positive `v`).
    pub fn fraction(&self, v: Real) -> Real {
        if !(v.is_finite() && v > 0.0) {
            return Real::NAN;
        }
        let (l0, l1) = (log10(self.min), log10(self.max));
        ((log10(v) - l0) / (l1 - l0)).clamp(0.0, 1.0)
    }

    /// Colour of `v`; grey for unbounded.
    pub fn color(&self, v: Real) -> [u8; 3] {
        viridis(self.fraction(v))
    }

    /// How many bounded (finite, > 0) `values` lie below `min` and above `max`: `[below,
    /// above]`, the cells a fixed scale draws in its end colours.
    pub fn clamped_counts(&self, values: &[Real]) -> [usize; 2] {
        let mut n = [0, 0];
        for &v in values.iter().filter(|v| v.is_finite() && **v > 0.0) {
            n[0] += usize::from(v < self.min);
            n[1] += usize::from(v > self.max);
        }
        n
    }

    /// Whether some bounded `values` lie below `min` and above `max` ([`clamped_counts`](LogScale::clamped_counts) > 0).
    pub fn clamped(&self, values: &[Real]) -> [bool; 2] {
        self.clamped_counts(values).map(|n| n > 0)
    }

    /// The ticks of a colour bar on this scale ([`colorbar_ticks`], at most `max_labels`
    /// labels; minor ticks have an empty label), each with its
    /// [`fraction`](LogScale::fraction) from the dark end.
    pub fn ticks(&self, max_labels: usize) -> Vec<(Real, Tick)> {
        colorbar_ticks(self.min, self.max, max_labels)
            .into_iter()
            .map(|t| (self.fraction(t.value), t))
            .collect()
    }
}

/// Fills `rgba` (4 bytes per value, `values` order) with the colours of `values` on `scale`.
/// Returns false (and writes nothing) if the lengths do not match.
pub fn fill_rgba(values: &[Real], scale: &LogScale, rgba: &mut [u8]) -> bool {
    if rgba.len() != 4 * values.len() {
        return false;
    }
    for (v, px) in values.iter().zip(rgba.chunks_exact_mut(4)) {
        let c = scale.color(*v);
        px.copy_from_slice(&[c[0], c[1], c[2], 255]);
    }
    true
}

/// Colours a map (`values`, m) into `rgba` (4 bytes per value) on the log scale spanning its
/// finite values and returns that scale; `None` (and all grey) when no value is bounded.
pub fn render_rgba(values: &[Real], rgba: &mut [u8]) -> Result<Option<LogScale>> {
    check_len(
        "rgba buffer (4 bytes per map value)",
        4 * values.len(),
        rgba.len(),
    )?;
    let scale = LogScale::spanning(values);
    match &scale {
        Some(s) => {
            fill_rgba(values, s, rgba);
        }
        None => {
            for px in rgba.chunks_exact_mut(4) {
                px.copy_from_slice(&[UNBOUNDED_RGB[0], UNBOUNDED_RGB[1], UNBOUNDED_RGB[2], 255]);
            }
        }
    }
    Ok(scale)
}

/// `n` RGBA pixels (`n` clamped to 2..=4096) of the colour bar gradient, dark (small error) first.
pub fn colorbar_rgba(n: usize) -> Vec<u8> {
    let n = n.clamp(2, 4096);
    (0..n)
        .flat_map(|i| {
            let c = viridis(i as Real / (n - 1) as Real);
            [c[0], c[1], c[2], 255]
        })
        .collect()
}

#[cfg(test)]
mod tests;
