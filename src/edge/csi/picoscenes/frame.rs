//! The RXS frames of a PicoScenes file and the capture made of them (module doc of
//! `picoscenes`).

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use super::csi::{self, Csi};
use super::cursor::Cursor;
use crate::edge::csi::capture::{CsiCapture, CsiFormat};
use crate::error::limits::{MAX_RECORDING_SAMPLES, MAX_SNAPSHOTS};
use crate::error::{Error, Result};
use crate::math::Real;

/// The frame's magic word.
const MAGIC: u32 = 0x2015_0315;

/// What one frame holds: the `RxSBasic` timestamp (µs for the NICs, ns for the SDRs) and the
/// CSI, where present.
fn parse_frame(body: &[u8], frame: usize) -> Result<(Option<u64>, Option<Csi>)> {
    let mut c = Cursor::new(body, frame, "");
    let magic = c.u32("magic")?;
    if magic != MAGIC {
        return Err(c.bad("magic", format!("{magic:#010x}: {MAGIC:#010x} expected")));
    }
    let version = c.u16("frame version")?;
    if version != 1 {
        return Err(c.bad(
            "frame version",
            format!("{version}: unsupported (1 is read)"),
        ));
    }
    let n = c.u8("numRxSegments")?;
    let (mut tstamp, mut data) = (None, None);
    for i in 0..n {
        let len = c.u32(&format!("segment {i} length"))? as usize;
        let seg = c.take(&format!("segment {i} length"), len)?;
        let mut s = Cursor::new(seg, frame, &format!("segment {i}"));
        let name_len = usize::from(s.u8("name length")?);
        let name = s.take("name", name_len)?;
        let name = name.split(|&b| b == 0).next().unwrap_or_default();
        let version = s.u16("version")?;
        match name {
            b"RxSBasic" => {
                let mut r = Cursor::new(s.rest(), frame, "RxSBasic");
                let size = match version {
                    1 => 26,
                    2 => 28,
                    3 => 30,
                    v => {
                        return Err(r.bad("version", format!("{v}: unsupported (1 to 3 are read)")))
                    }
                };
                r.u16("deviceType")?;
                tstamp = Some(r.u64("tstamp")?);
                r.take("header", size - 10)?;
            }
            b"CSI" => {
                let mut r = Cursor::new(s.rest(), frame, "CSI");
                data = Some(csi::parse(&mut r, version)?);
            }
            _ => {}
        }
    }
    Ok((tstamp, data))
}

/// What must agree between frames, in words.
fn describe(c: &Csi) -> String {
    format!(
        "{} {} {} MHz at {} Hz, {} Rx × {} Tx, {} subcarriers {}…{} spaced {} Hz",
        csi::device_name(c.device),
        csi::format_name(c.format),
        c.cbw,
        c.carrier_hz,
        c.n_rx,
        c.n_tx,
        c.subcarriers.len(),
        c.subcarriers.first().copied().unwrap_or(0),
        c.subcarriers.last().copied().unwrap_or(0),
        c.spacing_hz
    )
}

/// Whether `bytes` start like a PicoScenes RXS frame (magic word and frame version 1).
pub fn sniff(bytes: &[u8]) -> bool {
    bytes.get(4..8) == Some(&MAGIC.to_le_bytes()[..]) && bytes.get(8..10) == Some(&[1, 0][..])
}

/// The length of the frame at the start of `bytes` (`4 + frame length`), once its length field
/// is there: how the stream splitter cuts the file (`None`: fewer than 4 bytes).
pub(crate) fn record_len(bytes: &[u8]) -> Option<usize> {
    let h = bytes.get(..4)?;
    Some(4usize.saturating_add(u32::from_le_bytes([h[0], h[1], h[2], h[3]]) as usize))
}

/// The state of a file read frame by frame (what [`read`] and the stream share): the first CSI
/// frame's layout and the frames read since the last [`Reader::capture`].
#[derive(Default)]
pub(crate) struct Reader {
    frame: usize,
    first: Option<Csi>,
    t_s: Vec<Real>,
    values: Vec<crate::math::Complex>,
    /// Frames and values taken out by earlier [`Reader::capture`] calls (for the caps).
    taken: (usize, usize),
    skipped: Vec<(usize, String)>,
}

impl Reader {
    /// The frame at the start of `rest` (maybe more bytes after it); returns its length.
    pub(crate) fn frame(&mut self, rest: &[u8]) -> Result<usize> {
        let frame = self.frame;
        let mut c = Cursor::new(rest, frame, "");
        let len = c.u32("frame length")? as usize;
        let body = c.take("frame length", len)?;
        self.frame += 1;
        let (tstamp, data) = parse_frame(body, frame)?;
        let (tstamp, data) = match (tstamp, data) {
            (Some(t), Some(d)) => (t, d),
            (_, None) => {
                self.skipped.push((frame, "no CSI segment".into()));
                return Ok(4 + len);
            }
            (None, Some(_)) => {
                self.skipped
                    .push((frame, "no RxSBasic segment (no timestamp)".into()));
                return Ok(4 + len);
            }
        };
        let reference = self.first.get_or_insert_with(|| Csi {
            values: Vec::new(),
            ..data.clone()
        });
        let same = (
            data.device,
            data.format,
            data.cbw,
            data.carrier_hz,
            data.spacing_hz,
        ) == (
            reference.device,
            reference.format,
            reference.cbw,
            reference.carrier_hz,
            reference.spacing_hz,
        ) && (data.n_rx, data.n_tx) == (reference.n_rx, reference.n_tx)
            && data.subcarriers == reference.subcarriers;
        if !same {
            let reason = format!(
                "{} differs from the first CSI frame's {}",
                describe(&data),
                describe(reference)
            );
            self.skipped.push((frame, reason));
            return Ok(4 + len);
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
        let values = self.taken.1 + self.values.len() + data.values.len();
        if values > MAX_RECORDING_SAMPLES {
            return Err(Error::SizeLimit {
                field: "CSI values",
                value: values,
                min: 1,
                max: MAX_RECORDING_SAMPLES,
            });
        }
        self.values.extend_from_slice(&data.values);
        self.t_s
            .push(tstamp as Real / csi::ticks_per_second(data.device));
        Ok(4 + len)
    }

    /// Whether frames were read since the last [`Reader::capture`].
    pub(crate) fn has_frames(&self) -> bool {
        !self.t_s.is_empty()
    }

    /// The capture of the frames read since the last call (taken out; the state kept).
    /// Errors: no CSI frame at all.
    pub(crate) fn capture(&mut self) -> Result<CsiCapture> {
        let Some(r) = &self.first else {
            return Err(Error::InvalidFile {
                field: "frame 0: CSI".into(),
                reason: format!(
                    "none of the {} frames has CSI and RxSBasic segments",
                    self.frame
                ),
            });
        };
        let t_s = core::mem::take(&mut self.t_s);
        let values = core::mem::take(&mut self.values);
        self.taken = (self.taken.0 + t_s.len(), self.taken.1 + values.len());
        let mut notes: Vec<String> = Vec::new();
        notes.push("antenna phase offsets not calibrated".into());
        notes.push(
            "timing offset (SFO/STO) and carrier phase (CFO) not removed: the front end removes \
             them per snapshot (C9/C10)"
                .into(),
        );
        if r.device == 0x5300 {
            notes.push("ANTSEL not applied (as csiread and PicoScenes' parser leave it)".into());
        }
        if r.n_tx > 1 {
            notes.push("CSI per space-time stream: the spatial mapping is not removed".into());
        }
        notes.push("no gain: PicoScenes reports RSSI but no CSI amplitude scaling".into());
        if matches!(r.device, 0x2000 | 0x2100) {
            notes.push("pilots left out (the AX200/AX210 firmware writes 0 there)".into());
        }
        // The pilots shift with the indices (`SubcarrierOffset`).
        let pilots = csi::pilots(r.format, r.cbw)
            .into_iter()
            .map(|p| p + r.offset)
            .filter(|p| r.subcarriers.contains(p))
            .collect();
        let cap = CsiCapture {
            format: CsiFormat::PicoScenes,
            device: csi::device_name(r.device),
            frame_format: csi::format_name(r.format).into(),
            center_hz: (r.carrier_hz > 0).then_some(r.carrier_hz as Real),
            bandwidth_hz: Real::from(r.cbw) * 1e6,
            spacing_hz: Real::from(r.spacing_hz),
            subcarriers: r.subcarriers.clone(),
            pilots,
            n_rx: r.n_rx,
            n_tx: r.n_tx,
            t_s,
            csi: values,
            gain: None,
            notes,
            skipped: self.skipped.clone(),
        };
        cap.validate()?;
        Ok(cap)
    }
}

/// Reads a PicoScenes `.csi` file (module doc). Errors name the frame (0-based, file order)
/// and the field (`frame length`, `magic`, `segment i length`, `CSI.NumTones`,
/// `CSI.CSIBufferLength`, …); an unsupported device layout or segment version is an error
/// naming it.
pub fn read(bytes: &[u8]) -> Result<CsiCapture> {
    let mut reader = Reader::default();
    let mut pos = 0usize;
    while pos < bytes.len() {
        pos += reader.frame(bytes.get(pos..).unwrap_or_default())?;
    }
    reader.capture()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Complex;

    use crate::edge::csi::test_file as file;

    fn example() -> Vec<u8> {
        file("pico/picoscenes_iwl5300_example.csi")
    }

    /// Frame 0 is 4 + 358 bytes; frame 1 4 + 1618.
    const F0: usize = 362;
    const F1: usize = 1622;

    fn err_of(edit: &[(usize, &[u8])]) -> String {
        let mut v = example();
        for (at, b) in edit {
            v[*at..*at + b.len()].copy_from_slice(b);
        }
        read(&v).unwrap_err().to_string()
    }

    #[test]
    fn reads_the_iwl5300_example_like_csiread() {
        let cap = read(&example()).unwrap();
        // csiread 1.4.1: c = csiread.Picoscenes(f, {'CSI': [30, 3, 2], 'PilotCSI': [0, 0, 0],
        // 'LegacyCSI': [0, 0, 0], 'BasebandSignals': [0, 0, 0], 'PreEQSymbols': [0, 0, 0],
        // 'MPDU': 1522}, if_report=False); c.read(): 112 frames; raw['CSI']['Info'] NumTx 1,
        // NumRx 2 except these 13 (12 with 2 streams, frame 47 with 1 chain).
        let skipped: Vec<usize> = cap.skipped.iter().map(|s| s.0).collect();
        assert_eq!(
            skipped,
            [4, 16, 33, 47, 50, 53, 64, 68, 72, 78, 82, 91, 101]
        );
        assert!(cap.skipped[0]
            .1
            .starts_with("Intel 5300 HT 20 MHz at 2437000000 Hz, 2 Rx × 2 Tx"));
        assert!(cap.skipped[3].1.contains("1 Rx × 1 Tx"));
        assert_eq!(cap.frame_count(), 99);
        assert_eq!((cap.n_rx, cap.n_tx), (2, 1));
        assert_eq!(
            (cap.device.as_str(), cap.frame_format.as_str()),
            ("Intel 5300", "HT")
        );
        assert_eq!(cap.bandwidth_hz, 20e6);
        assert_eq!(cap.center_hz, Some(2.437e9));
        assert_eq!(cap.spacing_hz, 312_500.0);
        assert_eq!(cap.gain, None);
        // raw['CSI']['SubcarrierIndex'][0].
        let want = [
            -28, -26, -24, -22, -20, -18, -16, -14, -12, -10, -8, -6, -4, -2, -1, 1, 3, 5, 7, 9,
            11, 13, 15, 17, 19, 21, 23, 25, 27, 28,
        ];
        assert_eq!(cap.subcarriers, want);
        assert_eq!(cap.pilots, [7, 21]);
        // raw['CSI']['CSI'][file frame, k, r, t]; capture frame = file frame − skipped before.
        for ((file_f, f, r, k), (re, im)) in [
            ((0, 0, 0, 0), (-6, 12)),
            ((0, 0, 1, 29), (2, 8)),
            ((0, 0, 1, 14), (10, -10)),
            ((57, 51, 0, 13), (-4, 27)),
            ((111, 98, 0, 0), (-10, -16)),
            ((111, 98, 1, 29), (-3, -8)),
        ] {
            let z = cap.pair(f, r, 0)[k];
            assert_eq!(
                z,
                Complex::new(re as Real, im as Real),
                "file frame {file_f}"
            );
        }
        // raw['RxSBasic']['Timestamp'][0], [-1] (µs).
        assert_eq!(cap.t_s[0], 302584960555.0 / 1e6);
        assert_eq!(cap.t_s[98], 302595358943.0 / 1e6);
    }

    #[test]
    fn truncation_never_panics_and_errs_inside_a_frame() {
        let bytes = example();
        for cut in 0..F0 + F1 + 5 {
            match read(&bytes[..cut]) {
                Ok(cap) => {
                    assert!(cut == F0 || cut == F0 + F1, "cut {cut} parsed");
                    assert_eq!(cap.frame_count(), 1 + usize::from(cut > F0));
                }
                Err(e) => {
                    let f = usize::from(cut >= F0) + usize::from(cut >= F0 + F1);
                    let f = if cut == 0 { 0 } else { f };
                    let e = e.to_string();
                    assert!(e.starts_with(&format!("frame {f}: ")), "cut {cut}: {e}");
                }
            }
        }
    }

    #[test]
    fn malformed_frames_name_frame_and_field() {
        type Edit<'a> = &'a [(usize, &'a [u8])];
        let cases: [(Edit, &str); 11] = [
            (&[(4, &[0])], "frame 0: magic"),
            (&[(8, &[2])], "frame 0: frame version"),
            (&[(F0, &[0xF0, 0xFF, 0xFF, 0xFF])], "frame 1: frame length"),
            (&[(11, &[0xFF, 0xFF, 0, 0])], "frame 0: segment 0 length"),
            (&[(0x6d, &[9])], "frame 0: CSI.version"),
            (&[(0x6f, &[0x02, 0x08])], "frame 0: CSI.DeviceType"),
            (&[(0x88, &[31])], "frame 0: CSI.NumTones"),
            (&[(0x8b, &[0])], "frame 0: CSI.NumRx"),
            (&[(0x8b, &[4])], "frame 0: CSI.NumRx"),
            (&[(0x90, &[72])], "frame 0: CSI.CSIBufferLength"),
            (&[(0x90, &[0xFF, 0xFF, 0xFF])], "frame 0: CSI.CSI buffer"),
        ];
        for (edit, want) in cases {
            let e = err_of(edit);
            assert!(e.starts_with(want), "{want}: {e}");
        }
        assert!(err_of(&[(0x6f, &[0x02, 0x08])]).contains("unsupported"));
        let e = read(&[0, 0, 0, 0]).unwrap_err().to_string();
        assert!(
            e.starts_with("frame 1: CSI") || e.starts_with("frame 0: "),
            "{e}"
        );
    }

    #[test]
    fn any_byte_of_the_first_frames_overwritten_never_panics() {
        let good = example();
        for at in 0..F0 + F1 {
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
            "intel/example.dat",
            "nexmon/example_4366c0.pcap",
            "feitcsi/HESU160_5500.csi",
            "feitcsi/VHT80_5500.csi",
            "esp32/example_data.csv",
            "../recording-cir-int16.npz",
        ] {
            assert!(!sniff(&file(other)), "{other}");
        }
        assert!(!sniff(&example()[..9]));
    }
}
