//! The Doppler of one path over a coherent processing interval (issue 42 §2; docs/doppler.md
//! D2, D4, D5, D9): a path's complex amplitude `α_n`, fitted at its delay in each of the CPI's
//! snapshots, turns as `e^{j2π f_D t_n}` with `f_D = −ṙ/λ` (D2; the carrier phase
//! `e^{−j2π f_c τ(t)}` of the signal model C1 with `τ(t) = τ₀ + ṙt/c`). The maximum-likelihood
//! frequency of one complex sinusoid in white noise maximises the periodogram
//! `|Σ_n α_n e^{−j2πf(t_n − t̄)}|²` (D9): a grid of [`DOPPLER_OVERSAMPLING`]`·N` frequencies over
//! the unambiguous band `|f| < 1/(2T_min)`, then a golden-section search of at most
//! [`DOPPLER_REFINE_STEPS`] steps within one grid step of the best. Its σ is D4's bound at the
//! path's per-snapshot SNR with the snapshots' own times, and the range rate's σ adds the model
//! floor (D5).

use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::{sincos, sqrt, Complex, Real, PI};

/// Grid frequencies per snapshot of the coarse search.
pub const DOPPLER_OVERSAMPLING: usize = 8;
/// Most golden-section steps of the refinement (the bracket shrinks by 0.618 a step: 60 steps
/// take one grid step to 3·10⁻¹³ of it).
pub const DOPPLER_REFINE_STEPS: usize = 60;

/// A path's range rate from one CPI.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RateEstimate {
    /// `ṙ = −λ f̂_D`, m/s.
    pub range_rate_mps: Real,
    /// `√(λ²/F_ff + σ_floor²)`, m/s (D5 with the snapshots' times).
    pub sigma_mps: Real,
    /// `f̂_D`, Hz.
    pub doppler_hz: Real,
}

/// `|Σ_n α_n e^{−j2πf(t_n − t̄)}|²`.
fn periodogram(t: &[Real], alpha: &[Complex], f: Real) -> Real {
    let mut s = Complex::new(0.0, 0.0);
    for (tn, a) in t.iter().zip(alpha) {
        let (sin, cos) = sincos(-2.0 * PI * f * tn);
        s += a * Complex::new(cos, sin);
    }
    s.norm_sqr()
}

/// The ML frequency (Hz) of the samples `alpha` at times `t_s` (module docs); `None` with fewer
/// than two snapshots or all amplitudes zero. Errors name a length mismatch, a non-finite
/// input, or times not strictly increasing.
pub fn ml_frequency(t_s: &[Real], alpha: &[Complex]) -> Result<Option<Real>> {
    if t_s.len() != alpha.len() {
        return Err(Error::LengthMismatch {
            field: "cpi.amplitudes",
            expected: t_s.len(),
            found: alpha.len(),
        });
    }
    if t_s.iter().any(|t| !t.is_finite())
        || alpha
            .iter()
            .any(|a| !(a.re.is_finite() && a.im.is_finite()))
    {
        return Err(Error::NonFinite {
            field: "cpi".into(),
        });
    }
    let n = t_s.len();
    if n < 2 || alpha.iter().all(|a| a.norm_sqr() == 0.0) {
        return Ok(None);
    }
    let min_gap = t_s
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(Real::INFINITY, Real::min);
    if min_gap.is_nan() || min_gap <= 0.0 {
        return Err(Error::OutOfRange {
            field: "cpi.t_s".into(),
            value: min_gap,
            allowed: "strictly increasing snapshot times",
        });
    }
    let mean = t_s.iter().sum::<Real>() / n as Real;
    let t: Vec<Real> = t_s.iter().map(|v| v - mean).collect();
    let f_max = 0.5 / min_gap;
    let m = DOPPLER_OVERSAMPLING * n;
    let step = 2.0 * f_max / m as Real;
    let (mut best, mut best_p) = (0.0, Real::NEG_INFINITY);
    for k in 0..m {
        let f = -f_max + k as Real * step;
        let p = periodogram(&t, alpha, f);
        if p > best_p {
            (best, best_p) = (f, p);
        }
    }
    // Golden-section search for the maximum in [best − step, best + step].
    let g = 0.5 * (sqrt(5.0) - 1.0);
    let (mut a, mut b) = (best - step, best + step);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut pc, mut pd) = (periodogram(&t, alpha, c), periodogram(&t, alpha, d));
    for _ in 0..DOPPLER_REFINE_STEPS {
        if pc >= pd {
            b = d;
            d = c;
            pd = pc;
            c = b - g * (b - a);
            pc = periodogram(&t, alpha, c);
        } else {
            a = c;
            c = d;
            pc = pd;
            d = a + g * (b - a);
            pd = periodogram(&t, alpha, d);
        }
    }
    let f = 0.5 * (a + b);
    Ok(Some(if periodogram(&t, alpha, f) >= best_p {
        f
    } else {
        best
    }))
}

/// The range rate of a path whose amplitudes over a CPI are `alpha` at times `t_s`, with
/// per-snapshot SNR `snr` (linear, `|α|²/var(α̂)`), on a carrier of wavelength `wavelength_m`,
/// and the floor `floor_mps` on its σ (module docs). `None` without a frequency
/// ([`ml_frequency`]) or without information (an SNR that is not positive).
pub fn path_rate(
    t_s: &[Real],
    alpha: &[Complex],
    snr: Real,
    wavelength_m: Real,
    floor_mps: Real,
) -> Result<Option<RateEstimate>> {
    let Some(f) = ml_frequency(t_s, alpha)? else {
        return Ok(None);
    };
    let n = t_s.len() as Real;
    let mean = t_s.iter().sum::<Real>() / n;
    let spread: Real = t_s.iter().map(|t| (t - mean) * (t - mean)).sum();
    let info = 8.0 * PI * PI * snr * spread;
    if !(info.is_finite() && info > 0.0) {
        return Ok(None);
    }
    let sigma = sqrt(wavelength_m * wavelength_m / info + floor_mps * floor_mps);
    Ok(Some(RateEstimate {
        range_rate_mps: -wavelength_m * f,
        sigma_mps: sigma,
        doppler_hz: f,
    }))
}
