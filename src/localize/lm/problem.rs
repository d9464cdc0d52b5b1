//! The fix as a weighted least-squares problem in range units: the used links with their
//! weights, the cost 𝓛(r) (E5) and its linearisation.

use alloc::vec::Vec;

use super::iterate::LmProblem;
use super::{DelayMeasurements, MIN_LINKS};
use crate::error::{check_len, limits, Error, Result};
use crate::math::{Mat2, Real, Vec2, SPEED_OF_LIGHT};
use crate::measure::{bistatic_range_dz, range_and_gradient_dz, Network};

/// One used link in range units: foci, their vertical offsets from the target's plane, measured
/// range `cτ̂` and weight `1/(cσ)²`.
#[derive(Clone, Copy)]
pub(super) struct Row {
    pub(super) tx: Vec2,
    pub(super) rx: Vec2,
    pub(super) dz_tx: Real,
    pub(super) dz_rx: Real,
    pub(super) range: Real,
    pub(super) weight: Real,
}

/// Validated problem in range units.
pub(super) struct Problem {
    pub(super) rows: Vec<Row>,
}

impl Problem {
    pub(super) fn new(net: &Network, m: &DelayMeasurements) -> Result<Problem> {
        let n = net.link_count();
        check_len("delays_s", n, m.delays_s.len())?;
        check_len("sigma_s", n, m.sigmas_s.len())?;
        let mut rows = Vec::with_capacity(n);
        for (p, (d, s)) in m.delays_s.iter().zip(m.sigmas_s).enumerate() {
            let Some(d) = *d else { continue };
            if !limits::DELAY_S.contains(d) {
                return Err(Error::InvalidDelay { link: p, value: d });
            }
            if !limits::DELAY_SIGMA_S.contains(*s) {
                return Err(Error::InvalidSigma { link: p, value: *s });
            }
            let (tx, rx) = net.link_nodes(p);
            let (dz_tx, dz_rx) = net.link_dz(p);
            let sr = SPEED_OF_LIGHT * s;
            rows.push(Row {
                tx,
                rx,
                dz_tx,
                dz_rx,
                range: SPEED_OF_LIGHT * d,
                weight: 1.0 / (sr * sr),
            });
        }
        if rows.len() < MIN_LINKS {
            return Err(Error::TooFewLinks {
                available: rows.len(),
                required: MIN_LINKS,
            });
        }
        Ok(Problem { rows })
    }

    /// 𝓛(r) (E5).
    #[inline]
    pub(super) fn cost(&self, r: Vec2) -> Real {
        self.rows
            .iter()
            .map(|row| {
                let e = row.range - bistatic_range_dz(row.tx, row.dz_tx, row.rx, row.dz_rx, r);
                row.weight * e * e
            })
            .sum()
    }

    /// Cost, normal matrix `JᵀWJ` and gradient term `JᵀW(ρ̂ − h)` at `r` (range units).
    #[inline]
    pub(super) fn linearize(&self, r: Vec2) -> (Real, Mat2, Vec2) {
        let (mut cost, mut n, mut g) = (0.0, Mat2::zeros(), Vec2::zeros());
        for row in &self.rows {
            let (d, j) = range_and_gradient_dz(row.tx, row.dz_tx, row.rx, row.dz_rx, r);
            let e = row.range - d;
            cost += row.weight * e * e;
            n += row.weight * j * j.transpose();
            g += (row.weight * e) * j;
        }
        (cost, n, g)
    }
}

impl LmProblem<2> for Problem {
    fn cost(&self, x: &Vec2) -> Real {
        Problem::cost(self, *x)
    }

    fn linearize(&self, x: &Vec2) -> (Real, Mat2, Vec2) {
        Problem::linearize(self, *x)
    }
}
