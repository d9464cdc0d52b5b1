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
//! | 60–63, 64–67 | u32 | `rssi_1`, `rssi_2` (dB, positive: −dBm)                   |
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
//! frame and antenna: 0 at HT ±7, ±21; HT/VHT 40 ±11, ±25, ±53; VHT 80 ±11, ±39, ±75, ±103;
//! VHT 160 ±25, ±53, ±89, ±117, ±139, ±167, ±203, ±231; HE 20 ±22, ±48, ±90, ±116; …), so they
//! are not reported subcarriers and the conversion masks them (`P[n] = 0`) rather than
//! interpolate them as FeitCSI's GUI and CSIKit do; `pilots` is therefore empty. The other
//! values are the file's, unscaled. Frames of another format, width or antenna count than the
//! first readable frame, and CCK/EHT/320 MHz frames (no map here), are skipped with the reason.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use super::capture::{CsiCapture, CsiFormat};
use crate::error::limits::{MAX_RECORDING_SAMPLES, MAX_SNAPSHOTS};
use crate::error::{Error, Result};
use crate::math::{Complex, Real};

/// The header's size.
const HEADER: usize = 272;
/// The `ftm_clock` tick, s (320 MHz).
const TICK_S: Real = 3.125e-9;
/// `ftm_clock` ticks per `mu_clock` µs.
const TICKS_PER_US: u64 = 320;
/// The most antennas per side a header may claim (the AX210 has two).
const MAX_ANTENNAS: u8 = 4;

/// The PHY formats with a subcarrier map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phy {
    Legacy,
    Ht,
    Vht,
    He,
}

impl Phy {
    fn name(self) -> &'static str {
        match self {
            Phy::Legacy => "legacy",
            Phy::Ht => "HT",
            Phy::Vht => "VHT",
            // FeitCSI's injector and capture modes are NOHT, HT, VHT and HESU.
            Phy::He => "HE-SU",
        }
    }
}

/// A subcarrier map: the occupied tones as inclusive ranges, the pilots' positive indices
/// (mirrored), and the padding entries of the 160 MHz firmware bug `(raw K, first, end)`.
#[derive(Debug, Clone, Copy)]
struct Map {
    ranges: &'static [(i32, i32)],
    pilots: &'static [i32],
    bug: Option<(usize, usize, usize)>,
}

fn map(phy: Phy, width_mhz: u32) -> Option<Map> {
    let m = |ranges, pilots| {
        Some(Map {
            ranges,
            pilots,
            bug: None,
        })
    };
    const P20: &[i32] = &[7, 21];
    const P40: &[i32] = &[11, 25, 53];
    match (phy, width_mhz) {
        (Phy::Legacy, 20) => m(&[(-26, -1), (1, 26)], P20),
        (Phy::Ht | Phy::Vht, 20) => m(&[(-28, -1), (1, 28)], P20),
        (Phy::Ht | Phy::Vht, 40) => m(&[(-58, -2), (2, 58)], P40),
        (Phy::Vht, 80) => m(&[(-122, -2), (2, 122)], &[11, 39, 75, 103]),
        (Phy::Vht, 160) => Some(Map {
            ranges: &[(-250, -130), (-126, -6), (6, 126), (130, 250)],
            pilots: &[25, 53, 89, 117, 139, 167, 203, 231],
            bug: Some((498, 242, 256)),
        }),
        (Phy::He, 20) => m(&[(-122, -2), (2, 122)], &[22, 48, 90, 116]),
        (Phy::He, 40) => m(
            &[(-244, -3), (3, 244)],
            &[10, 36, 78, 104, 144, 170, 212, 238],
        ),
        (Phy::He, 80) => m(
            &[(-500, -3), (3, 500)],
            &[24, 92, 158, 226, 266, 334, 400, 468],
        ),
        (Phy::He, 160) => Some(Map {
            ranges: &[(-1012, -515), (-509, -12), (12, 509), (515, 1012)],
            // The HE 80 pilots around ±512.
            pilots: &[
                44, 112, 178, 246, 286, 354, 420, 488, 536, 604, 670, 738, 778, 846, 912, 980,
            ],
            bug: Some((2020, 996, 1024)),
        }),
        _ => None,
    }
}

impl Map {
    /// Every occupied tone, in index order.
    fn tones(&self) -> Vec<i32> {
        self.ranges.iter().flat_map(|&(a, b)| a..=b).collect()
    }

    fn is_pilot(&self, k: i32) -> bool {
        self.pilots.contains(&k.abs())
    }
}

/// The fields of a header this reader uses.
struct Header {
    csi_length: usize,
    ftm_clock: u32,
    mu_clock: u32,
    num_rx: u8,
    num_tx: u8,
    num_subcarriers: u32,
    rate_flags: u32,
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    let mut w = [0u8; 4];
    if let Some(s) = b.get(at..at + 4) {
        w.copy_from_slice(s);
    }
    u32::from_le_bytes(w)
}

/// The header at the start of `b` (`None`: fewer than 272 bytes).
fn header(b: &[u8]) -> Option<Header> {
    let h = b.get(..HEADER)?;
    Some(Header {
        csi_length: u32_at(h, 0) as usize,
        ftm_clock: u32_at(h, 8),
        mu_clock: u32_at(h, 88),
        num_rx: h[46],
        num_tx: h[47],
        num_subcarriers: u32_at(h, 52),
        rate_flags: u32_at(h, 92),
    })
}

/// The PHY format and width of `rate_flags` (`Err`: the reason no map applies).
fn rate(flags: u32) -> core::result::Result<(Phy, u32), String> {
    let phy = match (flags >> 8) & 7 {
        1 => Phy::Legacy,
        2 => Phy::Ht,
        3 => Phy::Vht,
        4 => Phy::He,
        0 => return Err("a CCK frame (no OFDM subcarrier map)".into()),
        5 => return Err("an EHT frame (no subcarrier map here)".into()),
        f => return Err(format!("rate format {f} is not one FeitCSI defines")),
    };
    let width = match (flags >> 11) & 7 {
        0 => 20,
        1 => 40,
        2 => 80,
        3 => 160,
        w => {
            return Err(format!(
                "channel width code {w} (320 MHz or unknown) has no map here"
            ))
        }
    };
    Ok((phy, width))
}

/// Whether `bytes` look like a FeitCSI file: a complete first frame whose `csi_length` is
/// 4 · `num_rx` · `num_tx` · `num_subcarriers`, with 1–4 antennas per side and a subcarrier
/// count of the map its rate format and width name.
pub fn sniff(bytes: &[u8]) -> bool {
    let Some(h) = header(bytes) else { return false };
    let antennas = 1..=MAX_ANTENNAS;
    if !(antennas.contains(&h.num_rx) && antennas.contains(&h.num_tx)) {
        return false;
    }
    let Ok((phy, width)) = rate(h.rate_flags) else {
        return false;
    };
    let Some(m) = map(phy, width) else {
        return false;
    };
    let k = h.num_subcarriers as usize;
    let known = k == m.tones().len() || m.bug.is_some_and(|(raw, _, _)| raw == k);
    known
        && Some(h.csi_length) == (4 * h.num_rx as usize * h.num_tx as usize).checked_mul(k)
        && HEADER
            .checked_add(h.csi_length)
            .is_some_and(|end| end <= bytes.len())
}

/// The frame's map and configuration: `Ok(Err(reason))` to skip it (no map, or not the
/// capture's configuration), `Err` for a subcarrier count its map does not have.
#[allow(clippy::type_complexity)]
fn frame_map(
    i: usize,
    h: &Header,
    capture: Option<Config>,
) -> Result<core::result::Result<(Config, Map, Option<(usize, usize)>), String>> {
    let (phy, width) = match rate(h.rate_flags) {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let Some(m) = map(phy, width) else {
        return Ok(Err(format!(
            "{} at {width} MHz has no subcarrier map",
            phy.name()
        )));
    };
    let k_raw = h.num_subcarriers as usize;
    let k = m.tones().len();
    let gap = match m.bug {
        Some((raw, a, b)) if raw == k_raw => Some((a, b)),
        _ if k_raw == k => None,
        _ => {
            return Err(Error::InvalidFile {
                field: format!("frame {i}: num_subcarriers"),
                reason: format!("{k_raw}: {} at {width} MHz has {k} subcarriers", phy.name()),
            })
        }
    };
    let cfg = Config {
        phy,
        width,
        rx: h.num_rx,
        tx: h.num_tx,
    };
    match capture {
        Some(c) if c != cfg => Ok(Err(format!(
            "{} {} MHz {}×{}, the capture is {} {} MHz {}×{}",
            cfg.phy.name(),
            cfg.width,
            cfg.rx,
            cfg.tx,
            c.phy.name(),
            c.width,
            c.rx,
            c.tx
        ))),
        _ => Ok(Ok((cfg, m, gap))),
    }
}

/// Appends the values of one frame's CSI bytes (`k_raw` values per antenna pair, in rx, tx
/// order) on the map's non-pilot tones, without the firmware bug's padding `gap`.
fn push_values(
    csi: &mut Vec<Complex>,
    data: &[u8],
    k_raw: usize,
    m: &Map,
    gap: Option<(usize, usize)>,
) {
    let tones = m.tones();
    for block in data.chunks_exact(4 * k_raw) {
        let entries = block
            .chunks_exact(4)
            .enumerate()
            .filter(|(n, _)| !gap.is_some_and(|(a, b)| (a..b).contains(n)))
            .map(|(_, v)| v);
        for (&k, v) in tones.iter().zip(entries) {
            if !m.is_pilot(k) {
                let re = i16::from_le_bytes([v[0], v[1]]);
                let im = i16::from_le_bytes([v[2], v[3]]);
                csi.push(Complex::new(re.into(), im.into()));
            }
        }
    }
}

/// One frame's configuration: the capture keeps the first readable frame's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Config {
    phy: Phy,
    width: u32,
    rx: u8,
    tx: u8,
}

/// Reads a FeitCSI file (module doc): the raw values on every non-pilot tone of the map of the
/// first readable frame's format and width. Errors name the frame and the field: a header cut
/// short, a `csi_length` past the end of the file or not 4·rx·tx·K, an antenna count outside
/// 1–4, a subcarrier count not of its map; no readable frame at all; the caps.
pub fn read(bytes: &[u8]) -> Result<CsiCapture> {
    let bad = |i: usize, field: &str, reason: String| Error::InvalidFile {
        field: format!("frame {i}: {field}"),
        reason,
    };
    let mut config: Option<Config> = None;
    let mut subcarriers = Vec::new();
    let mut t_s = Vec::new();
    let mut csi: Vec<Complex> = Vec::new();
    let mut skipped = Vec::new();
    let mut notes = Vec::new();
    // The previous frame's clocks and its time in ticks from the first frame's.
    let mut clock: Option<(u32, u32, u64)> = None;
    let mut first_tick = 0u32;
    let (mut pos, mut i) = (0usize, 0usize);
    while let Some(rest) = bytes.get(pos..).filter(|r| !r.is_empty()) {
        let h = header(rest).ok_or_else(|| {
            bad(
                i,
                "header",
                format!("{} bytes left, a header is {HEADER}", rest.len()),
            )
        })?;
        let end = HEADER
            .checked_add(h.csi_length)
            .filter(|&e| e <= rest.len())
            .ok_or_else(|| {
                let left = rest.len() - HEADER;
                bad(
                    i,
                    "csi_length",
                    format!("{} bytes, only {left} remain", h.csi_length),
                )
            })?;
        for (field, n) in [("num_rx", h.num_rx), ("num_tx", h.num_tx)] {
            if !(1..=MAX_ANTENNAS).contains(&n) {
                return Err(bad(
                    i,
                    field,
                    format!("{n}: impossible, 1 to {MAX_ANTENNAS}"),
                ));
            }
        }
        let (rx, tx) = (h.num_rx as usize, h.num_tx as usize);
        let k_raw = h.num_subcarriers as usize;
        if Some(h.csi_length) != (4 * rx * tx).checked_mul(k_raw) {
            return Err(bad(
                i,
                "csi_length",
                format!(
                    "{} bytes, not 4 · {rx} rx · {tx} tx · {k_raw} subcarriers",
                    h.csi_length
                ),
            ));
        }
        // Times: the tick difference to the previous frame, wraps counted by `mu_clock`.
        let ticks = match clock {
            None => {
                first_tick = h.ftm_clock;
                0
            }
            Some((ftm, mu, ticks)) => {
                let fine = u64::from(h.ftm_clock.wrapping_sub(ftm));
                let coarse = u64::from(h.mu_clock.wrapping_sub(mu)) * TICKS_PER_US;
                let wraps = coarse.saturating_sub(fine).saturating_add(1 << 31) >> 32;
                ticks.saturating_add(fine + (wraps << 32))
            }
        };
        clock = Some((h.ftm_clock, h.mu_clock, ticks));
        match frame_map(i, &h, config)? {
            Err(why) => skipped.push((i, why)),
            Ok((cfg, m, gap)) => {
                if config.is_none() {
                    let tones = m.tones().into_iter();
                    subcarriers = tones.filter(|&k| !m.is_pilot(k)).collect();
                    config = Some(cfg);
                }
                if t_s.len() >= MAX_SNAPSHOTS {
                    return Err(Error::SizeLimit {
                        field: "frames",
                        value: t_s.len() + 1,
                        min: 1,
                        max: MAX_SNAPSHOTS,
                    });
                }
                let values = csi.len() + rx * tx * subcarriers.len();
                if values > MAX_RECORDING_SAMPLES {
                    return Err(Error::SizeLimit {
                        field: "CSI values",
                        value: values,
                        min: 1,
                        max: MAX_RECORDING_SAMPLES,
                    });
                }
                if gap.is_some() && !notes.iter().any(|n: &String| n.contains("firmware bug")) {
                    notes.push(format!(
                        "160 MHz firmware bug: {k_raw} values per antenna pair, the padding \
                         entries dropped as FeitCSI does (from frame {i})"
                    ));
                }
                push_values(&mut csi, &rest[HEADER..end], k_raw, &m, gap);
                t_s.push((u64::from(first_tick) + ticks) as Real * TICK_S);
            }
        }
        pos += end;
        i += 1;
    }
    let Some(c) = config else {
        return Err(bad(
            0,
            "rate_flags",
            format!("no frame of a format with a subcarrier map ({} frames)", i),
        ));
    };
    notes.extend([
        "pilot tones left out: the firmware writes 0 there (not interpolated)".to_string(),
        "antenna phase offsets not calibrated".to_string(),
        "timing offset (SFO/STO) and carrier phase (CFO) not removed: the front end removes them \
         per snapshot (C9/C10)"
            .to_string(),
        "no AGC reported: RSSI (rssi_1/rssi_2) not applied as a gain".to_string(),
        "carrier frequency not stored in the file".to_string(),
    ]);
    let spacing_hz = if c.phy == Phy::He {
        78_125.0
    } else {
        312_500.0
    };
    let cap = CsiCapture {
        format: CsiFormat::FeitCsi,
        device: "Intel AX200/AX210".into(),
        frame_format: c.phy.name().into(),
        center_hz: None,
        bandwidth_hz: Real::from(c.width) * 1e6,
        spacing_hz,
        subcarriers,
        pilots: Vec::new(),
        n_rx: c.rx.into(),
        n_tx: c.tx.into(),
        t_s,
        csi,
        gain: None,
        notes,
        skipped,
    };
    cap.validate()?;
    Ok(cap)
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;

    const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/csi/");

    fn file(name: &str) -> Vec<u8> {
        std::fs::read(format!("{DIR}{name}")).unwrap()
    }

    fn tones(ranges: &[(i32, i32)], pilots: &[i32]) -> Vec<i32> {
        let all = ranges.iter().flat_map(|&(a, b)| a..=b);
        all.filter(|k| !pilots.contains(&k.abs())).collect()
    }

    /// One synthetic frame: `k` values per antenna pair, value `n` of a pair = (n, −n).
    fn frame(flags: u32, rx: u8, tx: u8, k: u32, ftm: u32, mu: u32) -> Vec<u8> {
        let mut b = vec![0u8; HEADER];
        let len = 4 * u32::from(rx) * u32::from(tx) * k;
        b[0..4].copy_from_slice(&len.to_le_bytes());
        b[8..12].copy_from_slice(&ftm.to_le_bytes());
        b[46] = rx;
        b[47] = tx;
        b[52..56].copy_from_slice(&k.to_le_bytes());
        b[88..92].copy_from_slice(&mu.to_le_bytes());
        b[92..96].copy_from_slice(&flags.to_le_bytes());
        for _ in 0..u32::from(rx) * u32::from(tx) {
            for n in 0..k as i16 {
                b.extend(n.to_le_bytes());
                b.extend((-n).to_le_bytes());
            }
        }
        b
    }

    /// Rate flags: format code, width code.
    fn flags(format: u32, width: u32) -> u32 {
        (format << 8) | (width << 11) | (3 << 14)
    }

    fn err(bytes: &[u8]) -> String {
        read(bytes).unwrap_err().to_string()
    }

    /// The independent reader: CSIKit 2.5, `get_reader(f).read_file(f, scaled=False,
    /// interpolate=False)` (CSIKit's default `interpolate=True` replaces the pilot tones by
    /// interpolated values), `frames[f].csi_matrix[position of k in the full map, rx, 0]`;
    /// times `timestamps[-1]` (relative to the first frame; ours add the first `ftm_clock`).
    #[test]
    fn he160_file_matches_csikit() {
        let cap = read(&file("feitcsi/HESU160_5500.csi")).unwrap();
        assert_eq!(cap.frame_count(), 26);
        assert_eq!((cap.n_rx, cap.n_tx), (2, 1));
        assert_eq!(cap.bandwidth_hz, 160e6);
        assert_eq!(cap.spacing_hz, 78_125.0);
        assert_eq!(cap.frame_format, "HE-SU");
        assert_eq!(cap.center_hz, None);
        assert!(cap.pilots.is_empty() && cap.skipped.is_empty() && cap.gain.is_none());
        // CSIKit's 1992 subcarriers = the HE 160 map; the 32 zeroed pilot tones left out.
        let map = [(-1012, -515), (-509, -12), (12, 509), (515, 1012)];
        assert_eq!(tones(&map, &[]).len(), 1992);
        let pilots = [
            44, 112, 178, 246, 286, 354, 420, 488, 536, 604, 670, 738, 778, 846, 912, 980,
        ];
        assert_eq!(cap.subcarriers, tones(&map, &pilots));
        assert_eq!(cap.subcarriers.len(), 1960);
        let truth = [
            (0, 0, -1012, -45, -88),
            (0, 0, -1011, -36, -93),
            (0, 0, -12, 48, -124),
            (0, 0, 12, 128, 53),
            (0, 0, 1012, -2, 54),
            (0, 1, -1012, 91, -70),
            (0, 1, -12, 207, -91),
            (0, 1, 12, 74, 199),
            (0, 1, 1012, 8, 80),
            (13, 0, -1011, 99, -5),
            (13, 1, -12, 150, -185),
            (25, 0, -1012, 38, -86),
            (25, 0, 12, 17, 122),
            (25, 1, -1011, -112, -46),
            (25, 1, 1012, 71, -11),
        ];
        check(&cap, &truth);
        // ftm_clock 806346444 and 1408974812 ticks of 3.125 ns; CSIKit: last − first 1.88321365 s.
        assert!((cap.t_s[0] - 806_346_444.0 * 3.125e-9).abs() < 1e-12);
        assert!((cap.t_s[25] - cap.t_s[0] - 1.883_213_65).abs() < 1e-9);
    }

    fn check(cap: &CsiCapture, truth: &[(usize, usize, i32, i32, i32)]) {
        for &(f, r, k, re, im) in truth {
            let j = cap.subcarriers.iter().position(|&s| s == k).unwrap();
            let z = cap.pair(f, r, 0)[j];
            assert_eq!(
                (z.re, z.im),
                (re as Real, im as Real),
                "frame {f} rx {r} k {k}"
            );
        }
    }

    /// CSIKit as above, VHT 80: 242 subcarriers (the map), 8 pilots left out.
    #[test]
    fn vht80_file_matches_csikit() {
        let cap = read(&file("feitcsi/VHT80_5500.csi")).unwrap();
        assert_eq!(cap.frame_count(), 40);
        assert_eq!((cap.n_rx, cap.n_tx), (2, 1));
        assert_eq!((cap.bandwidth_hz, cap.spacing_hz), (80e6, 312_500.0));
        assert_eq!(cap.frame_format, "VHT");
        let map = [(-122, -2), (2, 122)];
        assert_eq!(tones(&map, &[]).len(), 242);
        assert_eq!(cap.subcarriers, tones(&map, &[11, 39, 75, 103]));
        let truth = [
            (0, 0, -122, -74, 91),
            (0, 0, -121, -107, 74),
            (0, 0, -2, -168, 103),
            (0, 0, 2, -223, -107),
            (0, 0, 122, 61, 38),
            (0, 1, -122, -143, -31),
            (0, 1, 122, 91, 109),
            (20, 0, 2, -39, -245),
            (20, 1, -121, -72, -128),
            (39, 0, -122, -83, 77),
            (39, 0, 2, 244, 19),
            (39, 1, -2, -160, 119),
            (39, 1, 122, -146, 13),
        ];
        check(&cap, &truth);
        assert!((cap.t_s[0] - 750_633_892.0 * 3.125e-9).abs() < 1e-12);
        assert!((cap.t_s[39] - cap.t_s[0] - 2.095_110_55).abs() < 1e-9);
    }

    /// The raw files hold exactly 0 at every pilot tone (why they are left out).
    #[test]
    fn raw_pilot_tones_are_zero() {
        for name in ["feitcsi/HESU160_5500.csi", "feitcsi/VHT80_5500.csi"] {
            let b = file(name);
            let mut pos = 0;
            while pos < b.len() {
                let h = header(&b[pos..]).unwrap();
                let (phy, w) = rate(h.rate_flags).unwrap();
                let m = map(phy, w).unwrap();
                let data = &b[pos + HEADER..pos + HEADER + h.csi_length];
                for block in data.chunks_exact(4 * h.num_subcarriers as usize) {
                    for (k, v) in m.tones().iter().zip(block.chunks_exact(4)) {
                        assert_eq!(m.is_pilot(*k), v == [0, 0, 0, 0], "{name} k {k}");
                    }
                }
                pos += HEADER + h.csi_length;
            }
        }
    }

    /// The pilots' positions in each map are FeitCSI's `*_PILOT_INDICES` (include/Csi.h).
    #[test]
    fn pilot_positions_are_feitcsis() {
        let feit: [(Phy, u32, &[usize]); 9] = [
            (Phy::Legacy, 20, &[5, 19, 32, 46]),
            (Phy::Ht, 20, &[7, 21, 34, 48]),
            (Phy::Vht, 40, &[5, 33, 47, 66, 80, 108]),
            (Phy::Vht, 80, &[19, 47, 83, 111, 130, 158, 194, 222]),
            (
                Phy::Vht,
                160,
                &[
                    19, 47, 83, 111, 130, 158, 194, 222, 261, 289, 325, 353, 372, 400, 436, 464,
                ],
            ),
            (Phy::He, 20, &[6, 32, 74, 100, 141, 167, 209, 235]),
            (
                Phy::He,
                40,
                &[
                    6, 32, 74, 100, 140, 166, 208, 234, 249, 275, 317, 343, 383, 409, 451, 477,
                ],
            ),
            (
                Phy::He,
                80,
                &[
                    32, 100, 166, 234, 274, 342, 408, 476, 519, 587, 653, 721, 761, 829, 895, 963,
                ],
            ),
            (
                Phy::He,
                160,
                &[
                    32, 100, 166, 234, 274, 342, 408, 476, 519, 587, 653, 721, 761, 829, 895, 963,
                    1028, 1096, 1162, 1230, 1270, 1338, 1404, 1472, 1515, 1583, 1649, 1717, 1757,
                    1825, 1891, 1959,
                ],
            ),
        ];
        let sizes = [52, 56, 114, 242, 484, 242, 484, 996, 1992];
        for ((phy, w, want), size) in feit.into_iter().zip(sizes) {
            let m = map(phy, w).unwrap();
            let t = m.tones();
            let got: Vec<usize> = (0..t.len()).filter(|&n| m.is_pilot(t[n])).collect();
            assert_eq!((got.as_slice(), t.len()), (want, size), "{phy:?} {w}");
        }
    }

    #[test]
    fn truncated_files_fail_with_the_frame_and_field() {
        let b = file("feitcsi/VHT80_5500.csi");
        let one = HEADER + 1936;
        for cut in 1..2 * one {
            match read(&b[..cut]) {
                Ok(cap) => assert_eq!((cut, cap.frame_count()), (one, 1)),
                Err(e) => {
                    let (f, text) = (cut / one, e.to_string());
                    let field = if cut % one < HEADER {
                        "header"
                    } else {
                        "csi_length"
                    };
                    assert!(
                        text.starts_with(&format!("frame {f}: {field}:")),
                        "{cut}: {text}"
                    );
                }
            }
        }
        assert!(read(&[]).is_err());
    }

    #[test]
    fn bad_headers_are_named() {
        let he160 = flags(4, 3);
        let mut b = frame(he160, 2, 1, 1992, 0, 0);
        b[0..4].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(err(&b).starts_with("frame 0: csi_length: 4294967295 bytes, only 15936"));
        let mut two = frame(he160, 2, 1, 1992, 0, 0);
        let mut c = frame(he160, 2, 1, 1992, 1, 1);
        c[0..4].copy_from_slice(&15932u32.to_le_bytes());
        two.extend(c);
        assert!(err(&two).starts_with("frame 1: csi_length: 15932 bytes, not 4 · 2 rx"));
        for (at, v, field) in [(46, 0, "num_rx"), (46, 9, "num_rx"), (47, 0, "num_tx")] {
            let mut b = frame(he160, 2, 1, 1992, 0, 0);
            b[at] = v;
            assert!(err(&b).starts_with(&format!("frame 0: {field}: {v}: impossible")));
        }
        let b = frame(he160, 2, 1, 1000, 0, 0);
        let e = err(&b);
        assert!(
            e.starts_with("frame 0: num_subcarriers: 1000: HE-SU at 160 MHz has 1992"),
            "{e}"
        );
        let b = frame(flags(0, 0), 1, 1, 52, 0, 0);
        assert!(err(&b).starts_with("frame 0: rate_flags: no frame of a format"));
    }

    #[test]
    fn other_configurations_are_skipped_and_the_160_bug_is_fixed() {
        // VHT 160 written with the firmware bug: 498 values, entries 242..256 padding.
        let mut b = frame(flags(3, 3), 1, 1, 498, 100, 0);
        b.extend(frame(flags(0, 0), 1, 1, 52, 200, 1));
        b.extend(frame(flags(3, 2), 1, 1, 242, 300, 2));
        b.extend(frame(flags(3, 3), 1, 1, 484, 400, 3));
        let cap = read(&b).unwrap();
        assert_eq!(cap.frame_count(), 2);
        assert_eq!(cap.subcarriers.len(), 484 - 16);
        let skipped: Vec<usize> = cap.skipped.iter().map(|s| s.0).collect();
        assert_eq!(skipped, [1, 2]);
        assert!(cap.skipped[1]
            .1
            .contains("VHT 80 MHz 1×1, the capture is VHT 160 MHz 1×1"));
        // Entry 256 (after the padding) is tone 6 (the 122nd of the map); entry 241 tone −6.
        let j = |k: i32| cap.subcarriers.iter().position(|&s| s == k).unwrap();
        assert_eq!(cap.pair(0, 0, 0)[j(-6)].re, 241.0);
        assert_eq!(cap.pair(0, 0, 0)[j(6)].re, 256.0);
        assert_eq!(cap.pair(1, 0, 0)[j(6)].re, 242.0);
        assert!(cap.notes.iter().any(|n| n.contains("firmware bug")));
        assert_eq!(cap.t_s[1] - cap.t_s[0], 300.0 * 3.125e-9);
    }

    #[test]
    fn ftm_clock_wraps_are_counted_with_mu_clock() {
        let f = flags(4, 0);
        let mut b = frame(f, 1, 1, 242, 0xFFFF_FF00, 1000);
        b.extend(frame(f, 1, 1, 242, 0x100, 1001));
        // 20 s later: the tick counter wrapped once (13.4 s), mu_clock says 20 s.
        let ticks = 0x100u64 + 20 * 320_000_000;
        b.extend(frame(f, 1, 1, 242, ticks as u32, 20_001_001));
        let cap = read(&b).unwrap();
        assert!((cap.t_s[1] - cap.t_s[0] - 512.0 * 3.125e-9).abs() < 1e-15);
        assert!((cap.t_s[2] - cap.t_s[1] - 20.0).abs() < 1e-9);
    }

    #[test]
    fn sniff_claims_only_feitcsi() {
        assert!(sniff(&file("feitcsi/HESU160_5500.csi")));
        assert!(sniff(&file("feitcsi/VHT80_5500.csi")));
        for other in [
            "intel/example.dat",
            "nexmon/example_4366c0.pcap",
            "pico/picoscenes_iwl5300_example.csi",
            "esp32/example_data.csv",
            "../recording-cir-int16.npz",
        ] {
            assert!(!sniff(&file(other)), "{other}");
        }
        assert!(!sniff(&[]));
    }
}
