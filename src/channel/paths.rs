//! Path tracking over snapshots (C6 **\[choice\]**: one Kalman filter per path, KEST-like).
//!
//! Per link, every path track carries the state `x = [τ, τ̇]` (s, s/s) with a constant-velocity
//! model in delay: over `Δt`, `F = [[1, Δt], [0, 1]]` and the process noise of a white
//! delay-acceleration of intensity `q_τ` (s²/s³), `Q = q_τ·[[Δt³/3, Δt²/2], [Δt²/2, Δt]]`. The
//! default `q_τ = (a/c)²` with `a = 2 m/s²` covers a walker's bistatic-range acceleration:
//! under this model the delay rate random-walks by `√(q_τ·Δt) = (a/c)·√Δt` over `Δt`, which
//! equals the rate change `(a/c)·Δt` of a steady acceleration `a` at `Δt = 1 s` and exceeds it
//! at the shorter snapshot spacings of recordings.
//!
//! One [`PathTracker::step`] per snapshot:
//! 1. predict every live track to the snapshot time `t_s`;
//! 2. call the estimator with the predicted delays of the live (confirmed and tentative) tracks
//!    as seeds, in track order (C6: the prediction seeds the refinement of its path);
//! 3. associate the returned paths to tracks by gated nearest neighbour: the pairs with
//!    normalised distance `d = |τ̂ − τ_pred|/√(P_ττ + σ̂²) ≤ gate` are taken greedily in
//!    ascending `d` (global nearest first; ties by track, then estimate order), each track and
//!    each estimate at most once;
//! 4. update each associated track with its estimate (measurement `τ̂`, variance `σ̂²`, Joseph
//!    form `P = (I − KH)P(I − KH)ᵀ + KRKᵀ`);
//! 5. start a tentative track from every unassociated estimate (`τ = τ̂`, `σ_τ = σ̂`, `τ̇ = 0`
//!    with `σ_τ̇` = [`PathTrackerConfig::rate_sigma`], default `4/c` s/s: a walker at up to
//!    about 2 m/s changes its bistatic range by up to about 4 m/s);
//! 6. confirm a track once it has `M` hits among its last `N` snapshots (the snapshot that
//!    started it counts as a hit; confirmed tracks stay confirmed), end it after `K`
//!    consecutive misses;
//! 7. keep at most [`PathTrackerConfig::max_tracks`] live tracks: past the cap the weakest
//!    (lowest last SNR) tentative track is dropped (a confirmed one only when no tentative one
//!    is left). An estimate whose new track is dropped at once still reports its (never reused)
//!    id, unconfirmed.
//!
//! Track ids are unique per tracker and increasing in the order tracks are started.

use alloc::vec::Vec;

use crate::channel::{PathEstimate, SnapshotEstimate};
use crate::error::{check_finite, limits, Error, Result};
use crate::math::{sqrt, Real, SPEED_OF_LIGHT};

/// Settings of the per-link path tracker (C6 **\[choice\]**).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathTrackerConfig {
    /// Association gate on `|τ̂ − τ_pred|/√(P_ττ + σ̂²)` (default 4).
    pub gate: Real,
    /// Confirm after `confirm_m` hits in the last `confirm_n` snapshots (default 3).
    pub confirm_m: usize,
    /// See `confirm_m` (default 4, at most 64).
    pub confirm_n: usize,
    /// End a track after this many consecutive misses (default 5).
    pub end_misses: usize,
    /// Process-noise intensity `q_τ` of the delay acceleration, s²/s³ (default `(2/c)²`: a
    /// walker's ~2 m/s² bistatic-range acceleration); `0` for a deterministic constant rate.
    pub process_noise: Real,
    /// Prior standard deviation of a new track's delay rate `τ̇` (which starts at 0), s/s
    /// (default `4/c`).
    pub rate_sigma: Real,
    /// Largest number of live tracks (default 64, at most [`limits::MAX_PATH_TRACKS`]).
    pub max_tracks: usize,
}

impl Default for PathTrackerConfig {
    fn default() -> Self {
        PathTrackerConfig {
            gate: 4.0,
            confirm_m: 3,
            confirm_n: 4,
            end_misses: 5,
            process_noise: (2.0 / SPEED_OF_LIGHT) * (2.0 / SPEED_OF_LIGHT),
            rate_sigma: 4.0 / SPEED_OF_LIGHT,
            max_tracks: 64,
        }
    }
}

impl PathTrackerConfig {
    /// Checks the settings: a finite gate and rate σ `> 0`, a finite process noise `≥ 0`,
    /// `1 ≤ confirm_m ≤ confirm_n ≤ 64`, `end_misses ≥ 1`, `1 ≤ max_tracks ≤`
    /// [`limits::MAX_PATH_TRACKS`].
    pub fn validate(&self) -> Result<()> {
        for (field, v) in [
            ("paths.gate", self.gate),
            ("paths.rate_sigma", self.rate_sigma),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::NotPositive {
                    field: field.into(),
                    value: v,
                });
            }
        }
        if !(self.process_noise.is_finite() && self.process_noise >= 0.0) {
            return Err(Error::OutOfRange {
                field: "paths.process_noise".into(),
                value: self.process_noise,
                allowed: "finite and ≥ 0 s²/s³",
            });
        }
        let sizes: [(&'static str, usize, usize, usize); 4] = [
            ("paths.confirm_n", self.confirm_n, 1, 64),
            ("paths.confirm_m", self.confirm_m, 1, self.confirm_n.max(1)),
            ("paths.end_misses", self.end_misses, 1, usize::MAX),
            (
                "paths.max_tracks",
                self.max_tracks,
                1,
                limits::MAX_PATH_TRACKS,
            ),
        ];
        for (field, value, min, max) in sizes {
            if !(min..=max).contains(&value) {
                return Err(Error::SizeLimit {
                    field,
                    value,
                    min,
                    max,
                });
            }
        }
        Ok(())
    }
}

/// One path of a snapshot with its track.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackedPath {
    /// The snapshot estimate.
    pub estimate: PathEstimate,
    /// The path track's id (unique per tracker, increasing in start order).
    pub track_id: u32,
    /// Whether the track is confirmed (C6: `M` hits in `N` snapshots).
    pub confirmed: bool,
    /// The track's filtered delay after this snapshot's update, s.
    pub filtered_delay_s: Real,
    /// Its standard deviation `√P_ττ`, s.
    pub filtered_sigma_s: Real,
}

/// One path track: a two-state Kalman filter and its hit record.
#[derive(Debug, Clone)]
struct Track {
    id: u32,
    /// `[τ, τ̇]` at `t_s`.
    x: [Real; 2],
    /// Covariance of `x` (symmetric, row-major).
    p: [[Real; 2]; 2],
    t_s: Real,
    /// Bit `i` set: a hit `i` snapshots ago (bit 0 = the latest).
    hits: u64,
    misses: usize,
    confirmed: bool,
    /// SNR of the latest associated estimate (ranks tracks for the cap).
    snr: Real,
}

impl Track {
    /// Prediction to `t_s` (CV model, white delay acceleration of intensity `q`).
    fn predict(&mut self, t_s: Real, q: Real) {
        let dt = t_s - self.t_s;
        let [[p00, p01], [_, p11]] = self.p;
        let a00 = p00 + 2.0 * dt * p01 + dt * dt * p11;
        let a01 = p01 + dt * p11;
        let (dt2, dt3) = (dt * dt, dt * dt * dt);
        self.x = [self.x[0] + dt * self.x[1], self.x[1]];
        self.p = [
            [a00 + q * dt3 / 3.0, a01 + q * dt2 / 2.0],
            [a01 + q * dt2 / 2.0, p11 + q * dt],
        ];
        self.t_s = t_s;
    }

    /// Innovation variance `S = P_ττ + σ̂²`.
    fn innovation_var(&self, sigma_s: Real) -> Real {
        self.p[0][0] + sigma_s * sigma_s
    }

    /// Measurement update with `τ̂` of variance `r` (Joseph form, `H = [1, 0]`).
    fn update(&mut self, z: Real, r: Real) {
        let s = self.p[0][0] + r;
        let k = [self.p[0][0] / s, self.p[1][0] / s];
        let nu = z - self.x[0];
        self.x = [self.x[0] + k[0] * nu, self.x[1] + k[1] * nu];
        // A = I − K H = [[1 − k0, 0], [−k1, 1]]; P' = A P Aᵀ + r K Kᵀ.
        let a = [[1.0 - k[0], 0.0], [-k[1], 1.0]];
        let p = self.p;
        let mut ap = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                ap[i][j] = a[i][0] * p[0][j] + a[i][1] * p[1][j];
            }
        }
        let mut out = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                out[i][j] = ap[i][0] * a[j][0] + ap[i][1] * a[j][1] + r * k[i] * k[j];
            }
        }
        let off = 0.5 * (out[0][1] + out[1][0]);
        self.p = [[out[0][0], off], [off, out[1][1]]];
    }

    /// Measurement update with a delay rate `τ̇ = ṙ/c` of variance `r` (issue 42 §2: the CPI's
    /// Doppler, `H = [0, 1]`): the same Joseph form with the roles of the states swapped.
    fn update_rate(&mut self, z: Real, r: Real) {
        self.swap();
        self.update(z, r);
        self.swap();
    }

    /// Swaps `τ` and `τ̇` (state and covariance).
    fn swap(&mut self) {
        self.x.swap(0, 1);
        let [[a, b], [_, d]] = self.p;
        self.p = [[d, b], [b, a]];
    }

    /// Both updates of an estimate: its delay, then its range rate if it has one.
    fn update_with(&mut self, e: &PathEstimate) {
        self.update(e.delay_s, e.sigma_s * e.sigma_s);
        if let Some(rate) = e.range_rate {
            let s = rate.sigma_mps / SPEED_OF_LIGHT;
            self.update_rate(rate.range_rate_mps / SPEED_OF_LIGHT, s * s);
        }
    }
}

/// The path tracker of one link (C6). It does not own the estimator: [`PathTracker::step`]
/// calls the one it is given with the tracks' predictions.
#[derive(Debug, Clone)]
pub struct PathTracker {
    cfg: PathTrackerConfig,
    tracks: Vec<Track>,
    next_id: u32,
    last_t_s: Option<Real>,
}

impl PathTracker {
    /// A tracker with `cfg` (validated: [`PathTrackerConfig::validate`]).
    pub fn new(cfg: PathTrackerConfig) -> Result<PathTracker> {
        cfg.validate()?;
        Ok(PathTracker {
            cfg,
            tracks: Vec::new(),
            next_id: 0,
            last_t_s: None,
        })
    }

    /// The settings.
    pub fn config(&self) -> &PathTrackerConfig {
        &self.cfg
    }

    /// Number of live (confirmed or tentative) tracks.
    pub fn live_tracks(&self) -> usize {
        self.tracks.len()
    }

    /// One snapshot at `t_s`: predict the tracks, call `estimate` with their predicted delays
    /// (s, in track order) as seeds, associate, update, start, confirm and end tracks (module
    /// docs). Returns one [`TrackedPath`] per returned estimate, ascending in delay. Errors: a
    /// non-finite `t_s` (`NonFinite`) or one not after the previous snapshot's (`OutOfRange`,
    /// field `paths.t_s`), the estimator's error, an estimate with a non-finite delay
    /// (`NonFinite`) or a `σ̂` not finite `> 0` (`NotPositive`). On error the tracker is
    /// unchanged.
    pub fn step(
        &mut self,
        t_s: Real,
        estimate: impl FnOnce(&[Real]) -> Result<SnapshotEstimate>,
    ) -> Result<Vec<TrackedPath>> {
        check_finite("paths.t_s", t_s)?;
        if let Some(last) = self.last_t_s {
            if t_s <= last {
                return Err(Error::OutOfRange {
                    field: "paths.t_s".into(),
                    value: t_s,
                    allowed: "after the previous snapshot's time",
                });
            }
        }
        let q = self.cfg.process_noise;
        let mut predicted = self.tracks.clone();
        for track in &mut predicted {
            track.predict(t_s, q);
        }
        let seeds: Vec<Real> = predicted.iter().map(|t| t.x[0]).collect();
        let snapshot = estimate(&seeds)?;
        let paths = snapshot.paths;
        for (i, e) in paths.iter().enumerate() {
            if !e.delay_s.is_finite() {
                return Err(Error::NonFinite {
                    field: alloc::format!("paths.estimate[{i}].delay_s"),
                });
            }
            if !(e.sigma_s.is_finite() && e.sigma_s > 0.0) {
                return Err(Error::NotPositive {
                    field: alloc::format!("paths.estimate[{i}].sigma_s"),
                    value: e.sigma_s,
                });
            }
        }
        self.last_t_s = Some(t_s);
        self.tracks = predicted;

        // Gated global-nearest-neighbour association (greedy in ascending distance).
        let mut pairs: Vec<(Real, usize, usize)> = Vec::new();
        for (ti, track) in self.tracks.iter().enumerate() {
            for (ei, e) in paths.iter().enumerate() {
                let d = (e.delay_s - track.x[0]).abs() / sqrt(track.innovation_var(e.sigma_s));
                if d <= self.cfg.gate {
                    pairs.push((d, ti, ei));
                }
            }
        }
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut track_of: Vec<Option<usize>> = alloc::vec![None; paths.len()];
        let mut taken = alloc::vec![false; self.tracks.len()];
        for &(_, ti, ei) in &pairs {
            if !taken[ti] && track_of[ei].is_none() {
                taken[ti] = true;
                track_of[ei] = Some(ti);
            }
        }

        let window: u64 = if self.cfg.confirm_n >= 64 {
            u64::MAX
        } else {
            (1u64 << self.cfg.confirm_n) - 1
        };
        let m = self.cfg.confirm_m as u32;
        for (ti, track) in self.tracks.iter_mut().enumerate() {
            track.hits <<= 1;
            if taken[ti] {
                track.hits |= 1;
                track.misses = 0;
            } else {
                track.misses += 1;
            }
        }
        for (ei, e) in paths.iter().enumerate() {
            if let Some(ti) = track_of[ei] {
                let track = &mut self.tracks[ti];
                track.update_with(e);
                track.snr = e.snr;
            }
        }
        // Outputs of the associated estimates, taken before tracks end or are dropped.
        let mut out: Vec<TrackedPath> = Vec::with_capacity(paths.len());
        for (ei, e) in paths.iter().enumerate() {
            if let Some(ti) = track_of[ei] {
                let track = &mut self.tracks[ti];
                if (track.hits & window).count_ones() >= m {
                    track.confirmed = true;
                }
                out.push(TrackedPath {
                    estimate: *e,
                    track_id: track.id,
                    confirmed: track.confirmed,
                    filtered_delay_s: track.x[0],
                    filtered_sigma_s: sqrt(track.p[0][0]),
                });
            }
        }
        let end = self.cfg.end_misses;
        self.tracks.retain(|t| t.misses < end);

        // New tentative tracks from the unassociated estimates.
        let rate_var = self.cfg.rate_sigma * self.cfg.rate_sigma;
        for (ei, e) in paths.iter().enumerate() {
            if track_of[ei].is_some() {
                continue;
            }
            let id = self.next_id;
            self.next_id = self.next_id.saturating_add(1);
            let confirmed = m <= 1;
            // A CPI's Doppler starts the track's delay rate (issue 42 §2).
            let (rate, var) = match e.range_rate {
                Some(r) => {
                    let s = r.sigma_mps / SPEED_OF_LIGHT;
                    (r.range_rate_mps / SPEED_OF_LIGHT, s * s)
                }
                None => (0.0, rate_var),
            };
            self.tracks.push(Track {
                id,
                x: [e.delay_s, rate],
                p: [[e.sigma_s * e.sigma_s, 0.0], [0.0, var]],
                t_s,
                hits: 1,
                misses: 0,
                confirmed,
                snr: e.snr,
            });
            out.push(TrackedPath {
                estimate: *e,
                track_id: id,
                confirmed,
                filtered_delay_s: e.delay_s,
                filtered_sigma_s: e.sigma_s,
            });
        }

        // The cap: drop the weakest tentative track (then the weakest confirmed one).
        while self.tracks.len() > self.cfg.max_tracks {
            let weakest = (0..self.tracks.len())
                .min_by(|&a, &b| {
                    let (ta, tb) = (&self.tracks[a], &self.tracks[b]);
                    ta.confirmed
                        .cmp(&tb.confirmed)
                        .then(ta.snr.total_cmp(&tb.snr))
                        .then(tb.id.cmp(&ta.id))
                })
                .unwrap_or(0);
            self.tracks.remove(weakest);
        }

        out.sort_by(|a, b| {
            a.estimate
                .delay_s
                .total_cmp(&b.estimate.delay_s)
                .then(a.track_id.cmp(&b.track_id))
        });
        Ok(out)
    }
}

#[cfg(test)]
mod tests;
