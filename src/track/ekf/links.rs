//! Pass 1 of an update: the links' position information at the predicted position `r̂⁻`, with
//! the delays (E1), the Jacobian rows (E3) and the SNR (E8) of every link evaluated once,
//! together, in fixed-size blocks of links; no allocation and no per-link dispatch (the noise
//! option is resolved once per update).
//!
//! The transmitters' geometry (distance, unit vector, floored `1/d²`) and, for `R` at the
//! prediction, their gain toward `r̂⁻` are evaluated once per update and shared by their links.
//! Then per block of [`BLOCK`] links, in structure-of-arrays form (each operation runs on two
//! links per SSE2 or simd128 instruction): the receivers' geometry, and per link the range
//! innovation `ν = cz − (d_Tx + d_Rx)`, the range Jacobian row `g = u_Tx + u_Rx` (`cJ`, E3) and the
//! range-domain information `w = 1/(cσ_p)²` (for `R` at the prediction `w = 8π²β²·SNR_p(r̂⁻)/c²`,
//! E8). The sums `M = Σ w g gᵀ`, `b = Σ w ν g` and `νᵀR⁻¹ν` are added in link order, so they are
//! bitwise those of a link-by-link loop: a lane without a measurement has `w = 0` and `ν = 0`,
//! so its terms are `±0`, which leave a sum unchanged (a sum that starts at `+0` never is `−0`).

use crate::error::limits;
use crate::math::{Real, Vec2, SPEED_OF_LIGHT};
use crate::measure::Model;
use crate::scenario::LinkIndex;
use crate::track::shared::{
    finite_probe, information_from_sigma, range_information_per_snr, NodeViews,
};
use crate::track::MeasurementNoise;

/// Links evaluated together; a network's last block is padded with unused lanes.
const BLOCK: usize = 4;

/// Transmitters whose view is evaluated up front when there are several (the link order is
/// Tx-fastest, spec §1); a further transmitter is evaluated when a link needs it and kept until
/// a link needs another one.
const TX_TABLE: usize = 4;

/// Running sums of pass 1 for one filter (module docs): `M`, `b`, `νᵀR⁻¹ν`, the number of
/// links used and whether every used link's inputs were valid.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Information {
    pub(super) m00: Real,
    pub(super) m01: Real,
    pub(super) m11: Real,
    pub(super) b0: Real,
    pub(super) b1: Real,
    pub(super) nu_info_nu: Real,
    pub(crate) links_used: usize,
    /// Every used link has a delay in [`limits::DELAY_S`], a valid `σ_p` and a finite, positive
    /// `w` (otherwise the caller rescans the inputs for the named error).
    pub(crate) valid: bool,
}

const NO_INFORMATION: Information = Information {
    m00: 0.0,
    m01: 0.0,
    m11: 0.0,
    b0: 0.0,
    b1: 0.0,
    nu_info_nu: 0.0,
    links_used: 0,
    valid: true,
};

/// A transmitter as seen from `r̂⁻`: distance, unit vector, floored `1/d²` and, for `R` at the
/// prediction, its gain toward `r̂⁻` (E8; 0 otherwise).
#[derive(Debug, Clone, Copy)]
struct TxView {
    distance: Real,
    ux: Real,
    uy: Real,
    inv_floored_sq: Real,
    gain: Real,
}

const NO_TX: TxView = TxView {
    distance: 0.0,
    ux: 0.0,
    uy: 0.0,
    inv_floored_sq: 0.0,
    gain: 0.0,
};

/// Transmitters `first ..` (at most `B`, lanes past the last one unused) as seen from `r`.
#[inline(always)]
fn tx_views<const B: usize>(model: &Model, first: usize, r: Vec2, gain: bool) -> [TxView; B] {
    let net = &model.network;
    let nodes = net.transmitters[first..]
        .iter()
        .zip(&net.transmitters_dz[first..]);
    let (mut x, mut y, mut dz) = ([0.0; B], [0.0; B], [0.0; B]);
    for (i, (node, &z)) in nodes.take(B).enumerate() {
        (x[i], y[i], dz[i]) = (node.x, node.y, z);
    }
    let v = NodeViews::new(&x, &y, &dz, &[r.x; B], &[r.y; B]);
    let mut out = [NO_TX; B];
    for (i, pattern) in model.patterns[first..].iter().take(B).enumerate() {
        out[i] = TxView {
            distance: v.distance[i],
            ux: v.ux[i],
            uy: v.uy[i],
            inv_floored_sq: v.inv_floored_sq[i],
            gain: if gain {
                pattern.gain_toward(Vec2::new(v.ux[i], v.uy[i]))
            } else {
                0.0
            },
        };
    }
    out
}

/// Transmitter `k` as seen from each of the points `r` (their gains evaluated side by side).
#[inline(always)]
fn tx_seen_from<const L: usize>(model: &Model, k: usize, r: &[Vec2; L], gain: bool) -> [TxView; L] {
    let node = model.network.transmitters[k];
    let dz = model.network.transmitters_dz[k];
    let v = NodeViews::new(
        &[node.x; L],
        &[node.y; L],
        &[dz; L],
        &r.map(|r| r.x),
        &r.map(|r| r.y),
    );
    let gains = if gain {
        model.patterns[k].gains_toward(v.ux, v.uy)
    } else {
        [0.0; L]
    };
    core::array::from_fn(|l| TxView {
        distance: v.distance[l],
        ux: v.ux[l],
        uy: v.uy[l],
        inv_floored_sq: v.inv_floored_sq[l],
        gain: gains[l],
    })
}

/// How a link's `w = 1/(cσ_p)²` follows from the noise option: one implementation per
/// [`MeasurementNoise`] variant, chosen once per update.
trait Weights {
    /// Whether `w` needs the transmitters' gain.
    const GAIN: bool;
    /// The factor of an unused lane, one that gives `w = 0`.
    const UNUSED: Real;
    /// The factor of `w` for used link `p` (its `snr_scale` or `σ_p`) and whether it is valid.
    fn factor(&self, p: usize) -> (Real, bool);
    /// `w` from the factor, the transmitter's gain and the floored `1/d²` of both nodes.
    fn weight(&self, factor: Real, gain: Real, tx_inv_sq: Real, rx_inv_sq: Real) -> Real;
}

/// `R` from the link budget at `r̂⁻`: `w = 8π²β²/c² · SNR_p(r̂⁻)` (E8).
struct AtPrediction<'a> {
    snr_scale: &'a [Real],
    info_per_snr: Real,
}

impl Weights for AtPrediction<'_> {
    const GAIN: bool = true;
    const UNUSED: Real = 0.0;
    #[inline(always)]
    fn factor(&self, p: usize) -> (Real, bool) {
        (self.snr_scale[p], true)
    }
    #[inline(always)]
    fn weight(&self, factor: Real, gain: Real, tx_inv_sq: Real, rx_inv_sq: Real) -> Real {
        self.info_per_snr * (factor * gain * tx_inv_sq * rx_inv_sq)
    }
}

/// Given `σ_p` (checked against [`limits::DELAY_SIGMA_S`]).
struct Given<'a>(&'a [Real]);

impl Weights for Given<'_> {
    const GAIN: bool = false;
    const UNUSED: Real = Real::INFINITY;
    #[inline(always)]
    fn factor(&self, p: usize) -> (Real, bool) {
        let sigma = self.0[p];
        (sigma, limits::DELAY_SIGMA_S.contains(sigma))
    }
    #[inline(always)]
    fn weight(&self, sigma: Real, _: Real, _: Real, _: Real) -> Real {
        information_from_sigma(sigma)
    }
}

/// `σ_p` from the link budget at a given point.
struct AtPoint<'a> {
    model: &'a Model,
    point: Vec2,
}

impl Weights for AtPoint<'_> {
    const GAIN: bool = false;
    const UNUSED: Real = Real::INFINITY;
    #[inline(always)]
    fn factor(&self, p: usize) -> (Real, bool) {
        let sigma = self.model.sigma_delay(p, self.point);
        (sigma, sigma > 0.0)
    }
    #[inline(always)]
    fn weight(&self, sigma: Real, _: Real, _: Real, _: Real) -> Real {
        information_from_sigma(sigma)
    }
}

/// Pass 1 for `L` filters with predicted positions `r[j]` and delays `z[j]` (one per link,
/// lengths checked by the caller; `active[j] = false` skips filter `j`): the sums over the
/// available links (module docs). The filters' transmitter gains, the longest dependency chain
/// of an update, are evaluated side by side. `per_link(j, p, ν_p, w_p)` receives each used
/// link's range innovation, m, and range information `w_p = 1/(cσ_p)²`, 1/m², in link order
/// (the UKF takes its `R` from these).
#[inline(always)]
pub(crate) fn link_information<const L: usize>(
    model: &Model,
    r: &[Vec2; L],
    z: &[&[Option<Real>]; L],
    active: &[bool; L],
    noise: MeasurementNoise,
    per_link: impl FnMut(usize, usize, Real, Real),
) -> [Information; L] {
    match noise {
        MeasurementNoise::AtPrediction => {
            let w = AtPrediction {
                snr_scale: &model.snr_scale,
                info_per_snr: range_information_per_snr(model),
            };
            with_transmitters(model, r, z, active, &w, per_link)
        }
        MeasurementNoise::Fixed(sigma) => {
            with_transmitters(model, r, z, active, &Given(sigma), per_link)
        }
        MeasurementNoise::At(point) => {
            let w = AtPoint { model, point };
            with_transmitters(model, r, z, active, &w, per_link)
        }
    }
}

/// [`link_information`] with the transmitters' views evaluated once per filter.
#[inline(always)]
fn with_transmitters<W: Weights, const L: usize>(
    model: &Model,
    r: &[Vec2; L],
    z: &[&[Option<Real>]; L],
    active: &[bool; L],
    w: &W,
    per_link: impl FnMut(usize, usize, Real, Real),
) -> [Information; L] {
    if model.network.transmitters.len() == 1 {
        // One transmitter (both presets): the same view for every link of a filter.
        let tx = tx_seen_from(model, 0, r, W::GAIN);
        return blocks(model, r, z, active, w, |j, _| tx[j], per_link);
    }
    let table: [[TxView; TX_TABLE]; L] =
        core::array::from_fn(|j| tx_views::<TX_TABLE>(model, 0, r[j], W::GAIN));
    // Per filter the last transmitter past the table that a link needed, and its view.
    let mut spill = [(usize::MAX, NO_TX); L];
    let tx_view = |j: usize, k: usize| {
        if k < TX_TABLE {
            table[j][k]
        } else {
            if spill[j].0 != k {
                spill[j] = (k, tx_views::<1>(model, k, r[j], W::GAIN)[0]);
            }
            spill[j].1
        }
    };
    blocks(model, r, z, active, w, tx_view, per_link)
}

/// The full blocks of links, then the last one padded with unused lanes (which repeat the last
/// link, without a measurement); per block the active filters one after the other.
#[inline(always)]
fn blocks<W: Weights, const L: usize>(
    model: &Model,
    r: &[Vec2; L],
    z: &[&[Option<Real>]; L],
    active: &[bool; L],
    w: &W,
    mut tx_view: impl FnMut(usize, usize) -> TxView,
    mut per_link: impl FnMut(usize, usize, Real, Real),
) -> [Information; L] {
    let links = &model.network.links[..];
    let n = links.len();
    let z = z.map(|z| &z[..n]);
    let full = n - n % BLOCK;
    let mut acc = [NO_INFORMATION; L];
    for first in (0..full).step_by(BLOCK) {
        let block_links = fixed(&links[first..]);
        for j in 0..L {
            if active[j] {
                let block_z = fixed(&z[j][first..]);
                let (a, r) = (&mut acc[j], r[j]);
                let mut tx = |k| tx_view(j, k);
                let mut inn = |p, nu, w| per_link(j, p, nu, w);
                add_block(
                    a,
                    model,
                    r,
                    w,
                    first,
                    &block_links,
                    &block_z,
                    &mut tx,
                    &mut inn,
                );
            }
        }
    }
    if full < n {
        let mut block_links = [links[n - 1]; BLOCK];
        block_links[..n - full].copy_from_slice(&links[full..]);
        for j in 0..L {
            if active[j] {
                let mut block_z = [None; BLOCK];
                block_z[..n - full].copy_from_slice(&z[j][full..]);
                let (a, r) = (&mut acc[j], r[j]);
                let mut tx = |k| tx_view(j, k);
                let mut inn = |p, nu, w| per_link(j, p, nu, w);
                add_block(
                    a,
                    model,
                    r,
                    w,
                    full,
                    &block_links,
                    &block_z,
                    &mut tx,
                    &mut inn,
                );
            }
        }
    }
    acc
}

/// The first `BLOCK` elements of a slice (the caller passes at least `BLOCK`).
#[inline(always)]
fn fixed<T: Copy>(s: &[T]) -> [T; BLOCK] {
    *s.first_chunk().expect("a full block")
}

/// Adds links `first ..` (`links`, delays `z`; `None` = missing or an unused lane) to `acc`, in
/// link order (module docs).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn add_block<W: Weights>(
    acc: &mut Information,
    model: &Model,
    r: Vec2,
    w: &W,
    first: usize,
    links: &[LinkIndex; BLOCK],
    z: &[Option<Real>; BLOCK],
    tx_view: &mut impl FnMut(usize) -> TxView,
    per_link: &mut impl FnMut(usize, Real, Real),
) {
    // Gather: the transmitter's view, the receiver, the delay and the factor of w. An unused lane
    // gets z = 0 and a factor that gives w = 0; its inputs are not checked.
    let tx: [TxView; BLOCK] = core::array::from_fn(|i| tx_view(links[i].tx));
    let (mut rx_x, mut rx_y, mut rx_dz) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
    let (mut zv, mut factor, mut used) = ([0.0; BLOCK], [W::UNUSED; BLOCK], [false; BLOCK]);
    let mut valid = true;
    for i in 0..BLOCK {
        let node = model.network.receivers[links[i].rx];
        (rx_x[i], rx_y[i]) = (node.x, node.y);
        rx_dz[i] = model.network.receivers_dz[links[i].rx];
        if let Some(v) = z[i] {
            let (f, ok) = w.factor(first + i);
            (zv[i], factor[i], used[i]) = (v, f, true);
            valid &= ok & limits::DELAY_S.contains(v);
        }
    }
    let rv = NodeViews::<BLOCK>::new(&rx_x, &rx_y, &rx_dz, &[r.x; BLOCK], &[r.y; BLOCK]);
    // Per link the terms of the sums; every used w positive, every z and w finite.
    let mut t = [[0.0; 6]; BLOCK];
    let (mut nu, mut weight) = ([0.0; BLOCK], [0.0; BLOCK]);
    let (mut positive, mut finite) = (0, 0.0);
    for i in 0..BLOCK {
        let wi = w.weight(
            factor[i],
            tx[i].gain,
            tx[i].inv_floored_sq,
            rv.inv_floored_sq[i],
        );
        let range = SPEED_OF_LIGHT * zv[i] - (tx[i].distance + rv.distance[i]);
        nu[i] = if used[i] { range } else { 0.0 };
        weight[i] = wi;
        let (gx, gy) = (tx[i].ux + rv.ux[i], tx[i].uy + rv.uy[i]);
        let (wgx, wgy) = (wi * gx, wi * gy);
        t[i] = [
            wgx * gx,
            wgx * gy,
            wgy * gy,
            wgx * nu[i],
            wgy * nu[i],
            wi * nu[i] * nu[i],
        ];
        positive += (wi > 0.0) as usize;
        finite += finite_probe(zv[i]) + wi;
    }
    // The sums in link order.
    for [m00, m01, m11, b0, b1, nu_info_nu] in t {
        acc.m00 += m00;
        acc.m01 += m01;
        acc.m11 += m11;
        acc.b0 += b0;
        acc.b1 += b1;
        acc.nu_info_nu += nu_info_nu;
    }
    // Unused lanes have w = 0: every used one has w > 0 iff `positive` counts the used lanes.
    let count = used.iter().filter(|&&u| u).count();
    acc.valid &= valid & (positive == count) & (finite < Real::INFINITY);
    acc.links_used += count;
    for i in 0..BLOCK {
        if used[i] {
            per_link(first + i, nu[i], weight[i]);
        }
    }
}
