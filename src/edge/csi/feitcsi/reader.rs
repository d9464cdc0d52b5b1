//! The frames of a FeitCSI file: headers, sniffing, reading.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use super::maps::{map, rate, Map, Phy};
use crate::edge::csi::capture::{CsiCapture, CsiFormat};
use crate::error::limits::{MAX_RECORDING_SAMPLES, MAX_SNAPSHOTS};
use crate::error::{Error, Result};
use crate::math::{Complex, Real};

/// The header's size.
pub(super) const HEADER: usize = 272;
/// The `ftm_clock` tick, s (320 MHz).
const TICK_S: Real = 3.125e-9;
/// `ftm_clock` ticks per `mu_clock` µs.
const TICKS_PER_US: u64 = 320;
/// The most antennas per side a header may claim (the AX210 has two).
const MAX_ANTENNAS: u8 = 4;

/// The fields of a header this reader uses.
pub(super) struct Header {
    pub(super) csi_length: usize,
    ftm_clock: u32,
    mu_clock: u32,
    num_rx: u8,
    num_tx: u8,
    pub(super) num_subcarriers: u32,
    pub(super) rate_flags: u32,
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    let mut w = [0u8; 4];
    if let Some(s) = b.get(at..at + 4) {
        w.copy_from_slice(s);
    }
    u32::from_le_bytes(w)
}

/// The header at the start of `b` (`None`: fewer than 272 bytes).
pub(super) fn header(b: &[u8]) -> Option<Header> {
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
    if k_raw == 0 {
        return;
    }
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

/// The length of the frame at the start of `bytes` (`HEADER + csi_length`), once its header is
/// there: how the stream splitter cuts the file (`None`: fewer than [`HEADER`] bytes).
pub(crate) fn record_len(bytes: &[u8]) -> Option<usize> {
    header(bytes).map(|h| HEADER.saturating_add(h.csi_length))
}

fn bad(i: usize, field: &str, reason: String) -> Error {
    Error::InvalidFile {
        field: format!("frame {i}: {field}"),
        reason,
    }
}

/// The state of a file read frame by frame (what [`read`] and the stream share): the first
/// readable frame's configuration and map, the clocks, and the frames read since the last
/// [`Reader::capture`].
#[derive(Default)]
pub(crate) struct Reader {
    config: Option<Config>,
    subcarriers: Vec<i32>,
    t_s: Vec<Real>,
    csi: Vec<Complex>,
    /// Frames and values taken out by earlier [`Reader::capture`] calls (for the caps).
    taken: (usize, usize),
    skipped: Vec<(usize, String)>,
    notes: Vec<String>,
    /// The previous frame's clocks and its time in ticks from the first frame's.
    clock: Option<(u32, u32, u64)>,
    first_tick: u32,
    /// Frames seen.
    i: usize,
}

impl Reader {
    /// The frame at the start of `rest` (its header and CSI, maybe more bytes after them);
    /// returns its length.
    pub(crate) fn frame(&mut self, rest: &[u8]) -> Result<usize> {
        let i = self.i;
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
        let ticks = match self.clock {
            None => {
                self.first_tick = h.ftm_clock;
                0
            }
            Some((ftm, mu, ticks)) => {
                let fine = u64::from(h.ftm_clock.wrapping_sub(ftm));
                let coarse = u64::from(h.mu_clock.wrapping_sub(mu)) * TICKS_PER_US;
                let wraps = coarse.saturating_sub(fine).saturating_add(1 << 31) >> 32;
                ticks.saturating_add(fine + (wraps << 32))
            }
        };
        self.clock = Some((h.ftm_clock, h.mu_clock, ticks));
        match frame_map(i, &h, self.config)? {
            Err(why) => self.skipped.push((i, why)),
            Ok((cfg, m, gap)) => {
                if self.config.is_none() {
                    let tones = m.tones().into_iter();
                    self.subcarriers = tones.filter(|&k| !m.is_pilot(k)).collect();
                    self.config = Some(cfg);
                }
                let frames = self.taken.0 + self.t_s.len();
                if frames >= MAX_SNAPSHOTS {
                    return Err(Error::SizeLimit {
                        field: "frames",
                        value: frames + 1,
                        min: 1,
                        max: MAX_SNAPSHOTS,
                    });
                }
                let values = self.taken.1 + self.csi.len() + rx * tx * self.subcarriers.len();
                if values > MAX_RECORDING_SAMPLES {
                    return Err(Error::SizeLimit {
                        field: "CSI values",
                        value: values,
                        min: 1,
                        max: MAX_RECORDING_SAMPLES,
                    });
                }
                if gap.is_some()
                    && !self
                        .notes
                        .iter()
                        .any(|n: &String| n.contains("firmware bug"))
                {
                    self.notes.push(format!(
                        "160 MHz firmware bug: {k_raw} values per antenna pair, the padding \
                         entries dropped as FeitCSI does (from frame {i})"
                    ));
                }
                push_values(&mut self.csi, &rest[HEADER..end], k_raw, &m, gap);
                self.t_s
                    .push((u64::from(self.first_tick) + ticks) as Real * TICK_S);
            }
        }
        self.i += 1;
        Ok(end)
    }

    /// Whether frames were read since the last [`Reader::capture`].
    pub(crate) fn has_frames(&self) -> bool {
        !self.t_s.is_empty()
    }

    /// The capture of the frames read since the last call (taken out; the state kept).
    /// Errors: no readable frame at all.
    pub(crate) fn capture(&mut self) -> Result<CsiCapture> {
        let Some(c) = self.config else {
            return Err(match self.i {
                0 => bad(0, "header", "an empty file".into()),
                i => bad(
                    0,
                    "rate_flags",
                    format!("no frame of a format with a subcarrier map ({i} frames)"),
                ),
            });
        };
        let t_s = core::mem::take(&mut self.t_s);
        let csi = core::mem::take(&mut self.csi);
        self.taken = (self.taken.0 + t_s.len(), self.taken.1 + csi.len());
        let mut notes = self.notes.clone();
        notes.extend([
            "pilot tones left out: the firmware writes 0 there (not interpolated)".to_string(),
            "antenna phase offsets not calibrated".to_string(),
            "timing offset (SFO/STO) and carrier phase (CFO) not removed: the front end removes \
             them per snapshot (C9/C10)"
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
            subcarriers: self.subcarriers.clone(),
            pilots: Vec::new(),
            n_rx: c.rx.into(),
            n_tx: c.tx.into(),
            t_s,
            csi,
            gain: None,
            notes,
            skipped: self.skipped.clone(),
        };
        cap.validate()?;
        Ok(cap)
    }
}

/// Reads a FeitCSI file (module doc): the raw values on every non-pilot tone of the map of the
/// first readable frame's format and width. Errors name the frame and the field: a header cut
/// short, a `csi_length` past the end of the file or not 4·rx·tx·K, an antenna count outside
/// 1–4, a subcarrier count not of its map; no readable frame at all; the caps.
pub fn read(bytes: &[u8]) -> Result<CsiCapture> {
    let mut reader = Reader::default();
    let mut pos = 0usize;
    while let Some(rest) = bytes.get(pos..).filter(|r| !r.is_empty()) {
        pos += reader.frame(rest)?;
    }
    reader.capture()
}
