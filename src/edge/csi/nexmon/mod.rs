//! Nexmon CSI captures (seemoo-lab/nexmon_csi: Gringoli, Schulz, Link, Hollick, "Free your CSI:
//! a channel state information extraction platform for modern Wi-Fi chipsets", WiNTECH 2019;
//! its README "Analyzing the CSI", `src/csi_extractor.c` `struct csi_udp_frame`,
//! `utils/matlab/unpack_float.c`; csiread's `Nexmon`/`NexmonPull46`; CSIKit's `read_pcap.py`).
//!
//! The file is a classic pcap (read with the `pcap-file` crate: both byte orders, µs or ns
//! timestamps; link type Ethernet or Linux cooked; pcapng is refused with a named error). The
//! firmware sends one UDP packet per (core, spatial stream) of each received frame, from
//! 10.10.10.10 (Ethernet source `NEXMON`) to 255.255.255.255 port 5500. The UDP payload,
//! little-endian whatever the pcap's byte order:
//!
//! | offset | bytes | field |
//! |---|---|---|
//! | 0 | 2 | magic `0x1111` (older firmware: 4 bytes `0x11111111`, no RSSI/frame control) |
//! | 2 | 1 | RSSI, i8 dBm (newer firmware only; not applied) |
//! | 3 | 1 | frame control byte (newer firmware only) |
//! | 4 | 6 | source MAC of the frame |
//! | 10 | 2 | sequence number of the frame |
//! | 12 | 2 | bits 0–2 core (receive chain), bits 3–5 spatial stream |
//! | 14 | 2 | chanspec (d11ac: bits 0–7 channel, 8–10 control sideband, 11–13 bandwidth 2/3/4 = 20/40/80 MHz, 14–15 band 0 = 2.4, 3 = 5 GHz) |
//! | 16 | 2 | chip version (nexmon `firmware_version.h`: 1 BCM4339, 3 BCM4358, 101 BCM43455c0, 106 BCM4366c0) |
//! | 18 | 4·N | the CSI, `N` = 64/128/256 words for 20/40/80 MHz, in FFT order (bins 0…N/2−1, then −N/2…−1) |
//!
//! Words: BCM4339/BCM43455c0 two int16 per word (the firmware since its 2020-06 "I/Q order"
//! fix puts I in the low half; before it — the 4-byte-magic captures — in the high half, put
//! back here, where csiread and CSIKit read the low half as I in both); BCM4358/BCM4366c0 a
//! packed float (sign + 8/11-bit magnitude for I and for Q, 5/6-bit exponent; `M, E` = 9, 5 and
//! 12, 6), decoded as csiread's `unpack_float` (nexmon's `unpack_float_acphy`, nbits 10,
//! autoscale): the largest part of the frame is shifted to 10 bits, every part by the same
//! shift `s` (truncating smaller ones); [`super::CsiCapture::gain`] is `2^−s` per frame, which
//! gives back the chip's `mantissa·2^exponent`. csiread shifts each packet by its own; a frame
//! of one packet (the test file) gets exactly csiread's values. Newer firmware (2-byte magic)
//! writes 3 words of PHY status over bins 28–30 (20 MHz) or 0–2: subcarrier +28 or +2 is
//! dropped then.
//!
//! Frames: consecutive CSI packets with one sequence number (and no repeated antenna pair) make
//! a frame; `n_rx` = the distinct cores of the capture (in increasing order), `n_tx` = the
//! distinct spatial streams; a frame missing a pair is skipped with its sequence number. The
//! frame's time is its first packet's pcap time (s since 1970, the capture host's clock). The
//! first CSI packet fixes chip, chanspec and header version; packets with others are skipped,
//! as are records that are not UDP to port 5500 with the magic, and CSI packets shorter than
//! `18 + 4·N` bytes (snaplen cuts; longer ones are read, the extra bytes ignored). "Frame `i`"
//! in errors and in `skipped` is the pcap record `i` (0-based). Errors: a truncated record or
//! one whose `incl_len` exceeds the file, an unknown chip version (listing the known ones), a
//! chanspec bandwidth other than 20/40/80 MHz, no CSI packet, no complete frame.
//!
//! Subcarriers: the bins are reordered to indices `k` and only the occupied ones of the
//! chanspec's bandwidth kept (HT20 ±1…±28, pilots ±7, ±21; HT40 ±2…±58, pilots ±11, ±25, ±53;
//! VHT80 ±2…±122, pilots ±11, ±39, ±75, ±103), spacing 312.5 kHz. The carrier is the chanspec's
//! channel — for 40 and 80 MHz the d11ac chanspec holds the centre channel (the control
//! channel is `centre − (bw/10 − 2) + 4·sideband` in channel numbers) —: 5 GHz `5000 + 5·ch`,
//! 2.4 GHz `2407 + 5·ch` MHz (channel 14: 2484).

mod packet;
mod read;
#[cfg(test)]
mod tests;

pub use read::{read, sniff};
pub(crate) use read::{Reader, PCAP_HEADER};
