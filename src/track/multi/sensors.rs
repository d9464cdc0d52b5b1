//! What one scan measures (issue 41 §1): a [`MeasurementModel`] gives, per sensor, the
//! predicted measurement at a state with its Jacobian and noise (the EKF's linearisation, E3),
//! the clutter intensity `λ_c f_c` and the detection probability `P_D`. Two models: a 2-D
//! position sensor (the standard checks of the MTT literature, Williams-15) and the links of a
//! delay network (E1, `σ_p` from E8 or given), one sensor per link.

use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::{Real, Vec2, Vec4};
use crate::measure::{LinkMotion, Model};

/// One detection of a sensor: `value[..dim]` (a delay in s, or a position in m) and, if its
/// estimator gave one, its own σ (delays only; it replaces the model's noise). A delay may carry
/// its range rate (issue 42 §3): then `value[1]` is `ṙ` in m/s and `rate_sigma` its σ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detection {
    /// The measured value (first `dim` components used).
    pub value: [Real; 2],
    /// Its standard deviation, if known (units of `value`).
    pub sigma: Option<Real>,
    /// With a range rate in `value[1]`: its σ, m/s.
    pub rate_sigma: Option<Real>,
}

impl Detection {
    /// A delay (s) with an optional σ (s).
    pub fn delay(delay_s: Real, sigma_s: Option<Real>) -> Detection {
        Detection {
            value: [delay_s, 0.0],
            sigma: sigma_s,
            rate_sigma: None,
        }
    }

    /// A delay (s, optional σ in s) with its range rate `ṙ` and σ_ṙ, m/s (D1, D5).
    pub fn delay_rate(
        delay_s: Real,
        sigma_s: Option<Real>,
        rate_mps: Real,
        rate_sigma_mps: Real,
    ) -> Detection {
        Detection {
            value: [delay_s, rate_mps],
            sigma: sigma_s,
            rate_sigma: Some(rate_sigma_mps),
        }
    }

    /// A 2-D position, m.
    pub fn position(p: Vec2) -> Detection {
        Detection {
            value: [p.x, p.y],
            sigma: None,
            rate_sigma: None,
        }
    }
}

/// The measurement of one sensor at a state, linearised there (E3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Components used (1 for a delay, 2 for a position).
    pub dim: usize,
    /// Predicted measurement `h(x)`.
    pub value: [Real; 2],
    /// Rows of `∂h/∂x` (one per component).
    pub jacobian: [[Real; 4]; 2],
    /// Noise variance of each component.
    pub noise: [Real; 2],
}

/// The measurement side of a multi-target tracker: `sensor_count` sensors scanned together.
pub trait MeasurementModel {
    /// Number of sensors (links).
    fn sensor_count(&self) -> usize;
    /// The observation of `sensor` at state `x`; `sigma`, if given, replaces the model's noise.
    fn observe(&self, sensor: usize, x: &Vec4, sigma: Option<Real>) -> Observation;
    /// The clutter intensity `λ_c f_c` of `sensor` (per unit measurement volume).
    fn clutter_intensity(&self, sensor: usize) -> Real;
    /// The observation of `sensor` at `x` for detection `d` (its own σ; with a range rate, the
    /// rate as a second component, D1 and D3). By default [`Self::observe`] with `d.sigma`.
    fn observe_detection(&self, sensor: usize, x: &Vec4, d: &Detection) -> Observation {
        self.observe(sensor, x, d.sigma)
    }
    /// The clutter intensity of `sensor` in `d`'s measurement space (per s, or per s·m/s with a
    /// range rate). By default [`Self::clutter_intensity`].
    fn clutter_intensity_of(&self, sensor: usize, d: &Detection) -> Real {
        let _ = d;
        self.clutter_intensity(sensor)
    }
    /// `P_D`.
    fn detection_probability(&self) -> Real;
    /// The delay network behind the sensors and its fixed σ per link, if the sensors are the
    /// links of one (births from free delays need it).
    fn delay_model(&self) -> Option<(&Model, Option<&[Real]>)> {
        None
    }
}

/// A sensor that measures 2-D positions with noise `σ` per axis (`R = σ² I`), detection
/// probability `P_D` and Poisson clutter uniform over a region.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionSensor {
    /// `σ`, m.
    pub sigma_m: Real,
    /// `P_D`.
    pub detection: Real,
    /// `λ_c f_c`, 1/m² (mean clutter per scan over the region's area).
    pub clutter_intensity: Real,
}

impl MeasurementModel for PositionSensor {
    fn sensor_count(&self) -> usize {
        1
    }
    fn observe(&self, _sensor: usize, x: &Vec4, _sigma: Option<Real>) -> Observation {
        let v = self.sigma_m * self.sigma_m;
        Observation {
            dim: 2,
            value: [x[0], x[1]],
            jacobian: [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]],
            noise: [v, v],
        }
    }
    fn clutter_intensity(&self, _sensor: usize) -> Real {
        self.clutter_intensity
    }
    fn detection_probability(&self) -> Real {
        self.detection
    }
}

/// The links of a delay network as sensors: link `p` measures the bistatic delay `τ_p(r)` (E1)
/// with σ from the link budget at the state (E8), a fixed per-link σ, or the detection's own σ.
#[derive(Debug, Clone)]
pub struct DelayLinks<'a> {
    /// The compiled scenario.
    pub model: &'a Model,
    /// `P_D` per link.
    pub detection: Real,
    /// `λ_c f_c` per link, 1/s (mean clutter delays per scan over the delay window).
    pub clutter_intensity: Real,
    /// Fixed σ per link, s (`None`: E8 at the state).
    pub sigma_s: Option<Vec<Real>>,
    /// The span of clutter range rates, m/s (clutter rates uniform over it): divides the
    /// clutter intensity of a detection with a range rate.
    pub clutter_rate_span_mps: Real,
}

/// The default span of clutter range rates: ±3 m/s (a walker's bistatic range rate is at most
/// twice its speed).
pub const CLUTTER_RATE_SPAN_MPS: Real = 6.0;

impl<'a> DelayLinks<'a> {
    /// The links of `model` with `P_D`, `clutter` delays per link and scan uniform over a
    /// window of `window_s`, and optional fixed σ per link. Errors name a bad value.
    pub fn new(
        model: &'a Model,
        detection: Real,
        clutter: Real,
        window_s: Real,
        sigma_s: Option<Vec<Real>>,
    ) -> Result<DelayLinks<'a>> {
        check_detection(detection)?;
        if !(clutter.is_finite() && clutter >= 0.0) {
            return Err(Error::OutOfRange {
                field: "clutter".into(),
                value: clutter,
                allowed: "a mean clutter count ≥ 0 per link and scan",
            });
        }
        if !(window_s.is_finite() && window_s > 0.0) {
            return Err(Error::NotPositive {
                field: "clutter_window_s".into(),
                value: window_s,
            });
        }
        if let Some(s) = &sigma_s {
            crate::error::check_len("sigma_s", model.link_count(), s.len())?;
            if let Some(link) = s.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(Error::InvalidSigma {
                    link,
                    value: s[link],
                });
            }
        }
        Ok(DelayLinks {
            model,
            detection,
            // A floor keeps the likelihood ratio finite with no clutter at all.
            clutter_intensity: (clutter / window_s).max(1e-3 / window_s),
            sigma_s,
            clutter_rate_span_mps: CLUTTER_RATE_SPAN_MPS,
        })
    }
}

/// `P_D` in `(0, 1)`.
pub fn check_detection(pd: Real) -> Result<()> {
    if pd.is_finite() && pd > 0.0 && pd < 1.0 {
        Ok(())
    } else {
        Err(Error::OutOfRange {
            field: "detection_probability".into(),
            value: pd,
            allowed: "0 < P_D < 1",
        })
    }
}

impl MeasurementModel for DelayLinks<'_> {
    fn sensor_count(&self) -> usize {
        self.model.link_count()
    }
    fn observe(&self, p: usize, x: &Vec4, sigma: Option<Real>) -> Observation {
        let r = Vec2::new(x[0], x[1]);
        let j = self.model.network.jacobian_row(p, r);
        let s = sigma.unwrap_or_else(|| match &self.sigma_s {
            Some(v) => v[p],
            None => self.model.sigma_delay(p, r),
        });
        Observation {
            dim: 1,
            value: [self.model.network.delay(p, r), 0.0],
            jacobian: [[j.x, j.y, 0.0, 0.0], [0.0; 4]],
            noise: [s * s, 0.0],
        }
    }
    fn clutter_intensity(&self, _sensor: usize) -> Real {
        self.clutter_intensity
    }
    fn observe_detection(&self, p: usize, x: &Vec4, d: &Detection) -> Observation {
        let mut obs = self.observe(p, x, d.sigma);
        if let Some(s) = d.rate_sigma {
            let m = LinkMotion::new(
                &self.model.network,
                p,
                Vec2::new(x[0], x[1]),
                Vec2::new(x[2], x[3]),
            );
            let h = m.rate_row();
            obs.dim = 2;
            obs.value[1] = m.range_rate_mps;
            obs.jacobian[1] = [h[0], h[1], h[2], h[3]];
            obs.noise[1] = s * s;
        }
        obs
    }
    fn clutter_intensity_of(&self, _sensor: usize, d: &Detection) -> Real {
        match d.rate_sigma {
            Some(_) => self.clutter_intensity / self.clutter_rate_span_mps,
            None => self.clutter_intensity,
        }
    }
    fn detection_probability(&self) -> Real {
        self.detection
    }
    fn delay_model(&self) -> Option<(&Model, Option<&[Real]>)> {
        Some((self.model, self.sigma_s.as_deref()))
    }
}
