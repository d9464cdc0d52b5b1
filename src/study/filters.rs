//! The Monte Carlo study of one or more trackers on one configuration (issue 15, issue 23 §3):
//! every filter of the list runs on the same truth trajectories and measurements
//! ([`run_filter_chunk`]); the EKF alone is the list `[ekf]` and keeps its lane-batched fast
//! path ([`crate::track::run_chunk`]). A particle filter may be held to a work budget (the
//! leading chunks whose particle-steps fit). The lead filter — the EKF when it runs, else the
//! first — gives a result's top-level curves, and `ε_PCRLB` (E9) comes from the filter with
//! the most trajectories counted. The CLI (whole or one shard), its `merge` and the page's
//! worker all run a study through this type.

use alloc::string::ToString;
use alloc::vec::Vec;
use core::ops::Range;

use crate::error::{Error, Result};
use crate::measure::Model;
use crate::study::Driver;
use crate::track::{
    finish, run_filter_chunk, run_filter_chunk_in, FilterKind, MonteCarloConfig, MonteCarloResult,
    StudySums, CHUNK_TRAJECTORIES, MAX_PARTICLES, MAX_RUNS,
};

/// One tracker of a [`FilterStudy`]: its kind, the leading chunks it runs, its sums so far.
#[derive(Debug, Clone, PartialEq)]
pub struct FilterRun {
    /// The tracker.
    pub kind: FilterKind,
    /// It runs chunks `0 .. chunks` (all of them unless a particle budget holds it back).
    pub chunks: usize,
    /// Its sums over the chunks counted so far.
    pub sums: StudySums,
    /// Chunks counted so far.
    pub chunks_done: usize,
    /// The error of its first failed run in the chunks this process ran (not kept in part
    /// files: `None` after a merge).
    pub first_failure: Option<Error>,
}

impl FilterRun {
    /// The setting of this filter a user changes when all its runs fail: `particles` (too few
    /// particles degenerate), `ukf_alpha` (the sigma-point spread), `initial_covariance` (the
    /// EKF's prior).
    pub fn setting(&self) -> &'static str {
        match self.kind {
            FilterKind::Ekf => "initial_covariance",
            FilterKind::Ukf(_) => "ukf_alpha",
            FilterKind::Pf(_) => "particles",
        }
    }

    /// [`Error::AllRunsFailed`] for this filter: its setting, its failed runs, its first
    /// failure.
    pub fn all_failed(&self) -> Error {
        Error::AllRunsFailed {
            field: self.setting().into(),
            filter: self.kind.name(),
            runs: self.sums.failed_runs,
            cause: self.first_failure.as_ref().map(|e| e.to_string()),
        }
    }

    /// Runs the filter will have made when all its chunks are counted.
    pub fn runs_planned(&self, cfg: &MonteCarloConfig) -> usize {
        (self.chunks * CHUNK_TRAJECTORIES).min(cfg.trajectories) * cfg.noise_runs
    }
}

/// Several trackers' Monte Carlo study of one configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct FilterStudy {
    config: MonteCarloConfig,
    filters: Vec<FilterRun>,
    particle_budget: Option<usize>,
    /// Work items run by [`FilterStudy::run_items`].
    items_done: usize,
}

/// The curves of a [`FilterStudy`]: one result per filter that has counted a chunk, in the
/// order of the list, and which of them leads.
#[derive(Debug, Clone, PartialEq)]
pub struct FilterResults {
    /// `(index in the filter list, its curves)`.
    pub curves: Vec<(usize, MonteCarloResult)>,
    /// The entry of `curves` whose curves and counts are the study's top-level ones: the EKF's
    /// when it runs, else the first.
    pub lead: usize,
    /// The entry of `curves` with the most trajectories counted (the first on a tie): its
    /// `ε_PCRLB` is the study's.
    pub widest: usize,
    /// The filters that counted chunks but whose every run failed (issue 24), in list order:
    /// `(index in the filter list, the error naming the setting to change and the cause)`,
    /// an [`Error::AllRunsFailed`].
    pub failed: Vec<(usize, Error)>,
}

impl FilterResults {
    /// The lead filter's curves with the study's `ε_PCRLB` (from [`FilterResults::widest`]).
    pub fn top(&self) -> MonteCarloResult {
        let mut top = self.curves[self.lead].1.clone();
        top.rmse_pcrlb_m = self.curves[self.widest].1.rmse_pcrlb_m.clone();
        top
    }
}

/// The leading chunks of `cfg` a particle filter with `particles` particles runs within
/// `particle_budget` particle-steps (`runs × steps × particles`): as many whole chunks as fit,
/// at least one, at most all.
pub fn particle_chunks(cfg: &MonteCarloConfig, particles: usize, particle_budget: usize) -> usize {
    let per_run = (cfg.steps as u128) * (particles.clamp(1, MAX_PARTICLES) as u128);
    let runs = (particle_budget as u128 / per_run.max(1)) as usize;
    let per_chunk = CHUNK_TRAJECTORIES * cfg.noise_runs;
    (runs / per_chunk.max(1)).clamp(1, cfg.chunk_count().max(1))
}

impl FilterStudy {
    /// The study of `filters` (each at most once, at least one) on `config`, every filter over
    /// every chunk. Errors: the configuration's and the filters' own checks
    /// ([`MonteCarloConfig::validate`], [`FilterKind::validate`]); an empty list is
    /// [`Error::SizeLimit`] (`filters`); a repeated filter [`Error::OutOfRange`]
    /// (`filters[i]`).
    pub fn new(config: MonteCarloConfig, filters: &[FilterKind]) -> Result<FilterStudy> {
        FilterStudy::build(config, filters, None)
    }

    /// [`FilterStudy::new`] with the particle filter held to the leading chunks whose
    /// particle-steps fit `particle_budget` ([`particle_chunks`]); the other filters run every
    /// chunk.
    pub fn with_particle_budget(
        config: MonteCarloConfig,
        filters: &[FilterKind],
        particle_budget: usize,
    ) -> Result<FilterStudy> {
        FilterStudy::build(config, filters, Some(particle_budget))
    }

    fn build(
        config: MonteCarloConfig,
        filters: &[FilterKind],
        particle_budget: Option<usize>,
    ) -> Result<FilterStudy> {
        config.validate()?;
        if filters.is_empty() || filters.len() > 3 {
            return Err(Error::SizeLimit {
                field: "filters",
                value: filters.len(),
                min: 1,
                max: 3,
            });
        }
        let mut runs: Vec<FilterRun> = Vec::with_capacity(filters.len());
        for (i, &kind) in filters.iter().enumerate() {
            kind.validate()?;
            if runs.iter().any(|r| r.kind.name() == kind.name()) {
                return Err(Error::OutOfRange {
                    field: alloc::format!("filters[{i}]"),
                    value: i as f64,
                    allowed: "each filter at most once",
                });
            }
            let chunks = match (kind, particle_budget) {
                (FilterKind::Pf(c), Some(budget)) => particle_chunks(&config, c.particles, budget),
                _ => config.chunk_count(),
            };
            runs.push(FilterRun {
                kind,
                chunks,
                sums: StudySums::new(config.steps),
                chunks_done: 0,
                first_failure: None,
            });
        }
        let has_pf = filters.iter().any(|k| matches!(k, FilterKind::Pf(_)));
        Ok(FilterStudy {
            config,
            filters: runs,
            particle_budget: particle_budget.filter(|_| has_pf),
            items_done: 0,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &MonteCarloConfig {
        &self.config
    }

    /// The filters in the order of the list.
    pub fn filters(&self) -> &[FilterRun] {
        &self.filters
    }

    /// The filters' kinds in order.
    pub fn kinds(&self) -> Vec<FilterKind> {
        self.filters.iter().map(|f| f.kind).collect()
    }

    /// The particle budget, when a particle filter is held to one.
    pub fn particle_budget(&self) -> Option<usize> {
        self.particle_budget
    }

    /// The particle filter's particle count, when it runs.
    pub fn particles(&self) -> Option<usize> {
        self.filters.iter().find_map(|f| match f.kind {
            FilterKind::Pf(c) => Some(c.particles),
            _ => None,
        })
    }

    /// Work items of the study: chunks summed over the filters.
    pub fn item_count(&self) -> usize {
        self.filters.iter().map(|f| f.chunks).sum()
    }

    /// Work items run by [`FilterStudy::run_items`] so far.
    pub fn items_done(&self) -> usize {
        self.items_done
    }

    /// True once every work item has run.
    pub fn is_done(&self) -> bool {
        self.filters.iter().all(|f| f.chunks_done >= f.chunks)
    }

    /// The work items in run order: chunk by chunk, each chunk's filters in the order of the
    /// list (a filter drops out after its last chunk), as `(filter index, chunk)`.
    pub fn work_items(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        let chunks = self.filters.iter().map(|f| f.chunks).max().unwrap_or(0);
        (0..chunks).flat_map(move |c| {
            self.filters
                .iter()
                .enumerate()
                .filter(move |(_, f)| c < f.chunks)
                .map(move |(i, _)| (i, c))
        })
    }

    /// Runs up to `n` more work items in order on the calling thread (the page's worker);
    /// returns whether the study is complete. On error nothing of the failing item is counted.
    pub fn run_items(&mut self, model: &Model, n: usize) -> Result<bool> {
        let next: Vec<(usize, usize)> = self.work_items().skip(self.items_done).take(n).collect();
        for (i, chunk) in next {
            let f = &mut self.filters[i];
            let part = run_filter_chunk(model, &self.config, f.kind, chunk)?;
            f.sums.add(&part);
            if f.first_failure.is_none() {
                f.first_failure = part.first_failure;
            }
            f.chunks_done += 1;
            self.items_done += 1;
        }
        Ok(self.is_done())
    }

    /// Runs the chunks `chunks` (the whole study, or a shard's [`crate::math::Shard::range`])
    /// of every filter (each within its own chunks), filter after filter, through `driver`.
    /// `progress(done, total)` counts the runs of every filter. [`Error::IndexOutOfRange`]
    /// (`chunks`) past the last chunk.
    pub fn run_range(
        &mut self,
        model: &Model,
        chunks: Range<usize>,
        driver: &mut impl Driver,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<()> {
        let len = self.config.chunk_count();
        if chunks.end > len || chunks.start > chunks.end {
            return Err(Error::IndexOutOfRange {
                field: "chunks",
                index: chunks.end.max(chunks.start),
                len,
            });
        }
        let cfg = self.config;
        let ranges = self.ranges_of(&chunks);
        let runs_in = |r: &Range<usize>| cfg.trajectories_in(r) * cfg.noise_runs;
        let total = self.runs_in(&chunks);
        let mut offset = 0;
        for (f, range) in self.filters.iter_mut().zip(&ranges) {
            let (kind, first) = (f.kind, range.start);
            let mut sums = StudySums::new(cfg.steps);
            let failure = &mut f.first_failure;
            driver.run(
                range.len(),
                4,
                &|c, cancel| run_filter_chunk_in(model, &cfg, kind, first + c, cancel),
                &mut |part| {
                    sums.add(&part);
                    if failure.is_none() {
                        *failure = part.first_failure;
                    }
                },
                &mut |done| progress(offset + runs_in(&(first..first + done)), total),
            )?;
            f.sums.merge(&sums);
            f.chunks_done += range.len();
            offset += runs_in(range);
        }
        Ok(())
    }

    /// Each filter's part of `chunks` (a filter runs only its own leading chunks).
    fn ranges_of(&self, chunks: &Range<usize>) -> Vec<Range<usize>> {
        self.filters
            .iter()
            .map(|f| chunks.start.min(f.chunks)..chunks.end.min(f.chunks))
            .collect()
    }

    /// Runs of every filter in `chunks`: what [`FilterStudy::run_range`]'s progress counts to.
    pub fn runs_in(&self, chunks: &Range<usize>) -> usize {
        let cfg = &self.config;
        self.ranges_of(chunks)
            .iter()
            .map(|r| cfg.trajectories_in(r) * cfg.noise_runs)
            .sum()
    }

    /// Adds filter `filter`'s sums of `chunks` chunks (a part of a sharded run).
    pub fn add_sums(&mut self, filter: usize, sums: &StudySums, chunks: usize) {
        if let Some(f) = self.filters.get_mut(filter) {
            f.sums.merge(sums);
            f.chunks_done += chunks;
        }
    }

    /// Each filter's sums in order (what a shard's part file records).
    pub fn sums(&self) -> Vec<StudySums> {
        self.filters.iter().map(|f| f.sums.clone()).collect()
    }

    /// The curves of every filter that has counted a successful run ([`finish`]), the lead,
    /// the widest, and the filters whose every run failed (issue 24: reported on their own, the
    /// other filters' curves kept). [`Error::SizeLimit`] (`runs (successful)`) before any run
    /// is counted; when every filter that counted runs failed in all of them, the first one's
    /// [`Error::AllRunsFailed`] (naming the setting to change and the first failure).
    pub fn results(&self) -> Result<FilterResults> {
        let mut curves = Vec::new();
        let mut failed = Vec::new();
        for (i, f) in self.filters.iter().enumerate() {
            if f.sums.runs > 0 {
                curves.push((i, finish(&self.config, &f.sums)?));
            } else if f.sums.failed_runs > 0 {
                failed.push((i, f.all_failed()));
            }
        }
        if curves.is_empty() {
            if let Some((_, e)) = failed.into_iter().next() {
                return Err(e);
            }
            return Err(Error::SizeLimit {
                field: "runs (successful)",
                value: 0,
                min: 1,
                max: MAX_RUNS,
            });
        }
        let lead = curves
            .iter()
            .position(|(i, _)| self.filters[*i].kind == FilterKind::Ekf)
            .unwrap_or(0);
        let widest = curves
            .iter()
            .enumerate()
            .max_by_key(|(k, (i, _))| (self.filters[*i].sums.trajectories, core::cmp::Reverse(*k)))
            .map_or(0, |(k, _)| k);
        Ok(FilterResults {
            curves,
            lead,
            widest,
            failed,
        })
    }
}
