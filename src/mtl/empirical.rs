//! The empirical blocking model of spec `multi-target.md` §6.3: node-pattern probabilities
//! `P_node(γ^T = a, γ^R = b | x)` tabulated per grid cell, from measurements (counts of observed
//! LoS patterns) or from a simulation of the scatterer process. It implements
//! [`NodePatternModel`], so the Bayesian likelihood (M4–M5) consumes it exactly like the PPP
//! model (same interface, §6.3).
//!
//! Reconstruction choices (**\[P\]**, all parameters):
//! - the table is per cell of a regular `nx × ny` grid over the region `R`; a location outside
//!   `R` uses the nearest cell;
//! - probabilities are smoothed with an additive (Dirichlet) pseudo-count `α` per pattern,
//!   `P = (n_ℓ + α) / (n + α·2^{N_t+N_r})`, so no pattern has probability 0 (`L_b` stays
//!   finite) and an empty cell is uniform;
//! - [`EmpiricalTable::train_discs`] simulates the §7 disc process for a *fixed* network: disc
//!   centres a PPP of intensity `λ` in `R` without the centres within `D/2` of a node (nodes
//!   are outside scatterers, §7 step 2), one target point uniform in every cell per scene
//!   (skipped when a disc covers it, §7 step 3), LoS as §7 step (4). Unlike the rectangle model
//!   (M9–M11), this keeps the exclusion zones the spec's model caveat mentions.

use alloc::vec;
use alloc::vec::Vec;
use serde::{Deserialize, Serialize};

use crate::error::{check_len, Error, Result};
use crate::math::{Real, Vec2};
use crate::measure::Rng;
use crate::mtl::blocking::NodePatternModel;
use crate::mtl::polygon::Rect;
use crate::mtl::sim::scene::{is_free, poisson, segment_is_los, uniform};
use crate::mtl::trp::MAX_NODES;

/// Largest `nx · ny · 2^{N_t+N_r}` table accepted (16 Mi counts = 64 MiB).
pub const MAX_TABLE_ENTRIES: usize = 1 << 24;

/// Largest number of simulated scenes accepted by [`EmpiricalTable::train_discs`].
pub const MAX_TRAINING_SCENES: usize = 1_000_000;

/// Node-pattern counts per grid cell (§6.3). Serialised as the `empirical` model input of the
/// CLI; [`EmpiricalTable::validate`] checks a deserialised table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EmpiricalTable {
    /// Lower-left corner of the region `R`, m.
    pub min_m: [Real; 2],
    /// Upper-right corner of the region `R`, m.
    pub max_m: [Real; 2],
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Number of transmitters `N_t` (the pattern index is `a | b << N_t`).
    pub n_tx: usize,
    /// Number of receivers `N_r`.
    pub n_rx: usize,
    /// Additive pseudo-count `α` per pattern (≥ 0; **\[P\]** default 0.5).
    pub pseudo_count: Real,
    /// `counts[cell][a | b << N_t]`, cell `= ix + iy·nx`.
    pub counts: Vec<Vec<u32>>,
}

/// Default pseudo-count `α` (**\[P\]**, Jeffreys' prior).
pub const DEFAULT_PSEUDO_COUNT: Real = 0.5;

impl EmpiricalTable {
    /// An empty table (all counts 0) over `region` with `nx × ny` cells for `n_tx` TXs and
    /// `n_rx` RXs. Errors as [`EmpiricalTable::validate`].
    pub fn new(region: &Rect, nx: usize, ny: usize, n_tx: usize, n_rx: usize) -> Result<Self> {
        let mut t = EmpiricalTable {
            min_m: [region.min.x, region.min.y],
            max_m: [region.max.x, region.max.y],
            nx,
            ny,
            n_tx,
            n_rx,
            pseudo_count: DEFAULT_PSEUDO_COUNT,
            counts: Vec::new(),
        };
        t.check_shape()?;
        t.counts = vec![vec![0; t.n_patterns()]; nx * ny];
        Ok(t)
    }

    /// Number of node patterns `2^{N_t+N_r}`.
    pub fn n_patterns(&self) -> usize {
        1usize << (self.n_tx + self.n_rx)
    }

    /// The region `R`.
    pub fn region(&self) -> Result<Rect> {
        Rect::named(
            ["min_m/max_m", "min_m[0]/max_m[0]", "min_m[1]/max_m[1]"],
            Vec2::new(self.min_m[0], self.min_m[1]),
            Vec2::new(self.max_m[0], self.max_m[1]),
        )
    }

    fn check_shape(&self) -> Result<()> {
        self.region()?;
        for (field, n) in [("nx", self.nx), ("ny", self.ny)] {
            if !(1..=4096).contains(&n) {
                return Err(Error::SizeLimit {
                    field,
                    value: n,
                    min: 1,
                    max: 4096,
                });
            }
        }
        for (field, n) in [("n_tx", self.n_tx), ("n_rx", self.n_rx)] {
            if n == 0 {
                return Err(Error::EmptyNodeList { field });
            }
        }
        if self.n_tx + self.n_rx > MAX_NODES {
            return Err(Error::SizeLimit {
                field: "n_tx+n_rx",
                value: self.n_tx + self.n_rx,
                min: 2,
                max: MAX_NODES,
            });
        }
        let entries = self.nx * self.ny * self.n_patterns();
        if entries > MAX_TABLE_ENTRIES {
            return Err(Error::SizeLimit {
                field: "nx*ny*patterns",
                value: entries,
                min: 1,
                max: MAX_TABLE_ENTRIES,
            });
        }
        if !(self.pseudo_count.is_finite() && self.pseudo_count >= 0.0) {
            return Err(Error::OutOfRange {
                field: "pseudo_count".into(),
                value: self.pseudo_count,
                allowed: "a finite value ≥ 0",
            });
        }
        Ok(())
    }

    /// Checks a table (e.g. read from JSON). Errors: [`Error::InvertedArea`] / [`Error::NonFinite`]
    /// (region); [`Error::SizeLimit`] (`nx`, `ny` in 1..=4096, `n_tx+n_rx` ≤
    /// [`MAX_NODES`], `nx*ny*patterns` ≤ [`MAX_TABLE_ENTRIES`]); [`Error::EmptyNodeList`]
    /// (`n_tx`, `n_rx`); [`Error::OutOfRange`] (`pseudo_count`); [`Error::LengthMismatch`]
    /// (`counts`: one row per cell, one count per pattern); [`Error::OutOfRange`] (`counts`)
    /// when a cell has no observation and `α = 0` (its probabilities would be 0/0).
    pub fn validate(&self) -> Result<()> {
        self.check_shape()?;
        check_len("counts", self.nx * self.ny, self.counts.len())?;
        for row in &self.counts {
            check_len("counts[cell]", self.n_patterns(), row.len())?;
            if self.pseudo_count == 0.0 && row.iter().all(|&c| c == 0) {
                return Err(Error::OutOfRange {
                    field: "counts".into(),
                    value: 0.0,
                    allowed: "every cell needs an observation when pseudo_count = 0",
                });
            }
        }
        Ok(())
    }

    /// The cell of `x` (the nearest cell when `x` is outside the region); `None` when `x` is
    /// not finite.
    pub fn cell_of(&self, x: &Vec2) -> Option<usize> {
        if !(x.x.is_finite() && x.y.is_finite()) {
            return None;
        }
        let index = |v: Real, lo: Real, hi: Real, n: usize| {
            let t = (v - lo) / (hi - lo) * n as Real;
            (t.max(0.0) as usize).min(n - 1)
        };
        let ix = index(x.x, self.min_m[0], self.max_m[0], self.nx);
        let iy = index(x.y, self.min_m[1], self.max_m[1], self.ny);
        Some(ix + iy * self.nx)
    }

    /// The rectangle of cell `cell`.
    pub fn cell_rect(&self, cell: usize) -> Rect {
        let (ix, iy) = ((cell % self.nx) as Real, (cell / self.nx) as Real);
        let w = (self.max_m[0] - self.min_m[0]) / self.nx as Real;
        let h = (self.max_m[1] - self.min_m[1]) / self.ny as Real;
        let min = Vec2::new(self.min_m[0] + ix * w, self.min_m[1] + iy * h);
        Rect {
            min,
            max: min + Vec2::new(w, h),
        }
    }

    /// Records one observation: at `x`, TX LoS mask `a` and RX LoS mask `b`. Errors:
    /// [`Error::NonFinite`] (`x`); [`Error::IndexOutOfRange`] (`pattern`) when `a` or `b` has a
    /// bit past the node counts.
    pub fn record(&mut self, x: &Vec2, a: u64, b: u64) -> Result<()> {
        let cell = self
            .cell_of(x)
            .ok_or(Error::NonFinite { field: "x".into() })?;
        let index = (a | b << self.n_tx) as usize;
        if a >> self.n_tx != 0 || index >= self.n_patterns() {
            return Err(Error::IndexOutOfRange {
                field: "pattern",
                index,
                len: self.n_patterns(),
            });
        }
        let c = &mut self.counts[cell][index];
        *c = c.saturating_add(1);
        Ok(())
    }

    /// Observations in cell `cell`.
    pub fn observations(&self, cell: usize) -> u64 {
        self.counts
            .get(cell)
            .map_or(0, |r| r.iter().map(|&c| c as u64).sum())
    }

    /// The smoothed probabilities of cell `cell`, indexed `a | b << N_t` (they sum to 1).
    pub fn cell_probabilities(&self, cell: usize) -> Vec<Real> {
        let n = self.n_patterns();
        let Some(row) = self.counts.get(cell) else {
            return vec![0.0; n];
        };
        let total = self.observations(cell) as Real + self.pseudo_count * n as Real;
        if total <= 0.0 {
            return vec![0.0; n];
        }
        row.iter()
            .map(|&c| (c as Real + self.pseudo_count) / total)
            .collect()
    }

    /// Adds `scenes` simulated disc scenes for the fixed network `tx`, `rx` (see the module
    /// doc): disc centres a PPP of intensity `lambda` in the region, diameter `diameter`, one
    /// target point per cell per scene. Deterministic in `rng`'s state.
    ///
    /// Errors: [`Error::NonFinite`] (`tx[j]` / `rx[j]`); [`Error::LengthMismatch`] (`tx`, `rx`)
    /// when the node counts differ from the table's; the PPP parameter errors of
    /// [`crate::mtl::ppp::PppBlocking::new`]; [`Error::SizeLimit`] (`scenes`) above
    /// [`MAX_TRAINING_SCENES`]; [`Error::OutOfRange`] (`lambda`) when the mean disc count
    /// exceeds 10 000.
    pub fn train_discs(
        &mut self,
        tx: &[Vec2],
        rx: &[Vec2],
        lambda: Real,
        diameter: Real,
        scenes: usize,
        rng: &mut Rng,
    ) -> Result<()> {
        let region = self.region()?;
        crate::mtl::ppp::PppBlocking::new(lambda, diameter, Some(region), true)?;
        for (field, list, n) in [("tx", tx, self.n_tx), ("rx", rx, self.n_rx)] {
            if list.len() != n {
                return Err(Error::LengthMismatch {
                    field,
                    expected: n,
                    found: list.len(),
                });
            }
            if let Some(j) = list
                .iter()
                .position(|p| !(p.x.is_finite() && p.y.is_finite()))
            {
                return Err(Error::NonFinite {
                    field: alloc::format!("{field}[{j}]"),
                });
            }
        }
        if scenes > MAX_TRAINING_SCENES {
            return Err(Error::SizeLimit {
                field: "scenes",
                value: scenes,
                min: 0,
                max: MAX_TRAINING_SCENES,
            });
        }
        let mean = lambda * region.area();
        if mean > 10_000.0 {
            return Err(Error::OutOfRange {
                field: "lambda".into(),
                value: lambda,
                allowed: "a mean disc count ≤ 10 000",
            });
        }
        let mut discs = Vec::new();
        for _ in 0..scenes {
            discs.clear();
            for _ in 0..poisson(rng, mean) {
                let c = region.min
                    + Vec2::new(
                        (region.max.x - region.min.x) * uniform(rng),
                        (region.max.y - region.min.y) * uniform(rng),
                    );
                // Nodes lie outside every scatterer: the PPP conditioned on that is the PPP
                // without the centres near a node.
                if tx.iter().chain(rx).all(|n| is_free(n, &[c], diameter)) {
                    discs.push(c);
                }
            }
            for cell in 0..self.nx * self.ny {
                let r = self.cell_rect(cell);
                let x = r.min
                    + Vec2::new((r.max.x - r.min.x) * uniform(rng), 0.0)
                    + Vec2::new(0.0, (r.max.y - r.min.y) * uniform(rng));
                if !is_free(&x, &discs, diameter) {
                    continue;
                }
                let mask = |nodes: &[Vec2]| {
                    nodes.iter().enumerate().fold(0u64, |m, (j, n)| {
                        m | (segment_is_los(n, &x, &discs, diameter, None) as u64) << j
                    })
                };
                let (a, b) = (mask(tx), mask(rx));
                let c = &mut self.counts[cell][(a | b << self.n_tx) as usize];
                *c = c.saturating_add(1);
            }
        }
        Ok(())
    }
}

/// A validated [`EmpiricalTable`] as a [`NodePatternModel`] (§6.3).
#[derive(Debug, Clone, PartialEq)]
pub struct EmpiricalNodeModel {
    table: EmpiricalTable,
}

impl EmpiricalNodeModel {
    /// The model of `table`; errors as [`EmpiricalTable::validate`].
    pub fn new(table: EmpiricalTable) -> Result<Self> {
        table.validate()?;
        Ok(Self { table })
    }

    /// The table.
    pub fn table(&self) -> &EmpiricalTable {
        &self.table
    }
}

impl NodePatternModel for EmpiricalNodeModel {
    /// The smoothed frequency of pattern `(a, b)` in the cell of `x`; 0 when `x` is not finite
    /// or the pattern is out of range.
    fn node_pattern_probability(&self, x: &Vec2, a: u64, b: u64) -> Real {
        let t = &self.table;
        let index = (a | b << t.n_tx) as usize;
        match t.cell_of(x) {
            Some(cell) if a >> t.n_tx == 0 && index < t.n_patterns() => {
                let total = t.observations(cell) as Real + t.pseudo_count * t.n_patterns() as Real;
                (t.counts[cell][index] as Real + t.pseudo_count) / total
            }
            _ => 0.0,
        }
    }

    fn pattern_probabilities_at(&self, x: &Vec2, n_tx: usize, n_rx: usize) -> Vec<Real> {
        match self.table.cell_of(x) {
            Some(cell) if (n_tx, n_rx) == (self.table.n_tx, self.table.n_rx) => {
                self.table.cell_probabilities(cell)
            }
            _ => vec![0.0; 1 << (n_tx + n_rx)],
        }
    }
}
