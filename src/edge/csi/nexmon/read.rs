//! The pcap walk, the grouping of packets into frames and the capture.

use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use pcap_file::pcap::PcapParser;
use pcap_file::{Endianness, PcapError, TsResolution};

use super::packet::{
    chanspec, chip, int16_pair, nexmon_header, scale, top_bit, udp_payload, unpack_float, Chanspec,
    Chip, HeaderVersion, Sample, Word, LINKTYPE_ETHERNET, LINKTYPE_LINUX_SLL,
};
use crate::edge::csi::capture::{CsiCapture, CsiFormat};
use crate::error::limits::{MAX_RECORDING_SAMPLES, MAX_SNAPSHOTS};
use crate::error::{Error, Result};
use crate::math::{Complex, Real};

const PCAP_MAGICS: [[u8; 4]; 4] = [
    [0xd4, 0xc3, 0xb2, 0xa1],
    [0xa1, 0xb2, 0xc3, 0xd4],
    [0x4d, 0x3c, 0xb2, 0xa1],
    [0xa1, 0xb2, 0x3c, 0x4d],
];

fn is_pcapng(bytes: &[u8]) -> bool {
    bytes.starts_with(&[0x0a, 0x0d, 0x0d, 0x0a])
        && matches!(
            bytes.get(8..12),
            Some([0x4d, 0x3c, 0x2b, 0x1a] | [0x1a, 0x2b, 0x3c, 0x4d])
        )
}

/// Whether `bytes` start like a classic pcap (any of its four magic numbers, version 2) or a
/// pcapng section (which [`read`] refuses with a named error).
pub fn sniff(bytes: &[u8]) -> bool {
    let Some(magic) = bytes.get(..4) else {
        return false;
    };
    let pcap = PCAP_MAGICS.iter().any(|m| m == magic)
        && match magic.first() {
            Some(0xd4 | 0x4d) => bytes.get(4..6) == Some(&[2, 0][..]),
            _ => bytes.get(4..6) == Some(&[0, 2][..]),
        };
    pcap || is_pcapng(bytes)
}

fn bad(field: String, reason: String) -> Error {
    Error::InvalidFile { field, reason }
}

/// A CSI packet accepted for grouping.
struct Accepted {
    record: usize,
    t_s: Real,
    seq: u16,
    core: u8,
    stream: u8,
    words: Vec<u8>,
}

/// What the first CSI packet fixed for the whole capture.
#[derive(Clone, Copy)]
struct Config {
    chip: Chip,
    chanspec: Chanspec,
    version: HeaderVersion,
}

/// Bytes of the pcap file header.
pub(crate) const PCAP_HEADER: usize = 24;
/// Bytes of a pcap record header.
const RECORD_HEADER: usize = 16;

/// The state of a capture read packet by packet (what [`read`] and the stream share): the pcap
/// header, the first CSI packet's configuration, the packets accepted and not yet assembled.
pub(crate) struct Reader {
    parser: PcapParser,
    link: u32,
    frac_s: Real,
    frac_max: u32,
    skipped: Vec<(usize, String)>,
    accepted: Vec<Accepted>,
    config: Option<Config>,
    /// Records seen.
    record: usize,
    /// The stream's cores and streams, fixed by its first frame.
    masks: Option<(u8, u8)>,
}

impl Reader {
    /// The reader of a capture whose first bytes (at least its 24-byte header) are `bytes`.
    /// Errors: a pcapng file, not a pcap header, a link type nexmon_csi does not write.
    pub(crate) fn new(bytes: &[u8]) -> Result<Reader> {
        if is_pcapng(bytes) {
            return Err(bad(
                "capture".into(),
                "a pcapng file: save the capture as classic pcap (e.g. `editcap -F pcap \
                 in.pcapng out.pcap`, or `tcpdump -w`)"
                    .into(),
            ));
        }
        let (_, parser) = PcapParser::new(bytes).map_err(|e| {
            bad(
                "pcap header".into(),
                match e {
                    PcapError::IncompleteBuffer => {
                        format!("{} bytes, the pcap file header has 24", bytes.len())
                    }
                    _ => "not a pcap file (magic number)".into(),
                },
            )
        })?;
        let header = parser.header();
        let link = u32::from(header.datalink);
        if link != LINKTYPE_ETHERNET && link != LINKTYPE_LINUX_SLL {
            return Err(bad(
                "pcap header: link type".into(),
                format!("{link}: nexmon_csi captures are Ethernet (1) or Linux cooked (113)"),
            ));
        }
        let (frac_s, frac_max) = match header.ts_resolution {
            TsResolution::MicroSecond => (1e-6, 1_000_000),
            TsResolution::NanoSecond => (1e-9, 1_000_000_000),
        };
        Ok(Reader {
            parser,
            link,
            frac_s,
            frac_max,
            skipped: Vec::new(),
            accepted: Vec::new(),
            config: None,
            record: 0,
            masks: None,
        })
    }

    /// The length of the record at the start of `rest` (`16 + incl_len`), once its header is
    /// there: how the stream splitter cuts the capture.
    pub(crate) fn record_len(&self, rest: &[u8]) -> Option<usize> {
        let w = rest.get(8..12)?;
        let b = [w[0], w[1], w[2], w[3]];
        let incl = match self.parser.header().endianness {
            Endianness::Big => u32::from_be_bytes(b),
            Endianness::Little => u32::from_le_bytes(b),
        };
        Some(RECORD_HEADER.saturating_add(incl as usize))
    }

    /// The record at the start of `rest` (maybe more bytes after it); returns its length.
    pub(crate) fn packet(&mut self, rest: &[u8]) -> Result<usize> {
        let record = self.record;
        let (next, raw) = self.parser.next_raw_packet(rest).map_err(|_| {
            let reason = match self.record_len(rest) {
                Some(len) if rest.len() >= RECORD_HEADER => format!(
                    "incl_len {} bytes, but {} remain after the record header",
                    len - RECORD_HEADER,
                    rest.len() - RECORD_HEADER
                ),
                _ => format!("record header truncated: {} of its 16 bytes", rest.len()),
            };
            bad(format!("frame {record}: pcap record"), reason)
        })?;
        let used = rest.len() - next.len();
        let i = record;
        self.record += 1;
        if raw.ts_frac >= self.frac_max {
            return Err(bad(
                format!("frame {i}: timestamp"),
                format!("fraction {} ≥ {} (one second)", raw.ts_frac, self.frac_max),
            ));
        }
        // `next_raw_packet` borrows from `bytes` (never owns).
        let data: &[u8] = match raw.data {
            alloc::borrow::Cow::Borrowed(d) => d,
            alloc::borrow::Cow::Owned(_) => &[],
        };
        let packet = match udp_payload(self.link, data).and_then(nexmon_header) {
            Ok(p) => p,
            Err(reason) => {
                self.skipped.push((i, reason));
                return Ok(used);
            }
        };
        let this = Config {
            chip: chip(packet.chip_version, i)?,
            chanspec: chanspec(packet.chanspec, i)?,
            version: packet.version,
        };
        let cfg = *self.config.get_or_insert(this);
        if let Some(reason) = differs(&cfg, &this) {
            self.skipped.push((i, reason));
            return Ok(used);
        }
        let need = cfg.chanspec.nfft * 4;
        let Some(words) = packet.csi.get(..need) else {
            self.skipped.push((
                i,
                format!(
                    "CSI {} bytes: {} MHz needs {} words of 4 bytes (captured {} of {} bytes)",
                    packet.csi.len(),
                    cfg.chanspec.bw_mhz,
                    cfg.chanspec.nfft,
                    data.len(),
                    raw.orig_len
                ),
            ));
            return Ok(used);
        };
        let t_s = Real::from(raw.ts_sec) + Real::from(raw.ts_frac) * self.frac_s;
        self.accepted.push(Accepted {
            record: i,
            t_s,
            seq: packet.seq,
            core: packet.core,
            stream: packet.stream,
            words: words.to_vec(),
        });
        Ok(used)
    }

    /// The capture of every packet accepted (batch: the cores and streams over all of them).
    fn capture(&mut self) -> Result<CsiCapture> {
        let Some(cfg) = self.config.filter(|_| !self.accepted.is_empty()) else {
            let first = match self.skipped.first() {
                Some((i, why)) => format!(" (frame {i}: {why})"),
                None => String::new(),
            };
            return Err(bad(
                "capture".into(),
                format!(
                    "no Nexmon CSI packet (UDP to port 5500, magic 0x1111, a full CSI payload) \
                     among its {} pcap records{first}",
                    self.record
                ),
            ));
        };
        let masks = masks(&self.accepted);
        assemble(cfg, &self.accepted, self.skipped.clone(), masks)
    }

    /// Streaming: whether the first held frame is complete — a later packet starts another
    /// (another sequence number, or an antenna pair again) — or, at the stream's `end`, any
    /// packet is held.
    pub(crate) fn frame_ready(&self, end: bool) -> bool {
        let n = group_end(&self.accepted, 0);
        n > 0 && (end || n < self.accepted.len())
    }

    /// Streaming: the first held frame taken out, as a capture of one frame on the cores and
    /// streams of the stream's first frame (`None`: it lacks some of them or has others — skipped,
    /// as the batch read skips an incomplete frame).
    pub(crate) fn take_frame(&mut self) -> Result<Option<CsiCapture>> {
        let n = group_end(&self.accepted, 0);
        let group: Vec<Accepted> = self.accepted.drain(..n).collect();
        let Some(cfg) = self.config.filter(|_| !group.is_empty()) else {
            return Ok(None);
        };
        let (cores, streams) = *self.masks.get_or_insert_with(|| masks(&group));
        let (here_c, here_s) = masks(&group);
        let want = (cores.count_ones() * streams.count_ones()) as usize;
        if group.len() != want || here_c & !cores != 0 || here_s & !streams != 0 {
            self.skipped.push((
                group[0].record,
                format!(
                    "sequence number {}: {} antenna pairs, not the {want} of the stream's first \
                     frame — frame incomplete",
                    group[0].seq,
                    group.len()
                ),
            ));
            return Ok(None);
        }
        assemble(cfg, &group, self.skipped.clone(), (cores, streams)).map(Some)
    }
}

/// The cores and streams (bit masks) of `packets`.
fn masks(packets: &[Accepted]) -> (u8, u8) {
    let cores: u8 = packets.iter().fold(0, |m, p| m | 1 << p.core);
    let streams: u8 = packets.iter().fold(0, |m, p| m | 1 << p.stream);
    (cores, streams)
}

/// The end of the frame that starts at `start`: the run of one sequence number without a
/// repeated antenna pair.
fn group_end(packets: &[Accepted], start: usize) -> usize {
    let mut seen = 0u64;
    let mut end = start;
    while let Some(p) = packets.get(end) {
        let bit = 1u64 << (p.core * 8 + p.stream);
        if p.seq != packets[start].seq || seen & bit != 0 {
            break;
        }
        seen |= bit;
        end += 1;
    }
    end
}

/// Reads a Nexmon CSI pcap (module doc): every record to UDP port 5500 with the Nexmon magic
/// is one antenna pair of one frame; consecutive packets of one sequence number make a frame.
pub fn read(bytes: &[u8]) -> Result<CsiCapture> {
    let mut reader = Reader::new(bytes)?;
    let mut pos = PCAP_HEADER;
    while pos < bytes.len() {
        pos += reader.packet(&bytes[pos..])?;
    }
    reader.capture()
}

fn differs(cfg: &Config, this: &Config) -> Option<String> {
    if this.chip.version != cfg.chip.version {
        Some(format!(
            "chip {}, the capture's first CSI packet is {}",
            this.chip.name, cfg.chip.name
        ))
    } else if this.chanspec.raw != cfg.chanspec.raw {
        Some(format!(
            "chanspec 0x{:04x}, the capture's first CSI packet has 0x{:04x}",
            this.chanspec.raw, cfg.chanspec.raw
        ))
    } else if this.version != cfg.version {
        Some("another Nexmon header version (magic 0x1111 vs 0x11111111)".into())
    } else {
        None
    }
}

/// The occupied subcarriers of the chanspec's bandwidth (HT20, HT40, VHT80) and the pilots.
fn subcarrier_map(bw_mhz: u32) -> (i32, i32, &'static [i32]) {
    match bw_mhz {
        20 => (1, 28, &[7, 21]),
        40 => (2, 58, &[11, 25, 53]),
        _ => (2, 122, &[11, 39, 75, 103]),
    }
}

/// The FFT bin (Nexmon's order: 0…N/2−1, −N/2…−1) of subcarrier `k`.
fn bin(k: i32, nfft: usize) -> usize {
    if k >= 0 {
        k as usize
    } else {
        (nfft as i64 + i64::from(k)) as usize
    }
}

fn assemble(
    cfg: Config,
    packets: &[Accepted],
    mut skipped: Vec<(usize, String)>,
    (cores, streams): (u8, u8),
) -> Result<CsiCapture> {
    let nfft = cfg.chanspec.nfft;
    let (n_rx, n_tx) = (cores.count_ones() as usize, streams.count_ones() as usize);
    let rank = |mask: u8, i: u8| (mask & ((1u16 << i) - 1) as u8).count_ones() as usize;
    // The firmware's PHY status words (Rssi header) over bins o..o+3.
    let status_bins = match cfg.version {
        HeaderVersion::Magic4 => 0..0,
        HeaderVersion::Rssi if cfg.chanspec.bw_mhz == 20 => 28..31,
        HeaderVersion::Rssi => 0..3,
    };
    let (lo, hi, pilot_pos) = subcarrier_map(cfg.chanspec.bw_mhz);
    let subcarriers: Vec<i32> = (-hi..=-lo)
        .chain(lo..=hi)
        .filter(|&k| !status_bins.contains(&bin(k, nfft)))
        .collect();
    let mut pilots: Vec<i32> = pilot_pos
        .iter()
        .flat_map(|&p| [-p, p])
        .filter(|p| subcarriers.contains(p))
        .collect();
    pilots.sort_unstable();
    let kk = subcarriers.len();
    let per_frame = n_rx * n_tx * kk;
    let mut t_s = Vec::new();
    let mut csi: Vec<Complex> = Vec::new();
    let mut gain = Vec::new();
    let mut start = 0;
    while start < packets.len() {
        // The run of one sequence number without a repeated antenna pair.
        let end = group_end(packets, start);
        let group = &packets[start..end];
        start = end;
        let first = &group[0];
        if group.len() != n_rx * n_tx {
            let have: Vec<String> = group
                .iter()
                .map(|p| format!("core {}/stream {}", p.core, p.stream))
                .collect();
            skipped.push((
                first.record,
                format!(
                    "sequence number {}: {} of the {} antenna pairs ({}) — frame incomplete",
                    first.seq,
                    group.len(),
                    n_rx * n_tx,
                    have.join(", ")
                ),
            ));
            continue;
        }
        let caps = [
            ("frames", t_s.len() + 1, MAX_SNAPSHOTS),
            ("CSI values", csi.len() + per_frame, MAX_RECORDING_SAMPLES),
        ];
        if let Some(&(field, value, max)) = caps.iter().find(|c| c.1 > c.2) {
            return Err(Error::SizeLimit {
                field,
                value,
                min: 1,
                max,
            });
        }
        let base = csi.len();
        csi.resize(base + per_frame, Complex::new(0.0, 0.0));
        let unpacked: Vec<Vec<Word>> = group
            .iter()
            .map(|p| words(&p.words, cfg.chip.sample, cfg.version))
            .collect();
        // unpack_float's autoscale (nbits = 10), over every word of the frame.
        let shft = match cfg.chip.sample {
            Sample::Float { e, .. } => {
                let maxbit = unpacked
                    .iter()
                    .flat_map(|w| w.iter().enumerate())
                    .filter(|(b, _)| !status_bins.contains(b))
                    .filter_map(|(_, w)| top_bit(*w))
                    .max();
                10 - maxbit.unwrap_or(-(1 << (e - 1)))
            }
            Sample::Int16 => 0,
        };
        for (p, w) in group.iter().zip(&unpacked) {
            let pair = rank(cores, p.core) * n_tx + rank(streams, p.stream);
            let out = &mut csi[base + pair * kk..base + (pair + 1) * kk];
            for (z, &k) in out.iter_mut().zip(&subcarriers) {
                let Some(w) = w.get(bin(k, nfft)) else {
                    continue;
                };
                *z = match cfg.chip.sample {
                    Sample::Float { m, .. } => {
                        Complex::new(scale(w.re, w.exp, shft, m), scale(w.im, w.exp, shft, m))
                    }
                    Sample::Int16 => Complex::new(Real::from(w.re), Real::from(w.im)),
                };
            }
        }
        t_s.push(first.t_s);
        gain.push(libm::exp2(-Real::from(shft)));
    }
    if t_s.is_empty() {
        return Err(bad(
            "capture".into(),
            format!(
                "no complete frame: every sequence number lacks some of the {n_rx}×{n_tx} antenna \
                 pairs (first: frame {})",
                skipped.iter().map(|s| s.0).min().unwrap_or(0)
            ),
        ));
    }
    skipped.sort_by_key(|s| s.0);
    let float = matches!(cfg.chip.sample, Sample::Float { .. });
    let notes = notes(&cfg, float, &subcarriers);
    let (bw, frame_format) = (
        cfg.chanspec.bw_mhz,
        if cfg.chanspec.bw_mhz == 80 {
            "VHT"
        } else {
            "HT"
        },
    );
    let cap = CsiCapture {
        format: CsiFormat::Nexmon,
        device: cfg.chip.name.into(),
        frame_format: frame_format.into(),
        center_hz: cfg.chanspec.center_hz,
        bandwidth_hz: Real::from(bw) * 1e6,
        spacing_hz: 312.5e3,
        subcarriers,
        pilots,
        n_rx,
        n_tx,
        t_s,
        csi,
        gain: float.then_some(gain),
        notes,
        skipped,
    };
    cap.validate()?;
    Ok(cap)
}

/// The `nfft` words of a packet, unpacked (ints: `(re, im, 0)`).
fn words(bytes: &[u8], sample: Sample, version: HeaderVersion) -> Vec<Word> {
    bytes
        .chunks_exact(4)
        .map(|c| {
            let h = u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
            match sample {
                Sample::Float { m, e } => unpack_float(h, m, e),
                Sample::Int16 => {
                    let (low, high) = int16_pair(h);
                    // Before nexmon_csi's I/Q fix (2020-06, with the 4-byte magic) the
                    // firmware put I in the high half.
                    let (re, im) = match version {
                        HeaderVersion::Magic4 => (high, low),
                        HeaderVersion::Rssi => (low, high),
                    };
                    Word {
                        re: re.into(),
                        im: im.into(),
                        exp: 0,
                    }
                }
            }
        })
        .collect()
}

fn notes(cfg: &Config, float: bool, subcarriers: &[i32]) -> Vec<String> {
    let (lo, hi, _) = subcarrier_map(cfg.chanspec.bw_mhz);
    let mut n =
        vec![
        format!(
            "kept the occupied subcarriers of the chanspec's {} MHz ({}: ±{lo}…±{hi}); the guard \
             and DC bins Nexmon also reports are dropped",
            cfg.chanspec.bw_mhz,
            if cfg.chanspec.bw_mhz == 80 { "VHT" } else { "HT" }
        ),
        "the frame's own PHY format and bandwidth are not in the Nexmon header: a narrower frame \
         (e.g. a 20 MHz frame on the control channel of an 80 MHz chanspec) leaves the other \
         subcarriers at noise level"
            .into(),
        "antenna phase offsets not calibrated".into(),
        "timing offset (SFO/STO) and carrier phase (CFO) not removed: the front end removes them \
         per snapshot (C9/C10)"
            .into(),
    ];
    if float {
        n.push(
            "packed floats decoded as csiread/nexmon_csi's unpack_float with autoscale, one shift \
             per frame (the largest part gets 10 bits, smaller ones are truncated); gain = 2^−shift \
             restores the chip's mantissa·2^exponent scale (not calibrated to power)"
                .into(),
        );
    } else {
        n.push("int16 values as the chip reports them; no gain (RSSI/AGC) applied".into());
    }
    if cfg.version == HeaderVersion::Rssi {
        let k = if cfg.chanspec.bw_mhz == 20 { 28 } else { 2 };
        if !subcarriers.contains(&k) {
            n.push(format!(
                "subcarrier {k} dropped: this firmware (magic 0x1111, with RSSI) writes PHY \
                 status over its FFT bins; RSSI not applied"
            ));
        }
    }
    if cfg.chanspec.center_hz.is_none() {
        n.push(format!(
            "chanspec 0x{:04x}: band neither 2.4 nor 5 GHz, carrier unknown",
            cfg.chanspec.raw
        ));
    }
    n
}
