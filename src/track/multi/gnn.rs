//! The baseline of issue 41: global nearest neighbour association with one EKF per track and
//! M-of-N track management, as the passive-radar pipelines run it (per sensor one optimal
//! assignment, [`gnn_assignment`], on `−ln` likelihood ratios; hard EKF updates, S17).
//!
//! - A track is *detected* in a scan when at least half of the sensors (one for a position
//!   sensor) assigned it a measurement.
//! - A new track is tentative; it is confirmed when detected in `confirm_hits` of its first
//!   `confirm_window` scans (default 2 of 3), else dropped.
//! - A confirmed track is deleted after `delete_misses` scans in a row without detection
//!   (default 3).
//! - New tracks start from measurements no track took: each one of a position sensor, or a
//!   [`BirthGrid`] fix on the delays left on several links.

use alloc::vec;
use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::{ln, Mat4, Real, Vec4};
use crate::track::multi::association::gnn_assignment;
use crate::track::multi::birth::BirthGrid;
use crate::track::multi::gaussian::kalman_update;
use crate::track::multi::sensors::{Detection, MeasurementModel};
use crate::track::multi::{check_scan, MultiConfig, TargetEstimate, MAX_TRACKS};
use crate::track::shared::predict_gaussian;

/// Track management of the baseline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnnManagement {
    /// Detections needed among the first `confirm_window` scans (default 2).
    pub confirm_hits: usize,
    /// The confirmation window, scans (default 3).
    pub confirm_window: usize,
    /// Scans in a row without detection that delete a confirmed track (default 3).
    pub delete_misses: usize,
    /// A new track's velocity σ per axis, m/s (position births; default 1).
    pub velocity_sigma: Real,
}

impl Default for GnnManagement {
    fn default() -> Self {
        GnnManagement {
            confirm_hits: 2,
            confirm_window: 3,
            delete_misses: 3,
            velocity_sigma: 1.0,
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
struct GnnTrack {
    label: u64,
    state: Vec4,
    covariance: Mat4,
    age: usize,
    hits: usize,
    misses_in_row: usize,
    confirmed: bool,
}

/// The GNN tracker.
#[derive(Debug, Clone)]
pub struct Gnn {
    config: MultiConfig,
    management: GnnManagement,
    grid: Option<BirthGrid>,
    tracks: Vec<GnnTrack>,
    next_label: u64,
}

impl Gnn {
    /// A tracker with no track; `grid` starts tracks from delays (else from each free
    /// position measurement).
    pub fn new(
        config: MultiConfig,
        management: GnnManagement,
        grid: Option<BirthGrid>,
    ) -> Result<Gnn> {
        config.validate()?;
        if management.confirm_hits == 0
            || management.confirm_hits > management.confirm_window
            || management.delete_misses == 0
        {
            return Err(Error::SizeLimit {
                field: "confirm_hits",
                value: management.confirm_hits,
                min: 1,
                max: management.confirm_window,
            });
        }
        Ok(Gnn {
            config,
            management,
            grid,
            tracks: Vec::new(),
            next_label: 0,
        })
    }

    /// One scan: predict, per sensor assign and update, manage, start new tracks. On error (a
    /// malformed scan) the tracker is unchanged.
    pub fn step<M: MeasurementModel>(&mut self, model: &M, scan: &[Vec<Detection>]) -> Result<()> {
        check_scan(model, scan)?;
        let motion = self.config.motion;
        for t in &mut self.tracks {
            predict_gaussian(&mut t.state, &mut t.covariance, &motion);
            t.age += 1;
        }
        let pd = model.detection_probability();
        let mut counts = vec![0usize; self.tracks.len()];
        let mut free: Vec<Vec<(Real, Option<Real>)>> = vec![Vec::new(); scan.len()];
        let mut taken_all: Vec<Vec<bool>> = vec![Vec::new(); scan.len()];
        for (s, dets) in scan.iter().enumerate() {
            let (n, m) = (self.tracks.len(), dets.len());
            let mut cost = vec![None; n * m];
            let mut updated = vec![None; n * m];
            for (i, t) in self.tracks.iter().enumerate() {
                for (j, d) in dets.iter().enumerate() {
                    let obs = model.observe_detection(s, &t.state, d);
                    if let Some(u) = kalman_update(&t.state, &t.covariance, &obs, &d.value) {
                        if u.distance2 <= self.config.gate {
                            let lc = model.clutter_intensity_of(s, d);
                            // −ln(P_D 𝒩 / (λ_c f_c (1 − P_D))): negative when the pair beats
                            // "missed and clutter".
                            let c = -(ln(pd / (1.0 - pd)) + u.log_likelihood - ln(lc));
                            if c.is_finite() {
                                cost[i * m + j] = Some(c);
                                updated[i * m + j] = Some(u);
                            }
                        }
                    }
                }
            }
            let a = gnn_assignment(&cost, n, m);
            let taken = &mut taken_all[s];
            *taken = vec![false; m];
            for (i, j) in a.into_iter().enumerate() {
                if let Some(j) = j {
                    if let Some(u) = updated[i * m + j] {
                        self.tracks[i].state = u.state;
                        self.tracks[i].covariance = u.covariance;
                        counts[i] += 1;
                        taken[j] = true;
                    }
                }
            }
            free[s] = dets
                .iter()
                .zip(taken.iter())
                .filter(|(_, t)| !**t)
                .map(|(d, _)| (d.value[0], d.sigma))
                .collect();
        }
        let need = scan.len().div_ceil(2).max(1);
        let g = self.management;
        for (t, &c) in self.tracks.iter_mut().zip(&counts) {
            if c >= need {
                t.hits += 1;
                t.misses_in_row = 0;
            } else {
                t.misses_in_row += 1;
            }
            if !t.confirmed && t.hits >= g.confirm_hits {
                t.confirmed = true;
            }
        }
        self.tracks.retain(|t| {
            if t.confirmed {
                t.misses_in_row < g.delete_misses
            } else {
                // Still able to reach confirm_hits inside the window.
                t.age < g.confirm_window && t.hits + (g.confirm_window - t.age) >= g.confirm_hits
            }
        });
        // New tracks.
        match (&self.grid, model.delay_model()) {
            (Some(grid), Some((m, sigma))) => {
                let vs = grid.settings().velocity_sigma;
                for fix in grid.search(m, &free, sigma) {
                    let mut p = Mat4::zeros();
                    p.fixed_view_mut::<2, 2>(0, 0).copy_from(&fix.covariance);
                    p[(2, 2)] = vs * vs;
                    p[(3, 3)] = vs * vs;
                    self.start(Vec4::new(fix.position.x, fix.position.y, 0.0, 0.0), p);
                }
            }
            _ => {
                let vs = g.velocity_sigma;
                for (s, dets) in scan.iter().enumerate() {
                    for (d, _) in dets.iter().zip(&taken_all[s]).filter(|(_, t)| !**t) {
                        let obs = model.observe(s, &Vec4::zeros(), d.sigma);
                        let mut p = Mat4::zeros();
                        p[(0, 0)] = obs.noise[0];
                        p[(1, 1)] = obs.noise[1];
                        p[(2, 2)] = vs * vs;
                        p[(3, 3)] = vs * vs;
                        self.start(Vec4::new(d.value[0], d.value[1], 0.0, 0.0), p);
                    }
                }
            }
        }
        Ok(())
    }

    fn start(&mut self, state: Vec4, covariance: Mat4) {
        if self.tracks.len() >= MAX_TRACKS.min(self.config.max_bernoullis) {
            return;
        }
        self.tracks.push(GnnTrack {
            label: self.next_label,
            state,
            covariance,
            age: 0,
            hits: 1,
            misses_in_row: 0,
            confirmed: false,
        });
        self.next_label += 1;
    }

    /// The confirmed tracks, in label order.
    pub fn estimates(&self) -> Vec<TargetEstimate> {
        self.tracks
            .iter()
            .filter(|t| t.confirmed)
            .map(|t| TargetEstimate {
                label: t.label,
                state: t.state,
                covariance: t.covariance,
                existence: 1.0,
            })
            .collect()
    }
}
