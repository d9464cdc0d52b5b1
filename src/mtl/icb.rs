//! The i.c.b model (independent, constant blocking; spec §6.1, (M7)–(M8)): every DP is
//! undetected — blocked at either end or missed — independently with the same probability
//! `p_u = 1 − p_d p_LoS²` (M7). All vectors count as consistent and there is no Hamming
//! relaxation: `P(ĝ) = (1 − p_u)^{|ĝ|} p_u^{|S|−|ĝ|}`.

use crate::error::{Error, Result};
use crate::math::{ln, Real, Vec2};
use crate::mtl::blocking::{check_probability, check_vector, powu, BlockingModel, PartialVector};
use crate::mtl::trp::TrpMap;

/// `n · ln p` with `0 · ln 0 = 0` (so an absent factor never turns into NaN).
fn n_ln(n: usize, p: Real) -> Real {
    if n == 0 {
        0.0
    } else {
        n as Real * ln(p)
    }
}

/// The i.c.b blocking model (spec §6.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IcbModel {
    map: TrpMap,
    p_u: Real,
}

impl IcbModel {
    /// The model from the DP detection probability `p_d` and the LoS probability `p_LoS` between
    /// any two points: `p_u = 1 − p_d p_LoS²` (M7).
    ///
    /// Errors: [`Error::OutOfRange`] (`p_d` / `p_los`) unless in `[0, 1]`.
    pub fn new(map: TrpMap, p_d: Real, p_los: Real) -> Result<Self> {
        let p_d = check_probability("p_d", p_d)?;
        let p_los = check_probability("p_los", p_los)?;
        Ok(Self {
            map,
            p_u: 1.0 - p_d * p_los * p_los,
        })
    }

    /// The model with `p_u` given directly; [`Error::OutOfRange`] (`p_u`) unless in `[0, 1]`.
    pub fn from_p_u(map: TrpMap, p_u: Real) -> Result<Self> {
        let p_u = check_probability("p_u", p_u)?;
        Ok(Self { map, p_u })
    }

    /// The undetected-DP probability `p_u` (M7).
    pub fn p_u(&self) -> Real {
        self.p_u
    }

    /// `P(ĝ) = (1 − p_u)^{|ĝ|} p_u^{|S|−|ĝ|}` (§6.1; no validation of `v`).
    pub fn vector_probability(&self, v: &PartialVector) -> Real {
        let k = v.weight();
        powu(1.0 - self.p_u, k) * powu(self.p_u, v.len() - k)
    }

    /// `L_b = −|ĝ| ln(1 − p_u) − (|S| − |ĝ|) ln p_u`, computed in the log domain (no underflow);
    /// `+∞` when the probability is 0, never NaN (no validation of `v`).
    pub fn vector_likelihood(&self, v: &PartialVector) -> Real {
        let k = v.weight() as usize;
        let u = v.len() as usize - k;
        let l = -(n_ln(k, 1.0 - self.p_u) + n_ln(u, self.p_u));
        if l.is_nan() {
            Real::INFINITY
        } else {
            l.max(0.0)
        }
    }

    /// Probability that exactly `k` of the `M` TRPs show a DP: the Binomial`(M, 1 − p_u)` pmf
    /// (spec check 4, Table II's i.c.b row); 0 for `k > M`.
    pub fn dp_count_pmf(&self, k: usize) -> Real {
        let m = self.map.n_trps();
        if k > m {
            return 0.0;
        }
        binomial(m, k) * powu(1.0 - self.p_u, k as u32) * powu(self.p_u, (m - k) as u32)
    }

    /// The threshold (M8) `T_b(N_u) = −N_u ln p_u − (M − N_u) ln(1 − p_u)`: `L_b` of a full
    /// matching with `N_u` undetected DPs. For `p_u < 0.5`, `L_b ≤ T_b(N_u)` accepts exactly
    /// the matchings with at least `M − N_u` DPs (the size rule of \[SM\]).
    ///
    /// Errors: [`Error::SizeLimit`] (`n_u`) when `N_u > M`.
    pub fn threshold(&self, n_u: usize) -> Result<Real> {
        let m = self.map.n_trps();
        if n_u > m {
            return Err(Error::SizeLimit {
                field: "n_u",
                value: n_u,
                min: 0,
                max: m,
            });
        }
        let t = -(n_ln(n_u, self.p_u) + n_ln(m - n_u, 1.0 - self.p_u));
        Ok(if t.is_nan() { Real::INFINITY } else { t })
    }
}

/// `C(n, k)` as a float (exact for the `n ≤ 64` used here up to rounding).
fn binomial(n: usize, k: usize) -> Real {
    let k = k.min(n - k);
    let mut c = 1.0;
    for i in 0..k {
        c = c * (n - i) as Real / (i + 1) as Real;
    }
    c
}

impl BlockingModel for IcbModel {
    fn trp_map(&self) -> &TrpMap {
        &self.map
    }

    fn probability(&self, _x: &Vec2, v: &PartialVector) -> Result<Real> {
        check_vector(&self.map, v)?;
        Ok(self.vector_probability(v))
    }

    fn blocking_likelihood(&self, _x: &Vec2, v: &PartialVector) -> Result<Real> {
        check_vector(&self.map, v)?;
        Ok(self.vector_likelihood(v))
    }
}

#[cfg(test)]
mod tests;
