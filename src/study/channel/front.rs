//! One recorded link through the front end: its statics (the background of C9 and the static
//! clusters that gate what is left of it, or C7's clusters of the empty area), then snapshot
//! after snapshot the residual (or the full response), the snapshot estimator (C5) seeded by
//! the link's path tracker (C6), and the delays in the chosen reference (C10).
//!
//! **Statics** (per recorded link):
//! - `background` with an empty-area recording: its coherent mean (C9 step 1); the static
//!   clusters are the mean's own paths found by one C5 fit at the noise of *one* snapshot (at
//!   most [`BACKGROUND_MAX_PATHS`]): exactly the paths whose shadowed copy a snapshot's residual
//!   can show — a weaker path's shadow is never detected, and its poorly known delay would gate
//!   metres of range — each with what such a copy measures in one snapshot,
//!   `σ̄ = max(C4 at its single-snapshot SNR, 0.05/B)` (C4 alone: the joint Fisher bound of a
//!   dense fit of diffuse multipath is metres wide where paths crowd within `1/B`). The noise
//!   of one snapshot is the recording's `noise_var`, else the estimator's median estimate on
//!   the first empty snapshot.
//! - `background` without one (recursive, C9 step 1): the mean starts at the walk's first
//!   snapshot; its clusters are that snapshot's paths within [`RECURSIVE_CLUSTER_DB`] of its
//!   strongest (the shadowable ones: a person's echo is 30–40 dB below the direct path).
//! - `clusters`: C7 on the empty recording's snapshot estimates (delay and amplitude).
//!
//! **Delay reference** (C10): with `los` the direct path's delay is the earliest path within
//! [`LOS_WITHIN_DB`] of the strongest — of the background once (`background`), or of each
//! snapshot (`clusters`); a delay `τ` becomes `τ − τ₀ + ‖t − r‖/c` (excess delays taken in
//! `[−span/4, 3·span/4)` of the unambiguous span) with `σ² + σ₀²`; a result `≤ 0` is dropped.
//! A snapshot whose direct path is not found (`clusters`) gives that link no delay.
//!
//! **Joint alignment**: when snapshots are aligned (`los`), the first alignment is made with
//! the dynamic part present and leaves the residual as that part minus its projection on the
//! background; `δ`, `g` and the strongest paths of the first fit are then refined together
//! ([`LinkBackground::joint_align`]) and the residual estimated again, seeded by the refined
//! delays.

// `!(x > 0.0)` is meant: a NaN must fail these checks as well.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use alloc::vec::Vec;

use crate::channel::{
    Alignment, Band, EstimateWork, Estimator, EstimatorConfig, LinkBackground, PathEstimate,
    PathTracker, Recording, ResponseMap, SnapshotEstimate, TrackedPath,
};
use crate::error::{limits, Cancel, Error, Result};
use crate::math::{db_to_linear, floor, log10, sqrt, Complex, Real, SPEED_OF_LIGHT};
use crate::study::channel::{DelayReference, FrontEndConfig, FrontEndCpi, StaticMode};
use crate::track::gating::{AmplitudeClusterConfig, DelayEstimate, LinkCalibration, StaticCluster};

mod cpi;

use cpi::{rates, Burst};

/// Most paths of the background's own fit (its static clusters).
pub const BACKGROUND_MAX_PATHS: usize = 32;
/// Without an empty-area recording: the first snapshot's paths within this of its strongest
/// are the static clusters, dB.
pub const RECURSIVE_CLUSTER_DB: Real = 30.0;
/// The direct path is the earliest path within this of the strongest, dB (C10 **\[choice\]**).
pub const LOS_WITHIN_DB: Real = 20.0;
/// Floor of a background cluster's σ̄, in units of `1/B`.
const BACKGROUND_SIGMA_FLOOR: Real = 0.05;

/// What the front end made of one recorded link, snapshot after snapshot.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LinkEstimates {
    /// The tracked paths (ascending in delay), in the output reference.
    pub paths: Vec<Vec<TrackedPath>>,
    /// The noise variance the estimator used, W.
    pub noise_var: Vec<Real>,
    /// The alignment to the background (`background` mode).
    pub alignment: Vec<Option<Alignment>>,
    /// What each snapshot's estimation did against its bounds (both passes when aligned).
    pub work: Vec<EstimateWork>,
}

impl LinkEstimates {
    fn with_capacity(n: usize) -> LinkEstimates {
        LinkEstimates {
            paths: Vec::with_capacity(n),
            noise_var: Vec::with_capacity(n),
            alignment: Vec::with_capacity(n),
            work: Vec::with_capacity(n),
        }
    }
}

/// The direct path's delay (C10).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Reference {
    /// Absolute delays.
    Absolute,
    /// `τ₀` and its σ, fixed (the background's), and the baseline delay.
    Fixed {
        tau0: Real,
        sigma0: Real,
        base: Real,
    },
    /// Found in each snapshot; the baseline delay.
    PerSnapshot { base: Real },
}

/// One recorded link's static channel (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct LinkStatics {
    /// The background (`background` mode).
    pub background: Option<LinkBackground>,
    /// The static clusters, in the output reference.
    pub clusters: LinkCalibration,
    /// The direct path's delay in the background's time base and its σ, s (`los` with a
    /// background).
    pub los_s: Option<(Real, Real)>,
    /// Snapshots of the empty area used (0: recursive).
    pub empty_snapshots: usize,
    reference: Reference,
}

/// A band and the map of its recording's samples.
pub type BandMap = (Band, ResponseMap);

/// The baseline delay `‖t − r‖/c` of recorded link `link`, s (`baseline_s[link]`).
fn check_link(baseline_s: &[Real], link: usize) -> Result<Real> {
    baseline_s.get(link).copied().ok_or(Error::IndexOutOfRange {
        field: "links",
        index: link,
        len: baseline_s.len(),
    })
}

/// The per-bin noise variance of recorded link `link` when the recording gives one.
fn given_noise(rec: &Recording, map: &ResponseMap, link: usize) -> Option<Real> {
    rec.noise_var
        .as_ref()
        .and_then(|v| v.get(link))
        .map(|&v| map.noise_var_of_taps(v))
}

/// `τ − τ₀ + base`, the excess delay taken in `[−span/4, 3·span/4)`.
fn relative(tau: Real, tau0: Real, base: Real, span: Real) -> Real {
    let e = tau - tau0;
    base + e - span * floor((e + 0.25 * span) / span)
}

/// The direct path among `paths`: of the paths within [`LOS_WITHIN_DB`] of the strongest, the
/// one furthest before the strongest, cyclically, by less than a quarter of the unambiguous
/// span `span` (delays are known modulo it: a free-running receiver's direct path may sit just
/// below the span's end while its echoes wrap to its start).
pub(super) fn los_of(paths: &[PathEstimate], span: Real) -> Option<&PathEstimate> {
    let top = paths
        .iter()
        .max_by(|a, b| a.alpha.norm_sqr().total_cmp(&b.alpha.norm_sqr()))?;
    let strongest = top.alpha.norm_sqr();
    if !(strongest > 0.0) {
        return None;
    }
    let within = strongest * db_to_linear(-LOS_WITHIN_DB);
    let before = |p: &PathEstimate| {
        let d = top.delay_s - p.delay_s;
        d - span * floor(d / span)
    };
    paths
        .iter()
        .filter(|p| p.alpha.norm_sqr() >= within && before(p) < 0.25 * span)
        .max_by(|a, b| before(a).total_cmp(&before(b)))
}

/// The mean power per bin of `h`.
fn mean_power(h: &[Complex]) -> Real {
    h.iter().map(|v| v.norm_sqr()).sum::<Real>() / h.len().max(1) as Real
}

impl LinkStatics {
    /// No statics: absolute delays, or (`los`) the direct path found in each snapshot.
    pub fn none(reference: DelayReference, base: Real) -> LinkStatics {
        LinkStatics {
            background: None,
            clusters: LinkCalibration::default(),
            los_s: None,
            empty_snapshots: 0,
            reference: match reference {
                DelayReference::Absolute => Reference::Absolute,
                DelayReference::Los => Reference::PerSnapshot { base },
            },
        }
    }

    /// The statics of a background (`bg`, of `empty` snapshots; 0 = recursive, its clusters
    /// limited to [`RECURSIVE_CLUSTER_DB`]) fitted by one C5 run on its mean at the noise of
    /// one snapshot (`single_noise`, per bin): it finds exactly the paths whose shadowed copy
    /// a snapshot's residual can show.
    fn of_background(
        bg: LinkBackground,
        band: &Band,
        cfg: &FrontEndConfig,
        empty: usize,
        base: Real,
        single_noise: Real,
        cancel: Cancel,
    ) -> Result<LinkStatics> {
        let mut est = Estimator::new(
            band.clone(),
            EstimatorConfig {
                max_paths: BACKGROUND_MAX_PATHS.max(cfg.estimator.max_paths),
                ..cfg.estimator
            },
        )?;
        let nv = (single_noise > 0.0).then_some(single_noise);
        let fit = est.estimate_floored(bg.mean(), nv, &[], mean_power(bg.mean()), cancel)?;
        let los = los_of(&fit.paths, band.unambiguous_s()).map(|p| (p.delay_s, p.sigma_s));
        let reference = match (cfg.delay_reference, los) {
            (DelayReference::Absolute, _) => Reference::Absolute,
            (DelayReference::Los, Some((tau0, sigma0))) => Reference::Fixed { tau0, sigma0, base },
            (DelayReference::Los, None) => {
                return Err(Error::InvalidFile {
                    field: "calibration".into(),
                    reason: "delay_reference los: the background has no direct path (no path \
                             above the estimator's threshold)"
                        .into(),
                })
            }
        };
        let strongest = fit
            .paths
            .iter()
            .map(|p| p.alpha.norm_sqr())
            .fold(0.0, Real::max);
        let keep = if empty == 0 {
            strongest * db_to_linear(-RECURSIVE_CLUSTER_DB)
        } else {
            0.0
        };

        let bw = band.len() as Real * band.spacing_hz();
        let span = band.unambiguous_s();
        let mut clusters = Vec::new();
        for p in fit.paths.iter().filter(|p| p.alpha.norm_sqr() >= keep) {
            let mean = match reference {
                Reference::Fixed { tau0, base, .. } => relative(p.delay_s, tau0, base, span),
                _ => p.delay_s,
            };
            if !limits::DELAY_S.contains(mean) {
                continue;
            }
            let amp = sqrt(p.alpha.norm_sqr());
            clusters.push(StaticCluster {
                mean_s: mean,
                sigma_s: band.delay_bound_s(p.snr).max(BACKGROUND_SIGMA_FLOOR / bw),
                count: empty.max(1),
                snapshots: empty.max(1),
                amplitude_db_mean: (amp > 0.0).then(|| 20.0 * log10(amp)),
                amplitude_db_sigma: None,
            });
        }
        Ok(LinkStatics {
            background: Some(bg),
            clusters: LinkCalibration::from_clusters(0, clusters)?,
            los_s: match reference {
                Reference::Fixed { tau0, sigma0, .. } => Some((tau0, sigma0)),
                _ => None,
            },
            empty_snapshots: empty,
            reference,
        })
    }

    /// The statics of recorded link `link` from the empty-area recording `empty` (`None`: the
    /// recursive background from the walk `rec`'s first snapshot; `clusters` mode needs
    /// `empty`). `baseline_s[link]` is the link's baseline delay.
    pub fn build(
        empty: Option<(&Recording, &BandMap)>,
        rec: &Recording,
        band_map: &BandMap,
        link: usize,
        baseline_s: &[Real],
        cfg: &FrontEndConfig,
        cancel: Cancel,
    ) -> Result<LinkStatics> {
        let base = check_link(baseline_s, link)?;
        let (band, map) = band_map;
        match (cfg.statics, empty) {
            (StaticMode::Background, Some((e, (eb, emap)))) => {
                if eb != band {
                    return Err(Error::InvalidFile {
                        field: "calibration".into(),
                        reason: "its band (freq_hz, system response, taps or tap0_s) differs \
                                 from the recording's: a background must be on the same bins"
                            .into(),
                    });
                }
                let mut hs = Vec::with_capacity(e.snapshot_count());
                for s in 0..e.snapshot_count() {
                    cancel.check()?;
                    let mut h = Vec::new();
                    emap.fill(e, s, link, &mut h)?;
                    hs.push(h);
                }
                let nv = given_noise(e, emap, link);
                // Asked between the snapshots the background aligns (a long empty recording).
                let (bg, _) = LinkBackground::from_snapshots(
                    band,
                    hs.iter()
                        .map(Vec::as_slice)
                        .take_while(|_| !cancel.requested()),
                    nv.unwrap_or(0.0),
                    cfg.align(),
                )?;
                cancel.check()?;
                let single = match nv {
                    Some(v) => v,
                    None => Estimator::new(band.clone(), cfg.estimator)?.noise_of(&hs[0])?,
                };
                LinkStatics::of_background(bg, band, cfg, e.snapshot_count(), base, single, cancel)
            }
            (StaticMode::Background, None) => {
                let mut h = Vec::new();
                map.fill(rec, 0, link, &mut h)?;
                let nv = given_noise(rec, map, link);
                let bg = LinkBackground::new(band, &h, nv.unwrap_or(0.0), cfg.align())?;
                let single = match nv {
                    Some(v) => v,
                    None => Estimator::new(band.clone(), cfg.estimator)?.noise_of(&h)?,
                };
                LinkStatics::of_background(bg, band, cfg, 0, base, single, cancel)
            }
            (StaticMode::Clusters, Some((e, ebm))) => {
                let mut front = LinkFront::new(
                    e,
                    ebm,
                    link,
                    cfg,
                    LinkStatics::none(cfg.delay_reference, base),
                )?;
                for _ in 0..e.snapshot_count() {
                    front.step(e, &ebm.1, cancel)?;
                }
                let lists: Vec<Vec<DelayEstimate>> = front
                    .out
                    .paths
                    .iter()
                    .map(|l| l.iter().map(|t| t.estimate.delay_estimate()).collect())
                    .collect();
                let bw = band.len() as Real * band.spacing_hz();
                let ccfg = AmplitudeClusterConfig::for_bandwidth(bw)?;
                let mut statics = LinkStatics::none(cfg.delay_reference, base);
                statics.clusters = LinkCalibration::from_estimates(link, &lists, &ccfg)?;
                statics.empty_snapshots = e.snapshot_count();
                Ok(statics)
            }
            (StaticMode::Clusters, None) => Err(Error::InvalidFile {
                field: "calibration".into(),
                reason: "statics clusters: needs a recording of the empty area (a calibration \
                         recording, or a time range of the recording)"
                    .into(),
            }),
        }
    }
}

/// One recorded link's estimation in progress: the estimator, the path tracker, the statics,
/// and what came out so far, snapshot after snapshot.
#[derive(Debug, Clone)]
pub struct LinkFront {
    link: usize,
    estimator: Estimator,
    tracker: PathTracker,
    statics: LinkStatics,
    given: Option<Real>,
    span: Real,
    background_time_s: Real,
    h: Vec<Complex>,
    r: Vec<Complex>,
    /// The CPI (issue 42 §2) and the carrier's wavelength, m (`None`: no Doppler is read, e.g.
    /// a link estimated without its scenario).
    cpi: Option<FrontEndCpi>,
    wavelength_m: Option<Real>,
    /// What came out (one entry per scan).
    pub out: LinkEstimates,
}

impl LinkFront {
    /// The front end of recorded link `link` of `rec` with `statics` (from
    /// [`LinkStatics::build`] or [`LinkStatics::none`]).
    pub fn new(
        rec: &Recording,
        (band, map): &BandMap,
        link: usize,
        cfg: &FrontEndConfig,
        statics: LinkStatics,
    ) -> Result<LinkFront> {
        Ok(LinkFront {
            link,
            estimator: Estimator::new(band.clone(), cfg.estimator)?,
            tracker: PathTracker::new(cfg.paths)?,
            given: given_noise(rec, map, link),
            span: band.unambiguous_s(),
            background_time_s: cfg.background_time_s,
            statics,
            h: Vec::new(),
            r: Vec::new(),
            cpi: cfg.cpi,
            wavelength_m: None,
            out: LinkEstimates::with_capacity(
                rec.snapshot_count() / FrontEndCpi::per_scan(cfg.cpi),
            ),
        })
    }

    /// The carrier whose wavelength turns a CPI's Doppler into range rates (D2): without it no
    /// range rate is read.
    pub fn with_carrier(mut self, carrier_hz: Real) -> LinkFront {
        self.wavelength_m = Some(SPEED_OF_LIGHT / carrier_hz);
        self
    }

    /// Scans done (snapshots without a CPI).
    pub fn done(&self) -> usize {
        self.out.paths.len()
    }

    /// The statics (its background after the recursive updates so far).
    pub fn statics(&self) -> &LinkStatics {
        &self.statics
    }

    /// The statics and what came out.
    pub fn finish(self) -> (LinkStatics, LinkEstimates) {
        (self.statics, self.out)
    }

    /// Estimates the next scan of the link (a snapshot, or with a CPI its snapshots: module
    /// docs of [`FrontEndCpi`]); `cancel` is asked inside the estimator
    /// ([`Estimator::estimate_floored`]).
    pub fn step(&mut self, rec: &Recording, map: &ResponseMap, cancel: Cancel) -> Result<()> {
        let k = self.out.paths.len();
        let n = FrontEndCpi::per_scan(self.cpi);
        let mid = |k: usize| k * n + n / 2;
        let s = mid(k);
        let estimated = map.fill(rec, s, self.link, &mut self.h)?;
        let prev = k.checked_sub(1).map(|p| rec.t_s[mid(p)]);
        let burst = match (self.cpi, self.wavelength_m) {
            (Some(_), Some(_)) => Some(Burst {
                rec,
                map,
                first: k * n,
            }),
            _ => None,
        };
        let (tracked, used, align, work) =
            self.estimate_filled_cpi(k, rec.t_s[s], prev, estimated, burst, cancel)?;
        self.out.paths.push(tracked);
        self.out.noise_var.push(used);
        self.out.alignment.push(align);
        self.out.work.push(work);
        Ok(())
    }

    /// Snapshot `s` of the link at `t_s` (the previous one at `prev_t_s`) from its response
    /// `h` (a CFR's bins, as [`ResponseMap::fill`] gives them): the same estimation as
    /// [`LinkFront::step`], returned instead of kept (the live run, `study::LiveRun`).
    pub(super) fn step_response(
        &mut self,
        s: usize,
        t_s: Real,
        prev_t_s: Option<Real>,
        h: &[Complex],
        cancel: Cancel,
    ) -> Result<LinkSnapshot> {
        self.h.clear();
        self.h.extend_from_slice(h);
        self.estimate_filled_cpi(s, t_s, prev_t_s, None, None, cancel)
    }

    /// Estimates scan `s` (at `t_s`, the previous at `prev_t_s`) of the response in `self.h`;
    /// `estimated` the map's out-of-band noise estimate; with a `burst`, each path's range rate
    /// over the scan's CPI.
    fn estimate_filled_cpi(
        &mut self,
        s: usize,
        t_s: Real,
        prev_t_s: Option<Real>,
        estimated: Option<Real>,
        burst: Option<Burst>,
        cancel: Cancel,
    ) -> Result<LinkSnapshot> {
        let cpi = self.cpi;
        let wavelength = self.wavelength_m;
        let link = self.link;
        let nv = self.given.or(estimated);
        let lambda = match prev_t_s {
            Some(t0) if s > 0 => {
                let dt = t_s - t0;
                Real::max(dt / self.background_time_s, 1.0 / (s + 1) as Real)
            }
            _ => 0.0,
        };
        let recursive = self.statics.empty_snapshots == 0;
        let span = self.span;
        let LinkFront {
            estimator,
            tracker,
            statics,
            h,
            r,
            ..
        } = self;
        let reference = statics.reference;
        let mut used = 0.0;
        let mut work = EstimateWork::default();
        let mut align = None;
        let tracked = tracker.step(t_s, |seeds| {
            let e = match statics.background.as_mut() {
                Some(bg) => {
                    // Seeds back in the background's time base.
                    let seeds: Vec<Real> = match reference {
                        Reference::Fixed { tau0, base, .. } => {
                            seeds.iter().map(|t| t - base + tau0).collect()
                        }
                        _ => seeds.to_vec(),
                    };
                    let mut a = bg.align(h)?;
                    bg.residual(h, &a, r)?;
                    let power = mean_power(h) / a.gain.norm_sqr().max(Real::MIN_POSITIVE);
                    let nvr = nv.map(|v| bg.residual_noise(v, &a));
                    let mut e = estimator.estimate_floored(r, nvr, &seeds, power, cancel)?;
                    if a != Alignment::NONE && !e.paths.is_empty() {
                        let fit: Vec<(Real, Complex)> =
                            e.paths.iter().map(|p| (p.delay_s, p.alpha)).collect();
                        let first = e.work;
                        let joint = bg.joint_align(h, &fit, &a, limits::JOINT_ALIGN_ITERATIONS)?;
                        a = joint.alignment;
                        bg.residual(h, &a, r)?;
                        let seeds: Vec<Real> = joint.paths.iter().map(|f| f.0).collect();
                        let nvr = nv.map(|v| bg.residual_noise(v, &a));
                        e = estimator.estimate_floored(r, nvr, &seeds, power, cancel)?;
                        e.work = merge_work(first, e.work);
                    }
                    if let (Some(b), Some(c), Some(l)) = (&burst, cpi, wavelength) {
                        rates(
                            &mut e,
                            b,
                            c,
                            l,
                            link,
                            |h, r| {
                                let a = bg.align(h)?;
                                bg.residual(h, &a, r)?;
                                Ok(())
                            },
                            estimator,
                            false,
                            span,
                        )?;
                    }
                    if recursive && s > 0 {
                        bg.update(lambda, nv.unwrap_or(0.0), &a);
                    }
                    align = Some(a);
                    e
                }
                None => {
                    let seeds: &[Real] = match reference {
                        Reference::PerSnapshot { .. } => &[],
                        _ => seeds,
                    };
                    let mut e = estimator.estimate_floored(h, nv, seeds, mean_power(h), cancel)?;
                    if let (Some(b), Some(c), Some(l)) = (&burst, cpi, wavelength) {
                        let per_snapshot = matches!(reference, Reference::PerSnapshot { .. });
                        rates(
                            &mut e,
                            b,
                            c,
                            l,
                            link,
                            |h, r| {
                                r.clear();
                                r.extend_from_slice(h);
                                Ok(())
                            },
                            estimator,
                            per_snapshot,
                            span,
                        )?;
                    }
                    e
                }
            };
            used = e.noise_var;
            work = e.work;
            Ok(in_reference(e, reference, span))
        })?;
        Ok((tracked, used, align, work))
    }
}

/// One link-snapshot's output: its tracked paths, the noise variance used, its alignment, the
/// estimation's work.
pub(super) type LinkSnapshot = (Vec<TrackedPath>, Real, Option<Alignment>, EstimateWork);

/// Both passes of an aligned snapshot.
fn merge_work(a: EstimateWork, b: EstimateWork) -> EstimateWork {
    EstimateWork {
        passes: a.passes + b.passes,
        sweeps: a.sweeps.max(b.sweeps),
        newton: a.newton.max(b.newton),
        sweeps_capped: a.sweeps_capped || b.sweeps_capped,
        stop: b.stop,
    }
}

/// A snapshot's estimate with its delays in `reference` (those `≤ 0` dropped).
fn in_reference(mut e: SnapshotEstimate, reference: Reference, span: Real) -> SnapshotEstimate {
    let (tau0, sigma0, base) = match reference {
        Reference::Absolute => {
            e.paths.retain(|p| p.delay_s > 0.0);
            return e;
        }
        Reference::Fixed { tau0, sigma0, base } => (tau0, sigma0, base),
        Reference::PerSnapshot { base } => match los_of(&e.paths, span) {
            Some(p) => (p.delay_s, p.sigma_s, base),
            None => {
                e.paths.clear();
                return e;
            }
        },
    };
    for p in &mut e.paths {
        p.delay_s = relative(p.delay_s, tau0, base, span);
        p.sigma_s = sqrt(p.sigma_s * p.sigma_s + sigma0 * sigma0);
    }
    e.paths.retain(|p| p.delay_s > 0.0);
    e.paths.sort_by(|a, b| a.delay_s.total_cmp(&b.delay_s));
    e
}

/// The baseline delays `‖t − r‖/c` of `rec`'s links on `model` (recording order): 3-D, with the
/// nodes' own heights, when they differ ([`crate::measure::Network::los_delay`]).
pub fn baselines(model: &crate::measure::Model, rec: &Recording) -> Result<Vec<Real>> {
    let map = rec.link_map(model)?;
    Ok(map
        .iter()
        .map(|&i| {
            let l = &model.network.links[i];
            let (t, r) = (
                model.network.transmitters[l.tx],
                model.network.receivers[l.rx],
            );
            let h = model.network.receivers_dz[l.rx] - model.network.transmitters_dz[l.tx];
            sqrt((t - r).norm_squared() + h * h) / SPEED_OF_LIGHT
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path(delay_s: Real, amp: Real) -> PathEstimate {
        PathEstimate {
            delay_s,
            alpha: Complex::new(amp, 0.0),
            sigma_s: 1e-11,
            snr: 1e4,
            range_rate: None,
        }
    }

    /// The direct path is found cyclically: at 1990 ns of a 2 µs span, before echoes that
    /// wrapped to 20–60 ns; a weaker earlier path within 20 dB wins, one 30 dB down does not.
    #[test]
    fn the_direct_path_is_found_across_the_wrap() {
        let span = 2e-6;
        let paths = [
            path(20e-9, 0.3),
            path(60e-9, 0.2),
            path(1990e-9, 1.0),
            path(1000e-9, 0.5),
        ];
        assert_eq!(los_of(&paths, span).unwrap().delay_s, 1990e-9);
        let paths = [path(100e-9, 1.0), path(90e-9, 0.2), path(80e-9, 0.02)];
        assert_eq!(los_of(&paths, span).unwrap().delay_s, 90e-9);
        assert!(los_of(&[], span).is_none());
    }

    #[test]
    fn relative_delays_keep_the_excess_in_the_quarter_span_window() {
        let span = 2e-6;
        let base = 40e-9;
        assert!((relative(130e-9, 100e-9, base, span) - 70e-9).abs() < 1e-18);
        // 20 ns before the direct path: −20 ns of excess, not span − 20 ns.
        assert!((relative(80e-9, 100e-9, base, span) - 20e-9).abs() < 1e-18);
        // Wrapped: the direct path at 1990 ns, a path at 30 ns is 40 ns after it.
        assert!((relative(30e-9, 1990e-9, base, span) - 80e-9).abs() < 1e-15);
    }
}
