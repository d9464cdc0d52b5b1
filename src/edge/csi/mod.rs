//! The readers of the files Wi-Fi CSI tools write (issue 40), pure Rust so the CLI, Python and
//! the page share them (an edge, with the `npz` feature): Intel 5300 (Linux 802.11n CSI Tool
//! `.dat`), Nexmon CSI (pcap, through the `pcap-file` crate), PicoScenes `.csi`, FeitCSI `.csi`
//! and the ESP32 CSI tool's CSV. Each reader gives a [`CsiCapture`] (the raw values, the
//! subcarrier indices, pilots, antennas, times, the gain the format reports);
//! [`to_recording`] puts it on a uniform subcarrier grid with a mask (C1 with `P[n] = 0` where
//! nothing was reported), and [`open_recording`] opens any recording file — `.npz` or CSI — for
//! `cir estimate`/`cir track`/`cir convert`, the page and Python. Every malformed file is an
//! [`crate::Error::InvalidFile`] or [`crate::Error::SizeLimit`] naming the frame and the field.

mod bfee;
mod capture;
mod esp32;
mod feitcsi;
mod intel5300;
mod nexmon;
mod open;
mod picoscenes;
mod stream;
mod summary;
mod tones;

#[cfg(test)]
mod tests;

/// The bytes of `tests/data/csi/<name>` (the six real files), for the readers' tests.
#[cfg(test)]
pub(crate) fn test_file(name: &str) -> alloc::vec::Vec<u8> {
    std::fs::read(alloc::format!(
        "{}/tests/data/csi/{name}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("a test file of tests/data/csi")
}

pub use capture::{
    occupied, to_recording, Conversion, ConvertOptions, CsiCapture, CsiFormat, PairLink,
    UNOCCUPIED_BLOCK_DB, UNOCCUPIED_TONE_DB,
};
pub use open::{detect, open_recording, read_capture, CsiSummary, OpenOptions, Opened};
pub use stream::{CsiFrame, CsiStream, MAX_CSI_RECORD_BYTES};
pub use summary::LISTED;
