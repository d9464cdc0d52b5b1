//! The planner: moves nodes to minimise an ROI objective under the constraints, with CMA-ES and
//! IPOP restarts on a coarse ROI grid, then re-scores on the requested grid.

use alloc::vec::Vec;

use crate::error::{Error, Result};
use crate::localize::{crlb_map, Grid};
use crate::math::Real;
use crate::measure::Model;
use crate::scenario::{Area, Scenario};

use super::cmaes::{minimize, CmaesConfig, Termination};
use super::objective::{Objective, RoiObjective, Score};
use super::problem::{Constraints, Layout, MoveSpec, NodeRef, PlanScore, PlanSearch, PlanSpace};

/// Smallest ROI grid side of a plan.
pub const MIN_PLAN_GRID: usize = 2;
/// Largest ROI grid side of a plan.
pub const MAX_PLAN_GRID: usize = 512;
/// Largest evaluation budget of a plan.
pub const MAX_PLAN_BUDGET: usize = 1_000_000;
/// How many of the last improvements are re-scored on the requested grid to pick the result.
const FINALISTS: usize = 8;

/// What to plan.
#[derive(Debug, Clone)]
pub struct PlanConfig {
    /// The objective.
    pub objective: Objective,
    /// The region of interest (inside the scenario area).
    pub roi: Area,
    /// ROI grid side of the reported objective (`before`, `after`).
    pub grid: usize,
    /// ROI grid side of the search; `0` = `min(max(grid / 2, 16), grid)`.
    pub coarse_grid: usize,
    /// Which nodes move.
    pub movable: MoveSpec,
    /// Placement bounds (`None` = the scenario area), polygons and spacing.
    pub bounds: Option<Area>,
    /// Allowed polygons (empty = anywhere in the bounds).
    pub allowed: Vec<super::problem::Polygon>,
    /// Smallest distance between any two nodes, m.
    pub min_spacing_m: Real,
    /// Evaluations of the search.
    pub budget: usize,
    /// Seed of the search.
    pub seed: u64,
    /// The CRLB map kernel that scores layouts (default the core's [`crlb_map`]). A front end
    /// may pass a faster one (the CLI and the Python package: `native::crlb_map_exact`, this
    /// CPU's widest registers) **that returns the same bits**, so that a plan never depends on
    /// the CPU (issue 29).
    pub kernel: MapKernel,
}

/// A CRLB map kernel: the RMSE bound of every cell of a grid (the signature of [`crlb_map`]).
pub type MapKernel = fn(&Model, &Grid, &mut [Real]) -> Result<()>;

impl PlanConfig {
    /// Defaults for an ROI and an objective: receivers move, grid 64, budget 3000, seed 1.
    pub fn new(objective: Objective, roi: Area) -> PlanConfig {
        PlanConfig {
            objective,
            roi,
            grid: 64,
            coarse_grid: 0,
            movable: MoveSpec::Receivers,
            bounds: None,
            allowed: Vec::new(),
            min_spacing_m: 0.0,
            budget: 3000,
            seed: 1,
            kernel: crlb_map,
        }
    }

    /// The search grid side.
    pub fn search_grid(&self) -> usize {
        match self.coarse_grid {
            0 => (self.grid / 2).max(16).min(self.grid),
            n => n.min(self.grid),
        }
    }
}

/// One improvement of the search's best feasible layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Improvement {
    /// Evaluations when it was found.
    pub evaluations: usize,
    /// Its objective on the search grid.
    pub best: Score,
    /// The layout.
    pub layout: Layout,
}

/// What the observer sees after every generation of the search.
#[derive(Debug, Clone, Copy)]
pub struct PlanProgress<'a> {
    /// Evaluations so far.
    pub evaluations: usize,
    /// The budget.
    pub budget: usize,
    /// A new best feasible layout, when this generation found one.
    pub improvement: Option<&'a Improvement>,
    /// The plan's space (e.g. to turn a layout into a scenario).
    pub space: &'a PlanSpace,
}

/// The result of [`plan`].
#[derive(Debug, Clone, PartialEq)]
pub struct PlanReport {
    /// The optimised scenario (the base with the chosen layout).
    pub scenario: Scenario,
    /// The objective of the base scenario on the requested grid.
    pub before: Score,
    /// The objective of [`PlanReport::scenario`] on the requested grid.
    pub after: Score,
    /// Every improvement of the best feasible layout (search-grid objective).
    pub history: Vec<Improvement>,
    /// Evaluations made.
    pub evaluations: usize,
    /// CMA-ES runs (1 + restarts).
    pub runs: usize,
    /// Why the search stopped (the budget, or every restart converged).
    pub termination: Termination,
    /// The search grid side.
    pub search_grid: usize,
    /// The moved nodes' names.
    pub moved: Vec<alloc::string::String>,
    /// The moved nodes.
    pub moved_nodes: Vec<NodeRef>,
    /// The base layout and the chosen one (for drawing the moves).
    pub layouts: (Layout, Layout),
}

/// Plans a network: moves the chosen nodes of `scenario` (and turns beams) to optimise the
/// objective over the ROI, keeping the constraints (`filters-and-planning.md` §3).
///
/// The search is CMA-ES with IPOP restarts ([`minimize`](super::minimize)) over the moved nodes' positions
/// scaled to the bounds, ranked by constraint violation, then the objective on the search grid.
/// The first run starts at the base layout; restarts at uniform random layouts. The last
/// improvements and the base layout are re-scored on the requested grid, and the best feasible
/// one is the result (so `after` is never worse than a feasible `before`). `observe` sees every
/// generation and cancels by returning `false` ([`Error::Cancelled`]). Deterministic per seed.
pub fn plan(
    scenario: &Scenario,
    config: &PlanConfig,
    mut observe: impl FnMut(&PlanProgress<'_>) -> bool,
) -> Result<PlanReport> {
    scenario.validate()?;
    for (field, v, min, max) in [
        ("grid", config.grid, MIN_PLAN_GRID, MAX_PLAN_GRID),
        ("budget", config.budget, 1, MAX_PLAN_BUDGET),
    ] {
        if !(min..=max).contains(&v) {
            return Err(Error::SizeLimit {
                field,
                value: v,
                min,
                max,
            });
        }
    }
    config.roi.validate_as(["roi.x", "roi.y"])?;
    let a = scenario.area_m;
    let r = config.roi;
    if r.x[0] < a.x[0] || r.x[1] > a.x[1] || r.y[0] < a.y[0] || r.y[1] > a.y[1] {
        return Err(Error::Infeasible {
            field: "roi".into(),
            reason: alloc::format!(
                "[{}, {}] x [{}, {}] m must lie inside the scenario area [{}, {}] x [{}, {}] m",
                r.x[0],
                r.x[1],
                r.y[0],
                r.y[1],
                a.x[0],
                a.x[1],
                a.y[0],
                a.y[1]
            ),
        });
    }
    let constraints = Constraints {
        bounds: config.bounds.unwrap_or(a),
        allowed: config.allowed.clone(),
        min_spacing_m: config.min_spacing_m,
    };
    let space = PlanSpace::new(scenario, &config.movable, constraints)?;
    let base_model = Model::new(scenario)?;
    let search_grid = config.search_grid();
    let mut search = PlanSearch {
        space: &space,
        model: base_model.clone(),
        roi: RoiObjective::new(config.objective, config.roi, search_grid)?
            .with_kernel(config.kernel),
    };
    let base_layout = space.base_layout();
    let x0 = space.encode(&base_layout);
    let cmaes = CmaesConfig {
        budget: config.budget,
        seed: config.seed,
        ..CmaesConfig::default()
    };
    let mut history: Vec<Improvement> = Vec::new();
    let mut best_feasible: Option<PlanScore> = None;
    let report = minimize(&mut search, &x0, &cmaes, |g| {
        let mut improvement = None;
        if g.improved && g.best.feasible() && best_feasible.is_none_or(|b| g.best.rank(&b).is_lt())
        {
            best_feasible = Some(*g.best);
            history.push(Improvement {
                evaluations: g.evaluations,
                best: g.best.score,
                layout: space.decode(g.best_x).0,
            });
            improvement = history.last();
        }
        observe(&PlanProgress {
            evaluations: g.evaluations,
            budget: config.budget,
            improvement,
            space: &space,
        })
    });
    if report.termination == Termination::Cancelled {
        return Err(Error::Cancelled);
    }
    // Re-score the base layout and the last improvements on the requested grid.
    let mut fine = PlanSearch {
        space: &space,
        model: base_model,
        roi: RoiObjective::new(config.objective, config.roi, config.grid)?
            .with_kernel(config.kernel),
    };
    let before = fine.score_layout(&base_layout, 0.0);
    let mut chosen: Option<(PlanScore, Layout)> =
        before.feasible().then(|| (before, base_layout.clone()));
    for imp in history.iter().rev().take(FINALISTS) {
        let s = fine.score_layout(&imp.layout, 0.0);
        if chosen.as_ref().is_none_or(|(c, _)| s.rank(c).is_lt()) {
            chosen = Some((s, imp.layout.clone()));
        }
    }
    let Some((after, layout)) = chosen else {
        return Err(Error::Infeasible {
            field: "min_spacing".into(),
            reason: alloc::format!(
                "no layout that keeps the spacing and the allowed polygons was found in {} evaluations",
                report.evaluations
            ),
        });
    };
    let optimised = space.apply_to_scenario(&layout);
    // `after` is the objective of the scenario handed out, compiled afresh.
    let after = PlanScore {
        score: fine.roi.evaluate(&Model::new(&optimised)?),
        ..after
    };
    Ok(PlanReport {
        scenario: optimised,
        before: before.score,
        after: after.score,
        history,
        evaluations: report.evaluations,
        runs: report.runs,
        termination: report.termination,
        search_grid,
        moved: space
            .moved()
            .iter()
            .map(|&n| space.name(n).into())
            .collect(),
        moved_nodes: space.moved().to_vec(),
        layouts: (base_layout, layout),
    })
}
