//! A recording's estimates and statics over the model's links, whole (one [`Driver`] job per
//! recorded link: the links are independent, the snapshots of a link are not) or a few
//! snapshots at a time ([`EstimationRun`], the page's worker) — the same per-link work in the
//! same order, so both give the same bits.

use alloc::vec;
use alloc::vec::Vec;

use crate::channel::{Alignment, Band, EstimateWork, Recording, Snapshot, Stop, TrackedPath};
use crate::error::{Cancel, Error, Result};
use crate::math::Real;
use crate::measure::Model;
use crate::study::channel::front::{baselines, BandMap, LinkEstimates, LinkFront, LinkStatics};
use crate::study::channel::{FrontEndConfig, FrontEndCpi};
use crate::study::Driver;
use crate::track::gating::{Calibration, LinkCalibration};

/// The estimates of a recording: per snapshot and per link of the model (scenario link order)
/// the tracked paths; a link the recording does not hold has none.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingEstimates {
    /// Snapshot times, s.
    pub t_s: Vec<Real>,
    /// Per model link whether the recording holds it.
    pub recorded: Vec<bool>,
    /// `paths[s][p]`: link `p`'s paths in snapshot `s`, ascending in delay (in the front
    /// end's delay reference).
    pub paths: Vec<Vec<Vec<TrackedPath>>>,
    /// `noise_var[s][p]`: the noise variance the estimator used, W (0 for a link not recorded).
    pub noise_var: Vec<Vec<Real>>,
    /// `alignment[s][p]`: the snapshot's alignment to the background (C9 step 2; `None`
    /// without a background or for a link not recorded).
    pub alignment: Vec<Vec<Option<Alignment>>>,
    /// `work[s][p]`: what the estimation did against its bounds.
    pub work: Vec<Vec<EstimateWork>>,
}

/// How many link-snapshots ended at a bound of the estimator (returned what they had).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct BoundCounts {
    /// Link-snapshots estimated.
    pub link_snapshots: usize,
    /// … that reached `max_paths` with a peak above the threshold left.
    pub path_budget: usize,
    /// … whose refinement reached its sweep bound without converging.
    pub sweeps: usize,
    /// The most greedy passes of one link-snapshot (bound: `max_paths + 1` per pass, plus
    /// one per seed tried; twice that when aligned).
    pub max_passes: usize,
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

    /// The link-snapshots that ended at a bound, over the recorded links.
    pub fn bounds(&self) -> BoundCounts {
        let mut c = BoundCounts::default();
        for row in &self.work {
            for (p, w) in row.iter().enumerate() {
                if !self.recorded[p] {
                    continue;
                }
                c.link_snapshots += 1;
                c.path_budget += usize::from(w.stop == Stop::PathBudget);
                c.sweeps += usize::from(w.sweeps_capped);
                c.max_passes = c.max_passes.max(w.passes);
            }
        }
        c
    }
}

/// The static channel of a recording's links: the clusters gating uses (per model link; a link
/// not recorded has none) and per model link what the statics were made of.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelStatics {
    /// The static clusters (E4), in the front end's delay reference.
    pub calibration: Calibration,
    /// Per model link: the empty-area snapshots its statics used (0: a recursive background
    /// or none), whether a background is subtracted, the direct path's delay and σ in the
    /// background's time base (`los`), s. `None` for a link not recorded.
    pub links: Vec<Option<LinkStaticsInfo>>,
}

/// What one link's statics were made of.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LinkStaticsInfo {
    /// Empty-area snapshots averaged (0: recursive, from the walk itself).
    pub empty_snapshots: usize,
    /// Whether a background is subtracted (C9).
    pub background: bool,
    /// The direct path's delay in the background's time base, s (`los` with a background).
    pub los_delay_s: Option<Real>,
    /// Its σ, s.
    pub los_sigma_s: Option<Real>,
}

impl LinkStaticsInfo {
    pub(super) fn of(s: &LinkStatics) -> LinkStaticsInfo {
        LinkStaticsInfo {
            empty_snapshots: s.empty_snapshots,
            background: s.background.is_some(),
            los_delay_s: s.los_s.map(|l| l.0),
            los_sigma_s: s.los_s.map(|l| l.1),
        }
    }
}

/// A recording and the empty area's, checked and mapped onto a model.
#[derive(Debug, Clone)]
pub struct Prepared {
    pub(super) map: Vec<usize>,
    pub(super) band: BandMap,
    empty_band: Option<BandMap>,
    baseline_s: Vec<Real>,
    carrier_hz: Real,
    /// Scans of the recording (its snapshots over the CPI's).
    scans: usize,
}

/// The scans of `rec` under `cfg`: every snapshot, or with a CPI of `N` snapshots their count
/// over `N` ([`Error::InvalidFile`] of `cpi_snapshots` when `N` does not divide it).
pub fn scan_count(rec: &Recording, cfg: &FrontEndConfig) -> Result<usize> {
    let n = FrontEndCpi::per_scan(cfg.cpi);
    let s = rec.t_s.len();
    if !s.is_multiple_of(n) {
        return Err(Error::InvalidFile {
            field: "cpi_snapshots".into(),
            reason: alloc::format!(
                "the recording's {s} snapshots are not whole CPIs of {n} snapshots"
            ),
        });
    }
    Ok(s / n)
}

/// The time of each scan: its CPI's middle snapshot's (index `N/2`), or each snapshot's.
pub fn scan_times(rec: &Recording, cfg: &FrontEndConfig) -> Vec<Real> {
    let n = FrontEndCpi::per_scan(cfg.cpi);
    (0..rec.t_s.len() / n)
        .map(|k| rec.t_s[k * n + n / 2])
        .collect()
}

/// Checks `rec` (and `empty`) ([`Recording::validate`], their links on `model` — the same
/// links in the same order — and their bands), and that `cfg`'s statics have what they need
/// (`clusters` an empty area: [`Error::InvalidFile`] of `calibration`).
pub fn prepare(
    model: &Model,
    bandwidth_hz: Real,
    rec: &Recording,
    empty: Option<&Recording>,
    cfg: &FrontEndConfig,
) -> Result<Prepared> {
    if cfg.statics == super::StaticMode::Clusters && empty.is_none() {
        return Err(Error::InvalidFile {
            field: "calibration".into(),
            reason: "statics clusters: needs a recording of the empty area (a calibration \
                     recording, or a time range of the recording)"
                .into(),
        });
    }
    rec.validate()?;
    let map = rec.link_map(model)?;
    let band = Band::of_recording(rec, bandwidth_hz)?;
    let empty_band = match empty {
        Some(e) => {
            e.validate()?;
            e.link_map(model)?;
            if e.links != rec.links {
                return Err(Error::InvalidFile {
                    field: "calibration".into(),
                    reason: "its links (or their order) differ from the recording's".into(),
                });
            }
            Some(Band::of_recording(e, bandwidth_hz)?)
        }
        None => None,
    };
    let baseline_s = baselines(model, rec)?;
    let scans = scan_count(rec, cfg)?;
    Ok(Prepared {
        map,
        band,
        empty_band,
        baseline_s,
        carrier_hz: model.carrier_hz,
        scans,
    })
}

impl Prepared {
    /// The statics and the front end of recorded link `link`.
    pub(super) fn link(
        &self,
        rec: &Recording,
        empty: Option<&Recording>,
        link: usize,
        cfg: &FrontEndConfig,
        cancel: Cancel,
    ) -> Result<LinkFront> {
        let e = match (empty, &self.empty_band) {
            (Some(e), Some(b)) => Some((e, b)),
            _ => None,
        };
        let statics = LinkStatics::build(e, rec, &self.band, link, &self.baseline_s, cfg, cancel)?;
        Ok(LinkFront::new(rec, &self.band, link, cfg, statics)?.with_carrier(self.carrier_hz))
    }

    /// Scans of the recording.
    pub fn scans(&self) -> usize {
        self.scans
    }

    /// Recorded links.
    pub fn links(&self) -> usize {
        self.map.len()
    }
}

/// One recorded link, start to end.
fn link_run(
    p: &Prepared,
    rec: &Recording,
    empty: Option<&Recording>,
    link: usize,
    cfg: &FrontEndConfig,
    cancel: Cancel,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<(LinkStatics, LinkEstimates)> {
    let mut front = p.link(rec, empty, link, cfg, cancel)?;
    // Cancel and progress every 64 scans (well under 0.1 s of work).
    const EVERY: usize = 64;
    for s in 0..p.scans {
        if s % EVERY == 0 {
            cancel.check()?;
            if s > 0 {
                progress(EVERY);
            }
        }
        front.step(rec, &p.band.1, cancel)?;
    }
    let len = p.scans;
    progress(len - EVERY * (len.saturating_sub(1) / EVERY));
    Ok(front.finish())
}

/// The statics and estimates of every recorded link, assembled over `model`'s links.
fn assemble(
    model: &Model,
    t_s: Vec<Real>,
    map: &[usize],
    results: Vec<(LinkStatics, LinkEstimates)>,
) -> (ChannelStatics, RecordingEstimates) {
    let n = model.link_count();
    let snapshots = t_s.len();
    let mut est = RecordingEstimates {
        t_s,
        recorded: vec![false; n],
        paths: vec![vec![Vec::new(); n]; snapshots],
        noise_var: vec![vec![0.0; n]; snapshots],
        alignment: vec![vec![None; n]; snapshots],
        work: vec![vec![EstimateWork::default(); n]; snapshots],
    };
    let mut statics = ChannelStatics {
        calibration: Calibration {
            links: vec![LinkCalibration::default(); n],
        },
        links: vec![None; n],
    };
    for (link, (st, out)) in results.into_iter().enumerate() {
        let p = map[link];
        est.recorded[p] = true;
        statics.links[p] = Some(LinkStaticsInfo::of(&st));
        statics.calibration.links[p] = st.clusters;
        let rows = out
            .paths
            .into_iter()
            .zip(out.noise_var)
            .zip(out.alignment)
            .zip(out.work);
        for (s, (((l, v), a), w)) in rows.enumerate() {
            est.paths[s][p] = l;
            est.noise_var[s][p] = v;
            est.alignment[s][p] = a;
            est.work[s][p] = w;
        }
    }
    (statics, est)
}

/// The statics and estimates of every snapshot of `rec` on `model`'s links (C5, C6, C9/C7,
/// C10), one `driver` job per recorded link; `empty` the recording of the empty area
/// (`None`: a recursive background, or an error in `clusters` mode). `progress` is called with
/// the number of snapshots done since its last call (from any thread). Errors: the
/// recordings' ([`prepare`]), the front end's settings, [`Error::Cancelled`].
pub fn estimate_recording(
    model: &Model,
    bandwidth_hz: Real,
    rec: &Recording,
    empty: Option<&Recording>,
    cfg: &FrontEndConfig,
    driver: &mut impl Driver,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<(ChannelStatics, RecordingEstimates)> {
    cfg.validate()?;
    let p = prepare(model, bandwidth_hz, rec, empty, cfg)?;
    let mut results = Vec::with_capacity(p.links());
    driver.run(
        p.links(),
        1,
        &|link, cancel| link_run(&p, rec, empty, link, cfg, cancel, progress),
        &mut |r| results.push(r),
        &mut |_| {},
    )?;
    Ok(assemble(model, scan_times(rec, cfg), &p.map, results))
}

/// The paths of every snapshot of recorded link `link` of `rec` alone (C5 + C6), without a
/// scenario or statics (absolute delays): for a caller that holds responses but no network
/// (the Python package's `estimate`). `bandwidth_hz` is used by CIR recordings only
/// ([`Band::of_recording`]). Returns per snapshot the tracked paths (ascending in delay) and
/// the noise variance used. Errors: the recording's ([`Recording::validate`]),
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
    let cfg = FrontEndConfig {
        delay_reference: super::DelayReference::Absolute,
        ..*cfg
    };
    let statics = LinkStatics::none(cfg.delay_reference, 0.0);
    let mut front = LinkFront::new(rec, &band, link, &cfg, statics)?;
    let scans = scan_count(rec, &cfg)?;
    for s in 0..scans {
        if s % 64 == 0 {
            cancel.check()?;
            if s > 0 {
                progress(64);
            }
        }
        front.step(rec, &band.1, cancel)?;
    }
    let len = scans;
    progress(len - 64 * (len.saturating_sub(1) / 64));
    let (_, out) = front.finish();
    Ok((out.paths, out.noise_var))
}

/// [`estimate_recording`] a few snapshots at a time, for a caller that must return between
/// slices of work (the page's worker reports progress and obeys Stop between two calls of
/// [`EstimationRun::run`]): the same per-link work in the same order, so the finished result
/// equals [`estimate_recording`]'s.
#[derive(Debug, Clone)]
pub struct EstimationRun {
    prepared: Prepared,
    cfg: FrontEndConfig,
    current: Option<LinkFront>,
    results: Vec<(LinkStatics, LinkEstimates)>,
    snapshots: usize,
}

impl EstimationRun {
    /// The estimation of `rec` with the empty area `empty` (checked as
    /// [`estimate_recording`] does); nothing runs yet.
    pub fn new(
        model: &Model,
        bandwidth_hz: Real,
        rec: &Recording,
        empty: Option<&Recording>,
        cfg: &FrontEndConfig,
    ) -> Result<EstimationRun> {
        cfg.validate()?;
        let prepared = prepare(model, bandwidth_hz, rec, empty, cfg)?;
        Ok(EstimationRun {
            results: Vec::with_capacity(prepared.links()),
            snapshots: prepared.scans(),
            prepared,
            cfg: *cfg,
            current: None,
        })
    }

    /// Work units in all: recorded links × snapshots.
    pub fn total(&self) -> usize {
        self.prepared.links() * self.snapshots
    }

    /// Work units done.
    pub fn done(&self) -> usize {
        self.results.len() * self.snapshots + self.current.as_ref().map_or(0, LinkFront::done)
    }

    /// Whether every link is estimated.
    pub fn is_done(&self) -> bool {
        self.results.len() == self.prepared.links()
    }

    /// Estimates up to `units` more link-snapshots of `rec` with `empty` (the recordings given
    /// to [`EstimationRun::new`]; a link's statics are built with its first snapshot); returns
    /// whether the estimation is complete.
    pub fn run(
        &mut self,
        rec: &Recording,
        empty: Option<&Recording>,
        units: usize,
    ) -> Result<bool> {
        let mut left = units;
        while left > 0 && !self.is_done() {
            let link = self.results.len();
            if self.current.is_none() {
                self.current =
                    Some(
                        self.prepared
                            .link(rec, empty, link, &self.cfg, Cancel::NEVER)?,
                    );
            }
            if let Some(front) = self.current.as_mut() {
                front.step(rec, &self.prepared.band.1, Cancel::NEVER)?;
                left -= 1;
                if front.done() == self.snapshots {
                    let front = self.current.take().ok_or(Error::Cancelled)?;
                    self.results.push(front.finish());
                }
            }
        }
        Ok(self.is_done())
    }

    /// The statics and estimates of `rec` once done ([`Error::Cancelled`] before).
    pub fn finish(
        self,
        model: &Model,
        rec: &Recording,
    ) -> Result<(ChannelStatics, RecordingEstimates)> {
        if !self.is_done() {
            return Err(Error::Cancelled);
        }
        Ok(assemble(
            model,
            scan_times(rec, &self.cfg),
            &self.prepared.map,
            self.results,
        ))
    }
}
