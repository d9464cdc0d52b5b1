//! The multi-target tracker of issue 41: a Poisson multi-Bernoulli (PMB) filter with the
//! track-oriented marginal update (TOMB/P; Williams, IEEE TAES 51(3), 2015) whose association
//! marginals are computed per cluster of gated pairs ([`clustered_marginals`]): exactly for a
//! cluster of at most `exact_cluster` (default 6) tracks and measurements, by loopy belief propagation
//! ([`crate::track::multi::bp_marginals`]) beyond; one sensor (link) after the other as in Meyer
//! et al. (IEEE TSP 65(13), 2017): per scan the cost is linear in sensors and in gated
//! (track, measurement) pairs for bounded clusters.
//!
//! - Each target is a [`Bernoulli`]: existence `r`, a Gaussian on `[x, y, vx, vy]` moved by the
//!   CV model (E7) with survival `p_S`, and a label kept for its life.
//! - Sensor `s` with measurements `z_1 … z_m`: `ψ_ij = r_i P_D 𝒩(z_j; ẑ_i, S_ij) /
//!   ((1 − r_i P_D)(λ_c f_c + e_j))` inside the gate, where `e_j = P_D ∫ λ_u(x) 𝒩(z_j; h(x), R)`
//!   is the undetected targets' share (position sensors). The marginals are `p_i0`, `p_ij` and each
//!   measurement's free probability `q_j`.
//! - Bernoulli `i` becomes the moment match of "missed" (`r_i(1 − P_D)/(1 − r_i P_D)`, weight
//!   `p_i0`) and "produced `z_j`" (existence 1, the EKF update, weight `p_ij`).
//! - Births: a position sensor's measurement `j` starts a Bernoulli of existence
//!   `q_j e_j/(λ_c f_c + e_j)` from the Poisson intensity `λ_u` of undetected targets (a
//!   Gaussian mixture, thinned by `1 − P_D` per scan); delay links start targets from the
//!   delays left free on several links ([`BirthGrid`]).
//! - Bernoullis below `prune` are dropped, at most `max_bernoullis` kept; the estimate is every
//!   Bernoulli with `r > existence_threshold`.

use alloc::vec;
use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{exp, Mat4, Real, Vec4};
use crate::track::multi::association::clustered_marginals;
use crate::track::multi::birth::BirthGrid;
use crate::track::multi::gaussian::{by_weight_desc, kalman_update, moment_match, Bernoulli};
use crate::track::multi::sensors::{Detection, MeasurementModel};
use crate::track::multi::{check_scan, Component, MultiConfig, TargetEstimate};
use crate::track::shared::predict_gaussian;

/// Most components of the undetected-target intensity kept.
pub const MAX_UNDETECTED_COMPONENTS: usize = 64;

/// Where new targets come from.
#[derive(Debug, Clone)]
pub enum Births {
    /// A Poisson intensity of undetected targets (Gaussian mixture): at the start, and added
    /// at every scan (position sensors: each measurement may start a target).
    Poisson {
        /// `λ_u` before the first scan.
        initial: Vec<Component>,
        /// The birth intensity added at each prediction.
        per_scan: Vec<Component>,
    },
    /// Delays left free on several links ([`BirthGrid`]).
    Delays(BirthGrid),
}

/// The PMB tracker.
#[derive(Debug, Clone)]
pub struct Pmb {
    config: MultiConfig,
    births: Births,
    bernoullis: Vec<Bernoulli>,
    undetected: Vec<Component>,
    next_label: u64,
    scan: usize,
    /// Loopy BP iterations of the last scan (summed over sensors).
    pub last_bp_iterations: usize,
}

impl Pmb {
    /// A tracker with no target yet (validated settings).
    pub fn new(config: MultiConfig, births: Births) -> Result<Pmb> {
        config.validate()?;
        let undetected = match &births {
            Births::Poisson { initial, .. } => initial.clone(),
            Births::Delays(_) => Vec::new(),
        };
        Ok(Pmb {
            config,
            births,
            bernoullis: Vec::new(),
            undetected,
            next_label: 0,
            scan: 0,
            last_bp_iterations: 0,
        })
    }

    /// The Bernoullis (every hypothesised target, confirmed or not).
    pub fn bernoullis(&self) -> &[Bernoulli] {
        &self.bernoullis
    }

    /// One scan: predict by the CV model, update by each sensor's detections in turn, start
    /// new targets, prune. `scan[s]` holds sensor `s`'s detections. On error (a malformed
    /// scan) the tracker is unchanged.
    pub fn step<M: MeasurementModel>(&mut self, model: &M, scan: &[Vec<Detection>]) -> Result<()> {
        check_scan(model, scan)?;
        self.scan += 1;
        self.last_bp_iterations = 0;
        let motion = self.config.motion;
        let ps = self.config.survival;
        // The initial intensity is the prior at the first scan (no prediction before it).
        let first = self.scan == 1;
        for b in &mut self.bernoullis {
            b.existence *= ps;
            predict_gaussian(&mut b.state, &mut b.covariance, &motion);
        }
        if !first {
            for c in &mut self.undetected {
                c.weight *= ps;
                predict_gaussian(&mut c.state, &mut c.covariance, &motion);
            }
            if let Births::Poisson { per_scan, .. } = &self.births {
                self.undetected.extend(per_scan.iter().cloned());
                cap_components(&mut self.undetected);
            }
        }
        let mut free: Vec<Vec<(Real, Option<Real>)>> = vec![Vec::new(); scan.len()];
        for (s, dets) in scan.iter().enumerate() {
            let q = self.update_sensor(model, s, dets);
            free[s] = dets
                .iter()
                .zip(&q)
                .filter(|(_, q)| **q > 0.5)
                .map(|(d, _)| (d.value[0], d.sigma))
                .collect();
        }
        if let (Births::Delays(grid), Some((m, sigma))) = (&self.births, model.delay_model()) {
            let set = *grid.settings();
            let (pd, lc) = (model.detection_probability(), model.clutter_intensity(0));
            for fix in grid.search(m, &free, sigma) {
                let (vs, r) = (
                    set.velocity_sigma,
                    fix.existence(set.rate, &set.region, pd, lc),
                );
                let mut p = Mat4::zeros();
                p.fixed_view_mut::<2, 2>(0, 0).copy_from(&fix.covariance);
                p[(2, 2)] = vs * vs;
                p[(3, 3)] = vs * vs;
                let state = Vec4::new(fix.position.x, fix.position.y, 0.0, 0.0);
                self.push(r, state, p);
            }
        }
        self.prune();
        Ok(())
    }

    fn push(&mut self, existence: Real, state: Vec4, covariance: Mat4) {
        self.bernoullis.push(Bernoulli {
            label: self.next_label,
            existence,
            state,
            covariance,
            born: self.scan,
        });
        self.next_label += 1;
    }

    /// The update by sensor `s`; returns each measurement's free probability.
    fn update_sensor<M: MeasurementModel>(
        &mut self,
        model: &M,
        s: usize,
        dets: &[Detection],
    ) -> Vec<Real> {
        let (n, m) = (self.bernoullis.len(), dets.len());
        let pd = model.detection_probability();
        // The undetected targets' share of each measurement (position births).
        let mut e = vec![0.0; m];
        let mut born: Vec<Vec<(Real, Vec4, Mat4)>> = vec![Vec::new(); m];
        if !self.undetected.is_empty() {
            for (j, d) in dets.iter().enumerate() {
                for c in &self.undetected {
                    let obs = model.observe_detection(s, &c.state, d);
                    if let Some(u) = kalman_update(&c.state, &c.covariance, &obs, &d.value) {
                        let w = pd * c.weight * exp(u.log_likelihood);
                        if w > 0.0 {
                            e[j] += w;
                            born[j].push((w, u.state, u.covariance));
                        }
                    }
                }
            }
        }
        let mut psi = vec![0.0; n * m];
        let mut updated = vec![None; n * m];
        for (i, b) in self.bernoullis.iter().enumerate() {
            let obs0 = model.observe(s, &b.state, None);
            let r = b.existence;
            for (j, d) in dets.iter().enumerate() {
                let obs = match (d.sigma, d.rate_sigma) {
                    (None, None) => obs0,
                    _ => model.observe_detection(s, &b.state, d),
                };
                if let Some(u) = kalman_update(&b.state, &b.covariance, &obs, &d.value) {
                    if u.distance2 <= self.config.gate {
                        let lc = model.clutter_intensity_of(s, d);
                        let w = r * pd * exp(u.log_likelihood) / ((1.0 - r * pd) * (lc + e[j]));
                        if w.is_finite() && w > 0.0 {
                            psi[i * m + j] = w;
                            updated[i * m + j] = Some(u);
                        }
                    }
                }
            }
        }
        let marg = clustered_marginals(&psi, n, m, self.config.exact_cluster);
        self.last_bp_iterations += marg.iterations;
        for (i, b) in self.bernoullis.iter_mut().enumerate() {
            let row = &marg.track[i * (m + 1)..(i + 1) * (m + 1)];
            let r = b.existence;
            let r0 = r * (1.0 - pd) / (1.0 - r * pd);
            let mut parts = vec![(row[0] * r0, b.state, b.covariance)];
            for j in 0..m {
                if let Some(u) = updated[i * m + j] {
                    if row[j + 1] > 0.0 {
                        parts.push((row[j + 1], u.state, u.covariance));
                    }
                }
            }
            let total: Real = parts.iter().map(|p| p.0).sum();
            b.existence = total.min(1.0);
            if total > 0.0 && parts.len() > 1 {
                let best = (1..parts.len())
                    .max_by(|&a, &c| parts[a].0.total_cmp(&parts[c].0).then(c.cmp(&a)))
                    .unwrap_or(0);
                let det: Real = parts[1..].iter().map(|p| p.0).sum();
                let kept = [parts[0], (det, parts[best].1, parts[best].2)];
                let parts = kept;
                let (x, p) = moment_match(&parts);
                b.state = x;
                b.covariance = p;
            }
        }
        for j in 0..m {
            if e[j] > 0.0 {
                let lc = model.clutter_intensity_of(s, &dets[j]);
                let r = marg.free[j] * e[j] / (lc + e[j]);
                if r > self.config.prune {
                    let (x, p) = moment_match(&born[j]);
                    self.push(r, x, p);
                }
            }
        }
        for c in &mut self.undetected {
            c.weight *= 1.0 - pd;
        }
        marg.free
    }

    fn prune(&mut self) {
        let keep = self.config.prune;
        self.bernoullis.retain(|b| b.existence >= keep);
        if self.bernoullis.len() > self.config.max_bernoullis {
            let w: Vec<Real> = self.bernoullis.iter().map(|b| b.existence).collect();
            let mut order = by_weight_desc(&w);
            order.truncate(self.config.max_bernoullis);
            order.sort_unstable();
            let old = core::mem::take(&mut self.bernoullis);
            self.bernoullis = order.into_iter().map(|i| old[i].clone()).collect();
        }
        self.undetected.retain(|c| c.weight > 1e-12);
    }

    /// The targets reported, in label order: the `n̂` Bernoullis of highest existence, where
    /// `n̂` maximises the cardinality distribution of the multi-Bernoulli (the Poisson-binomial
    /// of the existences, García-Fernández et al. 2018, estimator 2), each also above
    /// `existence_threshold`.
    pub fn estimates(&self) -> Vec<TargetEstimate> {
        let t = self.config.existence_threshold;
        let r: Vec<Real> = self.bernoullis.iter().map(|b| b.existence).collect();
        let n_hat = map_cardinality(&r);
        let mut order = by_weight_desc(&r);
        order.truncate(n_hat);
        let mut v: Vec<TargetEstimate> = order
            .into_iter()
            .filter(|&i| r[i] > t)
            .map(|i| TargetEstimate::from(&self.bernoullis[i]))
            .collect();
        v.sort_by_key(|e| e.label);
        v
    }
}

/// The most likely number of targets of a multi-Bernoulli with existences `r`: the argmax of
/// the Poisson-binomial `P(n)` (dynamic programming, O(len²)).
pub fn map_cardinality(r: &[Real]) -> usize {
    let mut p = vec![1.0];
    for &ri in r {
        let mut next = vec![0.0; p.len() + 1];
        for (n, &v) in p.iter().enumerate() {
            next[n] += v * (1.0 - ri);
            next[n + 1] += v * ri;
        }
        p = next;
    }
    let mut best = 0;
    for (n, &v) in p.iter().enumerate() {
        if v > p[best] {
            best = n;
        }
    }
    best
}

/// Merge the components within Mahalanobis distance² 4 of a heavier one (Vo & Ma's GM-PHD
/// merge, heaviest first), then keep the heaviest [`MAX_UNDETECTED_COMPONENTS`]
/// (deterministic order).
fn cap_components(c: &mut Vec<Component>) {
    let w: Vec<Real> = c.iter().map(|c| c.weight).collect();
    let order = by_weight_desc(&w);
    let mut taken = vec![false; c.len()];
    let mut merged = Vec::new();
    for &i in &order {
        if taken[i] {
            continue;
        }
        let Some(inv) = c[i].covariance.try_inverse() else {
            taken[i] = true;
            merged.push(c[i].clone());
            continue;
        };
        let mut parts = Vec::new();
        for &k in &order {
            let d = c[k].state - c[i].state;
            if !taken[k] && (d.transpose() * inv * d)[0] <= 4.0 {
                taken[k] = true;
                parts.push((c[k].weight, c[k].state, c[k].covariance));
            }
        }
        let weight: Real = parts.iter().map(|p| p.0).sum();
        let (state, covariance) = moment_match(&parts);
        merged.push(Component {
            weight,
            state,
            covariance,
        });
    }
    merged.truncate(MAX_UNDETECTED_COMPONENTS);
    *c = merged;
}
