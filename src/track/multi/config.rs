//! The shared vocabulary of the multi-target trackers: their settings, a Gaussian-mixture
//! component, a reported target, the scan checks and the one value that is either tracker.

use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::math::{Mat4, Real, Vec4};
use crate::track::multi::gaussian::Bernoulli;
use crate::track::multi::sensors::{Detection, MeasurementModel};
use crate::track::multi::{Gnn, Pmb};
use crate::track::ConstantVelocity;

/// One scan: per sensor (link), its detections.
pub type Scan = Vec<Vec<Detection>>;

/// Most detections one sensor (link) may report in one scan: beyond it a scan is refused with
/// a named error, so a scan's time stays bounded (the BP and the gating are linear in it).
pub const MAX_DETECTIONS_PER_SENSOR: usize = 1024;

/// Most Bernoullis (or GNN tracks) a tracker keeps.
pub const MAX_TRACKS: usize = 512;

/// Settings shared by the PMB tracker and the GNN baseline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MultiConfig {
    /// The CV model (E7).
    pub motion: ConstantVelocity,
    /// Survival probability per scan `p_S` (default 0.99).
    pub survival: Real,
    /// Gate on the Mahalanobis distance² of a (track, measurement) pair (default 25).
    pub gate: Real,
    /// A target is reported when its existence exceeds this (default 0.5).
    pub existence_threshold: Real,
    /// Bernoullis below this existence are dropped (default 1e-4).
    pub prune: Real,
    /// Most Bernoullis kept (default 200, at most [`MAX_TRACKS`]).
    pub max_bernoullis: usize,
    /// Association marginals are enumerated exactly in clusters of at most this many tracks and
    /// measurements, loopy BP beyond (default 6; 0 = BP everywhere; at most
    /// [`crate::track::multi::MAX_EXACT_CLUSTER`]).
    pub exact_cluster: usize,
}

impl MultiConfig {
    /// The defaults above with the motion model `motion`.
    pub fn new(motion: ConstantVelocity) -> MultiConfig {
        MultiConfig {
            motion,
            survival: 0.99,
            gate: 25.0,
            existence_threshold: 0.5,
            prune: 1e-4,
            max_bernoullis: 200,
            exact_cluster: 6,
        }
    }

    /// Named errors for a bad setting.
    pub fn validate(&self) -> Result<()> {
        ConstantVelocity::validated(self.motion.dt_s, self.motion.intensity)?;
        let unit = |field: &str, v: Real| -> Result<()> {
            if v > 0.0 && v < 1.0 {
                Ok(())
            } else {
                Err(Error::OutOfRange {
                    field: field.into(),
                    value: v,
                    allowed: "a probability strictly between 0 and 1",
                })
            }
        };
        unit("survival", self.survival)?;
        unit("existence_threshold", self.existence_threshold)?;
        unit("prune", self.prune)?;
        if !(self.gate.is_finite() && self.gate > 0.0) {
            return Err(Error::NotPositive {
                field: "gate".into(),
                value: self.gate,
            });
        }
        if self.exact_cluster > crate::track::multi::MAX_EXACT_CLUSTER {
            return Err(Error::SizeLimit {
                field: "exact_cluster",
                value: self.exact_cluster,
                min: 0,
                max: crate::track::multi::MAX_EXACT_CLUSTER,
            });
        }
        if self.max_bernoullis == 0 || self.max_bernoullis > MAX_TRACKS {
            return Err(Error::SizeLimit {
                field: "max_bernoullis",
                value: self.max_bernoullis,
                min: 1,
                max: MAX_TRACKS,
            });
        }
        Ok(())
    }
}

/// One weighted Gaussian of an intensity (a PPP's mixture).
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    /// Weight (expected number of targets it holds).
    pub weight: Real,
    /// Mean `[x, y, vx, vy]`.
    pub state: Vec4,
    /// Covariance.
    pub covariance: Mat4,
}

/// One reported target.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetEstimate {
    /// Its label (stable over its life).
    pub label: u64,
    /// `[x, y, vx, vy]`, m and m/s.
    pub state: Vec4,
    /// Covariance.
    pub covariance: Mat4,
    /// Existence probability (the GNN baseline reports 1 for a confirmed track).
    pub existence: Real,
}

impl From<&Bernoulli> for TargetEstimate {
    fn from(b: &Bernoulli) -> Self {
        TargetEstimate {
            label: b.label,
            state: b.state,
            covariance: b.covariance,
            existence: b.existence,
        }
    }
}

/// A scan must hold one list per sensor, each of at most [`MAX_DETECTIONS_PER_SENSOR`] finite
/// detections with a finite σ > 0 where given.
pub fn check_scan<M: MeasurementModel>(model: &M, scan: &[Vec<Detection>]) -> Result<()> {
    crate::error::check_len("scan", model.sensor_count(), scan.len())?;
    for (s, dets) in scan.iter().enumerate() {
        if dets.len() > MAX_DETECTIONS_PER_SENSOR {
            return Err(Error::SizeLimit {
                field: "detections per link and scan",
                value: dets.len(),
                min: 0,
                max: MAX_DETECTIONS_PER_SENSOR,
            });
        }
        for (j, d) in dets.iter().enumerate() {
            if !(d.value[0].is_finite() && d.value[1].is_finite()) {
                return Err(Error::NonFinite {
                    field: alloc::format!("scan[{s}][{j}]"),
                });
            }
            if let Some(v) = d.sigma {
                if !(v.is_finite() && v > 0.0) {
                    return Err(Error::InvalidSigma { link: s, value: v });
                }
            }
        }
    }
    Ok(())
}

/// Which multi-target tracker a run uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MultiKind {
    /// The PMB tracker with BP association ([`Pmb`]).
    #[default]
    Pmb,
    /// The global-nearest-neighbour baseline ([`Gnn`]).
    Gnn,
}

impl MultiKind {
    /// `pmb` or `gnn`.
    pub fn name(self) -> &'static str {
        match self {
            MultiKind::Pmb => "pmb",
            MultiKind::Gnn => "gnn",
        }
    }

    /// Parses `pmb` or `gnn` (named error otherwise).
    pub fn parse(s: &str) -> Result<MultiKind> {
        match s {
            "pmb" => Ok(MultiKind::Pmb),
            "gnn" => Ok(MultiKind::Gnn),
            other => Err(Error::UnknownFilter {
                field: "method (pmb, gnn)".into(),
                name: other.into(),
            }),
        }
    }
}

/// Either multi-target tracker behind one interface (the seam every driver uses).
#[derive(Debug, Clone)]
pub enum MultiTracker {
    /// PMB with BP association.
    Pmb(Pmb),
    /// GNN baseline.
    Gnn(Gnn),
}

impl MultiTracker {
    /// One scan (see [`Pmb::step`], [`Gnn::step`]).
    pub fn step<M: MeasurementModel>(&mut self, model: &M, scan: &[Vec<Detection>]) -> Result<()> {
        match self {
            MultiTracker::Pmb(t) => t.step(model, scan),
            MultiTracker::Gnn(t) => t.step(model, scan),
        }
    }

    /// The reported targets, in label order.
    pub fn estimates(&self) -> Vec<TargetEstimate> {
        match self {
            MultiTracker::Pmb(t) => t.estimates(),
            MultiTracker::Gnn(t) => t.estimates(),
        }
    }

    /// `pmb` or `gnn`.
    pub fn name(&self) -> &'static str {
        match self {
            MultiTracker::Pmb(_) => "pmb",
            MultiTracker::Gnn(_) => "gnn",
        }
    }
}
