//! A channel recording (the `.npz` format of docs/recording.md, read and written by the `npz`
//! edge): per snapshot `s` and link `p` the channel frequency response at `N` baseband
//! frequencies (C1) or a band-limited impulse response of `M` taps (C2), the snapshot times, the
//! links as (transmitter, receiver) indices into the scenario, and the optional system response,
//! pulse and noise variances. Amplitudes are √W at the receiver input (C3).

use alloc::vec::Vec;

use crate::math::{Complex, Real};

/// The system pulse of a CIR recording (C2): samples at `spacing_s`, the middle sample at
/// `t = 0`, normalised to `p(0) = 1` by the reader.
#[derive(Debug, Clone, PartialEq)]
pub struct Pulse {
    /// The samples `p(k·spacing_s − (K−1)/2·spacing_s)`, `k = 0 … K−1`.
    pub samples: Vec<Complex>,
    /// Their spacing, s.
    pub spacing_s: Real,
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
}
