//! The planner's request and report as every front end reads and writes them (the CLI's
//! `plan.json`, the page's Plan panel): [`PlanRequest`] (the CLI's flags as fields) and
//! [`PlanJson`] (the optimised scenario, the objective before and after, the history of
//! improvements and each moved node's path).

use alloc::string::{String, ToString};
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::plan::{
    plan, MapKernel, MoveSpec, NodeRef, Objective, PlanConfig, PlanProgress, PlanReport, Polygon,
    Score, Termination,
};
use crate::scenario::{Area, Scenario};

/// What to plan, as the CLI's flags: `move`, `objective`, `roi`, optional `bounds`, `allowed`,
/// `min_spacing_m`, `grid`, `budget`, `seed`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanRequest {
    /// `rx`, `tx`, `all`, `tx-boresight` or comma-separated node names.
    #[serde(rename = "move")]
    pub movable: String,
    /// `mean`, `p90`, `max` or `coverage:T`.
    pub objective: String,
    /// Region of interest `[x0, x1, y0, y1]`, m.
    pub roi: [f64; 4],
    /// Placement bounds `[x0, x1, y0, y1]`, m (default: the scenario area).
    #[serde(default)]
    pub bounds: Option<[f64; 4]>,
    /// Allowed polygons (default: none, anywhere in the bounds).
    #[serde(default)]
    pub allowed: Vec<Polygon>,
    /// Smallest distance between any two nodes, m (default 0).
    #[serde(default)]
    pub min_spacing_m: f64,
    /// ROI grid side (default 64).
    #[serde(default)]
    pub grid: Option<usize>,
    /// Evaluations (default 10 000).
    #[serde(default)]
    pub budget: Option<usize>,
    /// Seed (default 1).
    #[serde(default)]
    pub seed: Option<u64>,
}

/// Default evaluation budget of a plan request.
pub const DEFAULT_PLAN_BUDGET: usize = 10_000;

/// `[x0, x1, y0, y1]` as an area.
pub fn area_of(v: [f64; 4]) -> Area {
    Area {
        x: [v[0], v[1]],
        y: [v[2], v[3]],
    }
}

impl PlanRequest {
    /// The core configuration (the objective parsed and checked; the rest is checked by
    /// [`plan`]).
    pub fn config(&self) -> Result<PlanConfig> {
        let mut c = PlanConfig::new(Objective::parse(&self.objective)?, area_of(self.roi));
        c.movable = MoveSpec::parse(&self.movable);
        c.bounds = self.bounds.map(area_of);
        c.allowed = self.allowed.clone();
        c.min_spacing_m = self.min_spacing_m;
        c.grid = self.grid.unwrap_or(64);
        c.budget = self.budget.unwrap_or(DEFAULT_PLAN_BUDGET);
        c.seed = self.seed.unwrap_or(1);
        Ok(c)
    }
}

/// The objective of a plan, before and after (`null` when unbounded).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanObjectiveJson {
    /// `mean`, `p90`, `max` or `coverage`.
    pub kind: String,
    /// As given (`coverage:0.1`).
    pub label: String,
    /// Whether larger is better (coverage).
    pub maximised: bool,
    /// The base scenario's value on the requested grid (m, or a fraction).
    pub before: Option<f64>,
    /// The optimised scenario's value on the requested grid.
    pub after: Option<f64>,
    /// Unbounded ROI cells before.
    pub unbounded_before: usize,
    /// Unbounded ROI cells after.
    pub unbounded_after: usize,
    /// The ROI `[x0, x1, y0, y1]`, m.
    pub roi: [f64; 4],
    /// The requested ROI grid side.
    pub grid: usize,
    /// The grid side the search used.
    pub search_grid: usize,
}

/// One improvement of the search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanHistoryJson {
    /// Evaluations when it was found.
    pub evaluations: usize,
    /// Its objective on the search grid (`null` when unbounded).
    pub best: Option<f64>,
}

/// A moved node's positions: base, each improvement, result (repeats removed), m.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanPathJson {
    /// Node name.
    pub name: String,
    /// `true` for a transmitter.
    pub transmitter: bool,
    /// `[x, y]` points.
    pub points: Vec<[f64; 2]>,
}

/// `plan.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanJson {
    /// The optimised scenario (schema v1; every command and the page load it).
    pub scenario: Scenario,
    /// The objective before and after.
    pub objective: PlanObjectiveJson,
    /// Every improvement of the best feasible layout.
    pub history: Vec<PlanHistoryJson>,
    /// Evaluations made.
    pub evaluations: usize,
    /// The seed.
    pub seed: u64,
    /// CMA-ES runs (1 + restarts).
    pub runs: usize,
    /// `budget` (spent) or `converged` (every restart converged).
    pub termination: String,
    /// The moved nodes' names.
    pub moved: Vec<String>,
    /// Each moved node's path.
    pub paths: Vec<PlanPathJson>,
}

impl PlanJson {
    /// The JSON view of a report for `config`.
    pub fn new(config: &PlanConfig, report: &PlanReport) -> PlanJson {
        let r = config.roi;
        let value = |s: &Score| s.finite_value();
        let layouts: Vec<&crate::plan::Layout> = core::iter::once(&report.layouts.0)
            .chain(report.history.iter().map(|h| &h.layout))
            .chain(core::iter::once(&report.layouts.1))
            .collect();
        let paths = report
            .moved_nodes
            .iter()
            .enumerate()
            .map(|(k, node)| {
                let mut points: Vec<[f64; 2]> = Vec::new();
                for l in &layouts {
                    let p = l.positions[k];
                    if points.last() != Some(&[p.x, p.y]) {
                        points.push([p.x, p.y]);
                    }
                }
                PlanPathJson {
                    name: report.moved[k].clone(),
                    transmitter: matches!(node, NodeRef::Tx(_)),
                    points,
                }
            })
            .collect();
        PlanJson {
            scenario: report.scenario.clone(),
            objective: PlanObjectiveJson {
                kind: config.objective.kind().into(),
                label: config.objective.label(),
                maximised: config.objective.maximised(),
                before: value(&report.before),
                after: value(&report.after),
                unbounded_before: report.before.unbounded,
                unbounded_after: report.after.unbounded,
                roi: [r.x[0], r.x[1], r.y[0], r.y[1]],
                grid: config.grid,
                search_grid: report.search_grid,
            },
            history: report
                .history
                .iter()
                .map(|h| PlanHistoryJson {
                    evaluations: h.evaluations,
                    best: value(&h.best),
                })
                .collect(),
            evaluations: report.evaluations,
            seed: config.seed,
            runs: report.runs,
            termination: match report.termination {
                Termination::Budget => "budget",
                Termination::Restarts => "converged",
                Termination::Cancelled => "cancelled",
            }
            .to_string(),
            moved: report.moved.clone(),
            paths,
        }
    }
}

/// A plan's progress as front ends show it: evaluations, and on an improvement the objective
/// (search grid) and the scenario with the new layout (for the page's gliding nodes).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanProgressJson {
    /// Evaluations so far.
    pub evaluations: usize,
    /// The budget.
    pub budget: usize,
    /// The improvement found by this generation, if any.
    pub improvement: Option<PlanImprovementJson>,
}

/// An improvement as front ends show it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanImprovementJson {
    /// Its objective on the search grid (`null` when unbounded).
    pub best: Option<f64>,
    /// The base scenario with the improved layout.
    pub scenario: Scenario,
}

/// Runs a plan request on `scenario`; `observe` sees every generation's progress (with the
/// improved scenario when there is one) and cancels by returning `false`.
pub fn run_plan(
    scenario: &Scenario,
    request: &PlanRequest,
    observe: impl FnMut(&PlanProgressJson) -> bool,
) -> Result<PlanJson> {
    run_plan_with(scenario, request, crate::localize::crlb_map, observe)
}

/// [`run_plan`] scoring layouts with `kernel` (the CLI and the Python package pass
/// `native::crlb_map_exact`, which returns the core kernel's bits on this CPU's widest
/// registers: the same plan, sooner).
pub fn run_plan_with(
    scenario: &Scenario,
    request: &PlanRequest,
    kernel: MapKernel,
    mut observe: impl FnMut(&PlanProgressJson) -> bool,
) -> Result<PlanJson> {
    let mut config = request.config()?;
    config.kernel = kernel;
    let report = plan(scenario, &config, |p: &PlanProgress<'_>| {
        observe(&PlanProgressJson {
            evaluations: p.evaluations,
            budget: p.budget,
            improvement: p.improvement.map(|imp| PlanImprovementJson {
                best: imp.best.finite_value(),
                scenario: p.space.apply_to_scenario(&imp.layout),
            }),
        })
    })?;
    Ok(PlanJson::new(&config, &report))
}
