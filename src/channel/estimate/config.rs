//! The estimator's settings (C5 **[choice]**): [`EstimatorConfig`], its defaults and its checks,
//! and the merge separation [`MERGE_FRACTION`].

use crate::error::{limits, Error, Result};
use crate::math::Real;

#[cfg(doc)]
use crate::channel::{Band, Estimator};

/// Paths closer than this fraction of `1/B` are merged (their joint fit is ill-conditioned).
pub const MERGE_FRACTION: Real = 0.25;

/// Settings of the snapshot estimator (C5 **[choice]**).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimatorConfig {
    /// Largest number of paths per snapshot `M_max` (1 … [`limits::MAX_PATHS`]).
    pub max_paths: usize,
    /// Design false-alarm probability per snapshot `P_fa` of the CFAR stop, in (0, 1).
    pub p_fa: Real,
    /// Delay-grid oversampling of the periodogram (4 … 64).
    pub oversample: usize,
    /// Search window `[start, end]` of absolute delays, s (`None`: the band's whole
    /// unambiguous span `[o, o + 1/Δf)`, `o` its [`Band::delay_origin_s`]: tap 0 of a CIR, 0
    /// for a CFR); at most `1/Δf` wide.
    pub window_s: Option<(Real, Real)>,
    /// The noise variance is never taken below the response's mean bin power this far down,
    /// dB ([`limits::ESTIMATOR_DYNAMIC_RANGE_DB`]; default 120): the rounding floor of a
    /// noise-free recording (complex64 samples hold about 144 dB).
    pub dynamic_range_db: Real,
}

impl Default for EstimatorConfig {
    /// [S]'s settings: 12 paths, `P_fa = 10⁻³` per snapshot, 4× oversampling, whole span; a
    /// 120 dB floor.
    fn default() -> Self {
        EstimatorConfig {
            max_paths: 12,
            p_fa: 1e-3,
            oversample: 4,
            window_s: None,
            dynamic_range_db: 120.0,
        }
    }
}

impl EstimatorConfig {
    /// Checks the settings: `p_fa` in (0, 1), `oversample` 4 … 64, `max_paths` 1 …
    /// [`limits::MAX_PATHS`], `dynamic_range_db` in [`limits::ESTIMATOR_DYNAMIC_RANGE_DB`]
    /// (the window is checked against the band by [`Estimator::new`]).
    pub fn validate(&self) -> Result<()> {
        let cfg = self;
        if !(cfg.p_fa > 0.0 && cfg.p_fa < 1.0) {
            return Err(Error::OutOfRange {
                field: "p_fa".into(),
                value: cfg.p_fa,
                allowed: "0 < p_fa < 1",
            });
        }
        if !(4..=64).contains(&cfg.oversample) {
            return Err(Error::SizeLimit {
                field: "oversample",
                value: cfg.oversample,
                min: 4,
                max: 64,
            });
        }
        if !(1..=limits::MAX_PATHS).contains(&cfg.max_paths) {
            return Err(Error::SizeLimit {
                field: "max_paths",
                value: cfg.max_paths,
                min: 1,
                max: limits::MAX_PATHS,
            });
        }
        limits::ESTIMATOR_DYNAMIC_RANGE_DB.check("dynamic_range_db", cfg.dynamic_range_db)?;
        Ok(())
    }
}
