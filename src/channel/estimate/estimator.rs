//! The estimator of one band ([`Estimator`]): its checked window, the periodogram's plan and grid
//! cells, the CFAR threshold `γ = ln(G/P_fa)`, the band's weights and the scratch buffers every
//! snapshot reuses; and [`fold`], a delay folded into the window.

use alloc::vec;
use alloc::vec::Vec;

use super::config::MERGE_FRACTION;
use crate::channel::fft::PaddedFft;
use crate::channel::{Band, EstimatorConfig};
use crate::error::{limits, Error, Result};
use crate::math::{ln, round, Complex, Real, PI};

/// The estimator of one band (plans, scratch buffers).
#[derive(Debug, Clone)]
pub struct Estimator {
    pub(super) band: Band,
    pub(super) cfg: EstimatorConfig,
    pub(super) fft: PaddedFft,
    /// Whether `P[n] = 1` for every bin (the products with `P` are skipped).
    pub(super) flat: bool,
    /// `f_n − f_c` (centred for conditioning), Hz.
    pub(super) fc: Vec<Real>,
    /// `2π·(f_n − f_c)`, rad/s (the kernels' weights).
    pub(super) tw: Vec<Real>,
    /// `|P[n]|²`.
    pub(super) w: Vec<Real>,
    /// `S_a(0)`, `a` = 0, 1, 2 ([`Estimator::kernels`] at a zero delay difference: every
    /// diagonal entry of the Gauss–Newton and Fisher matrices), computed once by the same sums.
    pub(super) kernels_at_zero: (Complex, Complex, Complex),
    pub(super) energy: Real,
    pub(super) df: Real,
    pub(super) span: Real,
    pub(super) win_start: Real,
    pub(super) win_end: Real,
    /// Grid cells in the window: (FFT output slot, delay in the window), in slot order.
    pub(super) cells: Vec<(u32, Real)>,
    /// Slots of the window's cells at the natural spacing (the median's cells).
    pub(super) median_slots: Vec<u32>,
    pub(super) gamma: Real,
    /// Per slot: within the merge separation of a fitted path (not a new path's peak).
    pub(super) masked: Vec<bool>,
    pub(super) scratch: Vec<Complex>,
    pub(super) resid: Vec<Complex>,
    pub(super) tmp: Vec<Complex>,
    pub(super) powers: Vec<Real>,
}

impl Estimator {
    /// An estimator for `band` with `cfg` (validated: `p_fa` in (0, 1), `oversample` 4 … 64,
    /// `max_paths` 1 … [`limits::MAX_PATHS`], a finite window `start < end ≤ start + 1/Δf`).
    pub fn new(band: Band, cfg: EstimatorConfig) -> Result<Estimator> {
        cfg.validate()?;
        let n = band.len();
        let l = (cfg.oversample * n).next_power_of_two();
        if l > limits::MAX_PERIODOGRAM {
            return Err(Error::SizeLimit {
                field: "oversample",
                value: cfg.oversample,
                min: 4,
                max: (limits::MAX_PERIODOGRAM / n).max(4),
            });
        }
        let df = band.spacing_hz();
        let span = 1.0 / df;
        let (ws, we) = match cfg.window_s {
            None => (band.delay_origin_s, band.delay_origin_s + span),
            Some((a, b)) => {
                if !(a.is_finite() && b.is_finite()) {
                    return Err(Error::NonFinite {
                        field: "window_s".into(),
                    });
                }
                if !(b > a && b - a <= span * (1.0 + 1e-12)) {
                    return Err(Error::OutOfRange {
                        field: "window_s".into(),
                        value: b - a,
                        allowed: "end > start and end − start ≤ 1/Δf (the unambiguous span)",
                    });
                }
                (a, b)
            }
        };
        let fft = PaddedFft::new(n, l);
        let cell = span / l as Real;
        let mut cells = Vec::new();
        let mut median_slots = Vec::new();
        let stride = l / n.next_power_of_two().min(l);
        for (slot, &k) in fft.natural().iter().enumerate() {
            let k = k as usize;
            let t = fold(k as Real * cell, ws, span);
            if cfg.window_s.is_none() || t <= we {
                cells.push((slot as u32, t));
                if k.is_multiple_of(stride) {
                    median_slots.push(slot as u32);
                }
            }
        }
        if cells.is_empty() {
            return Err(Error::OutOfRange {
                field: "window_s".into(),
                value: we - ws,
                allowed: "wide enough to hold one periodogram cell",
            });
        }
        if median_slots.is_empty() {
            median_slots = cells.iter().map(|c| c.0).collect();
        }
        let gamma = ln(cells.len() as Real / cfg.p_fa);
        let fcen = 0.5 * (band.freq_hz[0] + band.freq_hz[n - 1]);
        let fc: Vec<Real> = band.freq_hz.iter().map(|f| f - fcen).collect();
        let tw = fc.iter().map(|f| 2.0 * PI * f).collect();
        let w = band.response.iter().map(|p| p.norm_sqr()).collect();
        let energy = band.response_energy();
        let flat = band.response.iter().all(|p| *p == Complex::new(1.0, 0.0));
        let mut est = Estimator {
            fft,
            flat,
            fc,
            tw,
            w,
            energy,
            df,
            span,
            win_start: ws,
            win_end: we,
            cells,
            powers: Vec::with_capacity(median_slots.len()),
            median_slots,
            gamma,
            masked: vec![false; l],
            scratch: vec![Complex::new(0.0, 0.0); l],
            resid: vec![Complex::new(0.0, 0.0); n],
            tmp: vec![Complex::new(0.0, 0.0); n],
            band,
            cfg,
            kernels_at_zero: Default::default(),
        };
        est.kernels_at_zero = (est.kernel(0.0, 0), est.kernel(0.0, 1), est.kernel(0.0, 2));
        Ok(est)
    }

    /// The band.
    pub fn band(&self) -> &Band {
        &self.band
    }

    /// The configuration.
    pub fn config(&self) -> &EstimatorConfig {
        &self.cfg
    }

    /// The CFAR threshold `γ = ln(G/P_fa)` on the normalised periodogram.
    pub fn threshold(&self) -> Real {
        self.gamma
    }

    /// `G`, the periodogram cells in the search window.
    pub fn grid_cells(&self) -> usize {
        self.cells.len()
    }

    pub(super) fn merge_sep(&self) -> Real {
        MERGE_FRACTION / (self.df * self.band.len() as Real)
    }
}

/// `τ` folded into `[start, start + span)` (`start` itself where rounding would leave it below).
pub(super) fn fold(tau: Real, start: Real, span: Real) -> Real {
    let q = (tau - start) / span;
    let mut fl = round(q);
    if fl > q {
        fl -= 1.0;
    }
    let t = tau - fl * span;
    let t = if t >= start + span { t - span } else { t };
    // Rounding can leave `t` one step below `start` (a path exactly at the window's start:
    // found by the `cir_windows` fuzz kind, issue 37).
    t.max(start)
}
