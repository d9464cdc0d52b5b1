//! The multi-target use case (issue 41 §2): a measurements file's `raw_steps` (every link's
//! unlabelled delays per scan; `initial_snapshot`, if present, is the first scan) tracked by
//! the PMB tracker or the GNN baseline ([`crate::track::multi`]), with static paths removed by
//! a calibration (E4, C9) first. The CLI's `track --targets auto`, the Python package's
//! `track_multi` and the page call this one function and print its document
//! ([`MultiTrackOutput`]): per scan the labelled targets, and per label its life (first and
//! last scan, why it started and ended).

use alloc::string::String;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::error::{Cancel, Error, Result};
use crate::formats::{Measurements, RawEstimate, RawStep};
use crate::measure::Model;
use crate::scenario::Area;
use crate::track::gating::{Calibration, LinkCalibration};
use crate::track::multi::{
    BirthGrid, Births, DelayBirth, DelayLinks, Detection, Gnn, GnnManagement, MultiConfig,
    MultiKind, MultiTracker, Pmb, Scan, TargetEstimate,
};

/// The settings of a multi-target track (JSON keys as the fields; all optional in files).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MultiSettings {
    /// `pmb` (default) or `gnn`.
    #[serde(with = "kind_name")]
    pub method: MultiKind,
    /// `P_D` per link (default 0.9).
    pub detection_probability: f64,
    /// Mean clutter delays per link and scan (default 5).
    pub clutter: f64,
    /// The window clutter is spread over, s (default 60 ns).
    pub clutter_window_s: f64,
    /// Where targets appear (default: the scenario's area).
    pub birth_region: Option<Area>,
    /// Expected new targets per scan (default 0.01).
    pub birth_rate: f64,
    /// Spacing of the birth grid, m (default 0.25).
    pub birth_grid_m: f64,
    /// Gated delays a birth needs (default: links − 2, at least 3).
    pub birth_min_links: Option<usize>,
    /// Survival probability per scan (default 0.99).
    pub survival: f64,
    /// A target is reported above this existence (default 0.5).
    pub existence_threshold: f64,
    /// Association marginals exact in clusters of at most this many tracks and delays, loopy
    /// BP beyond (default 6; 0 = BP everywhere; at most 8).
    pub exact_cluster: usize,
}

impl Default for MultiSettings {
    fn default() -> Self {
        MultiSettings {
            method: MultiKind::Pmb,
            detection_probability: 0.9,
            clutter: 5.0,
            clutter_window_s: 60e-9,
            birth_region: None,
            birth_rate: 0.01,
            birth_grid_m: 0.25,
            birth_min_links: None,
            survival: 0.99,
            existence_threshold: 0.5,
            exact_cluster: 6,
        }
    }
}

mod kind_name {
    use super::MultiKind;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(k: &MultiKind, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(k.name())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<MultiKind, D::Error> {
        let s = alloc::string::String::deserialize(d)?;
        MultiKind::parse(&s).map_err(serde::de::Error::custom)
    }
}

/// One reported target of a scan.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetDoc {
    /// Its label.
    pub label: u64,
    /// `[x, y, vx, vy]`, m and m/s.
    pub state: [f64; 4],
    /// Covariance, row-major.
    pub covariance: [[f64; 4]; 4],
    /// Existence probability (1 for the GNN's confirmed tracks).
    pub existence: f64,
}

impl From<&TargetEstimate> for TargetDoc {
    fn from(e: &TargetEstimate) -> Self {
        TargetDoc {
            label: e.label,
            state: e.state.into(),
            covariance: core::array::from_fn(|i| core::array::from_fn(|j| e.covariance[(i, j)])),
            existence: e.existence,
        }
    }
}

/// One labelled track's life.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LabelledTrack {
    /// Its label.
    pub label: u64,
    /// First and last scan it was reported at (0-based, inclusive).
    pub first_scan: usize,
    /// Last scan reported.
    pub last_scan: usize,
    /// Scans it was reported at.
    pub scans: usize,
    /// `confirmed` (its first report).
    pub start: String,
    /// `lost` (no longer reported before the end) or `end_of_data`.
    pub end: String,
}

/// The document of a multi-target track.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MultiTrackOutput {
    /// `pmb` or `gnn`.
    pub method: String,
    /// The settings used.
    pub settings: MultiSettings,
    /// Scan times `t_k = k T` (the initial snapshot, if any, is scan 0), s.
    pub t_s: Vec<f64>,
    /// Per scan, the reported targets in label order.
    pub targets: Vec<Vec<TargetDoc>>,
    /// Per label, its life, in label order.
    pub tracks: Vec<LabelledTrack>,
    /// Estimates removed as static by the calibration, per scan (all links).
    pub static_removed: Vec<usize>,
}

/// The scans of a measurements file for a multi-target track: the `initial_snapshot` (if any)
/// then every raw step, each as detections per link (static ones removed).
pub fn multi_scans(
    m: &Measurements,
    links: usize,
    calibration: Option<&Calibration>,
) -> Result<(Vec<Scan>, Vec<usize>)> {
    let Some(raw) = &m.raw_steps else {
        return Err(Error::InvalidFile {
            field: "raw_steps".into(),
            reason: "a multi-target track needs raw_steps (every link's delays per scan)".into(),
        });
    };
    if let Some(c) = calibration {
        c.check_links(links)?;
    }
    let mut scans = Vec::with_capacity(raw.len() + 1);
    let mut removed = Vec::with_capacity(raw.len() + 1);
    let all: Vec<(String, &RawStep)> = m
        .initial_snapshot
        .iter()
        .map(|s| (String::from("initial_snapshot"), s))
        .chain(
            raw.iter()
                .enumerate()
                .map(|(k, s)| (alloc::format!("raw_steps[{k}]"), s)),
        )
        .collect();
    if all.len() > crate::track::MAX_STEPS {
        return Err(Error::InvalidFile {
            field: "raw_steps".into(),
            reason: alloc::format!(
                "{} scans, at most {} are allowed",
                all.len(),
                crate::track::MAX_STEPS
            ),
        });
    }
    for (field, step) in all {
        crate::formats::one_list_per_link(&field, step.len(), links)?;
        let mut gone = 0;
        let scan = step
            .iter()
            .enumerate()
            .map(|(p, list)| {
                let estimates = list.iter().map(|e| match *e {
                    RawEstimate::Pair([d, _]) => (d, None, None),
                    RawEstimate::WithSigma([d, _, s]) => (d, Some(s), None),
                });
                link_detections(estimates, calibration.map(|c| &c.links[p]), &mut gone)
            })
            .collect();
        scans.push(scan);
        removed.push(gone);
    }
    Ok((scans, removed))
}

/// One link's estimates of a scan as the multi-target tracker's detections (the step of
/// [`multi_scans`] and of [`cir_track_multi`](crate::study::cir_track_multi)): each estimate
/// `(delay, σ, rate)` (s; σ in s where there is one; the range rate and its σ `(ṙ, σ_ṙ)`, m/s,
/// where the front end read one: issue 42 §3) is dropped, and counted in `gone`, where its
/// delay lies in one of the link's static clusters `statics` (E4), else is a
/// [`Detection::delay`], or a [`Detection::delay_rate`] with its rate.
pub(crate) fn link_detections(
    estimates: impl IntoIterator<Item = (f64, Option<f64>, Option<(f64, f64)>)>,
    statics: Option<&LinkCalibration>,
    gone: &mut usize,
) -> Vec<Detection> {
    estimates
        .into_iter()
        .filter_map(|(d, s, rate)| {
            if statics.is_some_and(|c| c.is_static(d)) {
                *gone += 1;
                return None;
            }
            Some(match rate {
                Some((r, r_sigma)) => Detection::delay_rate(d, s, r, r_sigma),
                None => Detection::delay(d, s),
            })
        })
        .collect()
}

/// The tracker of `settings` for `model` (`sigma_s`: the file's fixed σ per link).
pub fn multi_tracker(
    model: &Model,
    area: &Area,
    motion: crate::track::ConstantVelocity,
    settings: &MultiSettings,
    sigma_s: Option<&[f64]>,
) -> Result<MultiTracker> {
    let links = model.link_count();
    let cfg = MultiConfig {
        survival: settings.survival,
        existence_threshold: settings.existence_threshold,
        exact_cluster: settings.exact_cluster,
        ..MultiConfig::new(motion)
    };
    let mut birth = DelayBirth::new(settings.birth_region.unwrap_or(*area), links);
    birth.rate = settings.birth_rate;
    birth.step_m = settings.birth_grid_m;
    if let Some(k) = settings.birth_min_links {
        birth.min_links = k;
    }
    let grid = BirthGrid::new(model, birth, sigma_s)?;
    Ok(match settings.method {
        MultiKind::Pmb => MultiTracker::Pmb(Pmb::new(cfg, Births::Delays(grid))?),
        MultiKind::Gnn => MultiTracker::Gnn(Gnn::new(cfg, GnnManagement::default(), Some(grid))?),
    })
}

/// A measurements file tracked with several targets (see the module docs); asks `cancel`
/// between scans.
pub fn track_multi(
    model: &Model,
    area: &Area,
    m: &Measurements,
    calibration: Option<&Calibration>,
    settings: &MultiSettings,
    cancel: Cancel,
) -> Result<MultiTrackOutput> {
    track_multi_clocked(model, area, m, calibration, settings, cancel, &|| 0.0).map(|r| r.0)
}

/// Where [`track_multi_clocked`]'s time went, in the units of its clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MultiTiming {
    /// Building the tracker (the birth grid: once per model) and reading the scans.
    pub setup: f64,
    /// Tracking the scans.
    pub scans: f64,
}

/// [`track_multi`] timed by `clock` (e.g. milliseconds from the front end's timer): the same
/// output, and the time of the setup and of the scans.
pub fn track_multi_clocked(
    model: &Model,
    area: &Area,
    m: &Measurements,
    calibration: Option<&Calibration>,
    settings: &MultiSettings,
    cancel: Cancel,
    clock: &dyn Fn() -> f64,
) -> Result<(MultiTrackOutput, MultiTiming)> {
    let t0 = clock();
    let links = model.link_count();
    let motion = m.motion()?;
    let sigmas = m.sigmas(links)?;
    let (scans, static_removed) = multi_scans(m, links, calibration)?;
    let scans = Scans {
        scans: &scans,
        static_removed,
        dt_s: m.dt_s,
    };
    track_scans(
        model, area, motion, sigmas, scans, settings, cancel, clock, t0,
    )
}

/// Scans of detections ready for a multi-target tracker: per scan and link the detections
/// (delays, with a range rate where the front end read one: issue 42 §3), what the static
/// clusters removed from each scan, and the scan interval, s.
#[derive(Debug, Clone)]
pub struct Scans<'a> {
    /// Per scan, per link, the detections.
    pub scans: &'a [Scan],
    /// Per scan, the estimates the static clusters removed.
    pub static_removed: Vec<usize>,
    /// Scan interval, s.
    pub dt_s: f64,
}

/// The tracker of `settings` over `scans` (the loop of [`track_multi_clocked`], whose setup
/// time is counted from `t0`): the estimates of every scan, the labels' lives.
#[allow(clippy::too_many_arguments)]
pub fn track_scans(
    model: &Model,
    area: &Area,
    motion: crate::track::ConstantVelocity,
    sigmas: Option<Vec<f64>>,
    scans: Scans,
    settings: &MultiSettings,
    cancel: Cancel,
    clock: &dyn Fn() -> f64,
    t0: f64,
) -> Result<(MultiTrackOutput, MultiTiming)> {
    let sensors = DelayLinks::new(
        model,
        settings.detection_probability,
        settings.clutter,
        settings.clutter_window_s,
        sigmas.clone(),
    )?;
    let mut tracker = multi_tracker(model, area, motion, settings, sigmas.as_deref())?;
    let Scans {
        scans,
        static_removed,
        dt_s,
    } = scans;
    let t1 = clock();
    let mut targets = Vec::with_capacity(scans.len());
    let mut t_s = Vec::with_capacity(scans.len());
    for (k, scan) in scans.iter().enumerate() {
        cancel.check()?;
        tracker
            .step(&sensors, scan)
            .map_err(|e| Error::InvalidFile {
                field: alloc::format!("scan {k}"),
                reason: alloc::format!("{e}"),
            })?;
        targets.push(tracker.estimates().iter().map(TargetDoc::from).collect());
        t_s.push(k as f64 * dt_s);
    }
    let timing = MultiTiming {
        setup: t1 - t0,
        scans: clock() - t1,
    };
    let tracks = lives(&targets);
    let out = MultiTrackOutput {
        method: tracker.name().into(),
        settings: *settings,
        t_s,
        targets,
        tracks,
        static_removed,
    };
    Ok((out, timing))
}

/// Each label's life from the per-scan reports.
pub fn lives(targets: &[Vec<TargetDoc>]) -> Vec<LabelledTrack> {
    let mut out: alloc::collections::BTreeMap<u64, LabelledTrack> = Default::default();
    let last = targets.len().saturating_sub(1);
    for (k, scan) in targets.iter().enumerate() {
        for t in scan {
            let e = out.entry(t.label).or_insert(LabelledTrack {
                label: t.label,
                first_scan: k,
                last_scan: k,
                scans: 0,
                start: "confirmed".into(),
                end: String::new(),
            });
            e.last_scan = k;
            e.scans += 1;
        }
    }
    out.into_values()
        .map(|mut t| {
            t.end = if t.last_scan == last {
                "end_of_data"
            } else {
                "lost"
            }
            .into();
            t
        })
        .collect()
}

/// One true target of a scan in a truth file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TruthTarget {
    /// Its label.
    pub label: u64,
    /// `[x, y, vx, vy]`, m and m/s.
    pub state: [f64; 4],
}

/// The truth of several targets (`simulate-walk --walkers`'s `truth.json`): per scan the targets
/// present.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MultiTruth {
    /// Scan times, s.
    pub t_s: Vec<f64>,
    /// Per scan, the targets present.
    pub targets: Vec<Vec<TruthTarget>>,
}

impl MultiTruth {
    /// The core's [`Truth`](crate::track::multi::Truth).
    pub fn to_truth(&self) -> crate::track::multi::Truth {
        crate::track::multi::Truth {
            steps: self
                .targets
                .iter()
                .map(|s| {
                    s.iter()
                        .map(|t| (t.label, crate::math::Vec4::from(t.state)))
                        .collect()
                })
                .collect(),
        }
    }
}

/// Who walks in [`simulate_people`]: a count of the planned walkers
/// ([`people_truth_in`](crate::track::multi::people_truth_in): crossing, side by side, one
/// standing still a while) or drawn paths ([`people_truth_drawn`](crate::track::multi::people_truth_drawn):
/// straight lines walked at constant velocity over the run).
#[derive(Debug, Clone, PartialEq)]
pub enum Walkers {
    /// The first `n` planned walkers (1 ..= 5).
    Count(usize),
    /// One walker per drawn path `([x0, y0], [x1, y1])`, m (1 ..= 5 paths).
    Drawn(Vec<crate::track::multi::DrawnPath>),
}

impl Walkers {
    /// How many people walk.
    pub fn count(&self) -> usize {
        match self {
            Walkers::Count(n) => *n,
            Walkers::Drawn(p) => p.len(),
        }
    }

    /// Checks the count (1 ..= 5, [`Error::SizeLimit`] `walkers`) or the drawn paths
    /// ([`check_drawn_paths`](crate::track::multi::check_drawn_paths)).
    pub fn check(&self) -> Result<()> {
        match self {
            Walkers::Count(n) if !(1..=crate::track::multi::MAX_WALKERS).contains(n) => {
                Err(Error::SizeLimit {
                    field: "walkers",
                    value: *n,
                    min: 1,
                    max: crate::track::multi::MAX_WALKERS,
                })
            }
            Walkers::Count(_) => Ok(()),
            Walkers::Drawn(p) => crate::track::multi::check_drawn_paths(p),
        }
    }
}

impl From<usize> for Walkers {
    fn from(n: usize) -> Self {
        Walkers::Count(n)
    }
}

impl From<Vec<crate::track::multi::DrawnPath>> for Walkers {
    fn from(p: Vec<crate::track::multi::DrawnPath>) -> Self {
        Walkers::Drawn(p)
    }
}

/// Several people walking in `model`'s network and their delay scans: the measurements file
/// (`raw_steps`, the first scan as `initial_snapshot`, process noise `process_noise`) and the
/// truth. `walkers` is a count (the planned walkers,
/// [`people_truth_in`](crate::track::multi::people_truth_in) over `region`) or drawn paths
/// ([`Walkers::Drawn`]: straight lines in scenario coordinates, `region` unused); the scans
/// are [`delay_scans`](crate::track::multi::delay_scans) of that truth. Seeded: the same seed
/// gives the same scans for the same truth.
#[allow(clippy::too_many_arguments)]
pub fn simulate_people(
    model: &Model,
    region: &Area,
    walkers: impl Into<Walkers>,
    steps: usize,
    dt_s: f64,
    process_noise: f64,
    settings: &MultiSettings,
    seed: u64,
) -> Result<(Measurements, MultiTruth)> {
    let walkers = walkers.into();
    crate::track::ConstantVelocity::validated(dt_s, process_noise)?;
    walkers.check()?;
    if !(2..=crate::track::MAX_STEPS).contains(&steps) {
        return Err(Error::SizeLimit {
            field: "steps",
            value: steps,
            min: 2,
            max: crate::track::MAX_STEPS,
        });
    }
    crate::track::multi::check_detection(settings.detection_probability)?;
    DelayLinks::new(
        model,
        settings.detection_probability,
        settings.clutter,
        settings.clutter_window_s,
        None,
    )?;
    let mut r = crate::measure::rng(seed, 0);
    let truth = match &walkers {
        Walkers::Count(n) => crate::track::multi::people_truth_in(region, *n, steps, dt_s, &mut r),
        Walkers::Drawn(p) => crate::track::multi::people_truth_drawn(p, steps, dt_s)?,
    };
    let scans = crate::track::multi::delay_scans(
        model,
        &truth,
        settings.detection_probability,
        settings.clutter,
        settings.clutter_window_s,
        &mut r,
    );
    let raw: Vec<RawStep> = scans
        .iter()
        .map(|scan| {
            scan.iter()
                .map(|l| {
                    l.iter()
                        .map(|d| RawEstimate::Pair([d.value[0], 1.0]))
                        .collect()
                })
                .collect()
        })
        .collect();
    let mut raw = raw.into_iter();
    let first = raw.next();
    let m = Measurements {
        dt_s,
        process_noise,
        initial_state: None,
        initial_covariance: None,
        initial_snapshot: first,
        sigma_s: None,
        steps: None,
        raw_steps: Some(raw.collect()),
    };
    let t = MultiTruth {
        t_s: (0..steps).map(|k| k as f64 * dt_s).collect(),
        targets: truth
            .steps
            .iter()
            .map(|s| {
                s.iter()
                    .map(|(label, x)| TruthTarget {
                        label: *label,
                        state: (*x).into(),
                    })
                    .collect()
            })
            .collect(),
    };
    Ok((m, t))
}

/// GOSPA (`c`, `p = 2`) of a multi-target track against a truth, per scan, with the label
/// switches and the mean cardinality error (the scores of issue 41 §1).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MultiScoreDoc {
    /// `c`, m.
    pub c_m: f64,
    /// GOSPA per scan, m.
    pub gospa_m: Vec<f64>,
    /// Its localisation part per scan, m².
    pub localisation_m2: Vec<f64>,
    /// Its missed part per scan, m².
    pub missed_m2: Vec<f64>,
    /// Its false part per scan, m².
    pub false_m2: Vec<f64>,
    /// Mean GOSPA over the scans, m.
    pub mean_gospa_m: f64,
    /// Label switches over all true targets.
    pub switches: usize,
    /// Mean `|n̂ − n|`.
    pub mean_cardinality_error: f64,
}

/// The score of `out` against `truth` (scans compared up to the shorter of the two).
pub fn score_multi(out: &MultiTrackOutput, truth: &MultiTruth, c_m: f64) -> Result<MultiScoreDoc> {
    let est: Vec<Vec<TargetEstimate>> = out
        .targets
        .iter()
        .map(|s| {
            s.iter()
                .map(|t| TargetEstimate {
                    label: t.label,
                    state: t.state.into(),
                    covariance: crate::math::Mat4::from_fn(|i, j| t.covariance[i][j]),
                    existence: t.existence,
                })
                .collect()
        })
        .collect();
    let s = crate::track::multi::score_run(
        &truth.to_truth(),
        &est,
        &crate::track::GospaConfig { c: c_m, p: 2.0 },
    )?;
    let n = s.steps.len().max(1) as f64;
    Ok(MultiScoreDoc {
        c_m,
        gospa_m: s.steps.iter().map(|x| x.gospa).collect(),
        localisation_m2: s.steps.iter().map(|x| x.localisation).collect(),
        missed_m2: s.steps.iter().map(|x| x.missed).collect(),
        false_m2: s.steps.iter().map(|x| x.false_).collect(),
        mean_gospa_m: s.steps.iter().map(|x| x.gospa).sum::<f64>() / n,
        switches: s.total_switches(),
        mean_cardinality_error: s
            .steps
            .iter()
            .map(|x| x.cardinality_error as f64)
            .sum::<f64>()
            / n,
    })
}

/// Where `simulate-walk --walkers` people walk in a scenario of area `area`: the people region
/// of issue 41 ([`people_region`](crate::track::multi::people_region)) when the area holds it,
/// else the central half of the area.
pub fn walk_region(area: &Area) -> Area {
    let p = crate::track::multi::people_region();
    if area.x[0] <= p.x[0] && area.x[1] >= p.x[1] && area.y[0] <= p.y[0] && area.y[1] >= p.y[1] {
        return p;
    }
    let (cx, cy) = ((area.x[0] + area.x[1]) / 2.0, (area.y[0] + area.y[1]) / 2.0);
    let (hx, hy) = ((area.x[1] - area.x[0]) / 4.0, (area.y[1] - area.y[0]) / 4.0);
    Area {
        x: [cx - hx, cx + hx],
        y: [cy - hy, cy + hy],
    }
}
