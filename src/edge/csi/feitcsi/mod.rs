//! FeitCSI `.csi` files (Intel AX200/AX210, <https://feitcsi.kuskosoft.com/csi_format/>, the
//! tool's `RawHeaderData` in `include/Csi.h` of github.com/KuskoSoft/FeitCSI; CSIKit's
//! `read_feitcsi.py` reads the same fields). A file is a sequence of frames, each a 272-byte
//! header then `csi_length` bytes of CSI; no magic number, no file header. Little-endian:
//!
//! | bytes   | type  | field                                                            |
//! |---------|-------|------------------------------------------------------------------|
//! | 0–3     | u32   | `csi_length`: bytes of CSI after the header (= 4·rx·tx·K)        |
//! | 8–11    | u32   | `ftm_clock`: the NIC's 320 MHz tick counter (3.125 ns, wraps 13.4 s) |
//! | 12–19   | u64   | `timestamp` (host µs in newer FeitCSI; 0 in the test files: unused) |
//! | 46      | u8    | `num_rx`                                                         |
//! | 47      | u8    | `num_tx`                                                         |
//! | 52–55   | u32   | `num_subcarriers` K                                              |
//! | 60–63, 64–67 | u32 | `rssi_1`, `rssi_2` (as the firmware reports them; not used)  |
//! | 68–73   | 6 × u8 | source MAC                                                      |
//! | 88–91   | u32   | `mu_clock`, µs (CSIKit's name; wraps after 71.6 min)             |
//! | 92–95   | u32   | `rate_flags`: bits 0–3 MCS, 8–10 format (0 CCK, 1 legacy OFDM, 2 HT, 3 VHT, 4 HE, 5 EHT), 11–13 width (0 20, 1 40, 2 80, 3 160, 4 320 MHz), 14/15 antenna A/B, 16 LDPC, 17 two streams, 19 beamforming |
//! | 272 …   | i16 × 2 | per value real, imaginary; order rx, then tx, then subcarrier (CSIKit's loops) |
//!
//! Time: `ftm_clock` ticks at 320 MHz (the test files: Δ`ftm_clock`/Δ`mu_clock` = 320.0 per µs),
//! unwrapped with `mu_clock` (the number of 2³² wraps that brings the tick difference closest to
//! the µs difference; plain modulo-2³² differences when `mu_clock` does not move), from the first
//! frame's `ftm_clock`. The carrier is not stored: `center_hz = None`.
//!
//! Subcarriers (in index order, 312.5 kHz; HE 78.125 kHz): legacy 20 −26…−1, 1…26; HT/VHT 20
//! −28…−1, 1…28; HT/VHT 40 −58…−2, 2…58; VHT 80 −122…−2, 2…122; VHT 160 −250…−130, −126…−6,
//! 6…126, 130…250; HE 20 −122…−2, 2…122; HE 40 −244…−3, 3…244; HE 80 −500…−3, 3…500; HE 160
//! −1012…−515, −509…−12, 12…509, 515…1012. A header whose K is not its map's size is an error
//! (except the 160 MHz firmware bug FeitCSI fixes itself: 498 VHT / 2020 HE values, whose
//! entries 242–255 / 996–1023 are padding and dropped).
//!
//! **Pilots are left out**: the firmware writes exactly 0 at every pilot tone (FeitCSI's docs:
//! "the CSI of pilot subcarriers is too low to be useful"; all ten FeitCSI files of CSIKit, every
//! frame and antenna: 0 at HT/VHT 20 ±7, ±21; HT/VHT 40 ±11, ±25, ±53; VHT 80 ±11, ±39, ±75, ±103;
//! VHT 160 ±25, ±53, ±89, ±117, ±139, ±167, ±203, ±231; HE 20 ±22, ±48, ±90, ±116; …), so they
//! are not reported subcarriers and the conversion masks them (`P[n] = 0`) rather than
//! interpolate them as FeitCSI's GUI and CSIKit do (legacy 20 MHz ±7, ±21 left out likewise, as
//! FeitCSI lists them; no legacy file was at hand); `pilots` is therefore empty. The other
//! values are the file's, unscaled. Frames of another format, width or antenna count than the
//! first readable frame, and CCK/EHT/320 MHz frames (no map here), are skipped with the reason.

mod maps;
mod reader;
#[cfg(test)]
mod tests;

pub use reader::{read, sniff};
pub(crate) use reader::{record_len, Reader};
