//! `scatterloc plan`: network planning (`filters-and-planning.md` §3). The flags become a
//! [`PlanRequest`] run by [`run_plan_with`] (the page's Plan panel runs the same function on the core kernel, which gives the same bits) under the
//! progress bar and Ctrl-C handling of the long commands; the result is `plan.json` and, with
//! `--figure`, the maps before and after ([`draw_plan_maps`]).

use plotters::coord::Shift;
use plotters::prelude::*;
use serde_json::json;

use scatterloc::chart::{
    check_area, draw_plan_maps, plan_caption, plan_chart_size, scenario_nodes, ChartError,
    ChartNode, MapData, PlanChartOptions, PlanPanel, PlanPath,
};
use scatterloc::localize::Grid;
use scatterloc::native::crlb_map_exact;
use scatterloc::native::crlb_map_parallel;
use scatterloc::plan::{Polygon, MAX_PLAN_GRID, MIN_PLAN_GRID};
use scatterloc::present::{run_plan_with, PlanJson, PlanRequest, DEFAULT_PLAN_BUDGET};
use scatterloc::{Error, Scenario};

use super::flags::{at_flag, flag_of};
use super::io::{emit_summary, model_of, one_stdin, read_json_file};
use super::output::{check_writable, Figure, Format, OutputSet};
use super::study::{cancelled, interrupted, load_layout, run_with_bar};
use crate::cli::PlanArgs;
use crate::failure::CliError;

/// Grid side of the figure's maps (as `crlb-map`'s default).
const FIGURE_GRID: usize = 256;
/// Width of the figure, pixels.
const FIGURE_WIDTH: u32 = 1600;

/// `scatterloc plan`.
pub fn plan(args: &PlanArgs) -> Result<(), CliError> {
    let out = args.out.as_str();
    Format::of("out", out, &[Format::Json])?;
    let figure = match args.figure.as_deref() {
        Some(p) => Some((p, Format::of("figure", p, &[Format::Svg, Format::Png])?)),
        None => None,
    };
    one_stdin(&[
        ("scenario", args.scenario.as_deref()),
        ("allowed", args.allowed.as_deref()),
    ])?;
    let (_, scenario) = load_layout(args.preset.as_deref(), args.scenario.as_deref())?;
    let allowed: Vec<Polygon> = match args.allowed.as_deref() {
        Some(path) => read_json_file("allowed", path)?,
        None => Vec::new(),
    };
    let request = PlanRequest {
        movable: args.movable.clone(),
        objective: args.objective.clone(),
        roi: args.roi,
        bounds: args.bounds,
        allowed,
        min_spacing_m: args.min_spacing.unwrap_or(0.0),
        grid: args.grid,
        budget: args.budget,
        seed: args.seed,
    };
    let errors = |e: Error| plan_error(e, args);
    if let Some(g) = args
        .grid
        .filter(|g| !(MIN_PLAN_GRID..=MAX_PLAN_GRID).contains(g))
    {
        return Err(CliError::usage(format!(
            "--grid: {g} is outside the allowed range {MIN_PLAN_GRID}..={MAX_PLAN_GRID}"
        )));
    }
    // The objective is parsed here so that a bad one is reported before any file is touched.
    let config = request.config().map_err(errors)?;
    if let Some((path, _)) = figure {
        check_area(&scenario.area_m).map_err(|e| at_flag("figure", format_args!("area_m: {e}")))?;
        check_writable("figure", path)?;
    }
    check_writable("out", out)?;

    let budget = args.budget.unwrap_or(DEFAULT_PLAN_BUDGET);
    let (result, wall) = run_with_bar(budget, "evaluations", "plan", |cancel, progress| {
        // Layouts scored on this CPU's widest exact kernel path: the core kernel's bits, so the
        // plan is the page's and any CPU's (issue 29).
        run_plan_with(&scenario, &request, crlb_map_exact, |p| {
            progress(p.evaluations.min(p.budget), p.budget);
            !cancel.load(std::sync::atomic::Ordering::SeqCst)
        })
    })?;
    let plan = result.map_err(errors)?;

    // The figure and the plan are renamed into place together, or neither (issue 24).
    let mut files = OutputSet::new();
    if let Some((path, format)) = figure {
        let maps = PlanMaps::compute(&scenario, &plan.scenario)?;
        if interrupted() {
            return Err(cancelled());
        }
        let figure = PlanFigure {
            maps: &maps,
            plan: &plan,
            before_nodes: scenario_nodes(&scenario),
            after_nodes: scenario_nodes(&plan.scenario),
            opts: chart_options(&scenario, &plan, &args.movable),
        };
        let size = plan_chart_size(&scenario.area_m, FIGURE_WIDTH);
        files.figure("figure", path, format, size, &figure)?;
    }
    if interrupted() {
        return Err(cancelled());
    }
    files.json("out", out, &plan)?;
    files.commit()?;

    let summary = json!({
        "out": out,
        "figure": figure.map(|(p, _)| p),
        "objective": plan.objective.label,
        "before": plan.objective.before,
        "after": plan.objective.after,
        "evaluations": plan.evaluations,
        "runs": plan.runs,
        "termination": plan.termination,
        "moved": plan.moved,
        "seed": config.seed,
        "wall_time_s": (wall * 1e3).round() / 1e3,
    });
    emit_summary(&summary.to_string())
}

/// A core error of the plan as the flag that caused it: `--roi: …`, `--move: …`,
/// `--min-spacing: …`, `--objective: …`, `--allowed FILE: …`; Ctrl-C as exit status 130.
fn plan_error(e: Error, args: &PlanArgs) -> CliError {
    match &e {
        Error::Cancelled => return cancelled(),
        Error::OutOfRange { field, value, .. } if field == "objective" && value.is_nan() => {
            return CliError::usage(format!(
                "--objective: '{}' is not mean, p90, max or coverage:T (T > 0 m)",
                args.objective
            ))
        }
        _ => {}
    }
    let field = e.field().unwrap_or_default().to_string();
    let base = field
        .split(['.', '[', ' '])
        .next()
        .unwrap_or_default()
        .to_string();
    let flag = match base.as_str() {
        // No feasible layout found: the spacing, the polygons and the bounds together.
        "min_spacing" if args.allowed.is_some() && matches!(e, Error::Infeasible { .. }) => {
            "--min-spacing / --allowed".to_string()
        }
        "allowed" => match &args.allowed {
            Some(path) => format!("--allowed {path}"),
            None => "--allowed".to_string(),
        },
        // The request's fields by the one table; any other field is the scenario's.
        b => match flag_of(b) {
            Some(flag) => flag.to_string(),
            None => return at_flag("scenario", e),
        },
    };
    let text = e.to_string();
    // `roi: …` becomes `--roi: …`; a longer path (`roi.x`, `allowed[2]`) is kept after the flag.
    let message = match text.strip_prefix(&format!("{field}: ")) {
        Some(rest) if field == base => rest.to_string(),
        _ => text,
    };
    CliError::usage(format!("{flag}: {message}"))
}

/// The title and subtitle of the figure.
fn chart_options(s: &Scenario, plan: &PlanJson, movable: &str) -> PlanChartOptions {
    let o = &plan.objective;
    let [x0, x1, y0, y1] = o.roi;
    PlanChartOptions {
        title: format!("Network plan — {}", s.name),
        subtitle: Some(format!(
            "move {} · objective {} over ROI [{x0}, {x1}] × [{y0}, {y1}] m ({}×{} grid) · {} \
             evaluations · seed {}",
            movable.trim(),
            o.label,
            o.grid,
            o.grid,
            plan.evaluations,
            plan.seed
        )),
        ..PlanChartOptions::default()
    }
}

/// The CRLB maps of the scenario before and after, over its area.
struct PlanMaps {
    grid: Grid,
    before: Vec<f64>,
    after: Vec<f64>,
}

impl PlanMaps {
    fn compute(before: &Scenario, after: &Scenario) -> Result<PlanMaps, CliError> {
        let grid = Grid::new(before.area_m, FIGURE_GRID, FIGURE_GRID)
            .map_err(|e| at_flag("figure", format_args!("area_m: {e}")))?;
        let map = |s: &Scenario| -> Result<Vec<f64>, CliError> {
            let model = model_of(s)?;
            let mut values = vec![0.0; grid.len()];
            crlb_map_parallel(&model, &grid, &mut values, 0)
                .map_err(|e| CliError::output(format!("--figure: {e}")))?;
            Ok(values)
        };
        Ok(PlanMaps {
            grid,
            before: map(before)?,
            after: map(after)?,
        })
    }
}

/// The figure of [`draw_plan_maps`] as a [`Figure`].
struct PlanFigure<'a> {
    maps: &'a PlanMaps,
    plan: &'a PlanJson,
    before_nodes: Vec<ChartNode>,
    after_nodes: Vec<ChartNode>,
    opts: PlanChartOptions,
}

impl Figure for PlanFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), ChartError> {
        let o = &self.plan.objective;
        let (cap_before, cap_after) = (
            plan_caption("before", o, false),
            plan_caption("after", o, true),
        );
        let before = PlanPanel {
            caption: &cap_before,
            map: MapData {
                grid: self.maps.grid,
                values_m: &self.maps.before,
            },
            nodes: &self.before_nodes,
        };
        let after = PlanPanel {
            caption: &cap_after,
            map: MapData {
                grid: self.maps.grid,
                values_m: &self.maps.after,
            },
            nodes: &self.after_nodes,
        };
        // Each node's move, start to end: the whole search path (plan.json `paths`) jumps
        // between the basins the restarts explore and would hide the maps.
        let moves: Vec<[[f64; 2]; 2]> = self
            .plan
            .paths
            .iter()
            .filter_map(|p| Some([*p.points.first()?, *p.points.last()?]))
            .collect();
        let paths: Vec<PlanPath> = moves.iter().map(|m| PlanPath { points_m: m }).collect();
        let roi = scatterloc::present::area_of(o.roi);
        draw_plan_maps(root, &before, &after, &roi, &paths, &self.opts).map(|_| ())
    }
}
