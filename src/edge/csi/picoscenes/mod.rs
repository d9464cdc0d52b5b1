//! PicoScenes `.csi` files (Jiang et al., "Eliminating the barriers: demystifying Wi-Fi
//! baseband design and introducing the PicoScenes Wi-Fi sensing platform", IEEE IoT-J 2022;
//! the `rxs_parsing_core` of the PicoScenes MATLAB/Python toolbox; csiread's `Picoscenes`).
//!
//! The file is a sequence of RXS frames (all little-endian):
//!
//! | bytes | field |
//! |---|---|
//! | 4 | `frameLength`: the bytes that follow |
//! | 4 | `magicWord` `0x20150315` |
//! | 2 | `frameVersion` (1) |
//! | 1 | `numRxSegments` |
//! | … | the segments, then the MPDU (ignored) |
//!
//! A segment: u32 `segmentLength` (the bytes that follow), u8 name length, the name
//! (`RxSBasic`, `ExtraInfo`, `MVMExtra`, `CSI`, `PilotCSI`, `LegacyCSI`, `BasebandSignal`, …),
//! u16 version, the body. Read here: `RxSBasic` (v1–v3: u16 `deviceType`, u64 `tstamp` — the
//! timestamp: **µs** of the NIC's clock for IWL5300/QCA9300/AX2x0, **ns** since the Unix epoch
//! for the SDRs (USRP, virtual SDR; csiread's USRP example file steps by ~10⁷ per frame, its
//! IWL5300 and QCA9300 files by ~10⁵ and ~10²) — then frequencies, CBW, format, MCS, antennas, noise floor and
//! RSSIs) and `CSI` (v1–v4):
//!
//! | bytes | field | version |
//! |---|---|---|
//! | 2 | `DeviceType` (`0x5300` IWL5300, `0x9300` QCA9300, `0x2000`/`0x2100` AX200/AX210, `0x1234` USRP, `0x1000` virtual SDR) | all |
//! | 1 | `FirmwareVersion` | 4 |
//! | 1 | `PacketFormat` (0 non-HT, 1 HT, 2 VHT, 3 HE-SU, 4 HE-MU) | all |
//! | 2 | `CBW`, MHz | all |
//! | 8 | `CarrierFreq`, Hz | all |
//! | 8 | `SamplingRate`, Hz | all |
//! | 4 | `SubcarrierBandwidth`, Hz | all |
//! | 2 | `NumTones` | all |
//! | 1+1+1 | `NumTx` (space-time streams), `NumRx`, `NumESS` | all |
//! | 2 | `NumCSI` (1 is read) | ≥ 3 |
//! | 1 | `ANTSEL` | all |
//! | 2 | `SubcarrierOffset` (i16, added to the indices) | ≥ 2 |
//! | 4 | `CSIBufferLength` | all |
//! | … | the CSI buffer, in the layout of the device | all |
//!
//! Layouts read: IWL5300 — the Intel 5300's beamforming-feedback payload (the `bfee` module,
//! 30 subcarriers of the 802.11n grouping), `60·NumRx·N + 12` bytes for `N` streams (`N`, not
//! `NumTx`, is the true stream count; the example file has `NumTx = 1, NumRx = 2`: 2 Rx × 1 Tx;
//! `ANTSEL` is not applied, as csiread and PicoScenes' parser leave it); QCA9300 — 10-bit
//! packed values on all HT subcarriers; USRP/virtual SDR — `NumTones` i16 subcarrier indices
//! and a `SignalMatrix` (`BBv1`/`BBv2`) of complex values; AX200/AX210 (MVM) — i16 pairs on the
//! firmware's table of the format and CBW, without its pilots (the `mvm` module). Other devices
//! are an "unsupported" error naming the device. The carrier is `CarrierFreq`,
//! the spacing `SubcarrierBandwidth`; no gain (PicoScenes reports RSSI, no CSI scaling).
//! Frames without CSI, or whose device, format, bandwidth, carrier, antennas or subcarriers
//! differ from the first CSI frame's, are skipped with the reason.

mod csi;
mod cursor;
mod frame;
mod mvm;

pub use frame::{read, sniff};
pub(crate) use frame::{record_len, Reader};
