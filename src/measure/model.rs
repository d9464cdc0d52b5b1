//! The measurement model of a validated scenario: geometry `h(r)` plus the link budget that sets
//! each link's SNR and delay standard deviation `σ_p` (E8).

use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{
    db_to_linear, dbm_to_watt, sqrt, Real, Vec2, BOLTZMANN, PI, REFERENCE_TEMPERATURE_K,
    SPEED_OF_LIGHT,
};
use crate::measure::Network;
use crate::measure::TxPattern;
use crate::scenario::{Pattern, Radio, Scenario, Transmitter};

/// Default receiver noise figure `F`, dB (spec §7).
pub const DEFAULT_NOISE_FIGURE_DB: Real = 10.0;
/// Distance floor inside the SNR only, m (spec §7: `max(d, 1 m)`).
pub const SNR_DISTANCE_FLOOR_M: Real = 1.0;

/// A scenario compiled for computation: node positions, link set and per-link budget constants.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// Geometry.
    pub network: Network,
    /// Tx patterns, one per transmitter.
    pub patterns: Vec<TxPattern>,
    /// Per link: `P_Tx G_Rx σ_RCS c² G_p / ((4π)³ f_c² P_n)` — the SNR at unit distances and unit
    /// Tx gain (E8 without `G_Tx(r)` and the distances).
    pub snr_scale: Vec<Real>,
    /// Effective RMS bandwidth squared `β² = B²/12`, Hz².
    pub beta2: Real,
    /// Receiver noise power `P_n`, W.
    pub noise_power_w: Real,
    /// The carrier `f_c`, Hz (the Doppler's wavelength `λ = c/f_c`, D2).
    pub carrier_hz: Real,
}

/// Whether two patterns are the same beam up to its boresight (both parabolic, same beamwidth
/// and floor).
fn same_beam(a: &Pattern, b: &Pattern) -> bool {
    match (a, b) {
        (
            Pattern::Parabolic {
                beamwidth_deg: w1,
                floor_db: f1,
                ..
            },
            Pattern::Parabolic {
                beamwidth_deg: w2,
                floor_db: f2,
                ..
            },
        ) => w1 == w2 && f1 == f2,
        _ => false,
    }
}

/// Noise power `P_n`, W: `k_B T₀ B F` or the explicit `noise_power_dbm` (spec §7).
pub fn noise_power_w(radio: &Radio) -> Real {
    match radio.noise_power_dbm {
        Some(p) => dbm_to_watt(p),
        None => {
            BOLTZMANN
                * REFERENCE_TEMPERATURE_K
                * radio.bandwidth_hz
                * db_to_linear(radio.noise_figure_db.unwrap_or(DEFAULT_NOISE_FIGURE_DB))
        }
    }
}

/// A node's vertical offset from the target's plane, `z_node − z_target`, m (exactly 0 when both
/// heights are 0, so a planar scenario keeps its bits).
fn vertical_offset(node_m: Real, target_m: Real) -> Real {
    if node_m == target_m {
        0.0
    } else {
        node_m - target_m
    }
}

/// `1/√(8π²β²·SNR)`: delay standard deviation for a given SNR (E8), s.
#[inline]
pub fn sigma_delay_from_snr(beta2: Real, snr: Real) -> Real {
    1.0 / sqrt(8.0 * PI * PI * beta2 * snr)
}

impl Model {
    /// Validates and compiles a scenario.
    pub fn new(s: &Scenario) -> Result<Model> {
        Model::compile(s, |_, t| TxPattern::new(t.gain_dbi, &t.pattern))
    }

    /// [`Model::new`] for `s`, an edit of `previous` (compiled as `self`): a transmitter whose
    /// peak gain and pattern are those of one in `previous` takes that one's compiled
    /// [`TxPattern`] (its fitted [`GainPolynomial`](crate::measure::GainPolynomial) is most of a
    /// compile, ≈ 0.15 ms), so a drag that moves a node recompiles in microseconds. The result is
    /// equal to `Model::new(s)` (compiling is deterministic; tested).
    /// A pattern that differs only in its boresight is turned ([`TxPattern::set_boresight_deg`]).
    pub fn recompile(&self, previous: &Scenario, s: &Scenario) -> Result<Model> {
        Model::compile(s, |i, t| {
            let same = |p: &&Transmitter| p.gain_dbi == t.gain_dbi && p.pattern == t.pattern;
            let turned =
                |p: &&Transmitter| p.gain_dbi == t.gain_dbi && same_beam(&p.pattern, &t.pattern);
            // The transmitter at the same index first: an edit of one node finds every other
            // pattern there at once (no search over large networks).
            let at_i = previous.transmitters.get(i).zip(self.patterns.get(i));
            let pairs = || {
                at_i.into_iter()
                    .chain(previous.transmitters.iter().zip(&self.patterns))
            };
            if let Some((_, c)) = pairs().find(|(p, _)| same(p)) {
                return c.clone();
            }
            match (pairs().find(|(p, _)| turned(p)), t.pattern) {
                (Some((_, c)), Pattern::Parabolic { boresight_deg, .. }) => {
                    let mut c = c.clone();
                    c.set_boresight_deg(boresight_deg);
                    c
                }
                _ => TxPattern::new(t.gain_dbi, &t.pattern),
            }
        })
    }

    fn compile(s: &Scenario, pattern: impl Fn(usize, &Transmitter) -> TxPattern) -> Result<Model> {
        s.validate()?;
        let links = s.link_indices()?;
        let pn = noise_power_w(&s.radio);
        let fc = s.radio.carrier_hz;
        let pg = db_to_linear(s.radio.processing_gain_db.unwrap_or(0.0));
        let four_pi3 = (4.0 * PI) * (4.0 * PI) * (4.0 * PI);
        let snr_scale = links
            .iter()
            .map(|l| {
                let tx = &s.transmitters[l.tx];
                let rx = &s.receivers[l.rx];
                dbm_to_watt(tx.power_dbm)
                    * db_to_linear(rx.gain_dbi)
                    * s.target.rcs_m2
                    * SPEED_OF_LIGHT
                    * SPEED_OF_LIGHT
                    * pg
                    / (four_pi3 * fc * fc * pn)
            })
            .collect();
        Ok(Model {
            network: Network {
                transmitters: s
                    .transmitters
                    .iter()
                    .map(|t| Vec2::new(t.position_m[0], t.position_m[1]))
                    .collect(),
                receivers: s
                    .receivers
                    .iter()
                    .map(|r| Vec2::new(r.position_m[0], r.position_m[1]))
                    .collect(),
                transmitters_dz: s
                    .transmitters
                    .iter()
                    .map(|t| vertical_offset(t.height_m, s.target.height_m))
                    .collect(),
                receivers_dz: s
                    .receivers
                    .iter()
                    .map(|r| vertical_offset(r.height_m, s.target.height_m))
                    .collect(),
                links,
            },
            patterns: s
                .transmitters
                .iter()
                .enumerate()
                .map(|(i, t)| pattern(i, t))
                .collect(),
            snr_scale,
            beta2: s.radio.bandwidth_hz * s.radio.bandwidth_hz / 12.0,
            noise_power_w: pn,
            carrier_hz: fc,
        })
    }

    /// Number of links.
    pub fn link_count(&self) -> usize {
        self.network.links.len()
    }

    /// `SNR_p(r)` of link `p` for a scatterer at `r`, linear (E8, with the 1 m distance floor;
    /// 3-D distances, the Tx gain toward the 3-D direction, see [`TxPattern::gain_toward`]).
    pub fn snr(&self, p: usize, r: Vec2) -> Real {
        let l = self.network.links[p];
        let (u_tx, d_tx) = self.network.tx_unit(l.tx, r);
        let (_, d_rx) = self.network.rx_unit(l.rx, r);
        self.snr_from_geometry(p, self.patterns[l.tx].gain_toward(u_tx), d_tx, d_rx)
    }

    /// `SNR_p` from already computed geometry: the Tx gain toward the scatterer (linear) and
    /// the distances `d_Tx`, `d_Rx` (m; floored at 1 m here, E8). For hot loops that already
    /// hold the unit vectors (EKF update, Monte Carlo).
    #[inline]
    pub fn snr_from_geometry(&self, p: usize, tx_gain: Real, d_tx: Real, d_rx: Real) -> Real {
        let d_tx = d_tx.max(SNR_DISTANCE_FLOOR_M);
        let d_rx = d_rx.max(SNR_DISTANCE_FLOOR_M);
        self.snr_scale[p] * tx_gain / (d_tx * d_tx * d_rx * d_rx)
    }

    /// Received scatter power `P_r` of link `p` at `r`, W (`SNR·P_n`, without processing gain
    /// only when none is configured).
    pub fn received_power_w(&self, p: usize, r: Vec2) -> Real {
        self.snr(p, r) * self.noise_power_w
    }

    /// Delay-domain Fisher information `[F_τ]_pp = 8π²β²·SNR_p(r)`, 1/s² (E8).
    pub fn delay_information(&self, p: usize, r: Vec2) -> Real {
        8.0 * PI * PI * self.beta2 * self.snr(p, r)
    }

    /// Delay standard deviation `σ_p(r) = [F_τ]_pp^(−1/2)`, s (E8).
    pub fn sigma_delay(&self, p: usize, r: Vec2) -> Real {
        sigma_delay_from_snr(self.beta2, self.snr(p, r))
    }

    /// `σ_p(r)` of every link in link order, s.
    pub fn sigma_delays(&self, r: Vec2) -> Vec<Real> {
        (0..self.link_count())
            .map(|p| self.sigma_delay(p, r))
            .collect()
    }
}
