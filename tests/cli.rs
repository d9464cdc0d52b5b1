//! End-to-end tests of the `scatterloc` binary, one module per command family: presets, CRLB,
//! maps, locate, help and completions (`basics`), tracking studies (`tracking`, `montecarlo`,
//! `filters`), the gating pipeline (`gating`), the Wi-Fi CSI files through `cir convert`/`cir estimate` (`csi`), the planner (`plan`), the multi-target commands
//! (`mtl`), `track` with range rates in the measurement file (`track_doppler`, issue 42 §5), sharded studies and `merge` (`scale_out`), bounded, named bad input (`hardening`;
//! issue 37's command-line items in `hardening3`), and the outputs of a fixed set of commands pinned to those of the binary before issue 23
//! (`pinned`), and the output writer's guarantees: atomic, never through a link, a FIFO or a
//! device, all-or-nothing, checked stdout (`outputs`, issue 24). Every module checks the "exit 2 + one stderr line naming the field" contract.
#![cfg(not(target_arch = "wasm32"))]

mod common;

/// SVG checks shared with the page tests (the map figure's embedded PNG).
#[allow(dead_code)]
#[path = "common/svg.rs"]
mod svg;

/// A channel track's NEES against its truth (issue 38 §11), shared with the page tests.
#[path = "common/nees.rs"]
mod nees;

#[path = "cli/basics.rs"]
mod basics;

#[path = "cli/cir.rs"]
mod cir;

/// The crossing walkers of issue 41 §3 (shared with the library's tests).
#[path = "common/crossing.rs"]
mod crossing;

#[path = "cli/cir_multi.rs"]
mod cir_multi;

#[path = "cli/cir_doppler.rs"]
mod cir_doppler;

#[cfg(feature = "npz")]
#[path = "cli/csi.rs"]
mod csi;

#[path = "cli/detections.rs"]
mod detections;

#[path = "cli/doppler.rs"]
mod doppler;

#[path = "cli/filters.rs"]
mod filters;

#[path = "cli/follow.rs"]
mod follow;

#[cfg(feature = "npz")]
#[path = "cli/follow_csi.rs"]
mod follow_csi;

#[path = "cli/free_z.rs"]
mod free_z;

#[path = "cli/gating.rs"]
mod gating;

#[path = "cli/hardening.rs"]
mod hardening;

#[path = "cli/hardening3.rs"]
mod hardening3;

#[path = "cli/montecarlo.rs"]
mod montecarlo;

#[path = "cli/multi.rs"]
mod multi;

#[path = "cli/mtl.rs"]
mod mtl;

#[path = "cli/outputs.rs"]
mod outputs;

#[path = "cli/pinned.rs"]
mod pinned;

#[path = "cli/plan.rs"]
mod plan;

#[path = "cli/scale_out.rs"]
mod scale_out;

#[path = "cli/tracking.rs"]
mod tracking;

#[path = "cli/track_doppler.rs"]
mod track_doppler;
