//! The measurements of one particle-filter update as its particle passes read them (the
//! delay-only update's used links, or the delay-and-Doppler rows of issue 42 §3, D8).

use alloc::vec;
use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{Real, Vec2, Vec4, SPEED_OF_LIGHT};
use crate::measure::Model;
use crate::track::doppler::{check_rates, rows as doppler_rows, RangeRates, Row};
use crate::track::shared::{check_update, first_input_error};
use crate::track::MeasurementNoise;

/// The measurements of one update as the particle passes read them: the delay-only update's
/// used links (ranges from each node's distance once), or the delay-and-Doppler rows; the
/// measured values `z` (range domain) and their information `1/σ²`.
pub(super) struct Measured {
    used: Vec<usize>,
    rows: Option<Vec<(usize, Row)>>,
    pub(super) z: Vec<Real>,
    pub(super) info: Vec<Real>,
    /// Links that gave a measurement.
    pub(super) links: usize,
}

impl Measured {
    /// The update's measurements after its checks (`σ` at the weighted mean `x̂⁻`).
    pub(super) fn new(
        model: &Model,
        z: &[Option<Real>],
        noise: MeasurementNoise,
        rates: Option<&RangeRates>,
        mean: &Vec4,
    ) -> Result<Measured> {
        let r_pred = Vec2::new(mean[0], mean[1]);
        if let Some(rates) = rates {
            check_rates(model, z, noise, rates, r_pred)?;
            let mut rows = Vec::new();
            let links = doppler_rows(model, mean, z, noise, rates, |p, row| rows.push((p, row)))?;
            return Ok(Measured {
                used: Vec::new(),
                z: rows.iter().map(|(_, r)| r.z).collect(),
                info: rows.iter().map(|(_, r)| r.w).collect(),
                rows: Some(rows),
                links,
            });
        }
        let m = check_update(model, z, noise)?;
        let used: Vec<usize> = (0..z.len()).filter(|&p| z[p].is_some()).collect();
        if m > 0 {
            if let Some(e) = first_input_error(model, z, noise, r_pred) {
                return Err(e);
            }
        }
        // Range domain: c·z and the information 1/(cσ_p)².
        let zc = used
            .iter()
            .map(|&p| SPEED_OF_LIGHT * z[p].unwrap_or_default())
            .collect();
        let info = used
            .iter()
            .map(|&p| {
                let s = SPEED_OF_LIGHT * noise.sigma(model, p, r_pred);
                1.0 / (s * s)
            })
            .collect();
        Ok(Measured {
            used,
            rows: None,
            z: zc,
            info,
            links: m,
        })
    }

    /// Each particle's `Σ w (z − h(x_j))²` into `q` and its predicted values into `ranges`
    /// (`N × m`).
    pub(super) fn pass(
        &self,
        model: &Model,
        particles: &[Vec4],
        ranges: &mut Vec<Real>,
        q: &mut [Real],
    ) {
        let Some(rows) = &self.rows else {
            return range_pass(model, &self.used, &self.z, &self.info, particles, ranges, q);
        };
        let m = rows.len();
        ranges.clear();
        ranges.resize(particles.len() * m, 0.0);
        for (j, x) in particles.iter().enumerate() {
            let mut s = 0.0;
            for (k, (p, row)) in rows.iter().enumerate() {
                let h = row.value_at(model, *p, x);
                ranges[j * m + k] = h;
                let e = row.z - h;
                s += e * e * row.w;
            }
            q[j] = s;
        }
    }
}

/// Every particle's range on each used link (E1, into `ranges`, `N × m`) and
/// `q_j = Σ_links (z − h(x_j))² / σ_p²` in the range domain (into `q`).
fn range_pass(
    model: &Model,
    used: &[usize],
    zc: &[Real],
    info: &[Real],
    particles: &[Vec4],
    ranges: &mut Vec<Real>,
    q: &mut [Real],
) {
    let m = used.len();
    ranges.clear();
    ranges.resize(particles.len() * m, 0.0);
    let net = &model.network;
    let (ntx, nrx) = (net.transmitters.len(), net.receivers.len());
    let mut d = vec![0.0; ntx + nrx];
    for (j, x) in particles.iter().enumerate() {
        // Each node's distance once (E1: a link's range is the sum of its two).
        net.node_distances_into(Vec2::new(x[0], x[1]), &mut d);
        let mut s = 0.0;
        for (k, &p) in used.iter().enumerate() {
            let l = net.links[p];
            let h = d[l.tx] + d[ntx + l.rx];
            ranges[j * m + k] = h;
            let e = zc[k] - h;
            s += e * e * info[k];
        }
        q[j] = s;
    }
}
