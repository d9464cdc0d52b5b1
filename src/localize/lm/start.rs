//! Grid multi-start: the starting points LM is run from when the caller gives none (or the
//! caller's start ends implausibly).

use alloc::vec::Vec;

use super::problem::Problem;
use crate::math::{Real, Vec2};
use crate::scenario::Area;

/// Most grid nodes evaluated by the start search; a larger area gets a coarser grid.
pub const MAX_GRID_START_NODES: usize = 1 << 20;
/// Number of grid local minima LM is started from when no start is given.
pub const GRID_STARTS: usize = 4;

/// Start candidates (spec §5 [choice], extended): the nodes of a `step` grid over `area` whose
/// cost is a local minimum among their 8 neighbours, best first, at most [`GRID_STARTS`], each
/// followed by its 8 neighbours. The first is the spec's "best node of the grid"; the others
/// cover the small basins of truths near a node, which a 0.5 m grid can straddle.
pub(super) fn grid_starts(p: &Problem, area: &Area, step: Real) -> Vec<Vec2> {
    let (w, h) = (area.x[1] - area.x[0], area.y[1] - area.y[0]);
    let mut step = step;
    while ((w / step) as usize + 1) * ((h / step) as usize + 1) > MAX_GRID_START_NODES {
        step *= 2.0;
    }
    let (nx, ny) = ((w / step) as usize + 1, (h / step) as usize + 1);
    let at =
        |i: usize, j: usize| Vec2::new(area.x[0] + i as Real * step, area.y[0] + j as Real * step);
    let mut cost = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            cost.push(p.cost(at(i, j)));
        }
    }
    let mut minima: Vec<(Real, usize)> = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let c = cost[j * nx + i];
            let lowest = (j.saturating_sub(1)..(j + 2).min(ny))
                .all(|jj| (i.saturating_sub(1)..(i + 2).min(nx)).all(|ii| cost[jj * nx + ii] >= c));
            if lowest && c.is_finite() {
                minima.push((c, j * nx + i));
            }
        }
    }
    minima.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut starts = Vec::with_capacity(9 * GRID_STARTS);
    for &(_, k) in minima.iter().take(GRID_STARTS) {
        let (i, j) = (k % nx, k / nx);
        starts.push(at(i, j));
        for jj in j.saturating_sub(1)..(j + 2).min(ny) {
            for ii in i.saturating_sub(1)..(i + 2).min(nx) {
                if (ii, jj) != (i, j) {
                    starts.push(at(ii, jj));
                }
            }
        }
    }
    starts
}
