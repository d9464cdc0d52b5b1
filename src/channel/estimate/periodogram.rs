//! The periodogram of the residual (one zero-padded FFT, C5 step 1) and what the greedy loop reads
//! from it: the noise level `σ̂²` (the median of the cells at the natural spacing), the cells masked
//! next to fitted paths, and a peak's sub-cell offset.

use crate::channel::band::median;
use crate::channel::Estimator;
use crate::error::{Error, Result};
use crate::math::{ln, round, Complex, Real};

#[cfg(doc)]
use crate::channel::fft::PaddedFft;

impl Estimator {
    /// `scratch` ← the zero-padded FFT of `P*·r` (slot `s`: `c(k/(LΔf))` up to a phase, `k`
    /// the slot's frequency index).
    pub(super) fn periodogram(&mut self) {
        if self.flat {
            self.fft.run(&self.resid, &mut self.scratch);
        } else {
            for ((t, r), p) in self
                .tmp
                .iter_mut()
                .zip(&self.resid)
                .zip(&self.band.response)
            {
                *t = p.conj() * r;
            }
            self.fft.run(&self.tmp, &mut self.scratch);
        }
    }

    /// The noise variance per bin of `h` as the estimator would estimate it before fitting a
    /// path: `median |c_k|²/(Σ|P|² ln 2)` of its periodogram (biased up where paths crowd the
    /// delay axis, as every first pass is).
    pub fn noise_of(&mut self, h: &[Complex]) -> Result<Real> {
        if h.len() != self.band.len() {
            return Err(Error::LengthMismatch {
                field: "response",
                expected: self.band.len(),
                found: h.len(),
            });
        }
        self.resid.clear();
        self.resid.extend_from_slice(h);
        self.periodogram();
        Ok(self.median_noise())
    }

    /// `masked[slot]` ← whether the slot's cell lies within the merge separation of a path or
    /// of an excluded delay.
    pub(super) fn mask_paths(&mut self, paths: &[(Real, Complex)], excluded: &[Real]) {
        for m in self.masked.iter_mut() {
            *m = false;
        }
        let l = self.fft.len();
        let cell = self.span / l as Real;
        let reach = (self.merge_sep() / cell) as i64 + 1;
        for tau in paths.iter().map(|p| p.0).chain(excluded.iter().copied()) {
            let k0 = round(tau / cell) as i64;
            for k in k0 - reach..=k0 + reach {
                let t = k as Real * cell;
                if (t - tau).abs() < self.merge_sep() {
                    let slot = self.fft.slot_of(k.rem_euclid(l as i64) as usize);
                    self.masked[slot as usize] = true;
                }
            }
        }
    }

    /// The sub-cell offset (s) of the peak in `slot` ([`PaddedFft::parabola`]).
    pub(super) fn parabola(&self, slot: u32) -> Real {
        self.fft.parabola(&self.scratch, slot) * self.span / self.fft.len() as Real
    }

    /// `median |c|² / (Σ|P|² ln 2)` over the window's cells at the natural spacing.
    pub(super) fn median_noise(&mut self) -> Real {
        self.powers.clear();
        self.powers.extend(
            self.median_slots
                .iter()
                .map(|&s| self.scratch[s as usize].norm_sqr()),
        );
        median(&mut self.powers) / (self.energy * ln(2.0))
    }
}
