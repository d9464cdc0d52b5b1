//! `scatterloc cir track --follow` and `scatterloc cir stream` (issue 40 §3): the frame stream
//! of docs/recording.md ("Streaming frames") read as it arrives — a file followed as it grows,
//! or standard input — through the core's live run ([`LiveFront`], [`LiveRun`]); one JSON line
//! per frame on stdout, written (unbuffered) as soon as the frame is tracked.
//!
//! The byte I/O is here; the parsing and every check are the core's ([`FrameHeader`]). A file
//! at its end is polled every [`POLL`] until more bytes, its end marker or Ctrl-C; standard
//! input is read by a thread (so Ctrl-C is seen while no byte comes), and its end between two
//! frames ends the run like the end marker, inside a frame it is a truncated frame. Ctrl-C:
//! exit 130 after the lines already written. At a clean end a summary line goes to stderr: frames,
//! the latency from a frame's last byte read to its line written (median, p99, max) and the
//! process's peak resident memory (`VmHWM`).
//!
//! With `--format intel5300|nexmon|picoscenes|feitcsi|esp32` (or `auto`, the default, by the
//! first bytes: `{` is a frame stream) `--cir` is a CSI tool's output read as a stream: the
//! bytes go to the core's [`CsiStream`] as they arrive (its records cut, each frame converted
//! as `cir track` converts the file, with `--links`, `--raw-gain`, `--all-subcarriers`; the grid
//! and mask fixed by the first frame), and each frame it completes is tracked at once. Standard
//! input's end ends the run (an incomplete last record: a named error after the lines written);
//! a followed CSI file has no end marker and is followed until Ctrl-C.

use std::collections::VecDeque;
use std::fs::File;
use std::io::{BufReader, Read, Write};
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use scatterloc::channel::{encode_frame, FrameHeader, END_MARKER};
use scatterloc::csi::{detect, CsiFormat, CsiFrame, CsiStream};
use scatterloc::error::limits::{MAX_RECORDING_BYTES, MAX_STREAM_HEADER_BYTES};
use scatterloc::math::Complex;
use scatterloc::study::{LiveFront, LiveRun};
use scatterloc::Error;

use super::cir::{flag_error, read_recording, request};
use super::flags::{at_flag, in_file};
use super::io::{model_of, one_stdin, read_bytes, read_scenario};
use super::study::{catch_ctrl_c, interrupted};
use crate::cli::{CirStreamArgs, CirTrackArgs, CsiArgs};
use crate::failure::CliError;

/// How often a followed file at its end is read again.
pub const POLL: Duration = Duration::from_millis(20);
/// Bytes per read of standard input's thread, and chunks it may hold unread (memory bound).
const CHUNK: usize = 64 << 10;
const CHUNKS_IN_FLIGHT: usize = 16;
/// Latency histogram: 1 µs bins up to 50 ms, one more for anything slower.
const LATENCY_BINS: usize = 50_000;

/// Exit 130 on Ctrl-C, the lines written kept.
fn stopped() -> CliError {
    CliError {
        message: "cancelled by Ctrl-C; the lines written are kept".into(),
        code: 130,
    }
}

/// Where the frames come from.
enum Source {
    /// A file followed as it grows.
    File(BufReader<File>),
    /// Standard input through its reader thread: chunks (an empty one: end of input).
    Stdin {
        rx: Receiver<std::io::Result<Vec<u8>>>,
        chunk: Vec<u8>,
        at: usize,
        ended: bool,
    },
}

impl Source {
    fn open(path: &str) -> Result<Source, CliError> {
        if path == "-" {
            let (tx, rx) = sync_channel(CHUNKS_IN_FLIGHT);
            std::thread::spawn(move || {
                let mut stdin = std::io::stdin().lock();
                let mut buf = vec![0u8; CHUNK];
                // Ends at end of input, at a read error, or when the run has gone.
                loop {
                    let r = stdin.read(&mut buf).map(|n| buf[..n].to_vec());
                    let last = !matches!(&r, Ok(v) if !v.is_empty());
                    if tx.send(r).is_err() || last {
                        break;
                    }
                }
            });
            return Ok(Source::Stdin {
                rx,
                chunk: Vec::new(),
                at: 0,
                ended: false,
            });
        }
        let f = File::open(path).map_err(|e| at_flag("cir", format!("{path}: {e}")))?;
        Ok(Source::File(BufReader::with_capacity(CHUNK, f)))
    }

    /// Fills `buf`; returns the bytes read: all of them, or fewer only at standard input's end.
    /// A file at its end is read again every [`POLL`]; Ctrl-C while waiting: exit 130.
    fn fill(&mut self, buf: &mut [u8]) -> Result<usize, CliError> {
        let mut got = 0;
        // Bounded by the bytes asked for: each turn reads ≥ 1 byte or ends.
        while got < buf.len() {
            match self.some(&mut buf[got..])? {
                0 => break,
                n => got += n,
            }
        }
        Ok(got)
    }

    /// Reads what is there into `buf`: at least one byte, or 0 at standard input's end. A file
    /// at its end is read again every [`POLL`] (a followed CSI file has no end marker: it is
    /// followed until Ctrl-C); Ctrl-C while waiting: exit 130.
    fn some(&mut self, buf: &mut [u8]) -> Result<usize, CliError> {
        // Bounded by Ctrl-C while waiting; each turn that does not wait returns.
        loop {
            match self {
                Source::File(f) => {
                    let n = f
                        .read(buf)
                        .map_err(|e| at_flag("cir", format!("reading: {e}")))?;
                    if n > 0 {
                        return Ok(n);
                    }
                    if interrupted() {
                        return Err(stopped());
                    }
                    std::thread::sleep(POLL);
                }
                Source::Stdin { chunk, at, .. } if *at < chunk.len() => {
                    let n = (chunk.len() - *at).min(buf.len());
                    buf[..n].copy_from_slice(&chunk[*at..*at + n]);
                    *at += n;
                    return Ok(n);
                }
                Source::Stdin { ended: true, .. } => return Ok(0),
                Source::Stdin { .. } => {
                    // Waits for the next chunk (or the end).
                    if let Source::Stdin {
                        rx,
                        chunk,
                        at,
                        ended,
                        ..
                    } = self
                    {
                        match rx.recv_timeout(POLL) {
                            Ok(Ok(c)) if c.is_empty() => *ended = true,
                            Ok(Ok(c)) => {
                                *chunk = c;
                                *at = 0;
                            }
                            Ok(Err(e)) => {
                                return Err(at_flag("cir", format!("reading standard input: {e}")))
                            }
                            Err(RecvTimeoutError::Timeout) => {
                                if interrupted() {
                                    return Err(stopped());
                                }
                            }
                            Err(RecvTimeoutError::Disconnected) => *ended = true,
                        }
                    }
                }
            }
        }
    }

    /// The header line (without its `\n`), at most [`MAX_STREAM_HEADER_BYTES`] bytes, after
    /// the bytes `line` already read of it (by the format's sniffing).
    fn header(&mut self, mut line: Vec<u8>) -> Result<Vec<u8>, Error> {
        if let Some(nl) = line.iter().position(|&b| b == b'\n') {
            line.truncate(nl);
            return Ok(line);
        }
        let mut b = [0u8; 1];
        // Bounded by the header cap.
        while line.len() <= MAX_STREAM_HEADER_BYTES {
            match self.fill(&mut b) {
                Ok(1) if b[0] == b'\n' => return Ok(line),
                Ok(1) => line.push(b[0]),
                Ok(_) => {
                    return Err(Error::InvalidFile {
                        field: "header".into(),
                        reason: format!(
                            "the input ended after {} bytes, before the header's end of line",
                            line.len()
                        ),
                    })
                }
                Err(e) => {
                    return Err(Error::InvalidFile {
                        field: "header".into(),
                        reason: e.message,
                    })
                }
            }
        }
        // Over the cap: the core names it.
        FrameHeader::from_json(&line).map(|_| line)
    }
}

/// The next frame `k` into `payload` (checked, its samples into `samples`): its time and when its
/// last byte was read; `None` at the end marker or at standard input's end between frames.
fn next_frame(
    src: &mut Source,
    header: &FrameHeader,
    k: u64,
    payload: &mut [u8],
    samples: &mut Vec<Complex>,
) -> Result<Option<(f64, Instant)>, FrameError> {
    let mut len = [0u8; 4];
    match src.fill(&mut len).map_err(FrameError::Cli)? {
        0 => return Ok(None),
        4 => {}
        n => {
            return Err(FrameError::Core(Error::InvalidFile {
                field: format!("frames[{k}]"),
                reason: format!("truncated: {n} of its 4 length bytes"),
            }))
        }
    }
    if header
        .check_length(k, u32::from_le_bytes(len))
        .map_err(FrameError::Core)?
        .is_none()
    {
        return Ok(None);
    }
    let n = src.fill(payload).map_err(FrameError::Cli)?;
    let read_at = Instant::now();
    let t = header
        .parse_frame(k, &payload[..n], samples)
        .map_err(FrameError::Core)?;
    Ok(Some((t, read_at)))
}

/// A frame's failure: the stream's (named by the core) or the CLI's (Ctrl-C, reading).
enum FrameError {
    Core(Error),
    Cli(CliError),
}

/// Latencies in 1 µs bins (flat memory), and the slowest.
struct Latency {
    bins: Vec<u64>,
    count: u64,
    max: Duration,
}

impl Latency {
    fn new() -> Latency {
        Latency {
            bins: vec![0; LATENCY_BINS + 1],
            count: 0,
            max: Duration::ZERO,
        }
    }

    fn record(&mut self, d: Duration) {
        let us = (d.as_micros() as usize).min(LATENCY_BINS);
        self.bins[us] += 1;
        self.count += 1;
        self.max = self.max.max(d);
    }

    /// The `q` quantile, ms (the upper edge of its bin).
    fn quantile_ms(&self, q: f64) -> Option<f64> {
        if self.count == 0 {
            return None;
        }
        let want = ((q * self.count as f64).ceil() as u64).clamp(1, self.count);
        let mut seen = 0;
        for (us, c) in self.bins.iter().enumerate() {
            seen += c;
            if seen >= want {
                return Some((us + 1) as f64 / 1000.0);
            }
        }
        Some(self.max.as_secs_f64() * 1e3)
    }
}

/// The process's peak resident memory, KiB (`VmHWM` of /proc/self/status; `None` elsewhere).
fn peak_rss_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The summary line on stderr.
fn summary(frames: u64, lat: &Latency) {
    let doc = serde_json::json!({
        "frames": frames,
        "latency_ms": {
            "median": lat.quantile_ms(0.5),
            "p99": lat.quantile_ms(0.99),
            "max": (lat.count > 0).then_some(lat.max.as_secs_f64() * 1e3),
        },
        "peak_rss_kib": peak_rss_kib(),
    });
    eprintln!("{doc}");
}

/// The most bytes read to tell a CSI format from a frame stream by their first bytes.
const SNIFF_BYTES: usize = 1 << 20;

/// What `--cir` holds: a frame stream, or a CSI format read as a stream (the core's
/// [`CsiStream`]: its records cut as they arrive, each frame converted as `cir track` converts
/// the whole file).
enum Input {
    Frames {
        header: FrameHeader,
        payload: Vec<u8>,
    },
    Csi {
        stream: Box<CsiStream>,
        /// Frames converted, not yet tracked, with when their last byte was read.
        ready: VecDeque<(CsiFrame, Instant)>,
        ended: bool,
    },
}

impl Input {
    /// The input of `--format` (`None`/`auto`: a frame stream when the first byte is `{` or
    /// white space, else the CSI format of the first bytes, else a frame stream whose header
    /// the core refuses: only a header that is not JSON reaches that, so no byte of a frame is
    /// lost to the sniffing).
    fn open(
        src: &mut Source,
        format: Option<&str>,
        options: &CsiArgs,
    ) -> Result<Input, FrameError> {
        let csi = |format: CsiFormat, first: &[u8]| -> Result<Input, FrameError> {
            let opts = super::cir_convert::options(options).map_err(FrameError::Cli)?;
            let stream = CsiStream::new(format, opts.convert).map_err(FrameError::Core)?;
            let mut input = Input::Csi {
                stream: Box::new(stream),
                ready: VecDeque::new(),
                ended: false,
            };
            if !first.is_empty() {
                input.feed(first, Instant::now())?;
            }
            Ok(input)
        };
        let frames = |src: &mut Source, first: Vec<u8>| -> Result<Input, FrameError> {
            let line = src.header(first).map_err(FrameError::Core)?;
            let header = FrameHeader::from_json(&line).map_err(FrameError::Core)?;
            let payload = vec![0u8; header.payload_len()];
            Ok(Input::Frames { header, payload })
        };
        match format.unwrap_or("auto") {
            "auto" => {}
            "npz" => {
                return Err(FrameError::Cli(at_flag(
                    "format",
                    "npz with --follow: a .npz is read whole (cir stream REC.npz | cir track \
                     --follow streams it)",
                )))
            }
            name => return csi(CsiFormat::parse(name).map_err(FrameError::Core)?, &[]),
        }
        let mut first: Vec<u8> = Vec::new();
        let mut buf = vec![0u8; CHUNK];
        // Bounded by SNIFF_BYTES (each turn reads ≥ 1 byte) and the input's end.
        while first.len() < SNIFF_BYTES {
            if matches!(first.first(), Some(b) if *b == b'{' || b.is_ascii_whitespace()) {
                return frames(src, first);
            }
            if let Some(f) = detect(&first) {
                return csi(f, &first);
            }
            // The first byte alone: a frame stream's bytes after it are its header's.
            let want = if first.is_empty() { 1 } else { CHUNK };
            let n = src.some(&mut buf[..want]).map_err(FrameError::Cli)?;
            if n == 0 {
                break;
            }
            first.extend_from_slice(&buf[..n]);
        }
        frames(src, first)
    }

    /// The frames' header (a CSI stream's: fixed by its first frame).
    fn header(&self) -> Option<&FrameHeader> {
        match self {
            Input::Frames { header, .. } => Some(header),
            Input::Csi { stream, .. } => stream.header(),
        }
    }

    /// CSI bytes read at `at` (empty: the input's end) into the stream.
    fn feed(&mut self, bytes: &[u8], at: Instant) -> Result<(), FrameError> {
        if let Input::Csi {
            stream,
            ready,
            ended,
        } = self
        {
            let mut out = Vec::new();
            if bytes.is_empty() {
                *ended = true;
                stream.end(&mut out)
            } else {
                stream.push(bytes, &mut out)
            }
            .map_err(FrameError::Core)?;
            ready.extend(out.into_iter().map(|f| (f, at)));
        }
        Ok(())
    }

    /// The next frame `k` (its samples into `samples`): its time and when its last byte was
    /// read; `None` at the end.
    fn next(
        &mut self,
        src: &mut Source,
        k: u64,
        samples: &mut Vec<Complex>,
    ) -> Result<Option<(f64, Instant)>, FrameError> {
        let mut buf = Vec::new();
        // Bounded by the input: each turn reads ≥ 1 byte or ends it.
        loop {
            match self {
                Input::Frames { header, payload } => {
                    return next_frame(src, header, k, payload, samples)
                }
                Input::Csi { ready, ended, .. } => {
                    if let Some((f, at)) = ready.pop_front() {
                        *samples = f.samples;
                        return Ok(Some((f.t_s, at)));
                    }
                    if *ended {
                        return Ok(None);
                    }
                }
            }
            buf.resize(CHUNK, 0);
            let n = src.some(&mut buf).map_err(FrameError::Cli)?;
            self.feed(&buf[..n], Instant::now())?;
        }
    }
}

/// `scatterloc cir track --follow --scenario S [--cir FRAMES|-] [--calibration CAL.npz]
/// [tracker and front-end flags]`.
pub fn cir_track_follow(args: &CirTrackArgs) -> Result<(), CliError> {
    catch_ctrl_c();
    let path = args.cir.as_deref().unwrap_or("-");
    one_stdin(&[
        ("scenario", Some(&args.scenario)),
        ("cir", Some(path)),
        ("calibration", args.calibration.as_deref()),
    ])?;
    let req = request(&args.front_end, Some(args))?;
    let scenario = read_scenario(&args.scenario)?;
    let model = model_of(&scenario)?;
    let empty = match args.calibration.as_deref() {
        Some(p) => Some(read_recording(
            "calibration",
            p,
            &model,
            &args.front_end.csi,
        )?),
        None => None,
    };
    let mut out = crate::stdout::result_stream()?;
    let mut src = Source::open(path)?;
    let bad = |e: Error| in_file("cir", path, e);
    let frame_err = |e: FrameError| match e {
        FrameError::Core(e) => bad(e),
        FrameError::Cli(e) => e,
    };
    let csi_args = &args.front_end.csi;
    let mut input =
        Input::open(&mut src, csi_args.format.as_deref(), csi_args).map_err(frame_err)?;
    let mut samples = Vec::new();
    let mut lat = Latency::new();
    let Some(first) = input.next(&mut src, 0, &mut samples).map_err(frame_err)? else {
        summary(0, &lat);
        return Ok(());
    };
    // A CSI stream's header is known from its first frame on.
    let Some(header) = input.header().cloned() else {
        return Err(bad(Error::InvalidFile {
            field: "frames[0]".into(),
            reason: "no header".into(),
        }));
    };
    let cfg = req.front_end(header.synchronized);
    let (statics, front) = LiveFront::new(
        &model,
        scenario.radio.bandwidth_hz,
        &header,
        first.0,
        &samples,
        empty.as_ref(),
        &cfg,
    )
    .map_err(|e| match e.field() {
        Some(f) if f.starts_with("calibration") => flag_error(&e),
        _ => bad(e),
    })?;
    let mut run = LiveRun::new(&req, &model, &scenario.area_m, &statics, front)
        .map_err(|e| flag_error(&e))?;
    let mut pending = Some(first);
    let mut k: u64 = 0;
    // One turn per frame, until the end marker, standard input's end, an error or Ctrl-C.
    let result = loop {
        let frame = match pending.take() {
            Some(f) => Some(f),
            None => match input.next(&mut src, k, &mut samples) {
                Ok(f) => f,
                Err(e) => break Err(frame_err(e)),
            },
        };
        let Some((t, read_at)) = frame else {
            break Ok(());
        };
        let state = match run.push(t, &samples) {
            Ok(s) => s,
            Err(e) if e.field().is_some_and(|f| f.starts_with("frames[")) => break Err(bad(e)),
            Err(e) => {
                break Err(bad(Error::InvalidFile {
                    field: format!("frames[{k}]"),
                    reason: e.to_string(),
                }))
            }
        };
        // The core's one serialisation of a frame's state (the page's Replay shows the same).
        let mut line = match state.to_json() {
            Ok(l) => l,
            Err(e) => break Err(CliError::output(format!("encoding JSON: {e}"))),
        };
        line.push('\n');
        if let Err(e) = out.write_all(line.as_bytes()) {
            break Err(CliError::output(format!("stdout: {e}")));
        }
        lat.record(read_at.elapsed());
        k += 1;
        if interrupted() {
            break Err(stopped());
        }
    };
    // The summary only after a clean end: an error's one stderr line stays the only one.
    if result.is_ok() {
        summary(k, &lat);
    }
    result
}

/// `scatterloc cir stream REC.npz [--repeat N] [--no-end]`: the recording as a frame stream
/// on stdout.
pub fn cir_stream(args: &CirStreamArgs) -> Result<(), CliError> {
    let path = args.input.as_str();
    let bytes = read_bytes("cir", path, MAX_RECORDING_BYTES)?;
    let rec = scatterloc::npz::read_recording(&bytes).map_err(|e| in_file("cir", path, e))?;
    let header = FrameHeader::of_recording(&rec).map_err(|e| in_file("cir", path, e))?;
    let repeat = args.repeat.unwrap_or(1);
    if repeat == 0 {
        return Err(at_flag("repeat", "0 copies: at least 1"));
    }
    let s = rec.t_s.len();
    let span = rec.t_s[s - 1] - rec.t_s[0];
    let step = if s > 1 { span / (s - 1) as f64 } else { 1.0 };
    let per = rec.links.len() * rec.samples_per_link();
    let mut out = std::io::BufWriter::with_capacity(CHUNK, crate::stdout::result_stream()?);
    let fail = |e: std::io::Error| CliError::output(format!("stdout: {e}"));
    out.write_all(&header.encode().map_err(|e| in_file("cir", path, e))?)
        .map_err(fail)?;
    for r in 0..repeat {
        let shift = r as f64 * (span + step);
        for k in 0..s {
            let frame = encode_frame(rec.t_s[k] + shift, &rec.samples[k * per..(k + 1) * per]);
            out.write_all(&frame).map_err(fail)?;
        }
    }
    if !args.no_end {
        out.write_all(&END_MARKER).map_err(fail)?;
    }
    out.flush().map_err(fail)
}
