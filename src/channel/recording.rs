//! A channel recording (the `.npz` format of docs/recording.md, read and written by the `npz`
//! edge): per snapshot `s` and link `p` the channel frequency response at `N` baseband
//! frequencies (C1) or a band-limited impulse response of `M` taps (C2), the snapshot times, the
//! links as (transmitter, receiver) indices into the scenario, and the optional system response,
//! pulse and noise variances. Amplitudes are √W at the receiver input (C3).

use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use crate::error::limits::{
    FREQ_UNIFORM_TOL, MAX_BINS_PER_LINK, MAX_LINKS, MAX_PULSE_SAMPLES, MAX_RECORDING_SAMPLES,
    MAX_SNAPSHOTS, PULSE_NORM_TOL,
};
use crate::error::{Error, Result};
use crate::math::{sqrt, Complex, Real};
use crate::measure::Model;

#[cfg(test)]
mod tests;

fn invalid(field: &str, reason: String) -> Error {
    Error::InvalidFile {
        field: field.into(),
        reason,
    }
}

fn size(field: &'static str, value: usize, min: usize, max: usize) -> Result<()> {
    if value < min || value > max {
        return Err(Error::SizeLimit {
            field,
            value,
            min,
            max,
        });
    }
    Ok(())
}

fn finite_c(z: &Complex) -> bool {
    z.re.is_finite() && z.im.is_finite()
}

/// `|z|` with the crate's portable square root.
fn abs_c(z: &Complex) -> Real {
    sqrt(z.re * z.re + z.im * z.im)
}

/// The system pulse of a CIR recording (C2): samples at `spacing_s`, the middle sample at
/// `t = 0`, normalised to `p(0) = 1` by the reader.
#[derive(Debug, Clone, PartialEq)]
pub struct Pulse {
    /// The samples `p(k·spacing_s − (K−1)/2·spacing_s)`, `k = 0 … K−1`.
    pub samples: Vec<Complex>,
    /// Their spacing, s.
    pub spacing_s: Real,
}

impl Pulse {
    /// Divides every sample by the middle one, so `p(0) = 1`; [`Error::InvalidFile`] naming
    /// `pulse` when K is even (no middle sample) or `p(0) = 0` or not finite.
    pub fn normalise(&mut self) -> Result<()> {
        let k = self.samples.len();
        if k.is_multiple_of(2) {
            return Err(invalid(
                "pulse",
                format!("{k} samples: an odd count is required (the middle one is t = 0)"),
            ));
        }
        let p0 = self.samples[k / 2];
        if !finite_c(&p0) || (p0.re == 0.0 && p0.im == 0.0) {
            return Err(invalid(
                "pulse",
                "the middle sample p(0) is 0 or not finite: cannot normalise to p(0) = 1".into(),
            ));
        }
        for z in &mut self.samples {
            *z /= p0;
        }
        Ok(())
    }
}

/// Which of the two layouts (C1 or C2) a recording holds.
#[derive(Debug, Clone, PartialEq)]
pub enum Layout {
    /// `cfr`: `H_p[n]` at `freq_hz` (uniformly spaced), optionally with `P[n]`.
    Cfr {
        /// Baseband frequencies `f_n` (offsets from the carrier), Hz, uniformly spaced.
        freq_hz: Vec<Real>,
        /// `P[n]` of C1 (`None`: 1).
        system_response: Option<Vec<Complex>>,
    },
    /// `cir`: `h_p[m]` at `t_m = tap0_s + m·tap_spacing_s`.
    Cir {
        /// Delay of tap 0, s.
        tap0_s: Real,
        /// Tap spacing `Δt`, s.
        tap_spacing_s: Real,
        /// The system pulse (`None`: the ideal sinc of the scenario's bandwidth).
        pulse: Option<Pulse>,
    },
}

impl Layout {
    /// The name of the samples' array: `cfr` or `cir`.
    pub fn array(&self) -> &'static str {
        match self {
            Layout::Cfr { .. } => "cfr",
            Layout::Cir { .. } => "cir",
        }
    }
}

/// A channel recording: `samples[(s·P + p)·L + i]` is sample `i` (frequency bin or tap) of link
/// `p` in snapshot `s`, `L` = [`Recording::samples_per_link`].
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Snapshot times, s, strictly increasing.
    pub t_s: Vec<Real>,
    /// Per recorded link `(transmitter index, receiver index)`, 0-based into the scenario.
    pub links: Vec<[usize; 2]>,
    /// The layout and its axis.
    pub layout: Layout,
    /// The samples, snapshot-major, then link, then bin or tap, √W.
    pub samples: Vec<Complex>,
    /// Per recorded link the per-sample noise variance `σ_p²`, W (`None`: estimated from the
    /// data).
    pub noise_var: Option<Vec<Real>>,
    /// Whether the receivers share the transmitter's clock (`true`: absolute delays; `false`:
    /// free-running, delays relative to each link's direct path, C10; `None`: not stated,
    /// absolute unless the user says otherwise).
    pub synchronized: Option<bool>,
}

impl Recording {
    /// Number of snapshots `S`.
    pub fn snapshot_count(&self) -> usize {
        self.t_s.len()
    }

    /// Number of recorded links `P`.
    pub fn link_count(&self) -> usize {
        self.links.len()
    }

    /// Samples per link and snapshot: `N` (CFR) or `M` (CIR).
    pub fn samples_per_link(&self) -> usize {
        self.samples
            .len()
            .checked_div(self.t_s.len() * self.links.len())
            .unwrap_or(0)
    }

    /// The samples of link `p` in snapshot `s`.
    pub fn response(&self, s: usize, p: usize) -> &[Complex] {
        let l = self.samples_per_link();
        let start = (s * self.links.len() + p) * l;
        &self.samples[start..start + l]
    }

    /// The snapshots with `t0_s ≤ t ≤ t1_s` as a recording of their own (e.g. a stretch of a
    /// recording marked as the empty area, used as the calibration recording). Errors:
    /// non-finite or reversed bounds ([`Error::OutOfRange`] of `field`), no snapshot in the
    /// range ([`Error::InvalidFile`] of `field`).
    pub fn between(&self, field: &str, t0_s: Real, t1_s: Real) -> Result<Recording> {
        for v in [t0_s, t1_s] {
            if !v.is_finite() {
                return Err(Error::OutOfRange {
                    field: field.into(),
                    value: v,
                    allowed: "finite times, s",
                });
            }
        }
        if t1_s < t0_s {
            return Err(Error::OutOfRange {
                field: field.into(),
                value: t1_s,
                allowed: "t1 >= t0",
            });
        }
        let keep: Vec<usize> = (0..self.t_s.len())
            .filter(|&s| self.t_s[s] >= t0_s && self.t_s[s] <= t1_s)
            .collect();
        if keep.is_empty() {
            return Err(Error::InvalidFile {
                field: field.into(),
                reason: alloc::format!(
                    "no snapshot between {t0_s} s and {t1_s} s (the recording spans {} … {} s)",
                    self.t_s.first().copied().unwrap_or(0.0),
                    self.t_s.last().copied().unwrap_or(0.0)
                ),
            });
        }
        let per = self.links.len() * self.samples_per_link();
        let mut samples = Vec::with_capacity(keep.len() * per);
        for &s in &keep {
            samples.extend_from_slice(&self.samples[s * per..(s + 1) * per]);
        }
        Ok(Recording {
            t_s: keep.iter().map(|&s| self.t_s[s]).collect(),
            links: self.links.clone(),
            layout: self.layout.clone(),
            samples,
            noise_var: self.noise_var.clone(),
            synchronized: self.synchronized,
        })
    }

    /// Checks everything a recording promises (docs/recording.md), naming the array at fault:
    /// `t_s` non-empty, finite and strictly increasing; at least one link; the sample count
    /// `S·P·L` with `L ≥ 2` (bins or taps) and all samples finite (the first bad one named as
    /// `[s, p, i]`); `freq_hz` finite, increasing and uniform within
    /// [`FREQ_UNIFORM_TOL`]`·Δf`; `system_response` of length N and finite; `tap0_s` finite,
    /// `tap_spacing_s` finite > 0; `pulse` of odd length K, finite, spacing > 0 and
    /// `|p(0) − 1| ≤` [`PULSE_NORM_TOL`]; `noise_var` one per link, finite > 0; and the caps
    /// [`MAX_SNAPSHOTS`], [`MAX_LINKS`], [`MAX_BINS_PER_LINK`], [`MAX_RECORDING_SAMPLES`],
    /// [`MAX_PULSE_SAMPLES`] ([`Error::SizeLimit`]).
    pub fn validate(&self) -> Result<()> {
        let s_count = self.t_s.len();
        let p_count = self.links.len();
        size("t_s", s_count, 1, MAX_SNAPSHOTS)?;
        size("links", p_count, 1, MAX_LINKS)?;
        for (s, &t) in self.t_s.iter().enumerate() {
            if !t.is_finite() {
                return Err(invalid("t_s", format!("t_s[{s}] is not a finite number")));
            }
            if s > 0 && t <= self.t_s[s - 1] {
                return Err(invalid(
                    "t_s",
                    format!(
                        "not strictly increasing: t_s[{s}] = {} after t_s[{}] = {}",
                        crate::error::Num(t),
                        s - 1,
                        crate::error::Num(self.t_s[s - 1])
                    ),
                ));
            }
        }
        let array = self.layout.array();
        let per_link = match &self.layout {
            Layout::Cfr {
                freq_hz,
                system_response,
            } => {
                check_freq(freq_hz)?;
                if let Some(p) = system_response {
                    if p.len() != freq_hz.len() {
                        return Err(invalid(
                            "system_response",
                            format!(
                                "{} values, expected one per freq_hz bin ({})",
                                p.len(),
                                freq_hz.len()
                            ),
                        ));
                    }
                    if let Some(n) = p.iter().position(|z| !finite_c(z)) {
                        return Err(invalid(
                            "system_response",
                            format!("system_response[{n}] is not finite"),
                        ));
                    }
                }
                freq_hz.len()
            }
            Layout::Cir {
                tap0_s,
                tap_spacing_s,
                pulse,
            } => {
                if !tap0_s.is_finite() {
                    return Err(Error::NonFinite {
                        field: "tap0_s".into(),
                    });
                }
                if !(tap_spacing_s.is_finite() && *tap_spacing_s > 0.0) {
                    return Err(Error::NotPositive {
                        field: "tap_spacing_s".into(),
                        value: *tap_spacing_s,
                    });
                }
                if let Some(p) = pulse {
                    check_pulse(p)?;
                }
                let rows = s_count * p_count;
                if !self.samples.len().is_multiple_of(rows) {
                    return Err(invalid(
                        "cir",
                        format!(
                            "{} samples is not a multiple of S·P = {s_count}·{p_count}",
                            self.samples.len()
                        ),
                    ));
                }
                self.samples.len() / rows
            }
        };
        size(
            if array == "cfr" { "freq_hz" } else { "cir" },
            per_link,
            2,
            MAX_BINS_PER_LINK,
        )?;
        let total = s_count
            .checked_mul(p_count)
            .and_then(|r| r.checked_mul(per_link))
            .unwrap_or(usize::MAX);
        size(
            if array == "cfr" { "cfr" } else { "cir" },
            total,
            1,
            MAX_RECORDING_SAMPLES,
        )?;
        if self.samples.len() != total {
            return Err(invalid(
                array,
                format!(
                    "{} samples, expected S·P·{} = {s_count}·{p_count}·{per_link} = {total}",
                    self.samples.len(),
                    if array == "cfr" { "N" } else { "M" }
                ),
            ));
        }
        if let Some(k) = self.samples.iter().position(|z| !finite_c(z)) {
            let (s, rest) = (k / (p_count * per_link), k % (p_count * per_link));
            let (p, i) = (rest / per_link, rest % per_link);
            return Err(invalid(
                array,
                format!("sample [{s}, {p}, {i}] is not finite"),
            ));
        }
        if let Some(nv) = &self.noise_var {
            if nv.len() != p_count {
                return Err(invalid(
                    "noise_var",
                    format!("{} values, expected one per link ({p_count})", nv.len()),
                ));
            }
            for (p, &v) in nv.iter().enumerate() {
                if !(v.is_finite() && v > 0.0) {
                    return Err(invalid(
                        "noise_var",
                        format!(
                            "noise_var[{p}] = {} must be a finite number > 0",
                            crate::error::Num(v)
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Per recorded link, its index in `model`'s link order: recorded link `(tx, rx)` is the
    /// model link `i` with `links[i].tx == tx` and `links[i].rx == rx`. A link the scenario
    /// does not have, or one recorded twice, is an [`Error::InvalidFile`] naming `links[p]`.
    pub fn link_map(&self, model: &Model) -> Result<Vec<usize>> {
        let links = &model.network.links;
        let mut seen = vec![usize::MAX; links.len()];
        let mut map = Vec::with_capacity(self.links.len());
        for (p, &[tx, rx]) in self.links.iter().enumerate() {
            let Some(i) = links.iter().position(|l| l.tx == tx && l.rx == rx) else {
                return Err(invalid(
                    &format!("links[{p}]"),
                    format!(
                        "the link (transmitter {tx}, receiver {rx}) is not one of the scenario's \
                         {} links",
                        links.len()
                    ),
                ));
            };
            if seen[i] != usize::MAX {
                return Err(invalid(
                    &format!("links[{p}]"),
                    format!(
                        "the link (transmitter {tx}, receiver {rx}) is recorded twice (also \
                         links[{}])",
                        seen[i]
                    ),
                ));
            }
            seen[i] = p;
            map.push(i);
        }
        Ok(map)
    }
}

fn check_freq(f: &[Real]) -> Result<()> {
    if let Some(n) = f.iter().position(|v| !v.is_finite()) {
        return Err(invalid("freq_hz", format!("freq_hz[{n}] is not finite")));
    }
    let n = f.len();
    if n < 2 {
        return Ok(()); // the count is checked against its cap by the caller
    }
    let df = (f[n - 1] - f[0]) / (n - 1) as Real;
    if !(df > 0.0 && df.is_finite()) {
        return Err(invalid(
            "freq_hz",
            "must be increasing (f[N-1] > f[0])".into(),
        ));
    }
    for k in 1..n {
        let step = f[k] - f[k - 1];
        let dev = step - df;
        if dev > FREQ_UNIFORM_TOL * df || -dev > FREQ_UNIFORM_TOL * df {
            return Err(invalid(
                "freq_hz",
                format!(
                    "not uniformly spaced: freq_hz[{k}] - freq_hz[{}] = {} Hz, the mean \
                     spacing is {} Hz (tolerance 1e-6 relative)",
                    k - 1,
                    crate::error::Num(step),
                    crate::error::Num(df)
                ),
            ));
        }
    }
    Ok(())
}

fn check_pulse(p: &Pulse) -> Result<()> {
    let k = p.samples.len();
    size("pulse", k, 1, MAX_PULSE_SAMPLES)?;
    if !(p.spacing_s.is_finite() && p.spacing_s > 0.0) {
        return Err(Error::NotPositive {
            field: "pulse_spacing_s".into(),
            value: p.spacing_s,
        });
    }
    if let Some(i) = p.samples.iter().position(|z| !finite_c(z)) {
        return Err(invalid("pulse", format!("pulse[{i}] is not finite")));
    }
    if k.is_multiple_of(2) {
        return Err(invalid(
            "pulse",
            format!("{k} samples: an odd count is required (the middle one is t = 0)"),
        ));
    }
    let p0 = p.samples[k / 2];
    if abs_c(&(p0 - Complex::new(1.0, 0.0))) > PULSE_NORM_TOL {
        return Err(invalid(
            "pulse",
            "not normalised: the middle sample p(0) must be 1".into(),
        ));
    }
    Ok(())
}
