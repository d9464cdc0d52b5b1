//! The `.npz` channel-recording format of docs/recording.md, read and written in pure Rust (an
//! edge, feature `npz`: the CLI reads `--cir` files with it, the page a dropped file). A `.npz`
//! is a zip archive of `.npy` arrays; the archive goes through the `zip` crate (deflate by
//! flate2's pure-Rust backend, so it builds for wasm32-unknown-unknown) and the `.npy` headers
//! (magic, version, the `descr`/`fortran_order`/`shape` dict) are parsed here: the format is
//! small, and parsing it ourselves gives complex64/complex128, both byte orders, reading from
//! memory and a size check before any array is allocated. Every malformed file is an
//! [`crate::Error::InvalidFile`] or [`crate::Error::SizeLimit`] naming the array; zip bombs
//! are refused by the declared size before inflating and by the actual size while inflating.

mod npy;
mod read;
mod write;

#[cfg(test)]
mod tests;

pub use read::{read_recording, read_recording_within};
pub use write::write_recording;

/// The arrays a recording may hold (docs/recording.md), in the order they are written. The
/// last two describe a recording made in coherent processing intervals (issue 42 §2): checked
/// on reading (`cpi_snapshots` an integer ≥ 1 dividing the snapshots, `cpi_spacing_s` > 0), not
/// kept — the front end takes the CPI from its settings (`cpi_snapshots`).
pub const ARRAYS: [&str; 14] = [
    "t_s",
    "links",
    "cfr",
    "freq_hz",
    "system_response",
    "cir",
    "tap0_s",
    "tap_spacing_s",
    "pulse",
    "pulse_spacing_s",
    "noise_var",
    "synchronized",
    "cpi_snapshots",
    "cpi_spacing_s",
];
