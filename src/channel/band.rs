//! The frequency-domain view of a recording's link (C1, C2): the bins `f_n`, the system
//! response `P[n]`, and each snapshot's `H[n]` (a CIR mapped by a DFT, keeping the in-band bins).
//!
//! **The C2 → C1 map and its scaling.** A CIR `h[m] = Σ_i α_i p(t_m − τ_i) + v[m]`,
//! `t_m = t_0 + mΔt`, `m = 0 … M−1`, has the DFT `D[k] = Σ_m h[m] e^{−j2πkm/M}` at
//! `f_k = k/(MΔt)` (`k` signed, `|k| < M/2`). For `Δt ≤ 1/B` and `|f_k| < B/2` (no aliasing),
//! `Δt·D[k] ≈ e^{j2πf_k t_0} Σ_i α_i P_c(f_k) e^{−j2πf_k τ_i}` with `P_c` the pulse's continuous
//! spectrum. We return `H[n] = B·Δt·e^{−j2πf_n t_0}·D[k_n]` and `P[n] = B·P_c(f_n)`: both sides
//! of C1 carry the same factor `B`, so `α_i` keeps its unit (√W) and value. For the default ideal
//! pulse `p(t) = sinc(Bt)`, `P_c = 1/B` in band, hence `P[n] = 1`. A measured pulse (samples at
//! spacing `Δp`, middle sample at `t = 0`) gives `P_c(f) = Δp Σ_k p_k e^{−j2πf t_k}`. The bins with
//! `|f_k| > B/2` hold noise only (the pulse has no energy there): the median of their `|H|²`
//! over `ln 2` (the median of an exponential) estimates the in-band noise variance `σ²` of C1,
//! which for white tap noise `σ_v²` is `(BΔt)²·M·σ_v²` ([`ResponseMap::noise_var_of_taps`]).
//! The DFT is our radix-2 FFT when `M` is a power of two, else a direct DFT of the in-band and
//! out-of-band bins (`O(M²)`, phasor recursion).

// `!(x > 0.0)` is meant: a NaN must fail these checks as well.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use alloc::vec;
use alloc::vec::Vec;

use crate::channel::fft::Fft;
use crate::channel::{Layout, Recording};
use crate::error::{Error, Result};
use crate::math::{ln, sincos, Complex, Real, PI};

/// Relative tolerance of "uniformly spaced" for `f_n` (a float64 grid written by numpy as
/// `f0 + n·Δf` is uniform to ~1e-12 relative).
const UNIFORM_TOL: Real = 1e-6;

/// The band an estimator works on: `f_n` (uniform, Hz) and `P[n]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// Baseband frequencies `f_n`, Hz, uniformly spaced, increasing.
    pub freq_hz: Vec<Real>,
    /// The system response `P[n]` (all ones for a calibrated sounder).
    pub response: Vec<Complex>,
    /// Where the delays this band observes start, s: `H[n]` is periodic in delay with period
    /// `1/Δf`, and a recording sees one period, `[origin, origin + 1/Δf)` — tap 0 of a CIR
    /// (`tap0_s`), 0 for a CFR ([`Band::new`]). The estimator's default search window.
    pub delay_origin_s: Real,
}

impl Band {
    /// A validated band: at least 2 bins, `f_n` finite, strictly increasing and uniform (to
    /// 1e-6 of `Δf`), `P[n]` finite with the same length and not all zero.
    pub fn new(freq_hz: Vec<Real>, response: Vec<Complex>) -> Result<Band> {
        let n = freq_hz.len();
        if n < 2 {
            return Err(Error::SizeLimit {
                field: "freq_hz",
                value: n,
                min: 2,
                max: crate::error::limits::MAX_PERIODOGRAM / 4,
            });
        }
        if n > crate::error::limits::MAX_PERIODOGRAM / 4 {
            return Err(Error::SizeLimit {
                field: "freq_hz",
                value: n,
                min: 2,
                max: crate::error::limits::MAX_PERIODOGRAM / 4,
            });
        }
        if response.len() != n {
            return Err(Error::LengthMismatch {
                field: "system_response",
                expected: n,
                found: response.len(),
            });
        }
        for (i, f) in freq_hz.iter().enumerate() {
            if !f.is_finite() {
                return Err(Error::NonFinite {
                    field: alloc::format!("freq_hz[{i}]"),
                });
            }
        }
        let df = (freq_hz[n - 1] - freq_hz[0]) / (n - 1) as Real;
        if !(df > 0.0) {
            return Err(Error::InvalidFile {
                field: "freq_hz".into(),
                reason: "must be strictly increasing".into(),
            });
        }
        for (i, f) in freq_hz.iter().enumerate() {
            let want = freq_hz[0] + df * i as Real;
            if (f - want).abs() > UNIFORM_TOL * df {
                return Err(Error::InvalidFile {
                    field: alloc::format!("freq_hz[{i}]"),
                    reason: alloc::format!(
                        "not uniformly spaced: {f} Hz, expected {want} Hz (spacing {df} Hz)"
                    ),
                });
            }
        }
        for (i, p) in response.iter().enumerate() {
            if !(p.re.is_finite() && p.im.is_finite()) {
                return Err(Error::NonFinite {
                    field: alloc::format!("system_response[{i}]"),
                });
            }
        }
        let band = Band {
            freq_hz,
            response,
            delay_origin_s: 0.0,
        };
        if !(band.response_energy() > 0.0) {
            return Err(Error::InvalidFile {
                field: "system_response".into(),
                reason: "all zero".into(),
            });
        }
        Ok(band)
    }

    /// A flat band (`P = 1`) of `n` bins spaced `spacing_hz`, centred on the carrier.
    pub fn flat(n: usize, spacing_hz: Real) -> Result<Band> {
        if !(spacing_hz > 0.0 && spacing_hz.is_finite()) {
            return Err(Error::NotPositive {
                field: "spacing_hz".into(),
                value: spacing_hz,
            });
        }
        let mid = (n as Real - 1.0) / 2.0;
        let f = (0..n).map(|i| (i as Real - mid) * spacing_hz).collect();
        Band::new(f, vec![Complex::new(1.0, 0.0); n])
    }

    /// Number of bins `N`.
    pub fn len(&self) -> usize {
        self.freq_hz.len()
    }

    /// Whether the band has no bins (never, for a validated band).
    pub fn is_empty(&self) -> bool {
        self.freq_hz.is_empty()
    }

    /// The bin spacing `Δf`, Hz.
    pub fn spacing_hz(&self) -> Real {
        let n = self.len();
        (self.freq_hz[n - 1] - self.freq_hz[0]) / (n - 1) as Real
    }

    /// The unambiguous delay span `1/Δf`, s (C1: delays are ambiguous modulo it).
    pub fn unambiguous_s(&self) -> Real {
        1.0 / self.spacing_hz()
    }

    /// `Σ_n |P[n]|²`.
    pub fn response_energy(&self) -> Real {
        self.response.iter().map(|p| p.norm_sqr()).sum()
    }

    /// The `|P|²`-weighted mean frequency `f̄`, Hz (C4).
    pub fn mean_freq_hz(&self) -> Real {
        let e = self.response_energy();
        self.response
            .iter()
            .zip(&self.freq_hz)
            .map(|(p, f)| p.norm_sqr() * f)
            .sum::<Real>()
            / e
    }

    /// `β_N² = Σ|P|²(f_n − f̄)² / Σ|P|²`, Hz² (C4); uniform band: `Δf²(N²−1)/12`.
    pub fn beta_sq(&self) -> Real {
        let e = self.response_energy();
        let fm = self.mean_freq_hz();
        self.response
            .iter()
            .zip(&self.freq_hz)
            .map(|(p, f)| p.norm_sqr() * (f - fm) * (f - fm))
            .sum::<Real>()
            / e
    }

    /// The single-path delay bound of C4, s: `1/√(8π²β_N²·SNR)` at integrated SNR `snr`
    /// (linear, C3); infinite for `snr ≤ 0`.
    pub fn delay_bound_s(&self, snr: Real) -> Real {
        if !(snr > 0.0) {
            return Real::INFINITY;
        }
        1.0 / crate::math::sqrt(8.0 * PI * PI * self.beta_sq() * snr)
    }

    /// The frequency-domain view of `rec` (C1/C2): its band and the map from its samples to
    /// `H[n]`. `bandwidth_hz` is the scenario's `B`: with [`Layout::Cir`] it selects the
    /// in-band bins `|f| < B/2` and the default sinc pulse; with [`Layout::Cfr`] it is unused
    /// (the bins are as recorded, `P` = `system_response` or 1).
    pub fn of_recording(rec: &Recording, bandwidth_hz: Real) -> Result<(Band, ResponseMap)> {
        let l = rec.samples_per_link();
        let expected = rec.t_s.len() * rec.links.len() * l;
        if rec.samples.len() != expected || l == 0 {
            return Err(Error::LengthMismatch {
                field: "samples",
                expected: expected.max(1),
                found: rec.samples.len(),
            });
        }
        match &rec.layout {
            Layout::Cfr {
                freq_hz,
                system_response,
            } => {
                let p = system_response
                    .clone()
                    .unwrap_or_else(|| vec![Complex::new(1.0, 0.0); freq_hz.len()]);
                if freq_hz.len() != l {
                    return Err(Error::LengthMismatch {
                        field: "freq_hz",
                        expected: l,
                        found: freq_hz.len(),
                    });
                }
                let band = Band::new(freq_hz.clone(), p)?;
                Ok((band, ResponseMap { cir: None, len: l }))
            }
            Layout::Cir {
                tap0_s,
                tap_spacing_s,
                pulse,
            } => {
                let (b, dt, t0) = (bandwidth_hz, *tap_spacing_s, *tap0_s);
                if !(b > 0.0 && b.is_finite()) {
                    return Err(Error::NotPositive {
                        field: "bandwidth_hz".into(),
                        value: b,
                    });
                }
                if !(dt > 0.0 && dt.is_finite()) {
                    return Err(Error::NotPositive {
                        field: "tap_spacing_s".into(),
                        value: dt,
                    });
                }
                if !t0.is_finite() {
                    return Err(Error::NonFinite {
                        field: "tap0_s".into(),
                    });
                }
                if dt * b > 1.0 + 1e-9 {
                    return Err(Error::OutOfRange {
                        field: "tap_spacing_s".into(),
                        value: dt,
                        allowed: "at most 1/B of the scenario's bandwidth (C2: no aliasing)",
                    });
                }
                let m = l;
                let fk = |k: i64| k as Real / (m as Real * dt);
                let half = (m as i64 - 1) / 2;
                let edge = b / 2.0 * (1.0 - 1e-9);
                let mut bins = Vec::new();
                let mut oob = Vec::new();
                for k in -half..=(m as i64 / 2) {
                    let f = fk(k);
                    let idx = k.rem_euclid(m as i64) as usize;
                    if f.abs() < edge {
                        bins.push((idx, f));
                    } else if f.abs() > b / 2.0 * (1.0 + 1e-9) && 2 * k.unsigned_abs() < m as u64 {
                        oob.push(idx);
                    }
                }
                if bins.len() < 2 {
                    return Err(Error::InvalidFile {
                        field: "cir".into(),
                        reason: "fewer than 2 frequency bins inside the band (too few taps)".into(),
                    });
                }
                let freq: Vec<Real> = bins.iter().map(|b| b.1).collect();
                let resp: Vec<Complex> = match pulse {
                    None => vec![Complex::new(1.0, 0.0); freq.len()],
                    Some(p) => {
                        if !(p.spacing_s > 0.0 && p.spacing_s.is_finite()) || p.samples.is_empty() {
                            return Err(Error::NotPositive {
                                field: "pulse_spacing_s".into(),
                                value: p.spacing_s,
                            });
                        }
                        let kk = p.samples.len();
                        let mid = (kk as Real - 1.0) / 2.0;
                        freq.iter()
                            .map(|&f| {
                                let mut acc = Complex::new(0.0, 0.0);
                                for (i, s) in p.samples.iter().enumerate() {
                                    let t = (i as Real - mid) * p.spacing_s;
                                    acc += s * cis(-2.0 * PI * f * t);
                                }
                                acc * (b * p.spacing_s)
                            })
                            .collect()
                    }
                };
                let scale: Vec<Complex> = freq
                    .iter()
                    .map(|&f| cis(-2.0 * PI * f * t0) * (b * dt))
                    .collect();
                // The taps see `[t0, t0 + MΔt)`: delays are searched there (issue 37 item 3:
                // searched in `[0, MΔt)` they came out one window early).
                let band = Band {
                    delay_origin_s: t0,
                    ..Band::new(freq, resp)?
                };
                let fft = if m.is_power_of_two() {
                    Some(Fft::new(m))
                } else {
                    None
                };
                Ok((
                    band,
                    ResponseMap {
                        len: l,
                        cir: Some(CirMap {
                            taps: m,
                            bins: bins.iter().map(|b| b.0).collect(),
                            oob,
                            scale,
                            b_dt: b * dt,
                            fft,
                        }),
                    },
                ))
            }
        }
    }
}

/// `e^{jx}`.
pub(crate) fn cis(x: Real) -> Complex {
    let (s, c) = sincos(x);
    Complex::new(c, s)
}

/// The map from a recording's samples of one link and snapshot to `H[n]` of its [`Band`]
/// (made by [`Band::of_recording`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseMap {
    len: usize,
    cir: Option<CirMap>,
}

#[derive(Debug, Clone, PartialEq)]
struct CirMap {
    taps: usize,
    /// DFT index of each in-band bin, ascending in frequency.
    bins: Vec<usize>,
    /// DFT indices of the out-of-band bins.
    oob: Vec<usize>,
    /// `B·Δt·e^{−j2πf_n t_0}` per in-band bin.
    scale: Vec<Complex>,
    b_dt: Real,
    fft: Option<Fft>,
}

impl ResponseMap {
    /// Fills `h` with `H[n]` of snapshot `s`, link `p` of `rec` (the recording this map was
    /// made from). Returns the out-of-band noise-variance estimate of `H`'s bins (CIR layout
    /// with at least 8 out-of-band bins: their median `|H|²`/ln 2), else `None`.
    pub fn fill(
        &self,
        rec: &Recording,
        s: usize,
        p: usize,
        h: &mut Vec<Complex>,
    ) -> Result<Option<Real>> {
        if s >= rec.snapshot_count() {
            return Err(Error::IndexOutOfRange {
                field: "snapshot",
                index: s,
                len: rec.snapshot_count(),
            });
        }
        if p >= rec.link_count() {
            return Err(Error::IndexOutOfRange {
                field: "link",
                index: p,
                len: rec.link_count(),
            });
        }
        if rec.samples_per_link() != self.len {
            return Err(Error::LengthMismatch {
                field: "samples",
                expected: self.len,
                found: rec.samples_per_link(),
            });
        }
        let x = rec.response(s, p);
        h.clear();
        let Some(c) = &self.cir else {
            h.extend_from_slice(x);
            return Ok(None);
        };
        let m = c.taps;
        let dft: Vec<Complex> = match &c.fft {
            Some(fft) => {
                let mut y = x.to_vec();
                fft.run(&mut y, false);
                y
            }
            None => {
                let mut y = vec![Complex::new(0.0, 0.0); m];
                for &k in c.bins.iter().chain(&c.oob) {
                    let w = cis(-2.0 * PI * k as Real / m as Real);
                    let mut ph = Complex::new(1.0, 0.0);
                    let mut acc = Complex::new(0.0, 0.0);
                    for v in x {
                        acc += v * ph;
                        ph *= w;
                    }
                    y[k] = acc;
                }
                y
            }
        };
        h.extend(c.bins.iter().zip(&c.scale).map(|(&k, sc)| dft[k] * sc));
        if c.oob.len() < 8 {
            return Ok(None);
        }
        let mut pw: Vec<Real> = c
            .oob
            .iter()
            .map(|&k| dft[k].norm_sqr() * c.b_dt * c.b_dt)
            .collect();
        Ok(Some(median(&mut pw) / ln(2.0)))
    }

    /// The noise variance of `H[n]` for white tap (CIR) or bin (CFR) noise of variance
    /// `per_sample` (the recording's `noise_var`): `(BΔt)²·M·σ_v²` for a CIR, unchanged for a CFR.
    pub fn noise_var_of_taps(&self, per_sample: Real) -> Real {
        match &self.cir {
            None => per_sample,
            Some(c) => c.b_dt * c.b_dt * c.taps as Real * per_sample,
        }
    }
}

/// The median of `v` (reordered; mean of the middle two for even lengths; 0 for empty).
pub(crate) fn median(v: &mut [Real]) -> Real {
    let n = v.len();
    if n == 0 {
        return 0.0;
    }
    // Selection, not a sort: O(n) (the estimator takes a median per greedy pass).
    let (lo, mid, _) = v.select_nth_unstable_by(n / 2, |a, b| a.total_cmp(b));
    let mid = *mid;
    if n % 2 == 1 {
        mid
    } else {
        let below = lo.iter().copied().fold(Real::NEG_INFINITY, Real::max);
        0.5 * (below + mid)
    }
}

#[cfg(test)]
mod tests;
