//! Flags of `scatterloc plan` (network planning, `filters-and-planning.md` §3).

use clap::Args;

use super::values::{finite, rect, seed, whole};

/// `scatterloc plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// Preset layout: sensors2019 or iclgnss2019 [default: sensors2019].
    #[arg(long, value_name = "NAME")]
    pub preset: Option<String>,
    /// Scenario JSON file ('-' = standard input) instead of --preset.
    #[arg(long, value_name = "FILE")]
    pub scenario: Option<String>,
    /// The nodes that move: rx (every receiver), tx (every transmitter), all, tx-boresight
    /// (every transmitter, and the boresight of each parabolic one turns) or comma-separated node
    /// names.
    #[arg(long = "move", value_name = "rx|tx|all|tx-boresight|NAME[,NAME..]")]
    pub movable: String,
    /// What to optimise over the ROI's cells: the mean, 90th percentile or maximum RMSE bound
    /// (minimised), or coverage:T, the fraction of cells whose bound is at most T metres
    /// (maximised).
    #[arg(long, value_name = "mean|p90|max|coverage:T")]
    pub objective: String,
    /// Region of interest, m: X0,X1,Y0,Y1 (inside the scenario's area_m).
    #[arg(long, value_name = "X0,X1,Y0,Y1", value_parser = rect)]
    pub roi: [f64; 4],
    /// Where moved nodes may go, m: X0,X1,Y0,Y1 [default: the scenario's area_m].
    #[arg(long, value_name = "X0,X1,Y0,Y1", value_parser = rect)]
    pub bounds: Option<[f64; 4]>,
    /// Allowed polygons JSON file ('-' = standard input): [[[x, y], ..], ..], each a list of
    /// vertices, m; every moved node must lie in one of them [default: anywhere in the bounds].
    #[arg(long, value_name = "FILE")]
    pub allowed: Option<String>,
    /// Smallest distance between any two nodes (moved or fixed), m [default: 0].
    #[arg(long, value_name = "M", value_parser = finite)]
    pub min_spacing: Option<f64>,
    /// ROI grid side of the reported objective, 2..=512 [default: 64] (the search uses N/2, at
    /// least 16, at most N).
    #[arg(long, value_name = "N", value_parser = whole)]
    pub grid: Option<usize>,
    /// Objective evaluations of the search, 1..=1000000 [default: 10000].
    #[arg(long, value_name = "EVALS", value_parser = whole)]
    pub budget: Option<usize>,
    /// Random seed of the search [default: 1].
    #[arg(long, value_name = "S", value_parser = seed)]
    pub seed: Option<u64>,
    /// Output plan file (.json): the optimised scenario, the objective before and after, the
    /// history and the moved nodes' paths.
    #[arg(long, value_name = "plan.json")]
    pub out: String,
    /// Figure (.svg or .png): the CRLB maps before and after side by side on one colour scale,
    /// the ROI and the moved nodes' paths.
    #[arg(long, value_name = "F.{svg,png}")]
    pub figure: Option<String>,
}
