//! Algorithm 1 of `shared/spec/multi-target.md` (§4): staged matching of measured ranges to
//! targets under correlated blocking.
//!
//! Seeds are ellipse intersections of the first two TRPs of the order `π` (stage 2); every later
//! stage tests the MPCs of one TRP against each live candidate with the ellipse test of the vector
//! likelihood (M6), branches by consistency of the observed blocking vector (cases 1 / 2a / 2b),
//! adds late seeds, deduplicates and caps the candidates per family; the end keeps, per family,
//! the accepted candidate of smallest score `J` (M2).
//!
//! - [`candidate`]: candidates, the vector likelihood (M6), `J` (M2) and Gauss–Newton refinement.
//! - [`stages`]: seeds, stage extension, case 1/2a/2b branching and late seeds.
//! - [`select`]: dedup, per-family caps and the final selection.
//! - [`cache`]: ellipse-intersection seeds cached per MPC pair (shared by threshold sweeps and
//!   the brute-force reference [`crate::mtl::brute`]).
//! - [`validate`]: input checks (named errors).
//!
//! Every reconstruction choice (\[C\]/\[P\] in the spec) is a field of [`MtlConfig`].

pub mod cache;
pub mod candidate;
pub mod select;
pub mod stages;
mod validate;

use alloc::vec::Vec;

use crate::error::Result;
use crate::math::{Real, Vec2};
use crate::mtl::blocking::BlockingModel;
use crate::mtl::polygon::Rect;

pub use cache::IntersectionCache;
pub use candidate::{Candidate, Pair};
pub use validate::validate;

/// The final acceptance test of a candidate (§4 step 5, check 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FinalTest {
    /// Bayesian MTL: `L_b ≤ T_b` (and `|ℳ| ≥ n_min`).
    Blocking,
    /// The size rule of \[SM\]: `|ℳ| ≥ min_matched` (`= M − N_u`; and `|ℳ| ≥ n_min`), `L_b` ignored.
    Size {
        /// Smallest accepted matching size `M − N_u`.
        min_matched: usize,
    },
}

/// Gauss–Newton location refinement (§4, \[P\]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Refinement {
    /// Largest number of iterations (spec: 20).
    pub max_iterations: usize,
    /// Stop when the step is shorter than this, m (spec: 1e-9).
    pub step_tol_m: Real,
}

impl Default for Refinement {
    fn default() -> Self {
        Self {
            max_iterations: 20,
            step_tol_m: 1e-9,
        }
    }
}

/// Every threshold and reconstruction choice of Algorithm 1 (§4). `p_d` is not here: it is a
/// parameter of the blocking model that needs it (e.g. [`crate::mtl::blocking::NodeBlockingModel`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MtlConfig {
    /// Ellipse-test threshold `T_e` in units of `σ_e` (M6). Default 3.
    pub t_e: Real,
    /// Blocking-test threshold `T_b` in nats. Default 20 (the top of the V-B sweep, \[P\]).
    pub t_b: Real,
    /// Largest number of candidates per family `B_max` (\[P\], default 16; `usize::MAX` = ∞).
    pub b_max: usize,
    /// Smallest matching size of a target `n_min` (\[P\], default 3).
    pub n_min: usize,
    /// TRP order `π` (0-based TRPs, a permutation of `0..M`); `None` = identity (\[P\]).
    pub order: Option<Vec<usize>>,
    /// Seeds outside this region enlarged by 1 m are dropped (§5.2); `None` keeps all.
    pub region: Option<Rect>,
    /// Branch on consistency of the observed vector (cases 2a/2b). Default on; turn it off for
    /// models under which every vector is consistent (i.c.b, §6.1), where only case 1 exists.
    pub consistency: bool,
    /// The final acceptance test (default [`FinalTest::Blocking`]).
    pub final_test: FinalTest,
    /// Apply the blocking test `L_b ≤ T_b` during the stages (default on). The size rule of
    /// \[SM\] has no blocking test; check 6 is run with it off for the size rule.
    pub stage_blocking_test: bool,
    /// Merge final targets sharing at least [`MtlConfig::merge_shared_pairs`] (TRP, MPC) pairs,
    /// the lower `J` winning (\[P\], default on).
    pub merge_final: bool,
    /// Shared pairs that make two final targets the same (\[P\], default 2).
    pub merge_shared_pairs: usize,
    /// Only targets within this distance of each other merge, m (\[P\], default `∞`: merge on
    /// shared pairs alone). Two ellipses meet in up to 4 points, so targets sharing two
    /// (TRP, MPC) pairs may be far apart; a finite radius keeps a true target that a distant
    /// ghost would otherwise suppress, at the price of many more false alarms (V-A, `N_u = 4`:
    /// `P_FA` at `T_e = 5` doubles with 1 m), so it is off by default.
    pub merge_radius_m: Real,
    /// Gauss–Newton settings.
    pub refinement: Refinement,
    /// Add late seeds at stages `s ≥ 3` (step 3, default on).
    pub late_seeds: bool,
    /// Run late seeds through the earlier processed TRPs before their blocking test (step 3,
    /// \[C\], default on). Off: late seeds only see the TRPs processed after their stage, and
    /// their vector `ĝ` covers only their own TRPs.
    pub late_seed_catch_up: bool,
    /// Record the candidate trace per stage (for visualisation).
    pub trace: bool,
    /// The work budget: the largest number of candidates one run may evaluate (every candidate
    /// that ends a stage with a [`Status`] counts once). Past it the run stops with
    /// [`crate::Error::WorkLimit`]; time and memory grow with this count (default
    /// [`DEFAULT_MAX_CANDIDATES`], at most [`MAX_CANDIDATES`]).
    pub max_candidates: usize,
}

/// The default work budget of one run of Algorithm 1, candidates: about 1 s and 25 MB on the
/// reference machine (3.6 µs per candidate measured; docs/cli.md, "Limits"), so a page edit or
/// a study realisation past it fails fast. The paper's experiments need at most 23 577 (V-B/V-C,
/// 300 realisations) and 6 266 (V-A): a margin of 10.
pub const DEFAULT_MAX_CANDIDATES: usize = 250_000;

/// The largest work budget a caller may set, candidates.
pub const MAX_CANDIDATES: usize = 100_000_000;

impl Default for MtlConfig {
    fn default() -> Self {
        Self {
            t_e: 3.0,
            t_b: 20.0,
            b_max: 16,
            n_min: 3,
            order: None,
            region: None,
            consistency: true,
            final_test: FinalTest::Blocking,
            stage_blocking_test: true,
            merge_final: true,
            merge_shared_pairs: 2,
            merge_radius_m: Real::INFINITY,
            refinement: Refinement::default(),
            late_seeds: true,
            late_seed_catch_up: true,
            trace: false,
            max_candidates: DEFAULT_MAX_CANDIDATES,
        }
    }
}

/// The measured input of one localization: node positions and the ranges per TRP.
#[derive(Debug, Clone, Copy)]
pub struct Measurements<'a> {
    /// TX positions `u_j`, m.
    pub tx: &'a [Vec2],
    /// RX positions `v_j`, m.
    pub rx: &'a [Vec2],
    /// Ranges `r_m` of every TRP `m` (0-based, Table I order), m.
    pub ranges: &'a [Vec<Real>],
    /// Range standard deviation `cσ`, m.
    pub c_sigma_m: Real,
}

/// A detected target (§4 step 5).
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    /// Estimated position `x̂`, m.
    pub position: Vec2,
    /// The matching `ℳ`, sorted by TRP.
    pub matching: Vec<Pair>,
    /// The observed blocking vector `ĝ` over all TRPs.
    pub g: crate::mtl::blocking::PartialVector,
    /// Score `J` (M2).
    pub j: Real,
    /// Blocking likelihood `L_b`, nats.
    pub l_b: Real,
    /// Family (seed) id.
    pub family: usize,
}

/// What happened to a candidate in the trace.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Survived the stage.
    Kept,
    /// Failed the blocking test `L_b ≤ T_b`.
    Blocking,
    /// Inconsistent with no unit-Hamming neighbour (case 2a).
    Inconsistent,
    /// Fewer than two pairs or a singular geometry: no location.
    Unlocatable,
    /// Merged into an identical `(ℳ, ĝ)` with lower `J`.
    Duplicate,
    /// Beyond `B_max` in its family.
    Capped,
}

impl Status {
    /// Every status, in the order of [`Status::index`].
    pub const ALL: [Status; 6] = [
        Status::Kept,
        Status::Blocking,
        Status::Inconsistent,
        Status::Unlocatable,
        Status::Duplicate,
        Status::Capped,
    ];

    /// Position in [`Status::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }
}

/// One candidate of the trace.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceEntry {
    /// The candidate.
    pub candidate: Candidate,
    /// Its fate at this stage.
    pub status: Status,
}

/// The result of [`locate`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MtlOutput {
    /// Detected targets, ascending `J`.
    pub targets: Vec<Target>,
    /// Per stage (index 0 = stage 2) the candidates and their fate, if
    /// [`MtlConfig::trace`] was set.
    pub trace: Vec<Vec<TraceEntry>>,
    /// Per stage (index 0 = stage 2) the number of candidates that ended with each [`Status`]
    /// (by [`Status::index`]), with or without the trace.
    pub stage_counts: Vec<[usize; 6]>,
}

impl MtlOutput {
    /// The number of candidates evaluated (the work counted against
    /// [`MtlConfig::max_candidates`]).
    pub fn evaluated(&self) -> usize {
        self.stage_counts.iter().flatten().sum()
    }
}

/// Run Algorithm 1 (§4) on `input` with blocking model `model`.
///
/// Errors: see [`validate`].
pub fn locate<B: BlockingModel + ?Sized>(
    input: &Measurements,
    model: &B,
    cfg: &MtlConfig,
) -> Result<MtlOutput> {
    locate_cached(input, model, cfg, &mut IntersectionCache::new())
}

/// [`locate`] with the ellipse intersections taken from (and added to) `cache`: repeated runs
/// on the same measurements (threshold sweeps) intersect each pair of ellipses once. Results are
/// identical to [`locate`].
pub fn locate_cached<B: BlockingModel + ?Sized>(
    input: &Measurements,
    model: &B,
    cfg: &MtlConfig,
    cache: &mut IntersectionCache,
) -> Result<MtlOutput> {
    let order = validate(input, model, cfg)?;
    let mut run = stages::Run::new(input, model, cfg, order, cache);
    let live = run.run()?;
    let targets = select::finalize(&live, cfg);
    let stage_counts = run.stage_counts().to_vec();
    Ok(MtlOutput {
        targets,
        trace: run.into_trace(),
        stage_counts,
    })
}
