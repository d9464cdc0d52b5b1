//! The library's API across layers, one module per topic: one test per bad-input class
//! (`bad_input`), the channel front end's loops within their bounds on random multipath
//! (`bounds`, spec C12 7), the SIMD CRLB map kernel against its scalar reference (`map_kernel`), the
//! planner's evidence (`planning`, `filters-and-planning.md` §3) and property tests of the core
//! (`properties`, proptest; shrunk failures in `library/properties.proptest-regressions`) and the
//! `.npz` recording format of docs/recording.md (`recording`, feature `npz`), the six real Wi-Fi
//! CSI files read and their direct paths found (`csi`, issue 40) and the house rules of
//! ARCHITECTURE.md read off the source (`house`: no import circle, the layer table, the line cap).
#![cfg(not(target_arch = "wasm32"))]

mod common;

#[path = "library/bad_input.rs"]
mod bad_input;

#[path = "library/bounds.rs"]
mod bounds;

#[path = "library/doppler.rs"]
mod doppler;

#[path = "library/channel_doppler.rs"]
mod channel_doppler;

#[path = "library/map_kernel.rs"]
mod map_kernel;

#[path = "library/planning.rs"]
mod planning;

#[path = "library/properties.rs"]
mod properties;

#[cfg(feature = "npz")]
#[path = "library/recording.rs"]
mod recording;

#[cfg(feature = "npz")]
#[path = "library/csi.rs"]
mod csi;

#[path = "library/house.rs"]
mod house;
