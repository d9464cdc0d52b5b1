//! The regular grid of cell centres that the CRLB map is computed on, and its size limits. A
//! leaf of `crlb`: the map (`map.rs`) and its SIMD kernel (`simd.rs`) both use it.

use crate::error::{checked_index, Error, Result};
use crate::math::{Real, Vec2};
use crate::scenario::Area;

/// Largest grid side accepted by the map kernel.
pub const MAX_GRID_SIDE: usize = 4096;
/// Largest number of grid cells accepted by the map kernel (2048²).
pub const MAX_GRID_CELLS: usize = 2048 * 2048;

/// A regular grid of cell centres over a rectangle: `x_i = x_min + (i + ½)·(x_max − x_min)/nx`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Extent, m.
    pub area: Area,
    /// Number of columns (x).
    pub nx: usize,
    /// Number of rows (y).
    pub ny: usize,
}

impl Grid {
    /// A validated grid: finite, non-inverted area; `2 ≤ nx, ny ≤ 4096`; at most 2048² cells.
    pub fn new(area: Area, nx: usize, ny: usize) -> Result<Grid> {
        area.validate()?;
        for (field, v) in [("nx", nx), ("ny", ny)] {
            if !(2..=MAX_GRID_SIDE).contains(&v) {
                return Err(Error::SizeLimit {
                    field,
                    value: v,
                    min: 2,
                    max: MAX_GRID_SIDE,
                });
            }
        }
        if nx * ny > MAX_GRID_CELLS {
            return Err(Error::SizeLimit {
                field: "nx*ny",
                value: nx * ny,
                min: 4,
                max: MAX_GRID_CELLS,
            });
        }
        Ok(Grid { area, nx, ny })
    }

    /// x of column `i` (cell centre), m.
    #[inline]
    pub fn x(&self, i: usize) -> Real {
        self.area.x[0] + (i as Real + 0.5) * (self.area.x[1] - self.area.x[0]) / self.nx as Real
    }

    /// y of row `j` (cell centre), m.
    #[inline]
    pub fn y(&self, j: usize) -> Real {
        self.area.y[0] + (j as Real + 0.5) * (self.area.y[1] - self.area.y[0]) / self.ny as Real
    }

    /// Centre of cell `(i, j)`, m; [`Error::IndexOutOfRange`] outside the grid.
    pub fn cell_center(&self, i: usize, j: usize) -> Result<Vec2> {
        let i = checked_index("grid columns", i, self.nx)?;
        let j = checked_index("grid rows", j, self.ny)?;
        Ok(Vec2::new(self.x(i), self.y(j)))
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// Always false for a validated grid.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}
