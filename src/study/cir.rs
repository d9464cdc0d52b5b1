//! From a channel recording to a track, as one use case (issue 25; spec C1–C7, §4, §6): every
//! recorded link's responses go through the snapshot estimator (C5) and that link's path
//! tracker (C6) ([`estimate_recording`], one driver job per link: the links are independent,
//! the snapshots of a link are not); the estimates of a recording of the empty area become the
//! static clusters in (delay, amplitude) (C7), against which every snapshot of the walk is gated
//! (E4) and associated (§4); the track starts from the first snapshot whose links give a
//! Levenberg–Marquardt fix (§5) and runs through any filter ([`cir_track`]). The CLI's
//! `cir estimate` and `cir track`, the page's channel view and library users call these.
//!
//! Delays are weighted with the estimator's own σ̂_τ (C4 at the fitted SNR) by default: it
//! comes from the data, where the link budget's σ (E8) needs the target's RCS and the radio's
//! losses, which a user of a recording rarely knows.

use alloc::format;
use alloc::string::ToString;
use alloc::vec;
use alloc::vec::Vec;

use serde::Serialize;

use crate::channel::{
    Band, DelayEstimate, Estimator, EstimatorConfig, PathTracker, PathTrackerConfig, Recording,
    ResponseMap, Snapshot, TrackedPath,
};
use crate::error::{check_every, Cancel, Error, Result};
use crate::math::{sqrt, Complex, Mat4, Real, Vec4, SPEED_OF_LIGHT};
use crate::measure::{rng, Model};
use crate::scenario::Area;
use crate::study::{Driver, TrackStart};
use crate::track::gating::{
    start_from_snapshot, AmplitudeClusterConfig, AssociationRule, Calibration, GatedTracker,
    Selection, START_SPEED_SIGMA_MPS,
};
use crate::track::{step_ns, ConstantVelocity, Filter, FilterKind, MeasurementNoise, Tracker};

/// The front end's settings: the snapshot estimator (C5) and the path tracker (C6).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrontEndConfig {
    /// The snapshot estimator.
    pub estimator: EstimatorConfig,
    /// The per-link path tracker.
    pub paths: PathTrackerConfig,
}

impl FrontEndConfig {
    /// The defaults ([S]'s estimator settings, the default path tracker) with `max_paths` and
    /// `p_fa` replaced where given — `cir estimate --max-paths --pfa` and the page's channel
    /// settings — validated ([`EstimatorConfig::validate`]'s named errors).
    pub fn with_overrides(max_paths: Option<usize>, p_fa: Option<Real>) -> Result<FrontEndConfig> {
        let mut cfg = FrontEndConfig::default();
        if let Some(k) = max_paths {
            cfg.estimator.max_paths = k;
        }
        if let Some(p) = p_fa {
            cfg.estimator.p_fa = p;
        }
        cfg.estimator.validate()?;
        Ok(cfg)
    }
}

/// The estimates of a recording: per snapshot and per link of the model (scenario link order)
/// the tracked paths; a link the recording does not hold has none.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingEstimates {
    /// Snapshot times, s.
    pub t_s: Vec<Real>,
    /// Per model link whether the recording holds it.
    pub recorded: Vec<bool>,
    /// `paths[s][p]`: link `p`'s paths in snapshot `s`, ascending in delay.
    pub paths: Vec<Vec<Vec<TrackedPath>>>,
    /// `noise_var[s][p]`: the noise variance the estimator used, W (0 for a link not recorded).
    pub noise_var: Vec<Vec<Real>>,
}

impl RecordingEstimates {
    /// Number of snapshots.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// Whether there is no snapshot.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// Snapshot `s` as gating reads it: every path (confirmed or not) with its delay, amplitude
    /// and σ̂_τ.
    pub fn snapshot(&self, s: usize) -> Snapshot {
        self.paths[s]
            .iter()
            .map(|l| l.iter().map(|t| t.estimate.delay_estimate()).collect())
            .collect()
    }

    /// Every snapshot ([`RecordingEstimates::snapshot`]).
    pub fn snapshots(&self) -> Vec<Snapshot> {
        (0..self.len()).map(|s| self.snapshot(s)).collect()
    }
}

/// One recorded link's estimation in progress (C5, C6): the estimator and path tracker of
/// that link and what they produced so far, snapshot after snapshot.
struct LinkRun {
    link: usize,
    estimator: Estimator,
    tracker: PathTracker,
    given: Option<Real>,
    h: Vec<Complex>,
    paths: Vec<Vec<TrackedPath>>,
    noise: Vec<Real>,
}

impl LinkRun {
    /// Recorded link `link` (index into the recording's links) of `rec`.
    fn new(
        rec: &Recording,
        (band, map): &(Band, ResponseMap),
        link: usize,
        cfg: &FrontEndConfig,
    ) -> Result<LinkRun> {
        Ok(LinkRun {
            link,
            estimator: Estimator::new(band.clone(), cfg.estimator)?,
            tracker: PathTracker::new(cfg.paths)?,
            given: rec
                .noise_var
                .as_ref()
                .map(|v| map.noise_var_of_taps(v[link])),
            h: Vec::new(),
            paths: Vec::with_capacity(rec.t_s.len()),
            noise: Vec::with_capacity(rec.t_s.len()),
        })
    }

    /// Estimates the next snapshot of the link (the frequency-domain response of C1; a CIR
    /// recording mapped by C2).
    fn step(&mut self, rec: &Recording, map: &ResponseMap) -> Result<()> {
        let s = self.paths.len();
        let estimated = map.fill(rec, s, self.link, &mut self.h)?;
        let nv = self.given.or(estimated);
        let mut used = 0.0;
        let (estimator, h) = (&mut self.estimator, &self.h);
        let tracked = self.tracker.step(rec.t_s[s], |seeds| {
            let e = estimator.estimate(h, nv, seeds)?;
            used = e.noise_var;
            Ok(e)
        })?;
        self.paths.push(tracked);
        self.noise.push(used);
        Ok(())
    }
}

/// The paths and noise variances of one recorded link, snapshot after snapshot.
fn link_paths(
    rec: &Recording,
    band_map: &(Band, ResponseMap),
    link: usize,
    cfg: &FrontEndConfig,
    cancel: Cancel,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<(Vec<Vec<TrackedPath>>, Vec<Real>)> {
    let mut run = LinkRun::new(rec, band_map, link, cfg)?;
    // Cancel and progress every 64 snapshots (≈ 0.1 s of work at 8 paths).
    const EVERY: usize = 64;
    for s in 0..rec.t_s.len() {
        if s % EVERY == 0 {
            cancel.check()?;
            if s > 0 {
                progress(EVERY);
            }
        }
        run.step(rec, &band_map.1)?;
    }
    // The snapshots after the last report (1 … EVERY of them).
    let len = rec.t_s.len();
    progress(len - EVERY * (len.saturating_sub(1) / EVERY));
    Ok((run.paths, run.noise))
}

/// The paths of every snapshot of recorded link `link` of `rec` alone (C5 + C6), without a
/// scenario: the estimation [`estimate_recording`] runs per link, for a caller that holds
/// responses but no network (the Python package's `estimate`). `bandwidth_hz` is used by CIR
/// recordings only ([`Band::of_recording`]). Returns per snapshot the tracked paths (ascending
/// in delay) and the noise variance used. Errors: the recording's ([`Recording::validate`]),
/// [`Error::IndexOutOfRange`] (`links`), the estimator's settings, [`Error::Cancelled`].
pub fn estimate_link(
    rec: &Recording,
    bandwidth_hz: Real,
    link: usize,
    cfg: &FrontEndConfig,
    cancel: Cancel,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<(Vec<Vec<TrackedPath>>, Vec<Real>)> {
    rec.validate()?;
    crate::error::checked_index("links", link, rec.links.len())?;
    let band = Band::of_recording(rec, bandwidth_hz)?;
    link_paths(rec, &band, link, cfg, cancel, progress)
}

/// The checks of an estimation: the recording ([`Recording::validate`]), its links on `model`
/// and its band.
fn prepare(
    model: &Model,
    bandwidth_hz: Real,
    rec: &Recording,
) -> Result<(Vec<usize>, (Band, ResponseMap))> {
    rec.validate()?;
    let map = rec.link_map(model)?;
    let band = Band::of_recording(rec, bandwidth_hz)?;
    Ok((map, band))
}

/// The estimates from each recorded link's results (in the recording's link order `map`).
fn assemble(
    model: &Model,
    rec: &Recording,
    map: &[usize],
    results: Vec<(Vec<Vec<TrackedPath>>, Vec<Real>)>,
) -> RecordingEstimates {
    let n = model.link_count();
    let snapshots = rec.t_s.len();
    let mut out = RecordingEstimates {
        t_s: rec.t_s.clone(),
        recorded: vec![false; n],
        paths: vec![vec![Vec::new(); n]; snapshots],
        noise_var: vec![vec![0.0; n]; snapshots],
    };
    for (link, (paths, noise)) in results.into_iter().enumerate() {
        let p = map[link];
        out.recorded[p] = true;
        for (s, (l, v)) in paths.into_iter().zip(noise).enumerate() {
            out.paths[s][p] = l;
            out.noise_var[s][p] = v;
        }
    }
    out
}

/// The estimates of every snapshot of `rec` on `model`'s links (C5, C6), one `driver` job per
/// recorded link; `progress` is called with the number of snapshots done since its last call
/// (from any thread). Errors: the recording's ([`Recording::validate`], a link the scenario
/// does not have), the estimator's settings, [`Error::Cancelled`].
pub fn estimate_recording(
    model: &Model,
    bandwidth_hz: Real,
    rec: &Recording,
    cfg: &FrontEndConfig,
    driver: &mut impl Driver,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<RecordingEstimates> {
    let (map, band) = prepare(model, bandwidth_hz, rec)?;
    let mut results = Vec::with_capacity(map.len());
    driver.run(
        map.len(),
        1,
        &|link, cancel| link_paths(rec, &band, link, cfg, cancel, progress),
        &mut |r| results.push(r),
        &mut |_| {},
    )?;
    Ok(assemble(model, rec, &map, results))
}

/// [`estimate_recording`] a few snapshots at a time, for a caller that must return between
/// slices of work (the page's worker reports progress and obeys Stop between two calls of
/// [`EstimationRun::run`]): the same per-link estimation in the same order, so the finished
/// estimates equal [`estimate_recording`]'s.
pub struct EstimationRun {
    map: Vec<usize>,
    band: (Band, ResponseMap),
    cfg: FrontEndConfig,
    current: Option<LinkRun>,
    results: Vec<(Vec<Vec<TrackedPath>>, Vec<Real>)>,
    snapshots: usize,
}

impl EstimationRun {
    /// The estimation of `rec` (checked as [`estimate_recording`] does); nothing runs yet.
    pub fn new(
        model: &Model,
        bandwidth_hz: Real,
        rec: &Recording,
        cfg: &FrontEndConfig,
    ) -> Result<EstimationRun> {
        let (map, band) = prepare(model, bandwidth_hz, rec)?;
        // The settings' errors now, not at the first slice.
        Estimator::new(band.0.clone(), cfg.estimator)?;
        PathTracker::new(cfg.paths)?;
        Ok(EstimationRun {
            results: Vec::with_capacity(map.len()),
            map,
            band,
            cfg: *cfg,
            current: None,
            snapshots: rec.t_s.len(),
        })
    }

    /// Work units in all: recorded links × snapshots.
    pub fn total(&self) -> usize {
        self.map.len() * self.snapshots
    }

    /// Work units done.
    pub fn done(&self) -> usize {
        self.results.len() * self.snapshots + self.current.as_ref().map_or(0, |r| r.paths.len())
    }

    /// Whether every link is estimated.
    pub fn is_done(&self) -> bool {
        self.results.len() == self.map.len()
    }

    /// Estimates up to `units` more link-snapshots of `rec` (the recording given to
    /// [`EstimationRun::new`]); returns whether the estimation is complete.
    pub fn run(&mut self, rec: &Recording, units: usize) -> Result<bool> {
        let mut left = units;
        while left > 0 && !self.is_done() {
            let link = self.results.len();
            if self.current.is_none() {
                self.current = Some(LinkRun::new(rec, &self.band, link, &self.cfg)?);
            }
            if let Some(run) = self.current.as_mut() {
                run.step(rec, &self.band.1)?;
                left -= 1;
                if run.paths.len() == self.snapshots {
                    let run = self.current.take().ok_or(Error::Cancelled)?;
                    self.results.push((run.paths, run.noise));
                }
            }
        }
        Ok(self.is_done())
    }

    /// The estimates of `rec` once done ([`Error::Cancelled`] before).
    pub fn finish(self, model: &Model, rec: &Recording) -> Result<RecordingEstimates> {
        if !self.is_done() {
            return Err(Error::Cancelled);
        }
        Ok(assemble(model, rec, &self.map, self.results))
    }
}

/// How `cir track` weights each delay.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DelaySigma {
    /// The estimator's own σ̂_τ (C4 at the fitted SNR): the default for recordings.
    #[default]
    Estimator,
    /// The link budget's σ at the prediction (E8: needs the scenario's RCS and radio).
    LinkBudget,
}

impl DelaySigma {
    /// The name in `TRACK.json` and on the CLI: `estimator`, `budget`.
    pub fn name(self) -> &'static str {
        match self {
            DelaySigma::Estimator => "estimator",
            DelaySigma::LinkBudget => "budget",
        }
    }
}

/// Default [`CirTrackRequest::extent_sigma_m`], m: a person's extent (body radius ≈ 0.2 m).
pub const EXTENT_SIGMA_M: Real = 0.2;

/// What [`cir_track`] runs on.
#[derive(Debug, Clone, Copy)]
pub struct CirTrackRequest<'a> {
    /// The measurement model of the scenario.
    pub model: &'a Model,
    /// The scenario's area (the start fix searches it).
    pub area: &'a Area,
    /// The static clusters of the empty area (e.g. [`calibrate_estimates`]).
    pub calibration: &'a Calibration,
    /// The estimates of the walk.
    pub estimates: &'a RecordingEstimates,
    /// The tracker.
    pub filter: FilterKind,
    /// Process-noise intensity `q̃` of the CV model (E7), m²/s³.
    pub process_noise: Real,
    /// How a link's candidates are associated.
    pub rule: AssociationRule,
    /// How each delay is weighted.
    pub sigma: DelaySigma,
    /// With [`DelaySigma::Estimator`]: the spread of the scatterer's own extent, as path length
    /// (m), added in quadrature to each estimate's σ̂ (a person is not a point: the strongest
    /// scattering centre moves over a body of radius ≈ 0.2 m, which moves the path length by up
    /// to ≈ 0.4 m, far more than σ̂_τ at tens of dB). Default [`EXTENT_SIGMA_M`].
    pub extent_sigma_m: Real,
    /// The particle filter's seed.
    pub seed: u64,
}

/// The track of a recording: one entry per snapshot; `null` before the track starts.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CirTrackOutput {
    /// Snapshot times, s.
    pub t_s: Vec<Real>,
    /// The estimates `[x, y, vx, vy]` after each snapshot's update (`null` before the start).
    pub states: Vec<Option<[Real; 4]>>,
    /// Their covariances (`null` before the start).
    pub covariances: Vec<Option<[[Real; 4]; 4]>>,
    /// Links used per snapshot.
    pub links_used: Vec<usize>,
    /// Per snapshot the delay taken per link (`null` = absent), s.
    pub delays_used_s: Vec<Vec<Option<Real>>>,
    /// Per snapshot the σ each used delay was weighted with, s (`null` = link absent; at the
    /// start snapshot the link budget's σ at the fix, which the LM fix weights with, §5).
    pub sigmas_used_s: Vec<Vec<Option<Real>>>,
    /// Per snapshot how each link was chosen (absent/single/nearest/strongest).
    pub choices: Vec<Vec<&'static str>>,
    /// Per snapshot per link the estimates discarded as static (E4).
    pub static_removed: Vec<Vec<usize>>,
    /// The snapshot the track started at and its LM fix (`null`: no snapshot gave one).
    pub start: Option<CirStart>,
}

/// Where a recording's track started.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CirStart {
    /// The snapshot index.
    pub snapshot: usize,
    /// Its time, s.
    pub t_s: Real,
    /// The fix.
    #[serde(flatten)]
    pub fix: TrackStart,
}

/// The static clusters of a recording of the empty area (C7): each link's estimates clustered
/// in (delay, amplitude in dB) by `cfg`.
pub fn calibrate_estimates(
    model: &Model,
    empty: &RecordingEstimates,
    cfg: &AmplitudeClusterConfig,
) -> Result<Calibration> {
    Calibration::from_estimates(&empty.snapshots(), model.link_count(), cfg)
}

/// Tracks a recording's estimates: gate and associate each snapshot, start from the first LM
/// fix, then filter with the CV model over each snapshot's time step. Asks `cancel` about every
/// millisecond of work.
pub fn cir_track(req: &CirTrackRequest, cancel: Cancel) -> Result<CirTrackOutput> {
    let (model, est) = (req.model, req.estimates);
    let n = model.link_count();
    req.calibration.check_links(n)?;
    if !(req.extent_sigma_m.is_finite() && req.extent_sigma_m >= 0.0) {
        return Err(Error::OutOfRange {
            field: "extent_sigma_m".into(),
            value: req.extent_sigma_m,
            allowed: "0 … finite m",
        });
    }
    let extent = req.extent_sigma_m / SPEED_OF_LIGHT;
    let snapshot = |k: usize| -> Snapshot {
        let mut s = est.snapshot(k);
        for e in s.iter_mut().flatten() {
            e.sigma_s = e.sigma_s.map(|v| sqrt(v * v + extent * extent));
        }
        s
    };
    let len = est.len();
    let mut out = CirTrackOutput {
        t_s: est.t_s.clone(),
        states: Vec::with_capacity(len),
        covariances: Vec::with_capacity(len),
        links_used: Vec::with_capacity(len),
        delays_used_s: Vec::with_capacity(len),
        sigmas_used_s: Vec::with_capacity(len),
        choices: Vec::with_capacity(len),
        static_removed: Vec::with_capacity(len),
        start: None,
    };
    let every = check_every(step_ns(req.filter, n));
    // Before the start: one fix attempt per snapshot.
    let mut k = 0;
    let fix = loop {
        if k == len {
            return Ok(out);
        }
        if k % every == 0 {
            cancel.check()?;
        }
        let start = start_from_snapshot(
            model,
            req.calibration,
            &snapshot(k),
            req.area,
            START_SPEED_SIGMA_MPS,
        );
        k += 1;
        match start {
            Ok(f) => break f,
            Err(_) => out.record(None, 0, None, vec![None; n]),
        }
    };
    let c = &fix.ekf.covariance;
    out.start = Some(CirStart {
        snapshot: k - 1,
        t_s: est.t_s[k - 1],
        fix: TrackStart {
            position_m: [fix.report.position.x, fix.report.position.y],
            covariance_m2: [[c[(0, 0)], c[(0, 1)]], [c[(1, 0)], c[(1, 1)]]],
            termination: fix.report.termination.as_str(),
            links_used: fix.report.links_used,
            choices: fix.selection.choices.iter().map(|c| c.name()).collect(),
            delays_used_s: fix.selection.delays.clone(),
        },
    });
    // The LM fix weights with the link budget's σ at the fix (§5).
    let at = fix.report.position;
    let sig = (0..n)
        .map(|p| fix.selection.delays[p].map(|_| model.sigma_delay(p, at)))
        .collect();
    let (x0, p0) = (fix.ekf.state, fix.ekf.covariance);
    out.record(
        Some((&x0, &p0)),
        fix.report.links_used,
        Some(fix.selection),
        sig,
    );
    let filter = Tracker::new(req.filter, x0, p0, rng(req.seed, 0))?;
    let motion = |k: usize| {
        ConstantVelocity::validated(est.t_s[k] - est.t_s[k - 1], req.process_noise).map_err(|e| {
            Error::InvalidFile {
                field: format!("t_s[{k}]"),
                reason: e.to_string(),
            }
        })
    };
    if k == len {
        return Ok(out);
    }
    let mut gated = GatedTracker::new(
        filter,
        model,
        req.calibration,
        motion(k)?,
        MeasurementNoise::AtPrediction,
        req.rule,
    )?
    .with_estimate_sigmas(req.sigma == DelaySigma::Estimator)
    .with_gate_sigma((req.sigma == DelaySigma::Estimator).then_some(extent));
    for k in k..len {
        if k % every == 0 {
            cancel.check()?;
        }
        gated.set_motion(motion(k)?);
        let step = gated.step(&snapshot(k)).map_err(|e| Error::InvalidFile {
            field: format!("snapshot {k}"),
            reason: e.to_string(),
        })?;
        let f = &gated.filter;
        out.record(
            Some((f.state(), f.covariance())),
            step.summary.links_used,
            Some(step.selection),
            step.sigmas_s,
        );
    }
    Ok(out)
}

impl CirTrackOutput {
    /// Appends one snapshot: the state and covariance (`None` before the start), the links
    /// used, what gating and association made of it (`None`: no attempt that counted, every
    /// link absent) and the σ of each used delay.
    fn record(
        &mut self,
        s: Option<(&Vec4, &Mat4)>,
        links_used: usize,
        selection: Option<Selection>,
        sigmas_s: Vec<Option<Real>>,
    ) {
        let n = sigmas_s.len();
        self.states.push(s.map(|(x, _)| (*x).into()));
        self.covariances
            .push(s.map(|(_, p)| core::array::from_fn(|i| core::array::from_fn(|j| p[(i, j)]))));
        self.links_used.push(links_used);
        self.sigmas_used_s.push(sigmas_s);
        match selection {
            Some(sel) => {
                self.choices
                    .push(sel.choices.iter().map(|c| c.name()).collect());
                self.delays_used_s.push(sel.delays);
                self.static_removed.push(sel.static_removed);
            }
            None => {
                self.choices.push(vec!["absent"; n]);
                self.delays_used_s.push(vec![None; n]);
                self.static_removed.push(vec![0; n]);
            }
        }
    }
}

/// The estimates of one snapshot as plain delay lists (the form `calibrate --snapshots` reads).
pub fn delays_only(snapshot: &[Vec<DelayEstimate>]) -> Vec<Vec<Real>> {
    snapshot
        .iter()
        .map(|l| l.iter().map(|e| e.delay_s).collect())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::channel::{simulate_recording, ChannelScene};
    use crate::scenario::presets;
    use crate::study::Sequential;

    /// 0.2 s of the hangar walk at 20 ms (11 snapshots) on sensors2019's 4 links.
    fn recording() -> (crate::Scenario, Model, Recording) {
        let s = presets::preset("sensors2019").unwrap();
        let m = Model::new(&s).unwrap();
        let mut scene = ChannelScene::hangar();
        scene.duration_s = Some(0.2);
        scene.dt_s = 0.02;
        let (rec, _) = simulate_recording(&s, &m, &scene, true, 3).unwrap();
        (s, m, rec)
    }

    #[test]
    fn the_sliced_estimation_equals_estimate_recording() {
        let (s, m, rec) = recording();
        let cfg = FrontEndConfig::default();
        let bw = s.radio.bandwidth_hz;
        let whole =
            estimate_recording(&m, bw, &rec, &cfg, &mut Sequential::new(), &|_| {}).unwrap();
        let mut run = EstimationRun::new(&m, bw, &rec, &cfg).unwrap();
        assert_eq!(run.total(), 4 * 11);
        let mut calls = 0;
        while !run.run(&rec, 3).unwrap() {
            calls += 1;
            assert_eq!(run.done(), 3 * calls);
        }
        assert_eq!(calls, 14); // 44 units in slices of 3: 14 partial slices, then the last
        assert_eq!(run.done(), run.total());
        assert_eq!(run.finish(&m, &rec).unwrap(), whole);
        // Unfinished: no estimates.
        let run = EstimationRun::new(&m, bw, &rec, &cfg).unwrap();
        assert_eq!(run.finish(&m, &rec), Err(Error::Cancelled));
    }

    #[test]
    fn a_time_range_of_a_recording_is_a_recording_of_its_snapshots() {
        let (_, _, rec) = recording();
        let part = rec
            .between("range", rec.t_s[3] - 1e-9, rec.t_s[5] + 1e-9)
            .unwrap();
        assert_eq!(part.t_s, rec.t_s[3..=5].to_vec());
        for s in 0..3 {
            for p in 0..4 {
                assert_eq!(part.response(s, p), rec.response(s + 3, p));
            }
        }
        part.validate().unwrap();
        let e = rec.between("range", 1.0, 2.0).unwrap_err().to_string();
        assert!(
            e.starts_with("range: no snapshot between 1 s and 2 s"),
            "{e}"
        );
        let e = rec.between("range", 0.1, 0.0).unwrap_err().to_string();
        assert_eq!(e, "range: 0 is out of range (t1 >= t0)");
        assert!(rec.between("range", f64::NAN, 0.0).is_err());
    }
}
