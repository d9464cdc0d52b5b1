//! The signal of one link's response: a path's phasors across the bins (re-anchored recursion), the
//! receiver clock's offsets, gain and phase noise (C10), and circular complex Gaussian draws.

use super::{Clock, ClockState};
use crate::math::{cos, db_to_linear, sin, sqrt, Complex, Real, PI};
use crate::measure::{standard_normal, Rng};

/// Bins between fresh `cos`/`sin` evaluations of a path's phasor (the recursion in between
/// rotates by `e^{−j2πΔfτ}`; re-anchoring bounds the accumulated rounding).
const REANCHOR_BINS: usize = 32;

/// `e^{−j2πx}`, with `x` reduced to its fractional part first (carrier phases are thousands of
/// cycles).
pub(super) fn cis_neg(x: Real) -> Complex {
    let f = x - (x as i64) as Real;
    let a = 2.0 * PI * f;
    Complex::new(cos(a), -sin(a))
}

/// Adds `α e^{−j2π f_n τ}` for `f_n = f0 + n·df` to `h` by phasor recursion, re-anchored every
/// [`REANCHOR_BINS`] bins.
pub(super) fn add_path(h: &mut [Complex], alpha: Complex, tau: Real, f0: Real, df: Real) {
    let step = cis_neg(df * tau);
    let mut z = Complex::new(0.0, 0.0);
    for (n, hn) in h.iter_mut().enumerate() {
        if n % REANCHOR_BINS == 0 {
            z = alpha * cis_neg((f0 + n as Real * df) * tau);
        }
        *hn += z;
        z *= step;
    }
}

/// The receiver clock `c` on snapshot `s` of one link's response `h` (bins `f0 + n·df`): draws
/// `δ` and `φ`, steps the AGC gain every `agc_every` snapshots, draws the phase noise, and
/// applies `g·e^{jφ}·e^{−j2πf_nδ}·e^{jε_n}`. Returns what it applied.
pub(super) fn apply_clock(
    c: &Clock,
    s: usize,
    gain_db: &mut Real,
    r: &mut Rng,
    h: &mut [Complex],
    f0: Real,
    df: Real,
) -> ClockState {
    let uniform = |r: &mut Rng| crate::measure::uniform01(r);
    let delay = if c.timing_offset_s > 0.0 {
        c.timing_offset_s * (2.0 * uniform(r) - 1.0)
    } else {
        0.0
    };
    let phase = if c.carrier_phase {
        2.0 * PI * uniform(r)
    } else {
        0.0
    };
    if c.agc_step_db > 0.0 && s > 0 && s.is_multiple_of(c.agc_every) {
        *gain_db += c.agc_step_db * (2.0 * uniform(r) - 1.0);
    }
    let g = sqrt(db_to_linear(*gain_db));
    for (n, v) in h.iter_mut().enumerate() {
        let f = f0 + n as Real * df;
        let mut rot = phase - 2.0 * PI * f * delay;
        if c.phase_noise_rad > 0.0 {
            rot += c.phase_noise_rad * standard_normal(r);
        }
        *v *= Complex::new(cos(rot), sin(rot)) * g;
    }
    ClockState {
        delay_s: delay,
        phase_rad: phase,
        gain_db: *gain_db,
    }
}

/// A unit-mean-power circular complex Gaussian draw.
pub(super) fn complex_normal(r: &mut Rng) -> Complex {
    let s = core::f64::consts::FRAC_1_SQRT_2;
    let re = standard_normal(r);
    let im = standard_normal(r);
    Complex::new(re * s, im * s)
}
