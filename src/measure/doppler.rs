//! The bistatic range rate of a moving scatterer and what a coherent processing interval (CPI)
//! says about it (issue 42 §1; the equations D1–D7 of docs/doppler.md).
//!
//! A scatterer at `r` moving at `v` (in the plane) has on link `p` the range rate
//! `ṙ_p = (û_T + û_R)·v = c ∇τ_p(r)·v` (D1; `û` the horizontal parts of the 3-D unit vectors
//! from the link's nodes to `r`, so [`Network::jacobian_row`] times `c`), the Doppler shift
//! `f_D = −ṙ_p/λ` (D2), and the gradients `∂ṙ/∂r = P_T v/d_T + P_R v/d_R`, `∂ṙ/∂v = û_T + û_R`
//! (D3, `P = I − ûûᵀ`). Over a CPI of `N` snapshots `T` apart, centred on the scan time, the
//! delay's Fisher information is `N` times E8's and the Doppler's
//! `F_ff = (2/3)π² ρ T² N(N² − 1)` (D4; the two decouple for a window symmetric about its
//! centre); the range rate's σ is `√(λ²/F_ff + σ_floor²)` (D5, the floor a model error: a body's
//! limbs and torso do not move at one velocity). [`state_fisher`] is the Fisher information of
//! the state `[r, v]` from every link's delay and range rate (D6–D7), the measurement term of
//! the PCRLB with Doppler.

use crate::error::{Error, Result};
use crate::math::{sqrt, Mat2, Mat4, Real, Vec2, Vec4, PI, SINGULAR_RCOND, SPEED_OF_LIGHT};
use crate::measure::{unit_from_dz, Model, Network};

/// The default floor on the range rate's σ, m/s (D5): a walking person's torso speed swings
/// within each stride by about a tenth of a metre per second, and the limbs move faster still
/// (the human walking model of Boulic, Magnenat-Thalmann and Thalmann, The Visual Computer 6,
/// 1990, as used for micro-Doppler by V. C. Chen, *The Micro-Doppler Effect in Radar*, 2011;
/// issue 42 §4 takes 0.1 m/s).
pub const DEFAULT_RANGE_RATE_FLOOR_MPS: Real = 0.1;

/// Most snapshots in a CPI.
pub const MAX_CPI_SNAPSHOTS: usize = 1 << 20;

/// A coherent processing interval: `snapshots` (`N`) snapshots `spacing_s` (`T`) apart on a
/// carrier of wavelength `wavelength_m` (`λ`), and the floor `floor_mps` on the range rate's σ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cpi {
    /// `N`, snapshots (1 … [`MAX_CPI_SNAPSHOTS`]; one snapshot measures no Doppler).
    pub snapshots: usize,
    /// `T`, s.
    pub spacing_s: Real,
    /// `λ = c/f_c`, m.
    pub wavelength_m: Real,
    /// `σ_floor`, m/s (≥ 0).
    pub floor_mps: Real,
}

impl Cpi {
    /// The CPI of `snapshots` snapshots `spacing_s` apart on carrier `carrier_hz`, with the
    /// floor `floor_mps`. Named errors for a count outside 1 … [`MAX_CPI_SNAPSHOTS`], a
    /// non-positive or non-finite spacing or carrier, a negative or non-finite floor.
    pub fn new(
        carrier_hz: Real,
        snapshots: usize,
        spacing_s: Real,
        floor_mps: Real,
    ) -> Result<Cpi> {
        if !(1..=MAX_CPI_SNAPSHOTS).contains(&snapshots) {
            return Err(Error::SizeLimit {
                field: "cpi.snapshots",
                value: snapshots,
                min: 1,
                max: MAX_CPI_SNAPSHOTS,
            });
        }
        for (field, v) in [
            ("cpi.spacing_s", spacing_s),
            ("radio.carrier_hz", carrier_hz),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::NotPositive {
                    field: field.into(),
                    value: v,
                });
            }
        }
        if !(floor_mps.is_finite() && floor_mps >= 0.0) {
            return Err(Error::OutOfRange {
                field: "cpi.floor_mps".into(),
                value: floor_mps,
                allowed: "a finite floor ≥ 0 m/s",
            });
        }
        Ok(Cpi {
            snapshots,
            spacing_s,
            wavelength_m: SPEED_OF_LIGHT / carrier_hz,
            floor_mps,
        })
    }

    /// `Σ_n t_n²` over the CPI's snapshot times about its centre, `T² N(N² − 1)/12`, s².
    pub fn time_spread_s2(&self) -> Real {
        let n = self.snapshots as Real;
        self.spacing_s * self.spacing_s * n * (n * n - 1.0) / 12.0
    }

    /// The Doppler's Fisher information `F_ff = 8π² ρ Σ t_n²` for a per-snapshot SNR `snr`
    /// (linear, E8's), 1/Hz² (D4).
    pub fn doppler_information(&self, snr: Real) -> Real {
        8.0 * PI * PI * snr * self.time_spread_s2()
    }

    /// The range rate's σ for a per-snapshot SNR `snr`: `√(λ²/F_ff + σ_floor²)`, m/s (D5);
    /// `+∞` when the CPI holds no Doppler information (one snapshot, or no SNR).
    pub fn sigma_range_rate(&self, snr: Real) -> Real {
        let f = self.doppler_information(snr);
        if f.is_nan() || f <= 0.0 {
            return Real::INFINITY;
        }
        sqrt(self.wavelength_m * self.wavelength_m / f + self.floor_mps * self.floor_mps)
    }
}

/// One link seen from a scatterer at `r` moving at `v`, from one evaluation of the link's unit
/// vectors: the bistatic range (E1), its gradient (E3, times `c`), the range rate (D1) and its
/// position gradient (D3), and the geometry the link budget (E8) reads. The one home of the
/// delay-and-Doppler rows of every tracker.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkMotion {
    /// `c·τ_p(r) = d_T + d_R` (3-D distances), m.
    pub range_m: Real,
    /// `û_T + û_R = c∇τ_p = ∂ṙ/∂v` (D3), 1.
    pub range_gradient: Vec2,
    /// `ṙ_p = (û_T + û_R)·v`, m/s (D1).
    pub range_rate_mps: Real,
    /// `∂ṙ/∂r = P_T v/d_T + P_R v/d_R`, 1/s (D3).
    pub rate_gradient_r: Vec2,
    /// `û_T`, the direction the transmitter's pattern is read in.
    pub unit_tx: Vec2,
    /// `d_T`, `d_R`, m.
    pub distances_m: (Real, Real),
}

/// One node of a link seen from a scatterer at `r` moving at `v`: the unit vector from the node
/// to the scatterer, the 3-D distance and the node's term `P v/d` of `∂ṙ/∂r` (D3). A link's
/// two nodes make its [`LinkMotion`]; the links of one transmitter share its view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeMotion {
    /// `û` (zero closer than
    /// [`UNIT_VECTOR_MIN_DISTANCE_M`](crate::measure::UNIT_VECTOR_MIN_DISTANCE_M)).
    pub unit: Vec2,
    /// `d`, m.
    pub distance_m: Real,
    /// `(I − ûûᵀ) v/d`, 1/s (zero with a zero `û`).
    pub rate_term: Vec2,
}

impl NodeMotion {
    /// The node at `node` (vertical offset `dz`) seen from `r` moving at `v`.
    #[inline(always)]
    pub fn new(node: Vec2, dz: Real, r: Vec2, v: Vec2) -> NodeMotion {
        let (unit, distance_m) = unit_from_dz(node, dz, r);
        // `1/d` beside `û = (r − node)/d` (both from `d` alone), so `P v/d` is a product, not a
        // second division after `û` (issue 42 §4: a shorter dependency chain per link).
        let inv = 1.0 / distance_m;
        let rate_term = if unit != Vec2::zeros() {
            (v - unit * unit.dot(&v)) * inv
        } else {
            Vec2::zeros()
        };
        NodeMotion {
            unit,
            distance_m,
            rate_term,
        }
    }
}

impl LinkMotion {
    /// Link `p` of `network` seen from `r` moving at `v` (a node closer than
    /// [`UNIT_VECTOR_MIN_DISTANCE_M`](crate::measure::UNIT_VECTOR_MIN_DISTANCE_M) adds nothing
    /// to the gradients).
    #[inline]
    pub fn new(network: &Network, p: usize, r: Vec2, v: Vec2) -> LinkMotion {
        let (tx, rx) = network.link_nodes(p);
        let (zt, zr) = network.link_dz(p);
        LinkMotion::of_nodes(
            &NodeMotion::new(tx, zt, r, v),
            &NodeMotion::new(rx, zr, r, v),
            v,
        )
    }

    /// The link of the transmitter `t` and the receiver `r`, each [`NodeMotion::new`] at the
    /// same point and the velocity `v`: the same bits as [`LinkMotion::new`].
    #[inline(always)]
    pub fn of_nodes(t: &NodeMotion, r: &NodeMotion, v: Vec2) -> LinkMotion {
        let g = t.unit + r.unit;
        LinkMotion {
            range_m: t.distance_m + r.distance_m,
            range_gradient: g,
            range_rate_mps: g.dot(&v),
            rate_gradient_r: Vec2::zeros() + t.rate_term + r.rate_term,
            unit_tx: t.unit,
            distances_m: (t.distance_m, r.distance_m),
        }
    }

    /// The link's per-snapshot SNR (E8) from this geometry.
    #[inline]
    pub fn snr(&self, model: &Model, p: usize) -> Real {
        let tx = model.network.links[p].tx;
        let gain = model.patterns[tx].gain_toward(self.unit_tx);
        model.snr_from_geometry(p, gain, self.distances_m.0, self.distances_m.1)
    }

    /// The range rate's row of the state Jacobian, `[∂ṙ/∂r, ∂ṙ/∂v]` (D3).
    #[inline]
    pub fn rate_row(&self) -> Vec4 {
        let (a, b) = (self.rate_gradient_r, self.range_gradient);
        Vec4::new(a.x, a.y, b.x, b.y)
    }
}

/// `ṙ_p(r, v) = (û_T + û_R)·v`, m/s (D1).
pub fn range_rate(network: &Network, p: usize, r: Vec2, v: Vec2) -> Real {
    LinkMotion::new(network, p, r, v).range_rate_mps
}

/// The gradients of [`range_rate`]: `(∂ṙ/∂r, ∂ṙ/∂v) = (P_T v/d_T + P_R v/d_R, û_T + û_R)`,
/// 1/s and 1 (D3; `P = I − ûûᵀ` with the 3-D distance `d`; a node closer than
/// [`UNIT_VECTOR_MIN_DISTANCE_M`](crate::measure::UNIT_VECTOR_MIN_DISTANCE_M) adds nothing).
pub fn range_rate_gradient(network: &Network, p: usize, r: Vec2, v: Vec2) -> (Vec2, Vec2) {
    let m = LinkMotion::new(network, p, r, v);
    (m.rate_gradient_r, m.range_gradient)
}

/// The Fisher information of the state `x = [r, v]` from one scan (D7):
/// `Σ_p [∇τ_p, 0]ᵀ[∇τ_p, 0]·N/σ_τ,p² + (with `doppler`) H_pᵀH_p/σ_ṙ,p²`, with
/// `H_p = [∂ṙ/∂r, ∂ṙ/∂v]` (D3), `σ_τ,p` E8's and `σ_ṙ,p` the CPI's (D5) at the link's SNR at `r`.
/// Units: the state's inverse squared (1/m², 1/(m·m/s), s²/m²).
pub fn state_fisher(model: &Model, x: &Vec4, cpi: &Cpi, doppler: bool) -> Mat4 {
    let r = Vec2::new(x[0], x[1]);
    let v = Vec2::new(x[2], x[3]);
    let n = cpi.snapshots as Real;
    let mut f = Mat4::zeros();
    for p in 0..model.link_count() {
        let j = model.network.jacobian_row(p, r);
        let s = model.sigma_delay(p, r);
        let block: Mat2 = j * j.transpose() * (n / (s * s));
        let mut pos = f.fixed_view_mut::<2, 2>(0, 0);
        pos += block;
        if doppler {
            let sr = cpi.sigma_range_rate(model.snr(p, r));
            if sr.is_finite() {
                let (dr, dv) = range_rate_gradient(&model.network, p, r, v);
                let h = Vec4::new(dr.x, dr.y, dv.x, dv.y);
                f += h * h.transpose() / (sr * sr);
            }
        }
    }
    f
}

/// The bounds of a state Fisher matrix `F` (D7): `(√(P₀₀ + P₁₁), √(P₂₂ + P₃₃))` of `P = F⁻¹`, m
/// and m/s, or `None` when `F` is singular: a diagonal entry not positive, or the matrix scaled
/// to a unit diagonal (units apart) with `λ_min/λ_max` below [`SINGULAR_RCOND`] (one link's range
/// rate cannot bound a 2-D velocity). Unbounded, never NaN.
pub fn state_bounds(f: &Mat4) -> Option<(Real, Real)> {
    let d: [Real; 4] = core::array::from_fn(|i| f[(i, i)]);
    if d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return None;
    }
    let scaled = Mat4::from_fn(|i, j| f[(i, j)] / sqrt(d[i] * d[j]));
    let e = scaled.symmetric_eigenvalues();
    let (lo, hi) = (e.min(), e.max());
    if lo.is_nan() || lo <= SINGULAR_RCOND * hi {
        return None;
    }
    let p = nalgebra::Cholesky::new(*f)?.inverse();
    let (a, b) = (p[(0, 0)] + p[(1, 1)], p[(2, 2)] + p[(3, 3)]);
    (a.is_finite() && b.is_finite() && a > 0.0 && b > 0.0).then(|| (sqrt(a), sqrt(b)))
}
