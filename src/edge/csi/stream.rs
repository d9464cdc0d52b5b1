//! The CSI formats read as streams (issue 40 §3; `cir track --follow --format F`,
//! docs/recording.md "CSI streams"): bytes pushed as they arrive, the frames of the live run
//! out as soon as they are complete. No I/O (`no_std` + `alloc`).
//!
//! Two steps. **The splitter** cuts the bytes into the format's records — Intel 5300: the
//! netlink records (`2 + field_len`); Nexmon: the pcap file header, then the pcap records
//! (`16 + incl_len`); PicoScenes: its frames (`4 + length`); FeitCSI: its frames
//! (`272 + csi_length`); ESP32: the CSV lines — keeping the bytes of an incomplete record, at
//! most [`MAX_CSI_RECORD_BYTES`] of them (a record announced longer is an
//! [`Error::SizeLimit`] of `record` at once). Each record goes to **the format's reader**, the
//! same one the whole-file read ([`super::read_capture`]) runs record by record (its
//! `Reader`: the state a file carries from record to record — the first frame's
//! configuration, the clock's wraps), which gives the frames complete so far as a capture.
//! Nexmon groups the packets of one sequence number into a frame: a frame is complete when a
//! packet of the next one arrives (or an antenna pair again), or when the stream ends.
//!
//! **The conversion** is [`super::to_recording`]'s, frame by frame. Fixed by the first frame:
//! the antenna pairs and links (`--links`), the reported subcarriers kept and so the uniform
//! grid and its mask (`P[n]`: [`super::occupied`] over the first frame alone — the batch
//! conversion averages every frame, so on a file where the two differ say
//! `--all-subcarriers`), whether the gain is applied (the first frame has one), and the time
//! origin (times are relative to the first frame's). A later frame of other antennas or
//! subcarriers (or spacing) is an [`Error::InvalidFile`] of `frames[k]`; so is a frame
//! without the gain the first one had. Frames whose time does not increase are dropped, as in
//! the batch conversion ([`CsiStream::dropped`]). At the end ([`CsiStream::end`]) the bytes of
//! a record left incomplete are an [`Error::InvalidFile`] of `record` (truncated).

use alloc::format;
use alloc::vec::Vec;

use super::capture::{ConvertOptions, CsiCapture, CsiFormat, Grid};
use super::{esp32, feitcsi, intel5300, nexmon, picoscenes};
use crate::channel::FrameHeader;
use crate::error::limits::MAX_STREAM_HEADER_BYTES;
use crate::error::{Error, Result};
use crate::math::{Complex, Real};

/// The most bytes of one record (a line, a netlink record, a pcap record, a frame) a stream
/// holds before it is complete: the frame stream's header cap, 16 MiB.
pub const MAX_CSI_RECORD_BYTES: usize = MAX_STREAM_HEADER_BYTES;

/// One frame for the live run: its time (s, from the stream's first frame) and its samples on
/// the grid, link-major (as a frame of the frame stream).
#[derive(Debug, Clone, PartialEq)]
pub struct CsiFrame {
    /// Time, s.
    pub t_s: Real,
    /// `P·N` samples, link-major.
    pub samples: Vec<Complex>,
}

/// The reader of each format (its record-by-record state).
enum Reader {
    Intel(intel5300::Reader),
    /// `None` until the pcap file header is read.
    Nexmon(Option<nexmon::Reader>),
    Pico(picoscenes::Reader),
    Feit(feitcsi::Reader),
    Esp32(esp32::Reader),
}

/// What the first frame fixed (module docs).
struct Fixed {
    grid: Grid,
    header: FrameHeader,
    n_rx: usize,
    n_tx: usize,
    subcarriers: Vec<i32>,
    spacing_hz: Real,
    t0: Real,
    /// The last frame's time (relative), at most one value.
    last: Vec<Real>,
}

/// A CSI file read as a stream (module docs): [`CsiStream::push`] bytes, frames out.
pub struct CsiStream {
    format: CsiFormat,
    options: ConvertOptions,
    reader: Reader,
    buf: Vec<u8>,
    /// Records cut so far.
    records: usize,
    /// Frames given out so far.
    frames: u64,
    dropped: usize,
    fixed: Option<Fixed>,
}

impl CsiStream {
    /// A stream of `format`, converted with `options` (as [`super::to_recording`]).
    pub fn new(format: CsiFormat, options: ConvertOptions) -> Result<CsiStream> {
        let reader = match format {
            CsiFormat::Intel5300 => Reader::Intel(intel5300::Reader::default()),
            CsiFormat::Nexmon => Reader::Nexmon(None),
            CsiFormat::PicoScenes => Reader::Pico(picoscenes::Reader::default()),
            CsiFormat::FeitCsi => Reader::Feit(feitcsi::Reader::default()),
            CsiFormat::Esp32 => Reader::Esp32(esp32::Reader::new()?),
        };
        Ok(CsiStream {
            format,
            options,
            reader,
            buf: Vec::new(),
            records: 0,
            frames: 0,
            dropped: 0,
            fixed: None,
        })
    }

    /// The format.
    pub fn format(&self) -> CsiFormat {
        self.format
    }

    /// The header of the frames given out (links, grid, mask, `synchronized = false`): `None`
    /// before the first frame.
    pub fn header(&self) -> Option<&FrameHeader> {
        self.fixed.as_ref().map(|f| &f.header)
    }

    /// Frames dropped because their time did not increase.
    pub fn dropped(&self) -> usize {
        self.dropped
    }

    /// Bytes held of an incomplete record.
    pub fn pending_bytes(&self) -> usize {
        self.buf.len()
    }

    /// The length of the record at the start of `buf`, when known (`None`: more bytes needed).
    fn record_len(&self, buf: &[u8]) -> Option<usize> {
        match &self.reader {
            Reader::Intel(_) => intel5300::record_len(buf),
            Reader::Nexmon(None) => Some(nexmon::PCAP_HEADER),
            Reader::Nexmon(Some(r)) => r.record_len(buf),
            Reader::Pico(_) => picoscenes::record_len(buf),
            Reader::Feit(_) => feitcsi::record_len(buf),
            Reader::Esp32(_) => buf.iter().position(|&b| b == b'\n').map(|i| i + 1),
        }
    }

    /// Takes `bytes`, appends the frames completed by them to `out`. Errors: a record over
    /// [`MAX_CSI_RECORD_BYTES`], the reader's (naming the frame and field), the conversion's
    /// (module docs). After an error the stream is not to be used again.
    pub fn push(&mut self, bytes: &[u8], out: &mut Vec<CsiFrame>) -> Result<()> {
        self.buf.extend_from_slice(bytes);
        let mut at = 0;
        // Bounded by the bytes held: each turn takes a record of ≥ 1 byte.
        loop {
            let rest = &self.buf[at..];
            let Some(len) = self.record_len(rest) else {
                if rest.len() > MAX_CSI_RECORD_BYTES {
                    return Err(self.too_long(rest.len()));
                }
                break;
            };
            if len > MAX_CSI_RECORD_BYTES {
                return Err(self.too_long(len));
            }
            if len == 0 || rest.len() < len {
                break;
            }
            let record = self.buf[at..at + len].to_vec();
            at += len;
            self.record(&record, out)?;
        }
        self.buf.drain(..at);
        Ok(())
    }

    fn too_long(&self, len: usize) -> Error {
        Error::SizeLimit {
            field: "record",
            value: len,
            min: 1,
            max: MAX_CSI_RECORD_BYTES,
        }
    }

    /// One complete record through its reader; the frames it completes converted.
    fn record(&mut self, rec: &[u8], out: &mut Vec<CsiFrame>) -> Result<()> {
        self.records += 1;
        let mut caps: Vec<CsiCapture> = Vec::new();
        match &mut self.reader {
            Reader::Intel(r) => {
                r.record(rec)?;
                if r.has_frames() {
                    caps.push(r.capture()?);
                }
            }
            Reader::Nexmon(r @ None) => *r = Some(nexmon::Reader::new(rec)?),
            Reader::Nexmon(Some(r)) => {
                r.packet(rec)?;
                // Bounded by the packets held.
                while r.frame_ready(false) {
                    caps.extend(r.take_frame()?);
                }
            }
            Reader::Pico(r) => {
                r.frame(rec)?;
                if r.has_frames() {
                    caps.push(r.capture()?);
                }
            }
            Reader::Feit(r) => {
                r.frame(rec)?;
                if r.has_frames() {
                    caps.push(r.capture()?);
                }
            }
            Reader::Esp32(r) => {
                r.line(rec.strip_suffix(b"\n").unwrap_or(rec))?;
                if r.has_frames() {
                    caps.push(r.capture()?);
                }
            }
        }
        for cap in &caps {
            self.convert(cap, out)?;
        }
        Ok(())
    }

    /// The end of the stream: a Nexmon frame held is complete; the bytes of an incomplete
    /// record are an [`Error::InvalidFile`] of `record` (truncated). ESP32: whitespace after
    /// the last line is ignored.
    pub fn end(&mut self, out: &mut Vec<CsiFrame>) -> Result<()> {
        let left = self.buf.len();
        let blank =
            matches!(self.reader, Reader::Esp32(_)) && self.buf.iter().all(u8::is_ascii_whitespace);
        if left > 0 && !blank {
            let want = match self.record_len(&self.buf) {
                Some(n) => format!("of its {n} bytes"),
                None => "bytes, its header or line incomplete".into(),
            };
            // Nexmon's pcap file header is not a record of the capture.
            let header = usize::from(matches!(self.reader, Reader::Nexmon(Some(_))));
            return Err(Error::InvalidFile {
                field: format!("record {}", self.records - header),
                reason: format!("truncated: the input ended after {left} {want}"),
            });
        }
        self.buf.clear();
        let mut caps = Vec::new();
        if let Reader::Nexmon(Some(r)) = &mut self.reader {
            // Bounded by the packets held.
            while r.frame_ready(true) {
                caps.extend(r.take_frame()?);
            }
        }
        for cap in &caps {
            self.convert(cap, out)?;
        }
        Ok(())
    }

    /// A capture of the frames just completed, on the first frame's grid (module docs).
    fn convert(&mut self, cap: &CsiCapture, out: &mut Vec<CsiFrame>) -> Result<()> {
        if self.fixed.is_none() {
            let grid = Grid::of(cap, &self.options)?;
            let zeros = alloc::vec![Complex::new(0.0, 0.0); grid.pairs.len() * grid.span];
            let first = grid.recording(alloc::vec![0.0], zeros);
            first.validate()?;
            self.fixed = Some(Fixed {
                header: FrameHeader::of_recording(&first)?,
                grid,
                n_rx: cap.n_rx,
                n_tx: cap.n_tx,
                subcarriers: cap.subcarriers.clone(),
                spacing_hz: cap.spacing_hz,
                t0: cap.t_s[0],
                last: Vec::new(),
            });
        }
        let Some(fx) = self.fixed.as_mut() else {
            return Ok(());
        };
        let k = self.frames;
        let same = (cap.n_rx, cap.n_tx, cap.spacing_hz) == (fx.n_rx, fx.n_tx, fx.spacing_hz)
            && cap.subcarriers == fx.subcarriers;
        if !same {
            return Err(Error::InvalidFile {
                field: format!("frames[{k}]"),
                reason: format!(
                    "{}×{} antennas, {} subcarriers at {} Hz: the stream's first frame fixed \
                     {}×{}, {} subcarriers at {} Hz (a stream's grid and mask are the first \
                     frame's; convert the file in one piece with cir convert)",
                    cap.n_rx,
                    cap.n_tx,
                    cap.subcarriers.len(),
                    cap.spacing_hz,
                    fx.n_rx,
                    fx.n_tx,
                    fx.subcarriers.len(),
                    fx.spacing_hz
                ),
            });
        }
        if fx.grid.gain_applied && cap.gain.is_none() {
            return Err(Error::InvalidFile {
                field: format!("frames[{k}]"),
                reason: "no gain (the format's factor is undefined for this frame) while the \
                         first frame's was applied: say --raw-gain to stream without it"
                    .into(),
            });
        }
        let mut dropped = Vec::new();
        let mut samples = Vec::new();
        let before = fx.last.len();
        fx.grid
            .frames(cap, fx.t0, &mut fx.last, &mut dropped, &mut samples);
        self.dropped += dropped.len();
        let per = fx.grid.pairs.len() * fx.grid.span;
        let times = fx.last.split_off(before.min(fx.last.len()));
        for (t, chunk) in times.iter().zip(samples.chunks_exact(per.max(1))) {
            out.push(CsiFrame {
                t_s: *t,
                samples: chunk.to_vec(),
            });
            self.frames += 1;
        }
        // Keep only the last time.
        if let Some(&t) = times.last() {
            fx.last = alloc::vec![t];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
