//! The residual `r = H − Ĥ` and its correlation with one path: `c(τ)` and its first two
//! derivatives ([`Moments`]), a path added to or taken from the residual, and Newton on
//! `J(τ) = |c(τ)|²` for a new path's delay (C5 step 3). Flat bands run the four-lane kernels of
//! `kernels.rs`.

use super::estimator::fold;
use super::kernels;
use crate::channel::band::cis;
use crate::channel::Estimator;
use crate::error::limits;
use crate::math::{Complex, Real, PI};

/// Convergence of a new path's Newton iterations, in units of `1/B`.
const NEWTON_TOL: Real = 1e-4;

/// One pass over the bins at delay `τ`: the phasors `e^{j2π(f_n−f_c)τ}` by recursion.
#[derive(Clone, Copy)]
pub(super) struct Phasor {
    pub(super) start: Complex,
    pub(super) step: Complex,
}

impl Phasor {
    pub(super) fn at(fc0: Real, df: Real, tau: Real) -> Phasor {
        Phasor {
            start: cis(2.0 * PI * fc0 * tau),
            step: cis(2.0 * PI * df * tau),
        }
    }
}

/// `c(τ)` and its first two derivatives `c'`, `c''` in `τ`.
#[derive(Clone, Copy)]
pub(super) struct Moments {
    pub(super) c0: Complex,
    pub(super) c1: Complex,
    pub(super) c2: Complex,
}

impl Moments {
    /// Newton's step on `J = |c|²` (a quarter-resolution gradient step where `J` is not
    /// concave), clipped to `max_step`.
    pub(super) fn newton_step(&self, max_step: Real) -> Real {
        let Moments { c0, c1, c2 } = *self;
        let d1 = 2.0 * (c0.conj() * c1).re;
        let d2 = 2.0 * (c1.norm_sqr() + (c0.conj() * c2).re);
        let mut dt = if d2 < 0.0 { -d1 / d2 } else { 0.0 };
        if d2 >= 0.0 || !dt.is_finite() {
            dt = if d1 > 0.0 {
                max_step * 0.25
            } else if d1 < 0.0 {
                -max_step * 0.25
            } else {
                0.0
            };
        }
        dt.clamp(-max_step, max_step)
    }

    /// `c(τ + dt)` by its second-order Taylor series.
    pub(super) fn at(&self, dt: Real) -> Complex {
        self.c0 + self.c1 * dt + self.c2 * (0.5 * dt * dt)
    }
}

impl Estimator {
    /// `c(τ)`, `c'(τ)`, `c''(τ)` of the residual (`c(τ) = Σ P*[n] r[n] e^{j2π(f_n−f_c)τ}`).
    fn moments(&self, tau: Real) -> Moments {
        let ph0 = Phasor::at(self.fc[0], self.df, tau);
        if self.flat {
            let (c0, c1, c2) = kernels::moments(&self.resid, &self.tw, ph0.start, ph0.step);
            return Moments { c0, c1, c2 };
        }
        let mut ph = ph0.start;
        let (mut c0, mut c1, mut c2) = (
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
        );
        let tp = 2.0 * PI;
        for i in 0..self.resid.len() {
            let r = if self.flat {
                self.resid[i]
            } else {
                self.band.response[i].conj() * self.resid[i]
            };
            let x = r * ph;
            let f = tp * self.fc[i];
            c0 += x;
            let xf = x * f;
            c1 += Complex::new(-xf.im, xf.re);
            c2 -= xf * f;
            ph *= ph0.step;
        }
        Moments { c0, c1, c2 }
    }

    /// `c(τ)` of the residual alone.
    pub(super) fn correlation(&self, tau: Real) -> Complex {
        let ph0 = Phasor::at(self.fc[0], self.df, tau);
        if self.flat {
            return kernels::correlation(&self.resid, ph0.start, ph0.step);
        }
        let mut ph = ph0.start;
        let mut c0 = Complex::new(0.0, 0.0);
        for i in 0..self.resid.len() {
            let r = if self.flat {
                self.resid[i]
            } else {
                self.band.response[i].conj() * self.resid[i]
            };
            c0 += r * ph;
            ph *= ph0.step;
        }
        c0
    }

    /// `resid += a·P·e^{−j2π(f_n−f_c)τ}`.
    pub(super) fn add_path(&mut self, tau: Real, a: Complex) {
        let ph0 = Phasor::at(self.fc[0], self.df, tau);
        let mut ph = ph0.start.conj() * a;
        let step = ph0.step.conj();
        if self.flat {
            kernels::add_rotating(&mut self.resid, ph, step);
        } else {
            for (r, p) in self.resid.iter_mut().zip(&self.band.response) {
                *r += p * ph;
                ph *= step;
            }
        }
    }

    /// `resid += a·P·e^{−j2π(f_n−f_c)τ}` and the moments of the new residual at `τ`, in one
    /// pass (a path added back before it is re-fitted).
    pub(super) fn add_back(&mut self, tau: Real, a: Complex) -> Moments {
        let ph0 = Phasor::at(self.fc[0], self.df, tau);
        if self.flat {
            let (c0, c1, c2) = kernels::add_back(&mut self.resid, &self.tw, a, ph0.start, ph0.step);
            return Moments { c0, c1, c2 };
        }
        let mut ph = ph0.start;
        let (mut c0, mut c1, mut c2) = (
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
            Complex::new(0.0, 0.0),
        );
        let tp = 2.0 * PI;
        for i in 0..self.resid.len() {
            let pa = if self.flat {
                a
            } else {
                self.band.response[i] * a
            };
            self.resid[i] += pa * ph.conj();
            let r = if self.flat {
                self.resid[i]
            } else {
                self.band.response[i].conj() * self.resid[i]
            };
            let x = r * ph;
            let f = tp * self.fc[i];
            c0 += x;
            let xf = x * f;
            c1 += Complex::new(-xf.im, xf.re);
            c2 -= xf * f;
            ph *= ph0.step;
        }
        Moments { c0, c1, c2 }
    }

    /// Newton on `J(τ) = |c(τ)|²` of the residual from `tau`, steps clipped to a quarter of
    /// `1/B`, at most [`limits::NEWTON_ITERATIONS`]: the delay (folded into the window), the
    /// moments at it and the iterations used.
    pub(super) fn newton(&self, mut tau: Real) -> (Real, Moments, usize) {
        let n = self.band.len();
        let max_step = 0.25 / (self.df * n as Real);
        let tol = NEWTON_TOL / (self.df * n as Real);
        let mut m = self.moments(tau);
        let mut used = 0;
        for _ in 0..limits::NEWTON_ITERATIONS {
            used += 1;
            let dt = m.newton_step(max_step);
            tau += dt;
            if dt.abs() < tol {
                let c = m.at(dt);
                m = Moments { c0: c, ..m };
                break;
            }
            m = self.moments(tau);
        }
        let folded = fold(tau, self.win_start, self.span).min(self.win_end);
        if folded != tau {
            m = self.moments(folded);
        }
        (folded, m, used)
    }
}
