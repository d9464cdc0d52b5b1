//! Planning objectives over a region of interest (`filters-and-planning.md` §3): the CRLB RMSE
//! bound (E8, S24) of every cell centre of an ROI grid, reduced to `mean`, `p90`, `max` or
//! `coverage:T`, and the total order the optimiser ranks layouts by.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;
use core::cmp::Ordering;

use crate::error::{Error, Result};
use crate::localize::{crlb_map, Grid};
use crate::math::Real;
use crate::measure::Model;
use crate::scenario::Area;

/// What a layout is judged by, over the ROI cells' RMSE bounds (m, `+∞` where unbounded).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Objective {
    /// Arithmetic mean, minimised (`+∞` when any cell is unbounded).
    Mean,
    /// The 90th percentile, minimised: linear interpolation between the order statistics at rank
    /// `0.9 (N − 1)` (numpy's default), `+∞` dominating, so coverage holes are punished.
    P90,
    /// The largest bound, minimised.
    Max,
    /// The fraction of cells whose bound is at most `threshold_m`, maximised; ties broken by the
    /// mean.
    Coverage {
        /// The threshold `T`, m.
        threshold_m: Real,
    },
}

impl Objective {
    /// Parses `mean`, `p90`, `max` or `coverage:T` (T in metres, finite and > 0).
    pub fn parse(text: &str) -> Result<Objective> {
        let bad = || Error::OutOfRange {
            field: "objective".into(),
            value: Real::NAN,
            allowed: "mean, p90, max or coverage:T with T > 0 m",
        };
        match text.trim() {
            "mean" => Ok(Objective::Mean),
            "p90" => Ok(Objective::P90),
            "max" => Ok(Objective::Max),
            t => {
                let v = t.strip_prefix("coverage:").ok_or_else(bad)?;
                let threshold_m: Real = v.trim().parse().map_err(|_| bad())?;
                Objective::Coverage { threshold_m }.validated()
            }
        }
    }

    /// The objective if its threshold is valid (finite, `0 < T ≤ 10⁸ m`).
    pub fn validated(self) -> Result<Objective> {
        if let Objective::Coverage { threshold_m } = self {
            if !(threshold_m.is_finite() && threshold_m > 0.0 && threshold_m <= 1e8) {
                return Err(Error::OutOfRange {
                    field: "objective.threshold_m".into(),
                    value: threshold_m,
                    allowed: "a coverage threshold T with 0 < T <= 1e8 m",
                });
            }
        }
        Ok(self)
    }

    /// The short name: `mean`, `p90`, `max`, `coverage`.
    pub fn kind(&self) -> &'static str {
        match self {
            Objective::Mean => "mean",
            Objective::P90 => "p90",
            Objective::Max => "max",
            Objective::Coverage { .. } => "coverage",
        }
    }

    /// `kind`, with `:T` for coverage (the CLI's spelling).
    pub fn label(&self) -> String {
        match self {
            Objective::Coverage { threshold_m } => format!("coverage:{threshold_m}"),
            o => o.kind().to_string(),
        }
    }

    /// Whether larger values are better (coverage).
    pub fn maximised(&self) -> bool {
        matches!(self, Objective::Coverage { .. })
    }

    /// Scores cell values (RMSE bounds, m; `+∞` unbounded; not NaN). `cells` is reordered.
    pub fn score(&self, cells: &mut [Real]) -> Score {
        let n = cells.len();
        let unbounded = cells.iter().filter(|v| !v.is_finite()).count();
        let bounded_sum: Real = cells.iter().filter(|v| v.is_finite()).sum();
        let bounded_mean = if unbounded < n {
            bounded_sum / (n - unbounded) as Real
        } else {
            Real::INFINITY
        };
        let mean = if unbounded > 0 {
            Real::INFINITY
        } else {
            bounded_mean
        };
        let value = match *self {
            Objective::Mean => mean,
            Objective::Max => cells.iter().copied().fold(0.0, Real::max),
            Objective::P90 => percentile(cells, 0.9),
            Objective::Coverage { threshold_m } => {
                cells.iter().filter(|&&v| v <= threshold_m).count() as Real / n as Real
            }
        };
        Score {
            value,
            cost: if self.maximised() { -value } else { value },
            unbounded,
            bounded_mean,
        }
    }
}

/// The interpolated percentile `q` of `v` (numpy's default "linear" method, rank `q (N − 1)`),
/// `+∞` dominating; `v` is reordered (two selections, O(N)).
pub(super) fn percentile(v: &mut [Real], q: Real) -> Real {
    let rank = q * (v.len() - 1) as Real;
    let k = rank as usize; // floor: rank ≥ 0
    let frac = rank - k as Real;
    let (_, lo, rest) = v.select_nth_unstable_by(k, Real::total_cmp);
    let lo = *lo;
    if frac == 0.0 || rest.is_empty() {
        return lo;
    }
    let hi = rest.iter().copied().fold(Real::INFINITY, Real::min);
    if hi.is_infinite() {
        return Real::INFINITY;
    }
    lo + frac * (hi - lo)
}

/// A layout's objective and the keys that rank it: `cost` (the value, negated when maximised),
/// then fewer unbounded cells, then a smaller mean over the bounded ones. The last two tell apart
/// layouts whose value is `+∞` (holes) or tied (coverage: "ties broken by the mean").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Score {
    /// The objective as reported: m, or a fraction for coverage; `+∞` when unbounded.
    pub value: Real,
    /// `value`, or `−value` when maximised: smaller is better.
    pub cost: Real,
    /// Unbounded ROI cells.
    pub unbounded: usize,
    /// Mean bound over the bounded cells, m (`+∞` when none).
    pub bounded_mean: Real,
}

impl Score {
    /// The total order of layouts: `Less` = better.
    pub fn rank(&self, other: &Score) -> Ordering {
        self.cost
            .total_cmp(&other.cost)
            .then(self.unbounded.cmp(&other.unbounded))
            .then(self.bounded_mean.total_cmp(&other.bounded_mean))
    }

    /// `value` for JSON: `None` when unbounded.
    pub fn finite_value(&self) -> Option<Real> {
        self.value.is_finite().then_some(self.value)
    }
}

/// An objective over an ROI grid with its reusable map buffer.
#[derive(Debug, Clone)]
pub struct RoiObjective {
    /// What is computed from the cells.
    pub objective: Objective,
    /// The ROI's cell centres.
    pub grid: Grid,
    cells: Vec<Real>,
    kernel: super::MapKernel,
}

impl RoiObjective {
    /// An `n × n` grid over `roi` (validated: errors name `roi`).
    pub fn new(objective: Objective, roi: Area, n: usize) -> Result<RoiObjective> {
        roi.validate_as(["roi.x", "roi.y"])?;
        let grid = Grid::new(roi, n, n)?;
        Ok(RoiObjective {
            objective: objective.validated()?,
            grid,
            cells: vec![0.0; grid.len()],
            kernel: crlb_map,
        })
    }

    /// The same objective scored with `kernel` (the planner's [`super::PlanConfig::kernel`]).
    pub fn with_kernel(mut self, kernel: super::MapKernel) -> RoiObjective {
        self.kernel = kernel;
        self
    }

    /// The score of `model` (the map kernel over the grid, then [`Objective::score`]).
    pub fn evaluate(&mut self, model: &Model) -> Score {
        // The buffer has the grid's length, so the kernel cannot fail.
        if (self.kernel)(model, &self.grid, &mut self.cells).is_err() {
            self.cells.fill(Real::INFINITY);
        }
        self.objective.score(&mut self.cells)
    }
}
