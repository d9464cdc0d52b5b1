//! The commands of `scatterloc`, one file per family: the single-snapshot commands (`preset`,
//! `crlb`, `locate` in `scenario`, `crlb-map` in `crlb_map`), tracking (`track` with its figure
//! in `track_fig`), the channel front end (`cir simulate|estimate|track` in `cir`; `cir convert`
//! and the opening of any recording file, `.npz` or CSI, in `cir_convert`; `cir track --follow` and
//! `cir stream`, the frame stream, in `cir_follow`), gating
//! (`calibrate`, `simulate-walk`), the tracking studies (`montecarlo`, `pcrlb`, sharing `study`
//! and `report`), network planning (`plan`), the multi-target commands (`mtl`), and scale-out:
//! one shard of a study (`--shard`, its part file in `shard`), `merge` (the part files read by
//! `parts`), and a sharded study submitted to Slurm (`slurm submit`). Each takes its parsed
//! flags from `crate::cli`, reads its inputs (`io`), calls the library and writes JSON to
//! stdout and files atomically (`output`).

mod cir;
mod cir_convert;
mod cir_fig;
mod cir_follow;
mod crlb_map;
mod doppler_study;
mod filters;
mod flags;
mod gating;
mod io;
mod merge;
mod montecarlo;
mod mtl;
mod multi_study;
mod output;
mod parts;
mod plan;
mod report;
mod scenario;
mod shard;
mod slurm;
mod study;
mod track;
mod track_fig;
mod track_people_fig;

pub use cir::{cir_estimate, cir_simulate, cir_track};
pub use cir_convert::cir_convert;
pub use cir_follow::{cir_stream, cir_track_follow};
pub use crlb_map::crlb_map;
pub use gating::{calibrate, simulate_walk};
pub use merge::merge;
pub use montecarlo::{montecarlo, pcrlb};
pub use mtl::{mtl_locate, mtl_roc, mtl_table2};
pub use plan::plan;
pub use scenario::{crlb, locate, preset};
pub use slurm::slurm_submit;
pub use track::track;
