//! The Monte Carlo study of [S] §5.2 (spec §8, §9.5, Fig. 3 of §10) as one use case: a layout,
//! the trajectories of §9.4, the step and duration ([`TrackStudy`]), the run counts and seed,
//! and the list of trackers ([`MonteCarloStudy`]), in `study.rs`; its persistent
//! configuration, the `config` of its part files ([`McConfig`], `config.rs`); its result
//! documents, one per trajectory ([`CurveDoc`] with [`McMeta`], or [`PcrlbMeta`] for a
//! posterior-CRLB curve, `documents.rs`); and the merge of its part files (`merge.rs`).

mod config;
mod documents;
mod merge;
mod study;

pub use config::{FiltersConfig, McConfig};
pub use documents::{
    curve_label, failed_label, CurveDoc, FilterCurves, FilterDoc, McMeta, PcrlbMeta, RunTime,
    FAILED_NOTE,
};
pub use study::{MonteCarloStudy, TrackStudy};

#[cfg(test)]
mod tests;
