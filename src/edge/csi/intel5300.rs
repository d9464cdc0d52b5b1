//! The Linux 802.11n CSI Tool's `.dat` log (Intel Wi-Fi Link 5300; Halperin, Hu, Sheth,
//! Wetherall, "Tool release: gathering 802.11n traces with channel state information", ACM
//! SIGCOMM CCR 41(1), 2011; `log_to_file.c`, `read_bfee.c`, `read_bf_file.m`,
//! `get_scaled_csi.m`; csiread's `Intel`).
//!
//! The file is a sequence of netlink records as `log_to_file` wrote them:
//!
//! | bytes | field |
//! |---|---|
//! | 2 | `field_len`, u16 **big-endian**: the bytes that follow (code + body) |
//! | 1 | `code`: `0xBB` beamforming feedback (bfee, the CSI); others (e.g. `0xC1`, the 802.11 header) are skipped |
//! | `field_len − 1` | body |
//!
//! The bfee body (little-endian):
//!
//! | offset | bytes | field |
//! |---|---|---|
//! | 0 | 4 | `timestamp_low`: the NIC's clock, µs, wraps at 2³² (unwrapped here) |
//! | 4 | 2 | `bfee_count` |
//! | 6 | 2 | reserved |
//! | 8 | 1 | `Nrx` (1–3) |
//! | 9 | 1 | `Ntx` (space-time streams, 1–3) |
//! | 10–12 | 3 | `rssi_a`, `rssi_b`, `rssi_c` (dB, 0 = chain off) |
//! | 13 | 1 | `noise` (i8, dBm; −127 = not measured) |
//! | 14 | 1 | `agc` (dB) |
//! | 15 | 1 | `antenna_sel`: `perm[r] = (antenna_sel >> 2r) & 3` |
//! | 16 | 2 | `len`: payload bytes, `60·Nrx·Ntx + 12` |
//! | 18 | 2 | `fake_rate_n_flags` (bit 11: 40 MHz) |
//! | 20 | `len` | the CSI bit stream (`bfee` module) |
//!
//! The CSI is placed as csiread's `Intel(file, nrxnum=3, ntxnum=2).csi` holds it: receive
//! chain `r` of the stream goes to row `perm[r]` (csiread applies the permutation always;
//! Halperin's `read_bf_file.m` when `perm` is a permutation of the `Nrx` chains, which is when
//! it is applied here — otherwise it is left as stored and a note says so). The values are the
//! raw 8-bit integers; [`CsiCapture::gain`] is `get_scaled_csi`'s factor per frame:
//! `√(scale / (N_thermal + scale·Nrx·Ntx))` with `scale = P_rssi / (Σ|H|²/30)`,
//! `P_rssi = dbinv(10·log10(Σ dbinv(rssi_x ≠ 0)) − 44 − agc)`, `N_thermal = dbinv(noise)`
//! (−92 dBm when −127), times `√2` for 2 streams and `√(10^0.45)` for 3, so `gain·H` is in
//! units of √SNR. Frames whose `Nrx`, `Ntx` or bandwidth differ from the first bfee's are
//! skipped with the reason. The subcarriers are the 802.11n grouping (20 MHz `Ng = 2`,
//! 40 MHz `Ng = 4`), spacing 312.5 kHz; the carrier is not in the file.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use super::bfee;
use super::capture::{CsiCapture, CsiFormat};
use crate::error::limits::{MAX_RECORDING_SAMPLES, MAX_SNAPSHOTS};
use crate::error::{Error, Result};
use crate::math::{db_to_linear, log10, sqrt, Real};

/// The record code of a beamforming-feedback (CSI) record.
const BFEE: u8 = 0xBB;
/// Bytes of the bfee header before the payload.
const HEADER: usize = 20;

/// One bfee record's header.
struct Bfee<'a> {
    timestamp_low: u32,
    n_rx: usize,
    n_tx: usize,
    rssi: [u8; 3],
    noise: i8,
    agc: u8,
    perm: [usize; 3],
    bw40: bool,
    payload: &'a [u8],
}

fn bad(frame: usize, field: &str, reason: String) -> Error {
    Error::InvalidFile {
        field: format!("frame {frame}: {field}"),
        reason,
    }
}

/// One record: `(code, body, bytes consumed)`.
fn record(bytes: &[u8], pos: usize, frame: usize) -> Result<(u8, &[u8], usize)> {
    let rest = bytes.get(pos..).unwrap_or_default();
    let head = rest.get(..3).ok_or_else(|| {
        bad(
            frame,
            "record header",
            format!("truncated: 3 bytes needed, {} remain", rest.len()),
        )
    })?;
    let field_len = usize::from(u16::from_be_bytes([head[0], head[1]]));
    if field_len == 0 {
        return Err(bad(frame, "field_len", "0: no room for the code".into()));
    }
    let body = rest.get(3..2 + field_len).ok_or_else(|| {
        bad(
            frame,
            "field_len",
            format!(
                "{field_len} bytes announced, {} remain: truncated record",
                rest.len() - 2
            ),
        )
    })?;
    Ok((head[2], body, 2 + field_len))
}

fn parse_bfee(body: &[u8], frame: usize) -> Result<Bfee<'_>> {
    let h = body.get(..HEADER).ok_or_else(|| {
        bad(
            frame,
            "bfee header",
            format!("{} bytes, {HEADER} needed", body.len()),
        )
    })?;
    let (n_rx, n_tx) = (usize::from(h[8]), usize::from(h[9]));
    if !(1..=3).contains(&n_rx) {
        return Err(bad(
            frame,
            "Nrx",
            format!("{n_rx}: the 5300 has 1 to 3 chains"),
        ));
    }
    if !(1..=3).contains(&n_tx) {
        return Err(bad(frame, "Ntx", format!("{n_tx}: 1 to 3 streams")));
    }
    let len = usize::from(u16::from_le_bytes([h[16], h[17]]));
    let want = bfee::payload_len(n_rx, n_tx).unwrap_or(usize::MAX);
    if len != want {
        return Err(bad(
            frame,
            "len",
            format!("{len}: {want} expected for Nrx = {n_rx}, Ntx = {n_tx} (60·Nrx·Ntx + 12)"),
        ));
    }
    let payload = body.get(HEADER..HEADER + len).ok_or_else(|| {
        bad(
            frame,
            "payload",
            format!(
                "{len} bytes announced, {} in the record",
                body.len() - HEADER
            ),
        )
    })?;
    let sel = usize::from(h[15]);
    Ok(Bfee {
        timestamp_low: u32::from_le_bytes([h[0], h[1], h[2], h[3]]),
        n_rx,
        n_tx,
        rssi: [h[10], h[11], h[12]],
        noise: h[13] as i8,
        agc: h[14],
        perm: [sel & 3, (sel >> 2) & 3, (sel >> 4) & 3],
        bw40: u16::from_le_bytes([h[18], h[19]]) & (1 << 11) != 0,
        payload,
    })
}

/// Halperin's `get_scaled_csi` factor (module doc) of one frame's raw values.
fn scaled_csi_gain(b: &Bfee<'_>, csi: &[crate::math::Complex]) -> Real {
    let rssi_mag: Real = b
        .rssi
        .iter()
        .filter(|&&r| r != 0)
        .map(|&r| db_to_linear(Real::from(r)))
        .sum();
    let total_rss = 10.0 * log10(rssi_mag) - 44.0 - Real::from(b.agc);
    let csi_pwr: Real = csi.iter().map(|z| z.norm_sqr()).sum();
    let scale = db_to_linear(total_rss) / (csi_pwr / bfee::TONES as Real);
    let noise_db = if b.noise == -127 {
        -92.0
    } else {
        Real::from(b.noise)
    };
    let total_noise = db_to_linear(noise_db) + scale * (b.n_rx * b.n_tx) as Real;
    let streams = match b.n_tx {
        2 => 2.0,
        3 => db_to_linear(4.5),
        _ => 1.0,
    };
    sqrt(scale / total_noise * streams)
}

/// Whether `bytes` look like a CSI Tool log: the records from the start chain without gaps
/// (up to 64 of them or the end of the file) and one of them is a self-consistent bfee.
pub fn sniff(bytes: &[u8]) -> bool {
    let mut pos = 0;
    for i in 0..64 {
        if pos >= bytes.len() {
            return false;
        }
        let Ok((code, body, used)) = record(bytes, pos, i) else {
            return false;
        };
        if code == BFEE {
            return parse_bfee(body, i).is_ok_and(|b| HEADER + b.payload.len() == body.len());
        }
        pos += used;
    }
    false
}

/// The length of the record at the start of `bytes` (`2 + field_len`), once its 2-byte length
/// is there: how the stream splitter cuts the log (`None`: fewer than 2 bytes).
pub(crate) fn record_len(bytes: &[u8]) -> Option<usize> {
    let h = bytes.get(..2)?;
    Some(2 + usize::from(u16::from_be_bytes([h[0], h[1]])))
}

/// The state of a log read record by record (what [`read`] and the stream share): the first
/// bfee's configuration, the clock's wraps, and the frames read since the last
/// [`Reader::capture`].
#[derive(Default)]
pub(crate) struct Reader {
    frame: usize,
    first: Option<(usize, usize, bool)>,
    t_s: Vec<Real>,
    csi: Vec<crate::math::Complex>,
    gain: Vec<Real>,
    /// Frames taken out by earlier [`Reader::capture`] calls (for the caps).
    taken: (usize, usize),
    skipped: Vec<(usize, String)>,
    wraps: u64,
    last_ts: Option<u32>,
    bad_perm: Option<(usize, Vec<usize>)>,
}

impl Reader {
    /// Record `self.frame` (the bytes of [`record`], length field included).
    pub(crate) fn record(&mut self, rec: &[u8]) -> Result<()> {
        let frame = self.frame;
        self.frame += 1;
        let (code, body, _) = record(rec, 0, frame)?;
        if code != BFEE {
            self.skipped.push((
                frame,
                format!("record code {code:#04x}: not CSI (bfee is 0xbb)"),
            ));
            return Ok(());
        }
        let b = parse_bfee(body, frame)?;
        if self.last_ts.is_some_and(|l| b.timestamp_low < l) {
            self.wraps += 1;
        }
        self.last_ts = Some(b.timestamp_low);
        let config = (b.n_rx, b.n_tx, b.bw40);
        let (n_rx, n_tx, bw40) = *self.first.get_or_insert(config);
        if config != (n_rx, n_tx, bw40) {
            let mhz = |w: bool| if w { 40 } else { 20 };
            self.skipped.push((
                frame,
                format!(
                    "Nrx {} Ntx {} {} MHz differs from the first CSI frame's Nrx {n_rx} Ntx \
                     {n_tx} {} MHz",
                    b.n_rx,
                    b.n_tx,
                    mhz(b.bw40),
                    mhz(bw40)
                ),
            ));
            return Ok(());
        }
        let p = &b.perm[..b.n_rx];
        let valid = (0..b.n_rx).all(|r| p.contains(&r));
        if !valid && self.bad_perm.is_none() {
            self.bad_perm = Some((frame, p.to_vec()));
        }
        let values = bfee::decode(b.payload, b.n_rx, b.n_tx, valid.then_some(p))
            .ok_or_else(|| bad(frame, "payload", "CSI bit stream shorter than len".into()))?;
        let frames = self.taken.0 + self.t_s.len();
        if frames >= MAX_SNAPSHOTS {
            return Err(Error::SizeLimit {
                field: "frames",
                value: frames + 1,
                min: 1,
                max: MAX_SNAPSHOTS,
            });
        }
        let values_now = self.taken.1 + self.csi.len() + values.len();
        if values_now > MAX_RECORDING_SAMPLES {
            return Err(Error::SizeLimit {
                field: "CSI values",
                value: values_now,
                min: 1,
                max: MAX_RECORDING_SAMPLES,
            });
        }
        self.gain.push(scaled_csi_gain(&b, &values));
        self.csi.extend_from_slice(&values);
        self.t_s
            .push(((self.wraps << 32) + u64::from(b.timestamp_low)) as Real / 1e6);
        Ok(())
    }

    /// Whether frames were read since the last [`Reader::capture`].
    pub(crate) fn has_frames(&self) -> bool {
        !self.t_s.is_empty()
    }

    /// The capture of the frames read since the last call (taken out; the state kept).
    /// Errors: no bfee record at all.
    pub(crate) fn capture(&mut self) -> Result<CsiCapture> {
        let Some((n_rx, n_tx, bw40)) = self.first else {
            return Err(Error::InvalidFile {
                field: "frame 0: code".into(),
                reason: format!(
                    "none of the {} records is beamforming feedback (0xbb): no CSI",
                    self.frame
                ),
            });
        };
        let t_s = core::mem::take(&mut self.t_s);
        let csi = core::mem::take(&mut self.csi);
        let gain = core::mem::take(&mut self.gain);
        self.taken = (self.taken.0 + t_s.len(), self.taken.1 + csi.len());
        let mut notes: Vec<String> = Vec::new();
        notes.push(
            "antenna phase offsets not calibrated (the 5300's chains start with random phases)"
                .into(),
        );
        notes.push(
            "timing offset (SFO/STO) and carrier phase (CFO) not removed: the front end removes \
             them per snapshot (C9/C10)"
                .into(),
        );
        if n_tx > 1 {
            notes.push(
                "CSI per space-time stream: the transmitter's spatial mapping is not removed \
                 (csiread's get_scaled_csi_sm)"
                    .into(),
            );
        }
        if let Some((f, p)) = &self.bad_perm {
            notes.push(format!(
                "antenna_sel of frame {f} (perm {p:?}) and possibly later ones is not a \
                 permutation of the {n_rx} chains: rows left as stored for those frames (csiread \
                 would scatter them)"
            ));
        }
        let gain = match gain.iter().position(|g| !(g.is_finite() && *g > 0.0)) {
            None => Some(gain),
            Some(i) => {
                notes.push(format!(
                    "no gain: get_scaled_csi's factor of CSI frame {i} is undefined (RSSI or CSI \
                     all zero)"
                ));
                None
            }
        };
        let cap = CsiCapture {
            format: CsiFormat::Intel5300,
            device: "Intel 5300".into(),
            frame_format: "HT".into(),
            center_hz: None,
            bandwidth_hz: if bw40 { 40e6 } else { 20e6 },
            spacing_hz: 312_500.0,
            subcarriers: bfee::subcarriers(bw40),
            pilots: bfee::pilots(bw40),
            n_rx,
            n_tx,
            t_s,
            csi,
            gain,
            notes,
            skipped: self.skipped.clone(),
        };
        cap.validate()?;
        Ok(cap)
    }
}

/// Reads a CSI Tool `.dat` log (module doc). Errors name the record (`frame i`, 0-based in
/// file order, every record counted) and the field: a truncated record, `field_len` 0, a bfee
/// header shorter than 20 bytes, `Nrx`/`Ntx` outside 1–3, `len` not `60·Nrx·Ntx + 12`, a
/// payload beyond the record; no bfee record at all.
pub fn read(bytes: &[u8]) -> Result<CsiCapture> {
    let mut pos = 0;
    let mut reader = Reader::default();
    while pos < bytes.len() {
        let (_, _, used) = record(bytes, pos, reader.frame)?;
        reader.record(&bytes[pos..pos + used])?;
        pos += used;
    }
    reader.capture()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Complex;

    use crate::edge::csi::test_file as file;

    fn example() -> Vec<u8> {
        file("intel/example.dat")
    }

    /// Record length of the example's bfee records (2 + field_len 393).
    const REC: usize = 395;

    fn err(bytes: &[u8]) -> String {
        read(bytes).unwrap_err().to_string()
    }

    #[test]
    fn reads_the_example_like_csiread() {
        let cap = read(&example()).unwrap();
        assert_eq!(cap.frame_count(), 26);
        assert!(cap.skipped.is_empty());
        assert_eq!((cap.n_rx, cap.n_tx), (3, 2));
        assert_eq!(cap.bandwidth_hz, 20e6);
        assert_eq!(cap.spacing_hz, 312_500.0);
        assert_eq!(cap.center_hz, None);
        assert_eq!(
            (cap.device.as_str(), cap.frame_format.as_str()),
            ("Intel 5300", "HT")
        );
        let mut want: Vec<i32> = (-28..=-2).step_by(2).collect();
        want.extend([-1, 1]);
        want.extend((3..=27).step_by(2));
        want.push(28);
        assert_eq!(cap.subcarriers, want);
        assert_eq!(cap.pilots, vec![7, 21]);
        // csiread 1.4.1: c = csiread.Intel(f, nrxnum=3, ntxnum=2, if_report=False); c.read();
        // c.csi[f, k, r, t] (the antenna permutation applied).
        for ((f, r, t, k), (re, im)) in [
            ((0, 0, 0, 0), (11, -1)),
            ((0, 2, 1, 29), (-2, -30)),
            ((0, 1, 0, 14), (-16, -23)),
            ((13, 1, 1, 7), (-1, 45)),
            ((25, 0, 1, 15), (27, 73)),
            ((25, 2, 0, 29), (11, 31)),
        ] {
            let z = cap.pair(f, r, t)[k];
            assert_eq!(
                z,
                Complex::new(re as Real, im as Real),
                "({f}, {r}, {t}, {k})"
            );
        }
        // c.timestamp_low[0], c.timestamp_low[-1] (µs; no wrap in this file).
        assert_eq!(cap.t_s[0], 2238735549.0 / 1e6);
        assert_eq!(cap.t_s[25], 2240749775.0 / 1e6);
        // c.get_scaled_csi()[f] / c.csi[f] (Halperin's get_scaled_csi factor).
        let g = cap.gain.as_ref().unwrap();
        for (f, want) in [
            (0, 0.5695650758192121),
            (12, 0.5666473188401879),
            (25, 0.563385637950138),
        ] {
            assert!(
                (g[f] - want).abs() < 1e-12 * want,
                "gain {f}: {} vs {want}",
                g[f]
            );
        }
    }

    #[test]
    fn gain_is_halperins_formula() {
        // get_scaled_csi.m written out for frame 0: rssi 37 38 39, agc 23, noise -72, 3 × 2.
        let bytes = example();
        let cap = read(&bytes).unwrap();
        let pwr: f64 = cap.csi[..180].iter().map(|z| z.norm_sqr()).sum();
        let dbinv = |x: f64| 10f64.powf(x / 10.0);
        let rss = 10.0 * (dbinv(37.0) + dbinv(38.0) + dbinv(39.0)).log10() - 44.0 - 23.0;
        let scale = dbinv(rss) / (pwr / 30.0);
        let want = (scale / (dbinv(-72.0) + scale * 6.0)).sqrt() * 2f64.sqrt();
        let g = cap.gain.unwrap()[0];
        assert!((g - want).abs() < 1e-12 * want, "{g} vs {want}");
    }

    #[test]
    fn truncation_never_panics_and_errs_inside_a_record() {
        let bytes = example();
        for cut in 0..2 * REC + 3 {
            match read(&bytes[..cut]) {
                Ok(cap) => {
                    assert!(cut == REC || cut == 2 * REC, "cut {cut} parsed");
                    assert_eq!(cap.frame_count(), cut / REC);
                }
                Err(e) => {
                    let f = cut / REC;
                    assert!(cut % REC != 0 || cut == 0, "cut {cut}: {e}");
                    assert!(
                        e.to_string().starts_with(&format!("frame {f}: ")),
                        "cut {cut}: {e}"
                    );
                }
            }
        }
    }

    #[test]
    fn malformed_records_name_frame_and_field() {
        let good = example();
        let edit = |at: usize, b: &[u8]| {
            let mut v = good.clone();
            v[at..at + b.len()].copy_from_slice(b);
            v
        };
        // Record 1's header starts at REC; its body at REC + 3.
        assert!(err(&edit(REC, &[0xFF, 0xFF])).starts_with("frame 1: field_len"));
        assert!(err(&edit(0, &[0, 0])).starts_with("frame 0: field_len"));
        assert!(err(&edit(3 + 8, &[4])).starts_with("frame 0: Nrx"));
        assert!(err(&edit(REC + 3 + 9, &[0])).starts_with("frame 1: Ntx"));
        assert!(err(&edit(3 + 16, &[0x75, 0x01])).starts_with("frame 0: len"));
        // A bfee too short for its header.
        assert!(err(&[0, 5, 0xBB, 1, 2, 3, 4]).starts_with("frame 0: bfee header"));
        // len consistent with Nrx = 3, Ntx = 3 but the record holds 372 bytes.
        assert!(err(&edit(3 + 9, &[3])).starts_with("frame 0: len"));
        let mut short = edit(3 + 9, &[3]);
        short[3 + 16..3 + 18].copy_from_slice(&552u16.to_le_bytes());
        assert!(err(&short).starts_with("frame 0: payload"));
        // No bfee at all: every code something else.
        let mut none = good[..2 * REC].to_vec();
        none[2] = 0xC1;
        none[REC + 2] = 0x01;
        assert!(err(&none).starts_with("frame 0: code"));
    }

    #[test]
    fn other_codes_and_configurations_are_skipped() {
        let mut v = example();
        v[REC + 2] = 0xC1;
        // Record 2: Nrx 2 (of Ntx 2) with a consistent len (the record keeps its extra bytes).
        v[2 * REC + 3 + 8] = 2;
        v[2 * REC + 3 + 16..2 * REC + 3 + 18].copy_from_slice(&252u16.to_le_bytes());
        // Record 3: 40 MHz.
        v[3 * REC + 3 + 19] |= 0x08;
        let cap = read(&v).unwrap();
        assert_eq!(cap.frame_count(), 23);
        let idx: Vec<usize> = cap.skipped.iter().map(|s| s.0).collect();
        assert_eq!(idx, vec![1, 2, 3]);
        assert!(cap.skipped[0].1.contains("0xc1"));
        assert!(cap.skipped[1].1.contains("Nrx 2"));
        assert!(cap.skipped[2].1.contains("40 MHz"));
        assert_eq!(cap.frame_count() + cap.skipped.len(), 26);
    }

    #[test]
    fn timestamp_wraps_are_unwrapped() {
        let mut v = example()[..2 * REC].to_vec();
        v[3..7].copy_from_slice(&0xFFFF_FF00u32.to_le_bytes());
        v[REC + 3..REC + 7].copy_from_slice(&0x10u32.to_le_bytes());
        let cap = read(&v).unwrap();
        assert_eq!(
            cap.t_s,
            vec![
                0xFFFF_FF00u32 as f64 / 1e6,
                (1u64 << 32 | 0x10) as f64 / 1e6
            ]
        );
    }

    #[test]
    fn any_byte_of_the_first_frames_overwritten_never_panics() {
        let good = example();
        for at in 0..2 * REC {
            for x in [0x00, 0x7F, 0xFF] {
                let mut v = good.clone();
                v[at] = x;
                let _ = read(&v);
            }
        }
    }

    #[test]
    fn sniff_claims_only_this_format() {
        assert!(sniff(&example()));
        for other in [
            "pico/picoscenes_iwl5300_example.csi",
            "nexmon/example_4366c0.pcap",
            "feitcsi/HESU160_5500.csi",
            "feitcsi/VHT80_5500.csi",
            "esp32/example_data.csv",
            "../recording-cir-int16.npz",
        ] {
            assert!(!sniff(&file(other)), "{other}");
        }
        assert!(!sniff(&[]));
        assert!(!sniff(&example()[..100]));
    }
}
