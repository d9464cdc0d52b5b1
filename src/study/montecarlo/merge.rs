//! The merge of a Monte Carlo study's part files: the sums a shard records
//! ([`MonteCarloStudy::part_sums`]) and a checked set of them added exactly, each part's sums
//! checked against the study first ([`MonteCarloStudy::merge`]).

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use super::{MonteCarloStudy, RunTime};
use crate::error::{Error, Result};
use crate::study::part::{inconsistent, load_sums, merged_timing, PartSet};
use crate::study::sums::check_sums;
use crate::study::FilterStudy;
use crate::track::StudySums;

impl MonteCarloStudy {
    /// The sums a shard's part file records: per trajectory, one entry per filter in order.
    pub fn part_sums(runs: &[FilterStudy]) -> Vec<StudySums> {
        runs.iter().flat_map(FilterStudy::sums).collect()
    }

    /// The merge of a checked set of part files ([`PartSet::read`]): the study of its
    /// configuration ([`MonteCarloStudy::from_config`]), every trajectory's runs with the sums
    /// of every shard added exactly, and each trajectory's run time (the wall times added, the
    /// most threads of any part, the thread time `Σ wall · threads`). Each part's sums are
    /// read again through `load`, one part at a time, and checked against their digest and the
    /// study ([`crate::study::Part::read_sums`], `check_sums`; the invariants are listed in
    /// [`crate::study::PartSet`]). A part whose sums or timing do not fit the study
    /// is [`Error::InconsistentPart`], naming the part and the field.
    pub fn merge(
        set: &PartSet,
        load: &mut dyn FnMut(&str) -> Result<String>,
    ) -> Result<(MonteCarloStudy, Vec<FilterStudy>, Vec<RunTime>)> {
        let parts = &set.parts;
        let first = parts.first().ok_or(Error::PartSet {
            what: "merge: no part files given".into(),
        })?;
        let study = MonteCarloStudy::from_config(&set.config).map_err(|e| match e {
            Error::Parse { message } => inconsistent(&first.path, message),
            e => inconsistent(&first.path, e),
        })?;
        let total = study.chunk_count();
        if first.shard.total != total {
            return Err(inconsistent(
                &first.path,
                format!(
                    "shard.total {} is not the study's {total} chunks",
                    first.shard.total
                ),
            ));
        }
        // Timing first (no sums read for a part whose header does not fit).
        let (timing, thread_s) = merged_timing(parts, study.configs.len())?;
        let per = study.filters.len();
        let entries = study.configs.len() * per;
        let steps = study.track.steps;
        // The longest array of a part's sums: the per-step lists, the entries, the partials of
        // an exact sum (at most ~40).
        let max_len = (steps + 1).max(entries).max(64);
        let mut runs = (0..study.configs.len())
            .map(|k| study.filter_study(k))
            .collect::<Result<Vec<_>>>()?;
        for part in parts {
            let sums: Vec<StudySums> = load_sums(part, max_len, load)?;
            let chunks = part.shard.range[0]..part.shard.range[1];
            if sums.len() != entries {
                return Err(inconsistent(
                    &part.path,
                    format!(
                        "sums: {} entries, not {} trajectories × {per} filters",
                        sums.len(),
                        study.configs.len()
                    ),
                ));
            }
            for (k, (cfg, run)) in study.configs.iter().zip(runs.iter_mut()).enumerate() {
                let of_trajectory = &sums[k * per..(k + 1) * per];
                check_sums(cfg, &chunks, k * per, of_trajectory)
                    .map_err(|what| inconsistent(&part.path, what))?;
                for (f, s) in of_trajectory.iter().enumerate() {
                    run.add_sums(f, s, chunks.len());
                }
            }
        }
        let times = timing
            .wall_time_s
            .iter()
            .zip(&thread_s)
            .map(|(&wall_s, &thread_s)| RunTime {
                wall_s,
                thread_s,
                threads: timing.threads,
            })
            .collect();
        Ok((study, runs, times))
    }
}
