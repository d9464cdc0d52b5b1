//! The edges around the `no_std` core, each a cargo feature (ARCHITECTURE.md, "Features"): the
//! parallel driver on threads (`native`, feature `parallel`, not on wasm32), the figures on any
//! plotters backend (`chart`), the `.npz` recording reader and writer (`npz`, std, native and
//! wasm32), the Wi-Fi CSI files' readers (`csi`, with `npz`) and the page's bindings (`wasm`, wasm32). They only wrap the core: no maths here. The
//! crate root re-exports them as `scatterloc::{native, chart, npz, csi, wasm}`.

#[cfg(feature = "chart")]
pub mod chart;
#[cfg(feature = "npz")]
pub mod csi;
#[cfg(all(feature = "parallel", not(target_arch = "wasm32")))]
pub mod native;
#[cfg(feature = "npz")]
pub mod npz;
#[cfg(all(feature = "wasm", target_arch = "wasm32"))]
pub mod wasm;
