//! The direct path of every snapshot of a recording, with the timing offset removed (C10, issue
//! 40): what a user of a Wi-Fi card wants to know first about a capture — does the front end
//! see the direct path in every frame, and how stable is its delay once each frame's timing
//! offset (packet detection delay, sampling-frequency offset) is taken out?
//!
//! Per recorded link: the C5 estimator on each snapshot's full response (nothing subtracted),
//! the direct path chosen as the front end chooses it (the earliest path within
//! [`super::LOS_WITHIN_DB`] of the strongest); each snapshot's timing offset `δ̂` is its C9
//! alignment (coarse search over the whole span, then Newton) to the link's first snapshot, so
//! the direct path's delay in the first snapshot's time base is `τ̂₀ − δ̂`, taken within half the
//! unambiguous span of the median; it is *stable* within a quarter of the resolution cell
//! (`1/(4B')`, `B'` the span of the subcarriers present) of the median. A snapshot whose estimator finds no path above the CFAR
//! threshold has no direct path. Bounded: one C5 fit (its own bounds) and one alignment (its
//! Newton bound) per snapshot and link.

use alloc::vec::Vec;

use super::front::los_of;
use crate::channel::{AlignMode, Band, Estimator, EstimatorConfig, LinkBackground, Recording};
use crate::error::{Cancel, Result};
use crate::math::{floor, sqrt, Real};

/// The direct path of one recorded link over the snapshots.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LinkDirectPath {
    /// The link `(transmitter, receiver)`.
    pub link: [usize; 2],
    /// Snapshots.
    pub snapshots: usize,
    /// Snapshots whose direct path was found.
    pub found: usize,
    /// `found / snapshots`.
    pub found_fraction: Real,
    /// Per snapshot `τ̂₀ − δ̂`, s (`None`: not found).
    #[serde(skip)]
    pub delay_s: Vec<Option<Real>>,
    /// The median of the found delays, s.
    pub median_s: Real,
    /// Their standard deviation, s.
    pub std_s: Real,
    /// `1.4826 × MAD` (a robust σ), s.
    pub robust_std_s: Real,
    /// The half-width of the central 90 % (`(p95 − p5)/2`), s.
    pub half_range_90_s: Real,
    /// The stability window: a quarter of the resolution `1/B'`, `B'` the span of the bins with
    /// `P[n] ≠ 0`, s.
    pub window_s: Real,
    /// Snapshots whose direct path was found within `window_s` of the median, over all
    /// snapshots.
    pub stable_fraction: Real,
}

/// The direct path of every link of `rec` (bins of `bandwidth_hz` as [`Band::of_recording`]).
/// Errors: the recording's band, the estimator's (non-finite responses), [`Cancel`] between
/// links.
pub fn direct_paths(
    rec: &Recording,
    bandwidth_hz: Real,
    cancel: Cancel,
) -> Result<Vec<LinkDirectPath>> {
    let (band, map) = Band::of_recording(rec, bandwidth_hz)?;
    let span = band.unambiguous_s();
    let present: Vec<Real> = band
        .freq_hz
        .iter()
        .zip(&band.response)
        .filter(|(_, p)| p.norm_sqr() > 0.0)
        .map(|(f, _)| *f)
        .collect();
    let width = match (present.first(), present.last()) {
        (Some(a), Some(b)) if b > a => b - a,
        _ => band.spacing_hz() * band.len() as Real,
    };
    let window = 0.25 / width;
    let mut est = Estimator::new(band.clone(), EstimatorConfig::default())?;
    let mut h = Vec::new();
    let mut out = Vec::with_capacity(rec.link_count());
    for p in 0..rec.link_count() {
        cancel.check()?;
        map.fill(rec, 0, p, &mut h)?;
        let mut bg = LinkBackground::new(&band, &h, 0.0, AlignMode::Coarse)?;
        let mut delay_s = Vec::with_capacity(rec.snapshot_count());
        for s in 0..rec.snapshot_count() {
            let nv = map.fill(rec, s, p, &mut h)?;
            let fit = est.estimate(&h, nv, &[])?;
            let Some(los) = los_of(&fit.paths, span) else {
                delay_s.push(None);
                continue;
            };
            let a = bg.align(&h)?;
            delay_s.push(Some(los.delay_s - a.delay_s));
        }
        out.push(summarise(rec.links[p], delay_s, span, window));
    }
    Ok(out)
}

/// The statistics of the found delays, each taken within half a span of the first found one's
/// cyclic median.
fn summarise(
    link: [usize; 2],
    mut delay_s: Vec<Option<Real>>,
    span: Real,
    window: Real,
) -> LinkDirectPath {
    let snapshots = delay_s.len();
    let wrap = |d: Real, c: Real| d - span * floor((d - c) / span + 0.5);
    // A reference inside the cluster: the median after wrapping around the first found delay.
    let first = delay_s.iter().flatten().next().copied();
    let mut v: Vec<Real> = match first {
        Some(c) => delay_s.iter().flatten().map(|&d| wrap(d, c)).collect(),
        None => Vec::new(),
    };
    let found = v.len();
    let median = |v: &mut Vec<Real>| -> Real {
        if v.is_empty() {
            return 0.0;
        }
        v.sort_by(Real::total_cmp);
        let n = v.len();
        if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    };
    let m0 = median(&mut v);
    for d in delay_s.iter_mut().flatten() {
        *d = wrap(*d, m0);
    }
    let mut v: Vec<Real> = delay_s.iter().flatten().copied().collect();
    let m = median(&mut v);
    let n = v.len().max(1) as Real;
    let mean = v.iter().sum::<Real>() / n;
    let std = sqrt(v.iter().map(|d| (d - mean) * (d - mean)).sum::<Real>() / n);
    let mut dev: Vec<Real> = v.iter().map(|d| (d - m).abs()).collect();
    let mad = median(&mut dev);
    let q = |f: Real| -> Real {
        if v.is_empty() {
            return 0.0;
        }
        let i = (f * (v.len() - 1) as Real + 0.5) as usize;
        v[i.min(v.len() - 1)]
    };
    let stable = v.iter().filter(|d| (*d - m).abs() <= window).count();
    LinkDirectPath {
        window_s: window,
        stable_fraction: stable as Real / snapshots.max(1) as Real,
        link,
        snapshots,
        found,
        found_fraction: found as Real / snapshots.max(1) as Real,
        delay_s,
        median_s: m,
        std_s: std,
        robust_std_s: 1.4826 * mad,
        half_range_90_s: 0.5 * (q(0.95) - q(0.05)),
    }
}
