//! The ESP32 CSI tool's CSV lines (Steven M. Hernandez's ESP32-CSI-Tool,
//! `_components/csi_component.h`, printing Espressif's `wifi_csi_info_t`, ESP-IDF
//! `esp_wifi_types.h` and the "Wi-Fi Channel State Information" section of the ESP-IDF Wi-Fi
//! guide). An optional header line, then one line per packet:
//!
//! | column (default position) | meaning                                                     |
//! |---------------------------|-------------------------------------------------------------|
//! | `type` (0)                | `CSI_DATA`                                                  |
//! | `role`, `mac`, `rssi`, `rate`, `sig_mode`, `mcs` (1–6) | not used                       |
//! | `bandwidth` (7)           | `cwb`: 0 = 20 MHz, 1 = 40 MHz                               |
//! | … `noise_floor`, `ampdu_cnt` (8–15) | not used                                          |
//! | `channel` (16)            | the primary channel                                         |
//! | `secondary_channel` (17)  | 0 none, 1 above, 2 below                                    |
//! | `local_timestamp` (18)    | µs, the chip's u32 clock (unwrapped here)                    |
//! | `ant` (19)                | the antenna                                                 |
//! | `sig_len` … `real_timestamp` (20–23) | not used                                         |
//! | `len` (24)                | bytes in the chip's CSI buffer                              |
//! | `CSI_DATA` (25)           | `[b0 b1 …]`: the buffer as int8, space-separated            |
//!
//! The columns are found by name in the header line when there is one (the default order
//! otherwise). The buffer holds two int8 per subcarrier, **imaginary first, then real**
//! (Espressif); for `secondary_channel = 0` its first 128 bytes are the L-LTF on subcarriers
//! 0…31, −32…−1, then the HT-LTF and the STBC-HT-LTF. This reader gives the **L-LTF only**: the
//! legacy tones −26…−1, 2…26 at 312.5 kHz (pilots ±7, ±21: the L-LTF covers them). Subcarrier 1
//! is left out: the ESP32's first four CSI bytes (subcarriers 0 and 1) are invalid (Espressif's
//! `first_word_invalid`, which the tool does not print; in the test file they are the same
//! `18 38 97 0` on every line). The HT-LTF is not used.
//!
//! A line's array may hold `len` values or 128 when `len` is larger (the tool's
//! `CONFIG_SHOULD_COLLECT_ONLY_LLTF`, as in the test file: `len` 384, 128 values); values 128–255
//! (older tool versions print the bytes unsigned) are the same int8. Lines that are not
//! `CSI_DATA`, arrays cut short or of another size, 40 MHz frames (`bandwidth` or
//! `secondary_channel` ≠ 0), and frames of another antenna or channel than the first are
//! skipped with the reason and the line number (`skipped` index: the CSI line's, or for a line
//! that is not a CSI line the index the next CSI line gets). "frame i" in errors is the i-th
//! `CSI_DATA` line (0-based).

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use super::capture::{CsiCapture, CsiFormat};
use crate::error::limits::{MAX_RECORDING_SAMPLES, MAX_SNAPSHOTS};
use crate::error::{Error, Result};
use crate::math::{Complex, Real};

/// The tool's header line, the default column order.
const DEFAULT_COLUMNS: [&str; 26] = [
    "type",
    "role",
    "mac",
    "rssi",
    "rate",
    "sig_mode",
    "mcs",
    "bandwidth",
    "smoothing",
    "not_sounding",
    "aggregation",
    "stbc",
    "fec_coding",
    "sgi",
    "noise_floor",
    "ampdu_cnt",
    "channel",
    "secondary_channel",
    "local_timestamp",
    "ant",
    "sig_len",
    "rx_state",
    "real_time_set",
    "real_timestamp",
    "len",
    "CSI_DATA",
];

/// Bytes of the L-LTF at the start of the buffer (64 subcarriers × 2).
const LLTF_BYTES: usize = 128;

/// The positions of the columns this reader uses.
#[derive(Debug, Clone, Copy)]
struct Columns {
    count: usize,
    bandwidth: Option<usize>,
    channel: usize,
    secondary: usize,
    timestamp: usize,
    ant: Option<usize>,
    len: usize,
}

impl Columns {
    /// The columns of a header line (`Err`: the missing column's name).
    fn of(names: &[&str]) -> core::result::Result<Columns, &'static str> {
        let at = |name: &'static str| names.iter().position(|n| n.trim() == name);
        let need = |name: &'static str| at(name).ok_or(name);
        Ok(Columns {
            count: names.len(),
            bandwidth: at("bandwidth"),
            channel: need("channel")?,
            secondary: need("secondary_channel")?,
            timestamp: need("local_timestamp")?,
            ant: at("ant"),
            len: need("len")?,
        })
    }
}

/// The legacy tones this reader reports: −26…−1, 2…26 (module doc: subcarrier 1 is invalid).
fn tones() -> impl Iterator<Item = i32> {
    (-26..=-1).chain(2..=26)
}

/// The carrier of a Wi-Fi channel number, Hz (2.4 GHz: 2407 + 5·ch MHz, ch 14 2484 MHz;
/// 5 GHz: 5000 + 5·ch MHz).
fn channel_hz(ch: i64) -> Option<Real> {
    let mhz = match ch {
        1..=13 => 2407 + 5 * ch,
        14 => 2484,
        32..=177 => 5000 + 5 * ch,
        _ => return None,
    };
    Some(mhz as Real * 1e6)
}

/// Whether `bytes` look like the tool's output: the first line starts with `type,role` (its
/// header) or `CSI_DATA,`.
pub fn sniff(bytes: &[u8]) -> bool {
    let b = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    b.starts_with(b"type,role") || b.starts_with(b"CSI_DATA,")
}

/// What a CSI line holds.
struct Line {
    channel: i64,
    ant: i64,
    timestamp: u32,
    lltf: Vec<i8>,
    /// Only the L-LTF printed although `len` is larger.
    lltf_only: bool,
    /// Values 128–255 seen (printed unsigned).
    unsigned: bool,
}

/// Parses CSI line `text` (frame `i`, line `n`): `Ok(Err(reason))` to skip it.
fn parse_line(
    text: &str,
    cols: &Columns,
    i: usize,
    n: usize,
) -> Result<core::result::Result<Line, String>> {
    let bad = |field: &str, reason: String| Error::InvalidFile {
        field: format!("frame {i}: {field}"),
        reason: format!("line {n}: {reason}"),
    };
    let Some(open) = text.find('[') else {
        return Ok(Err(format!("line {n}: no CSI array [ … ]")));
    };
    let Some(close) = text[open..].find(']').map(|c| open + c) else {
        return Ok(Err(format!(
            "line {n}: CSI array not closed (line cut short)"
        )));
    };
    let fields: Vec<&str> = text[..open].split(',').collect();
    if fields.len() != cols.count || fields.last().is_some_and(|f| !f.trim().is_empty()) {
        return Err(bad(
            "fields",
            format!(
                "{} comma-separated fields before the array, the header has {}",
                fields.len().saturating_sub(1),
                cols.count.saturating_sub(1)
            ),
        ));
    }
    let int = |name: &str, at: usize| -> Result<i64> {
        let s = fields.get(at).map_or("", |s| s.trim());
        s.parse::<i64>()
            .map_err(|_| bad(name, format!("{s:?} is not an integer")))
    };
    let len = int("len", cols.len)?;
    let secondary = int("secondary_channel", cols.secondary)?;
    let cwb = match cols.bandwidth {
        Some(at) => int("bandwidth", at)?,
        None => 0,
    };
    let channel = int("channel", cols.channel)?;
    if channel_hz(channel).is_none() {
        return Err(bad("channel", format!("{channel} is not a Wi-Fi channel")));
    }
    let ts = int("local_timestamp", cols.timestamp)?;
    let timestamp = u32::try_from(ts)
        .map_err(|_| bad("local_timestamp", format!("{ts} is not a u32 µs count")))?;
    let ant = match cols.ant {
        Some(at) => int("ant", at)?,
        None => 0,
    };
    let mut values = Vec::new();
    let mut unsigned = false;
    for (j, s) in text[open + 1..close].split_ascii_whitespace().enumerate() {
        let v = s
            .parse::<i16>()
            .ok()
            .filter(|v| (-128..=255).contains(v))
            .ok_or_else(|| bad("CSI_DATA", format!("value {j}: {s:?} is not an int8")))?;
        unsigned |= v > 127;
        values.push(v as u8 as i8);
    }
    let count = values.len() as i64;
    if secondary != 0 || cwb != 0 {
        return Ok(Err(format!(
            "line {n}: a 40 MHz frame (bandwidth {cwb}, secondary_channel {secondary}): only the \
             20 MHz L-LTF layout is read"
        )));
    }
    let lltf_only = count == LLTF_BYTES as i64 && len > count;
    if count != len && !lltf_only {
        return Ok(Err(format!("line {n}: {count} CSI values, len says {len}")));
    }
    if values.len() < LLTF_BYTES {
        return Ok(Err(format!(
            "line {n}: {count} CSI values, the L-LTF needs 128"
        )));
    }
    values.truncate(LLTF_BYTES);
    Ok(Ok(Line {
        channel,
        ant,
        timestamp,
        lltf: values,
        lltf_only,
        unsigned,
    }))
}

/// The state of the CSV read line by line (what [`read`] and the stream share): the columns,
/// the first line's channel and antenna, the clock, and the frames read since the last
/// [`Reader::capture`].
pub(crate) struct Reader {
    cols: Columns,
    /// Lines seen (the next one's number is `lines + 1`).
    lines: usize,
    /// `CSI_DATA` lines seen.
    i: usize,
    t_s: Vec<Real>,
    csi: Vec<Complex>,
    /// Frames and values taken out by earlier [`Reader::capture`] calls (for the caps).
    taken: (usize, usize),
    skipped: Vec<(usize, String)>,
    first: Option<(i64, i64)>,
    clock: Option<(u32, u64)>,
    lltf_only: bool,
    unsigned: bool,
}

impl Reader {
    /// A reader with the default columns.
    pub(crate) fn new() -> Result<Reader> {
        let cols = Columns::of(&DEFAULT_COLUMNS).map_err(|name| Error::InvalidFile {
            field: "header".into(),
            reason: format!("column {name} missing"),
        })?;
        Ok(Reader {
            cols,
            lines: 0,
            i: 0,
            t_s: Vec::new(),
            csi: Vec::new(),
            taken: (0, 0),
            skipped: Vec::new(),
            first: None,
            clock: None,
            lltf_only: false,
            unsigned: false,
        })
    }

    /// The next line (without its `\n`).
    pub(crate) fn line(&mut self, raw: &[u8]) -> Result<()> {
        self.lines += 1;
        let n = self.lines;
        let i = self.i;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let raw = if n == 1 {
            raw.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(raw)
        } else {
            raw
        };
        if raw.iter().all(u8::is_ascii_whitespace) {
            return Ok(());
        }
        let is_csi = raw.starts_with(b"CSI_DATA,");
        let Ok(text) = core::str::from_utf8(raw) else {
            if is_csi {
                return Err(Error::InvalidFile {
                    field: format!("frame {i}: line"),
                    reason: format!("line {n}: not UTF-8 text"),
                });
            }
            self.skipped
                .push((i, format!("line {n}: not a CSI_DATA line (not text)")));
            return Ok(());
        };
        if text.starts_with("type,") {
            let names: Vec<&str> = text.split(',').collect();
            self.cols = Columns::of(&names).map_err(|name| Error::InvalidFile {
                field: "header".into(),
                reason: format!("line {n}: column {name} missing"),
            })?;
            return Ok(());
        }
        if !is_csi {
            let start: String = text.chars().take(24).collect();
            self.skipped
                .push((i, format!("line {n}: not a CSI_DATA line ({start:?})")));
            return Ok(());
        }
        let frame = i;
        self.i += 1;
        let line = match parse_line(text, &self.cols, frame, n)? {
            Ok(line) => line,
            Err(why) => {
                self.skipped.push((frame, why));
                return Ok(());
            }
        };
        // Times over every parsed line (a skipped one's clock is as good), from the first line's
        // `local_timestamp` as the chip wrote it, each step modulo 2³² µs.
        let ticks = match self.clock {
            None => u64::from(line.timestamp),
            Some((prev, ticks)) => ticks + u64::from(line.timestamp.wrapping_sub(prev)),
        };
        self.clock = Some((line.timestamp, ticks));
        match self.first {
            None => self.first = Some((line.channel, line.ant)),
            Some((ch, ant)) if (ch, ant) != (line.channel, line.ant) => {
                self.skipped.push((
                    frame,
                    format!(
                        "line {n}: channel {} antenna {}, the capture is channel {ch} antenna {ant}",
                        line.channel, line.ant
                    ),
                ));
                return Ok(());
            }
            Some(_) => {}
        }
        let (frames, values) = (self.taken.0 + self.t_s.len(), self.taken.1 + self.csi.len());
        if frames >= MAX_SNAPSHOTS || values + 51 > MAX_RECORDING_SAMPLES {
            return Err(Error::SizeLimit {
                field: "frames",
                value: frames + 1,
                min: 1,
                max: MAX_SNAPSHOTS.min(MAX_RECORDING_SAMPLES / 51),
            });
        }
        for k in tones() {
            let e = k.rem_euclid(64) as usize;
            // Espressif: imaginary first, then real.
            let (im, re) = (line.lltf[2 * e], line.lltf[2 * e + 1]);
            self.csi.push(Complex::new(re.into(), im.into()));
        }
        self.t_s.push(ticks as Real / 1e6);
        self.lltf_only |= line.lltf_only;
        self.unsigned |= line.unsigned;
        Ok(())
    }

    /// Whether frames were read since the last [`Reader::capture`].
    pub(crate) fn has_frames(&self) -> bool {
        !self.t_s.is_empty()
    }

    /// The capture of the frames read since the last call (taken out; the state kept).
    /// Errors: no usable CSI line at all.
    pub(crate) fn capture(&mut self) -> Result<CsiCapture> {
        let i = self.i;
        let Some((channel, _)) = self.first else {
            let reason = match self.skipped.iter().find(|s| s.1.contains("CSI")) {
                _ if i == 0 => "no CSI_DATA line".to_string(),
                Some((_, why)) => format!("no usable CSI_DATA line ({i} skipped; {why})"),
                None => format!("no usable CSI_DATA line ({i} skipped)"),
            };
            return Err(Error::InvalidFile {
                field: "CSI_DATA".into(),
                reason,
            });
        };
        let t_s = core::mem::take(&mut self.t_s);
        let csi = core::mem::take(&mut self.csi);
        self.taken = (self.taken.0 + t_s.len(), self.taken.1 + csi.len());
        let mut notes = Vec::new();
        notes.push(
            "L-LTF only (legacy tones −26…−1, 2…26); the HT-LTF and STBC-HT-LTF are not used"
                .to_string(),
        );
        notes.push(
            "subcarrier 1 left out: the ESP32's first four CSI bytes (subcarriers 0, 1) are invalid"
                .to_string(),
        );
        if self.lltf_only {
            notes.push(
                "128 values printed where len is larger (the tool's ONLY_LLTF option)".into(),
            );
        }
        if self.unsigned {
            notes.push("values 128–255 (printed unsigned) read as int8".into());
        }
        notes.push(
            "timing offset (SFO/STO) and carrier phase (CFO) not removed: the front end removes \
             them per snapshot (C9/C10)"
                .to_string(),
        );
        notes.push(
            "no AGC gain reported: amplitudes are after the chip's AGC; rssi not applied".into(),
        );
        let cap = CsiCapture {
            format: CsiFormat::Esp32,
            device: "ESP32".into(),
            frame_format: "legacy".into(),
            center_hz: channel_hz(channel),
            bandwidth_hz: 20e6,
            spacing_hz: 312_500.0,
            subcarriers: tones().collect(),
            pilots: [-21, -7, 7, 21].into(),
            n_rx: 1,
            n_tx: 1,
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

/// Reads the tool's CSV (module doc): per kept CSI line the L-LTF on −26…−1, 2…26, the time
/// from `local_timestamp` (µs, unwrapped), the carrier from `channel`. Errors: a header line
/// without a column this reader needs, a CSI line whose field count is not the header's or a
/// field that does not parse (naming the frame, the field and the line), no usable CSI line,
/// the caps.
pub fn read(bytes: &[u8]) -> Result<CsiCapture> {
    let mut reader = Reader::new()?;
    for raw in bytes.split(|&b| b == b'\n') {
        reader.line(raw)?;
    }
    reader.capture()
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::edge::csi::test_file as file;

    fn err(text: &str) -> String {
        read(text.as_bytes()).unwrap_err().to_string()
    }

    const HEAD: &str = "type,role,mac,rssi,rate,sig_mode,mcs,bandwidth,smoothing,not_sounding,\
        aggregation,stbc,fec_coding,sgi,noise_floor,ampdu_cnt,channel,secondary_channel,\
        local_timestamp,ant,sig_len,rx_state,real_time_set,real_timestamp,len,CSI_DATA\n";

    /// A CSI line in the default order: buffer byte `j` = `j % 100 − 50`, `count` of them.
    fn line(channel: &str, second: &str, ts: &str, ant: &str, len: &str, count: usize) -> String {
        let values: Vec<String> = (0..count)
            .map(|j| (j as i64 % 100 - 50).to_string())
            .collect();
        format!(
            "CSI_DATA,PASSIVE,D0:6E:DE:27:6B:63,-77,11,1,4,0,1,1,1,1,0,0,-97,2,{channel},{second},\
             {ts},{ant},1554,0,0,2.695925,{len},[{} ]\n",
            values.join(" ")
        )
    }

    /// The independent reader: CSIKit 2.5 `CSVBeamformReader`, `get_reader(f).read_file(f,
    /// scaled=False)`: `frames[f].csi_matrix` holds the 64 buffer entries in buffer order
    /// (0…31, −32…−1) with the FIRST int8 of each pair as the real part. Espressif's docs put
    /// the imaginary part first, which this reader follows, and it sorts the tones: so ours at
    /// subcarrier k = CSIKit's `csi_matrix[k mod 64]` with real and imaginary swapped
    /// (`ours.re == csikit.imag`, `ours.im == csikit.real`), asserted exactly below on CSIKit's
    /// values `(frame, k, csikit.real, csikit.imag)`.
    #[test]
    fn example_file_matches_csikit_swapped() {
        let cap = read(&file("esp32/example_data.csv")).unwrap();
        assert_eq!(cap.frame_count(), 60);
        assert_eq!((cap.n_rx, cap.n_tx), (1, 1));
        assert_eq!((cap.bandwidth_hz, cap.spacing_hz), (20e6, 312_500.0));
        assert_eq!(cap.center_hz, Some(2437e6)); // channel 6
        let want: Vec<i32> = (-26..=-1).chain(2..=26).collect();
        assert_eq!(cap.subcarriers, want);
        assert_eq!(cap.pilots, [-21, -7, 7, 21]);
        assert!(cap.skipped.is_empty() && cap.gain.is_none());
        assert!(cap.notes.iter().any(|n| n.contains("ONLY_LLTF")));
        let csikit = [
            (0, -26, 8, -20),
            (0, -1, -6, 9),
            (0, 2, -20, -1),
            (0, 7, -30, -2),
            (0, 26, 21, -6),
            (30, -26, -22, 5),
            (30, -1, 9, -6),
            (30, 2, 19, 8),
            (30, 7, 28, 7),
            (30, 26, -18, 10),
            (59, -26, -6, 9),
            (59, -1, 7, -4),
            (59, 2, 14, 5),
            (59, 7, 20, 9),
            (59, 26, -11, -4),
        ];
        for (f, k, re, im) in csikit {
            let j = cap.subcarriers.iter().position(|&s| s == k).unwrap();
            let z = cap.pair(f, 0, 0)[j];
            assert_eq!((z.re, z.im), (im as Real, re as Real), "frame {f} k {k}");
        }
        // local_timestamp of the first and last lines (µs).
        assert_eq!(cap.t_s[0], 2_504_852e-6);
        assert_eq!(cap.t_s[59], 15_039_322e-6);
    }

    #[test]
    fn skipped_lines_name_the_line() {
        let text = format!(
            "{HEAD}I (123) wifi: hello\n{}{}{}{}{}{}",
            line("6", "0", "100", "0", "128", 128),
            line("6", "0", "200", "0", "384", 100),
            line("6", "1", "300", "0", "384", 384),
            line("6", "0", "400", "1", "128", 128),
            line("11", "0", "500", "0", "384", 384),
            "CSI_DATA,PASSIVE,D0,-77,11,1,4,0,1,1,1,1,0,0,-97,2,6,0,600,0,1,0,0,2.6,128,[1 2 3",
        );
        let cap = read(text.as_bytes()).unwrap();
        assert_eq!(cap.frame_count(), 1);
        let why: Vec<(usize, &str)> = cap.skipped.iter().map(|(i, s)| (*i, s.as_str())).collect();
        assert_eq!(why.len(), 6);
        assert!(why[0].0 == 0 && why[0].1.starts_with("line 2: not a CSI_DATA line"));
        assert!(why[1].0 == 1 && why[1].1.starts_with("line 4: 100 CSI values, len says 384"));
        assert!(why[2].0 == 2 && why[2].1.starts_with("line 5: a 40 MHz frame"));
        assert!(
            why[3].0 == 3
                && why[3]
                    .1
                    .contains("antenna 1, the capture is channel 6 antenna 0")
        );
        assert!(why[4].0 == 4 && why[4].1.starts_with("line 7: channel 11"));
        assert!(why[5].0 == 5 && why[5].1.starts_with("line 8: CSI array not closed"));
        // Buffer bytes 4, 5 (entry 2) = −46, −45: imaginary first.
        let z = cap.pair(0, 0, 0)[26];
        assert_eq!((cap.subcarriers[26], z.re, z.im), (2, -45.0, -46.0));
    }

    #[test]
    fn bad_fields_name_frame_field_and_line() {
        let ok = line("6", "0", "100", "0", "128", 128);
        let cases = [
            (
                line("6", "0", "x1", "0", "128", 128),
                "frame 1: local_timestamp: line 3: \"x1\"",
            ),
            (
                line("6", "0", "-5", "0", "128", 128),
                "frame 1: local_timestamp: line 3: -5",
            ),
            (
                line("6", "0", "4294967296", "0", "128", 128),
                "frame 1: local_timestamp",
            ),
            (
                line("0", "0", "1", "0", "128", 128),
                "frame 1: channel: line 3: 0 is not",
            ),
            (line("6", "0", "1", "0", "1e3", 128), "frame 1: len: line 3"),
            (
                line("6", "", "1", "0", "128", 128),
                "frame 1: secondary_channel: line 3",
            ),
            (
                line("6", "0", "1", "0", "128", 128).replace("[-50", "[-129"),
                "frame 1: CSI_DATA: line 3: value 0: \"-129\" is not an int8",
            ),
            (
                line("6", "0", "1", "0", "128", 128).replace(",PASSIVE,", ","),
                "frame 1: fields: line 3: 24 comma-separated fields before the array, the \
                 header has 25",
            ),
        ];
        for (bad, want) in cases {
            let e = err(&format!("{HEAD}{ok}{bad}"));
            assert!(e.starts_with(want), "{e}");
        }
        assert_eq!(err(HEAD), "CSI_DATA: no CSI_DATA line");
        assert_eq!(err(""), "CSI_DATA: no CSI_DATA line");
        let e = err(&format!("{HEAD}{}", line("6", "0", "1", "0", "384", 100)));
        assert!(
            e.starts_with("CSI_DATA: no usable CSI_DATA line (1 skipped; line 2: 100"),
            "{e}"
        );
        let e = err("type,role,mac,channel,len,CSI_DATA\n");
        assert_eq!(e, "header: line 1: column secondary_channel missing");
        assert!(err("CSI_DATA,\u{0}[1]").starts_with("frame 0: fields: line 1: 1 comma"));
        let mut b = b"CSI_DATA,".to_vec();
        b.push(0xff);
        let e = read(&b).unwrap_err().to_string();
        assert_eq!(e, "frame 0: line: line 1: not UTF-8 text");
    }

    #[test]
    fn truncations_never_panic() {
        let b = file("esp32/example_data.csv");
        let first_two = b
            .iter()
            .enumerate()
            .filter(|(_, &c)| c == b'\n')
            .nth(2)
            .unwrap()
            .0;
        for cut in 0..=first_two + 1 {
            match read(&b[..cut]) {
                Ok(cap) => assert!(cap.frame_count() <= 2),
                Err(e) => {
                    let e = e.to_string();
                    let header = e.starts_with("header: line 1: column");
                    assert!(header || e.starts_with("CSI_DATA: no"), "{cut}: {e}");
                }
            }
        }
    }

    #[test]
    fn any_character_changed_never_panics() {
        let b = file("esp32/example_data.csv");
        let end = b
            .iter()
            .enumerate()
            .filter(|(_, &c)| c == b'\n')
            .nth(1)
            .unwrap()
            .0;
        for at in 0..=end {
            for v in [b',', b'[', b']', b'\n', b'9', 0xff] {
                let mut c = b[..=end].to_vec();
                c[at] = v;
                let _ = read(&c);
            }
        }
    }

    #[test]
    fn headerless_unsigned_and_wrapping_clock() {
        let mut a = line("14", "0", "4294967000", "0", "128", 128);
        a = a.replace("[-50 ", "[200 ");
        let text = format!("{a}{}", line("14", "0", "704", "0", "128", 128));
        assert!(sniff(text.as_bytes()));
        let cap = read(text.as_bytes()).unwrap();
        assert_eq!(cap.center_hz, Some(2484e6));
        assert!((cap.t_s[1] - cap.t_s[0] - 1000e-6).abs() < 1e-9);
        assert!(cap.notes.iter().any(|n| n.contains("unsigned")));
        // Columns by the header's names, in another order.
        let head = "type,len,channel,secondary_channel,local_timestamp,CSI_DATA\n";
        let cap = read(format!("{head}CSI_DATA,128,1,0,7,[{} ]\n", "3 4 ".repeat(64)).as_bytes());
        let cap = cap.unwrap();
        assert_eq!((cap.center_hz, cap.t_s[0]), (Some(2412e6), 7e-6));
        assert_eq!((cap.csi[0].re, cap.csi[0].im), (4.0, 3.0));
    }

    #[test]
    fn sniff_claims_only_esp32() {
        assert!(sniff(&file("esp32/example_data.csv")));
        for other in [
            "intel/example.dat",
            "nexmon/example_4366c0.pcap",
            "pico/picoscenes_iwl5300_example.csi",
            "feitcsi/HESU160_5500.csi",
            "feitcsi/VHT80_5500.csi",
            "../recording-cir-int16.npz",
        ] {
            assert!(!sniff(&file(other)), "{other}");
        }
        assert!(!sniff(b"") && !sniff(b"time,csi\n"));
    }
}
