//! Network planning (`filters-and-planning.md` §3): move nodes (and turn beams) to minimise a
//! CRLB objective over a region of interest, under placement constraints. `objective` scores a
//! layout from the map kernel, `problem` holds the moved nodes, the constraints and the encoding,
//! `cmaes` is the seeded derivative-free optimiser (CMA-ES with IPOP restarts) and `planner`
//! drives a plan and reports it.

mod cmaes;
mod objective;
mod planner;
mod problem;

pub use cmaes::{minimize, CmaesConfig, CmaesReport, Generation, SearchProblem, Termination};
pub use objective::{Objective, RoiObjective, Score};
pub use planner::{
    plan, Improvement, MapKernel, PlanConfig, PlanProgress, PlanReport, MAX_PLAN_BUDGET,
    MAX_PLAN_GRID, MIN_PLAN_GRID,
};
pub use problem::{
    Constraints, Layout, MoveSpec, NodeRef, PlanScore, PlanSpace, Polygon, MAX_PLAN_DIMENSION,
    MAX_POLYGONS, MAX_POLYGON_VERTICES,
};

#[cfg(test)]
mod tests;
