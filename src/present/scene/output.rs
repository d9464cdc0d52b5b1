//! The view of one scene ([`MtlView`]): plain serde data, positions as `[x, y]` m, ellipses as
//! `{cx, cy, a, b, angle}` (the page's ellipse shape), indices 0-based. Every number is finite
//! (non-finite values would serialise as `null`; none are produced).

use alloc::string::String;
use alloc::vec::Vec;

use serde::Serialize;

use crate::math::Real;
use crate::measure::Ellipse;

/// An ellipse: centre `(cx, cy)` m, semi-axes `a ≥ b` m, major-axis angle rad from +x.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EllipseView {
    /// Centre x, m.
    pub cx: Real,
    /// Centre y, m.
    pub cy: Real,
    /// Semi-major axis, m.
    pub a: Real,
    /// Semi-minor axis, m.
    pub b: Real,
    /// Angle of the major axis, rad.
    pub angle: Real,
}

impl From<Ellipse> for EllipseView {
    fn from(e: Ellipse) -> Self {
        EllipseView {
            cx: e.center.x,
            cy: e.center.y,
            a: e.semi_major,
            b: e.semi_minor,
            angle: e.angle_rad,
        }
    }
}

/// One measured range `r_{m,i}` and its ground truth.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RangeView {
    /// Range, m.
    pub range_m: Real,
    /// `"dp"` (a target's direct path) or `"clutter"`.
    pub source: &'static str,
    /// The target whose DP this is (`null` for clutter).
    pub target: Option<usize>,
    /// Its ellipse (§5.1); `null` when `r < ‖u − v‖` (no ellipse).
    pub ellipse: Option<EllipseView>,
    /// Detected targets (indices into [`MtlView::detected`]) whose matching uses this range.
    pub matched_by: Vec<usize>,
}

/// One TRP (Table I) and its ranges, ascending.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrpView {
    /// TRP index `m`.
    pub trp: usize,
    /// Its TX index.
    pub tx: usize,
    /// Its RX index.
    pub rx: usize,
    /// Ranges after the resolution merge.
    pub ranges: Vec<RangeView>,
}

/// An ellipse-intersection seed (§4 steps 1 and 3, §5.2).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeedView {
    /// Position, m.
    pub x: [Real; 2],
    /// The two (TRP, MPC) pairs whose ellipses meet there.
    pub pairs: [[usize; 2]; 2],
}

/// A hypothesis alive after the last stage (a live candidate).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HypothesisView {
    /// Location estimate `x̂`, m.
    pub x: [Real; 2],
    /// Matching `ℳ` as `[trp, mpc]` pairs.
    pub matching: Vec<[usize; 2]>,
    /// Score `J` (M2).
    pub j: Real,
    /// Blocking likelihood `L_b`, nats.
    pub l_b: Real,
    /// Family (seed) id.
    pub family: usize,
    /// Passes the final test (`|ℳ| ≥ n_min`, `L_b ≤ T_b`).
    pub accepted: bool,
}

/// A detected target (§4 step 5).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DetectedView {
    /// Estimated position `x̂`, m.
    pub x: [Real; 2],
    /// The chosen matching `ℳ` as `[trp, mpc]` pairs.
    pub matching: Vec<[usize; 2]>,
    /// Score `J` (M2).
    pub j: Real,
    /// Blocking likelihood `L_b`, nats.
    pub l_b: Real,
    /// Family (seed) id.
    pub family: usize,
    /// The nearest true target (`null` without targets).
    pub nearest_target: Option<usize>,
    /// Distance to it, m (`null` without targets).
    pub error_m: Option<Real>,
    /// Within `r_det` of a true target (not a false alarm).
    pub hit: bool,
}

/// A true target.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetView {
    /// Position, m.
    pub x: [Real; 2],
    /// TRPs with a DP before detection (`γ = γ^R ⊗ γ^T`, (M3)).
    pub los_trps: Vec<usize>,
    /// TRPs whose DP survived detection (`p_d`) and the resolution merge.
    pub dp_trps: Vec<usize>,
    /// A detected target lies within `r_det`.
    pub detected: bool,
}

/// A node–target segment and its LoS state (§7 step (4)).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SegmentView {
    /// `"tx"` or `"rx"`.
    pub node: &'static str,
    /// Node index.
    pub index: usize,
    /// Target index.
    pub target: usize,
    /// Node end, m.
    pub a: [Real; 2],
    /// Target end, m.
    pub b: [Real; 2],
    /// A disc centre lies within `D/2` of the segment.
    pub blocked: bool,
    /// The first blocking disc.
    pub disc: Option<usize>,
}

/// `N_D`, `N_FA` (M12) of this scene and the per-scene ratios.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MetricsView {
    /// Targets `K`.
    pub targets: usize,
    /// Estimates `K̂`.
    pub estimates: usize,
    /// `N_D`.
    pub detected: usize,
    /// `N_FA`.
    pub false_alarms: usize,
    /// `N_D / K` (`null` when `K = 0`).
    pub p_d: Option<Real>,
    /// `N_FA / max(K̂, 1)`.
    pub p_fa: Real,
}

/// Candidate counts of one stage of the trace, by fate.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct StageCounts {
    /// Stage `s` (2 = seeds).
    pub stage: usize,
    /// Kept.
    pub kept: usize,
    /// Failed the blocking test.
    pub blocking: usize,
    /// Inconsistent, no neighbour (case 2a).
    pub inconsistent: usize,
    /// No location.
    pub unlocatable: usize,
    /// Merged duplicates.
    pub duplicate: usize,
    /// Beyond `B_max`.
    pub capped: usize,
}

/// The blocking model as run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelView {
    /// `"ppp"` or `"icb"`.
    pub kind: &'static str,
    /// `p_u` of the i.c.b model (`null` for PPP).
    pub p_u: Option<Real>,
    /// PPP: exact (M11) or bound (M10).
    pub exact: Option<bool>,
    /// Consistency branching (cases 2a/2b) on.
    pub consistency: bool,
    /// One-line description.
    pub label: String,
}

/// Everything the page draws for one scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MtlView {
    /// Per TRP: ranges with ellipses and truth.
    pub trps: Vec<TrpView>,
    /// All ellipse-intersection seeds.
    pub seeds: Vec<SeedView>,
    /// Candidates alive after the last stage.
    pub hypotheses: Vec<HypothesisView>,
    /// Detected targets, ascending `J`.
    pub detected: Vec<DetectedView>,
    /// True targets.
    pub targets: Vec<TargetView>,
    /// Node–target segments.
    pub segments: Vec<SegmentView>,
    /// Detection metrics.
    pub metrics: MetricsView,
    /// The trace, per stage.
    pub stages: Vec<StageCounts>,
    /// The blocking model.
    pub model: ModelView,
    /// Total number of ranges (MPCs) over all TRPs.
    pub mpcs: usize,
}
