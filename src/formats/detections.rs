//! The detections file (issue 40 §3, docs/detections.md): JSON lines, one object per frame and
//! per link, what passive-radar and ISAC tools write and `cir estimate --detections-out`
//! writes, read by `track --detections`:
//!
//! ```text
//! {"timestamp": t, "tx": k, "rx": l, "unit": "s", "delay": [d1, ..], "snr": [dB, ..],
//!  "sigma": [.., same unit], "doppler": [Hz, ..]}
//! ```
//!
//! (`"link": [k, l]` instead of `tx`/`rx`; `unit` `"s"` (delay, the default) or `"m"`
//! (bistatic range, delay = range / c, E1); `snr`, `sigma` and `doppler` optional, each as
//! long as `delay`, an `snr` or `sigma` entry may be `null` = unknown). A frame is the run of
//! lines with one timestamp, frames strictly increasing in time; blank lines and lines
//! starting with `#` are skipped. Every error is an [`Error::InvalidFile`] whose field starts
//! with the line number (`line 12: delay[3]: not a finite number`); the caps are
//! [`limits::MAX_DETECTION_LINE_BYTES`], [`limits::MAX_DETECTION_LINES`] and
//! [`limits::MAX_DETECTIONS_PER_LINE`].
//!
//! [`Detections::to_measurements`] turns the frames into the tracker's raw form (a
//! [`Measurements`] with `initial_snapshot` = the first frame and `raw_steps` = the others, the
//! frames uniform in time within [`limits::FRAME_UNIFORM_TOL`]): per detection
//! `[delay_s, amplitude, σ_s]` with amplitude `10^(snr/20)` (1 when the SNR is unknown; only
//! compared within a link) and σ the given one, else the E8/C4 bound `1/√(8π²β²·SNR)` at the
//! given SNR over the scenario's band (`β² = B²/12`), else none: the tracker's link budget at
//! the prediction (E8). Doppler is carried, not used by the tracker.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use super::measurements::{Measurements, RawEstimate, RawStep};
use crate::channel::TrackedPath;
use crate::error::{limits, Clip, Error, Num, Result};
use crate::math::{db_to_linear, linear_to_db, sqrt, Real, SPEED_OF_LIGHT};
use crate::measure::{sigma_delay_from_snr, Model};
use crate::scenario::LinkIndex;
use crate::track::{ConstantVelocity, MAX_STEPS};

/// The unit of a detection line's `delay` and `sigma`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
pub enum DelayUnit {
    /// Delay, s (the default).
    #[default]
    #[serde(rename = "s")]
    Seconds,
    /// Bistatic range `c·τ`, m (E1).
    #[serde(rename = "m")]
    Metres,
}

impl DelayUnit {
    /// A value of this unit in seconds (a range divided by c).
    pub fn to_seconds(self, v: Real) -> Real {
        match self {
            DelayUnit::Seconds => v,
            DelayUnit::Metres => v / SPEED_OF_LIGHT,
        }
    }

    /// `s` or `m`.
    pub fn name(self) -> &'static str {
        match self {
            DelayUnit::Seconds => "s",
            DelayUnit::Metres => "m",
        }
    }
}

/// One line of a detections file: one link's detections in one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectionLine {
    /// The line's number in the text, 1-based (0 for a line not read from a text).
    pub line: usize,
    /// The frame's time, s.
    pub timestamp_s: Real,
    /// The link: transmitter `k` and receiver `l` (indices into the scenario).
    pub link: LinkIndex,
    /// The unit of `delay` and `sigma`.
    pub unit: DelayUnit,
    /// The detections: delays (s) or bistatic ranges (m), possibly none.
    pub delay: Vec<Real>,
    /// Their SNR, dB (`None` entry: unknown; `None`: none given).
    pub snr_db: Option<Vec<Option<Real>>>,
    /// Their standard deviation in `unit` (`None` entry: unknown; `None`: none given).
    pub sigma: Option<Vec<Option<Real>>>,
    /// Their Doppler shift, Hz (carried through; the tracker does not use it yet).
    pub doppler_hz: Option<Vec<Real>>,
}

/// One frame: the lines of one timestamp, in file order, at most one per link.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectionFrame {
    /// The frame's time, s.
    pub timestamp_s: Real,
    /// Its lines.
    pub lines: Vec<DetectionLine>,
}

/// A detections file: its frames, strictly increasing in time.
///
/// # Example
///
/// ```
/// use scatterloc::formats::{Detections, RawEstimate};
/// use scatterloc::scenario::presets;
/// use scatterloc::Model;
///
/// let text = "# two frames of the L4 layout\n\
///     {\"timestamp\": 0.0, \"tx\": 0, \"rx\": 1, \"delay\": [5e-8], \"sigma\": [1e-10]}\n\
///     {\"timestamp\": 0.1, \"link\": [0, 1], \"unit\": \"m\", \"delay\": [15.0]}\n";
/// let d = Detections::from_text(text).unwrap();
/// assert_eq!(d.frames.len(), 2);
/// let model = Model::new(&presets::sensors2019()).unwrap();
/// let m = d.to_measurements(&model, 1.0).unwrap();
/// assert_eq!(m.dt_s, 0.1);
/// let first = m.initial_snapshot.unwrap();
/// assert_eq!(first[1], vec![RawEstimate::WithSigma([5e-8, 1.0, 1e-10])]);
/// // A bad line is named with its line and field.
/// let e = Detections::from_text("\n{\"timestamp\": 0, \"tx\": 0, \"rx\": 0, \"delay\": [0]}")
///     .unwrap_err();
/// assert_eq!(e.to_string(), "line 2: delay[0]: 0 s is out of range (0 < delay <= 1 s)");
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Detections {
    /// The frames.
    pub frames: Vec<DetectionFrame>,
}

/// A line as JSON (what serde checks: the keys, the types).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LineJson {
    timestamp: f64,
    #[serde(default)]
    tx: Option<usize>,
    #[serde(default)]
    rx: Option<usize>,
    #[serde(default)]
    link: Option<[usize; 2]>,
    #[serde(default)]
    unit: DelayUnit,
    delay: Vec<f64>,
    #[serde(default)]
    snr: Option<Vec<Option<f64>>>,
    #[serde(default)]
    sigma: Option<Vec<Option<f64>>>,
    #[serde(default)]
    doppler: Option<Vec<f64>>,
}

/// A line as the writer writes it (keys in the documented order, absent options left out).
#[derive(Serialize)]
struct LineOut<'a> {
    timestamp: f64,
    tx: usize,
    rx: usize,
    unit: DelayUnit,
    delay: &'a [f64],
    #[serde(skip_serializing_if = "Option::is_none")]
    snr: Option<&'a [Option<f64>]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    sigma: Option<&'a [Option<f64>]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    doppler: Option<&'a [f64]>,
}

/// The error of `field` on line `line`: `line 12: delay[3]: reason`.
fn at(line: usize, field: &str, reason: impl Into<String>) -> Error {
    Error::InvalidFile {
        field: if field.is_empty() {
            format!("line {line}")
        } else {
            format!("line {line}: {field}")
        },
        reason: reason.into(),
    }
}

/// The error of `field` of frame `k`: on its first line when read from a text, else `frame k`.
fn at_frame(f: &DetectionFrame, k: usize, field: &str, reason: String) -> Error {
    match f.lines.first() {
        Some(l) if l.line > 0 => at(l.line, field, reason),
        _ => Error::InvalidFile {
            field: format!("frame {k}: {field}"),
            reason,
        },
    }
}

/// serde_json's message without its position (a line is one line: the column is given).
fn json_message(e: &serde_json::Error) -> String {
    let text = e.to_string();
    match text.rfind(" at line ") {
        Some(i) => format!("{} (column {})", Clip(&text[..i]), e.column()),
        None => format!("{}", Clip(&text)),
    }
}

/// Parses one (non-blank, non-comment) line `n`.
fn parse_line(n: usize, text: &str) -> Result<DetectionLine> {
    let mut de = serde_json::Deserializer::from_str(text);
    let raw: LineJson = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        // serde_path_to_error's `.` (the top) and `?` (before any key): no field yet.
        let path = if path == "." || path == "?" {
            String::new()
        } else {
            path
        };
        at(n, &path, json_message(e.inner()))
    })?;
    de.end().map_err(|e| at(n, "", json_message(&e)))?;
    let link = match (raw.tx, raw.rx, raw.link) {
        (Some(tx), Some(rx), None) => LinkIndex { tx, rx },
        (None, None, Some([tx, rx])) => LinkIndex { tx, rx },
        _ => {
            return Err(at(
                n,
                "link",
                "give \"tx\" and \"rx\", or \"link\": [tx, rx] (not both)",
            ))
        }
    };
    let line = DetectionLine {
        line: n,
        timestamp_s: raw.timestamp,
        link,
        unit: raw.unit,
        delay: raw.delay,
        snr_db: raw.snr,
        sigma: raw.sigma,
        doppler_hz: raw.doppler,
    };
    line.check()?;
    Ok(line)
}

/// `Err` naming `line: field` unless `len` equals the number of delays `k`.
fn same_length(line: usize, field: &str, len: usize, k: usize) -> Result<()> {
    if len == k {
        Ok(())
    } else {
        Err(at(
            line,
            field,
            format!("{len} values, expected {k} (one per delay)"),
        ))
    }
}

impl DetectionLine {
    /// Checks what serde cannot: a finite timestamp; at most
    /// [`limits::MAX_DETECTIONS_PER_LINE`] detections; every delay finite and in
    /// [`limits::DELAY_S`] once in seconds; `snr`, `sigma` and `doppler` as long as `delay`,
    /// each SNR in [`limits::DETECTION_SNR_DB`], each σ finite and `> 0`, each Doppler finite.
    /// Errors name the line and the field (`line 12: delay[3]: not a finite number`).
    pub fn check(&self) -> Result<()> {
        let n = self.line;
        if !self.timestamp_s.is_finite() {
            return Err(at(n, "timestamp", "not a finite number"));
        }
        let k = self.delay.len();
        if k > limits::MAX_DETECTIONS_PER_LINE {
            return Err(at(
                n,
                "delay",
                format!(
                    "{k} detections, at most {} are allowed per line",
                    limits::MAX_DETECTIONS_PER_LINE
                ),
            ));
        }
        let unit = self.unit.name();
        for (i, &d) in self.delay.iter().enumerate() {
            if !d.is_finite() {
                return Err(at(n, &format!("delay[{i}]"), "not a finite number"));
            }
            if !limits::DELAY_S.contains(self.unit.to_seconds(d)) {
                return Err(at(
                    n,
                    &format!("delay[{i}]"),
                    format!(
                        "{} {unit} is out of range ({}{})",
                        Num(d),
                        limits::DELAY_S.allowed,
                        if unit == "m" {
                            " once divided by c"
                        } else {
                            ""
                        }
                    ),
                ));
            }
        }
        if let Some(snr) = &self.snr_db {
            same_length(n, "snr", snr.len(), k)?;
            for (i, s) in snr.iter().enumerate() {
                if let Some(s) = *s {
                    limits::DETECTION_SNR_DB
                        .check("", s)
                        .map_err(|e| at(n, &format!("snr[{i}]"), reason_of(&e)))?;
                }
            }
        }
        if let Some(sigma) = &self.sigma {
            same_length(n, "sigma", sigma.len(), k)?;
            for (i, s) in sigma.iter().enumerate() {
                match *s {
                    Some(s) if !s.is_finite() => {
                        return Err(at(n, &format!("sigma[{i}]"), "not a finite number"))
                    }
                    Some(s) if self.unit.to_seconds(s) <= 0.0 => {
                        return Err(at(
                            n,
                            &format!("sigma[{i}]"),
                            format!("must be > 0 (got {} {unit})", Num(s)),
                        ))
                    }
                    _ => {}
                }
            }
        }
        if let Some(doppler) = &self.doppler_hz {
            same_length(n, "doppler", doppler.len(), k)?;
            if let Some(i) = doppler.iter().position(|d| !d.is_finite()) {
                return Err(at(n, &format!("doppler[{i}]"), "not a finite number"));
            }
        }
        Ok(())
    }

    /// Detection `i` as the tracker's raw estimate `[delay_s, amplitude, σ_s]` (module docs:
    /// amplitude `10^(snr/20)`, 1 when unknown; σ given, else from the SNR by E8/C4 with
    /// `beta2` = β², Hz², else none: the link budget at the prediction).
    pub fn estimate(&self, i: usize, beta2: Real) -> RawEstimate {
        let delay_s = self.unit.to_seconds(self.delay[i]);
        let snr_db = self.snr_db.as_ref().and_then(|s| s[i]);
        let amplitude = snr_db.map_or(1.0, |s| sqrt(db_to_linear(s)));
        let sigma_s = match (self.sigma.as_ref().and_then(|s| s[i]), snr_db) {
            (Some(s), _) => Some(self.unit.to_seconds(s)),
            (None, Some(snr)) => Some(sigma_delay_from_snr(beta2, db_to_linear(snr))),
            (None, None) => None,
        };
        match sigma_s {
            Some(s) => RawEstimate::WithSigma([delay_s, amplitude, s]),
            None => RawEstimate::Pair([delay_s, amplitude]),
        }
    }
}

/// The reason of a core error (its text after the field).
fn reason_of(e: &Error) -> String {
    let text = e.to_string();
    text.strip_prefix(": ")
        .map_or(text.clone(), ToString::to_string)
}

impl Detections {
    /// Parses a detections file (module docs): the frames in time order. Errors name the line
    /// and the field: bad JSON, a missing or unknown key, a wrong type, a bad value
    /// ([`DetectionLine::check`]), a timestamp before the previous frame's, a link twice in a
    /// frame, a line longer than [`limits::MAX_DETECTION_LINE_BYTES`] or more lines than
    /// [`limits::MAX_DETECTION_LINES`].
    pub fn from_text(text: &str) -> Result<Detections> {
        let mut frames: Vec<DetectionFrame> = Vec::new();
        // Each pass reads one line; the count is capped.
        for (i, raw) in text.lines().enumerate() {
            let n = i + 1;
            if n > limits::MAX_DETECTION_LINES {
                return Err(at(
                    n,
                    "",
                    format!(
                        "more than {} lines are not allowed",
                        limits::MAX_DETECTION_LINES
                    ),
                ));
            }
            if raw.len() > limits::MAX_DETECTION_LINE_BYTES {
                return Err(at(
                    n,
                    "",
                    format!(
                        "{} bytes, a line may have at most {}",
                        raw.len(),
                        limits::MAX_DETECTION_LINE_BYTES
                    ),
                ));
            }
            let t = raw.trim();
            if t.is_empty() || t.starts_with('#') {
                continue;
            }
            let line = parse_line(n, t)?;
            match frames.last_mut() {
                Some(f) if f.timestamp_s == line.timestamp_s => {
                    if let Some(first) = f.lines.iter().find(|l| l.link == line.link) {
                        return Err(at(
                            n,
                            "link",
                            format!(
                                "[{}, {}] appears twice in the frame at {} s (first on line {})",
                                line.link.tx,
                                line.link.rx,
                                Num(line.timestamp_s),
                                first.line
                            ),
                        ));
                    }
                    f.lines.push(line);
                }
                Some(f) if line.timestamp_s < f.timestamp_s => {
                    return Err(at(
                        n,
                        "timestamp",
                        format!(
                            "{} s is before the previous frame's {} s (frames must come in \
                             increasing time; a frame's lines are consecutive)",
                            Num(line.timestamp_s),
                            Num(f.timestamp_s)
                        ),
                    ))
                }
                _ => frames.push(DetectionFrame {
                    timestamp_s: line.timestamp_s,
                    lines: vec![line],
                }),
            }
        }
        Ok(Detections { frames })
    }

    /// The file's text: one line per frame and link, in frame order, each ending in `\n`
    /// (numbers in their shortest round-trip form, so [`Detections::from_text`] gives the same
    /// bits; a non-finite SNR or σ is written as `null`, unknown).
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        for f in &self.frames {
            for l in &f.lines {
                let o = LineOut {
                    timestamp: f.timestamp_s,
                    tx: l.link.tx,
                    rx: l.link.rx,
                    unit: l.unit,
                    delay: &l.delay,
                    snr: l.snr_db.as_deref(),
                    sigma: l.sigma.as_deref(),
                    doppler: l.doppler_hz.as_deref(),
                };
                // Plain numbers, strings and lists: serialising cannot fail.
                out.push_str(&serde_json::to_string(&o).unwrap_or_default());
                out.push('\n');
            }
        }
        out
    }

    /// The detections of the channel front end's estimates (`cir estimate --detections-out`):
    /// per snapshot `s` (time `t_s[s]`) one line per recorded link `p` (`links[p]`,
    /// `recorded[p]`) with every path of `paths[s][p]` (confirmed or not, as
    /// `Measurements::raw_step` takes them): delay (s), SNR `10·log10` of the fitted
    /// integrated SNR (C3; `null` when not > 0), σ̂_τ (s; `null` when not finite and > 0), and
    /// the Doppler `f̂_D` (Hz) when the front end read one for every path of the line (a CPI).
    pub fn from_paths(
        links: &[LinkIndex],
        t_s: &[Real],
        recorded: &[bool],
        paths: &[Vec<Vec<TrackedPath>>],
    ) -> Detections {
        let frames = t_s
            .iter()
            .zip(paths)
            .map(|(&t, snap)| DetectionFrame {
                timestamp_s: t,
                lines: links
                    .iter()
                    .zip(recorded)
                    .zip(snap)
                    .filter(|((_, &r), _)| r)
                    .map(|((&link, _), list)| DetectionLine {
                        line: 0,
                        timestamp_s: t,
                        link,
                        unit: DelayUnit::Seconds,
                        delay: list.iter().map(|p| p.estimate.delay_s).collect(),
                        snr_db: Some(
                            list.iter()
                                .map(|p| {
                                    let s = p.estimate.snr;
                                    (s.is_finite() && s > 0.0).then(|| linear_to_db(s))
                                })
                                .collect(),
                        ),
                        sigma: Some(
                            list.iter()
                                .map(|p| {
                                    let s = p.estimate.sigma_s;
                                    (s.is_finite() && s > 0.0).then_some(s)
                                })
                                .collect(),
                        ),
                        // The CPI's Doppler (issue 42 §2) when every path of the line has one.
                        doppler_hz: list
                            .iter()
                            .map(|p| p.estimate.range_rate.map(|r| r.doppler_hz))
                            .collect::<Option<Vec<Real>>>()
                            .filter(|d| !d.is_empty()),
                    })
                    .collect(),
            })
            .collect();
        Detections { frames }
    }

    /// The frames as the tracker's raw measurements (module docs) on `model`'s links with
    /// process-noise intensity `process_noise`: `initial_snapshot` the first frame, `raw_steps`
    /// the others (a link of the scenario absent from a frame: no detection there), `dt_s` the
    /// mean frame spacing. Errors: fewer than 2 frames or more than [`MAX_STEPS`] + 1, frames
    /// not uniform within [`limits::FRAME_UNIFORM_TOL`] (naming the frame's first line), a link
    /// not in the scenario (naming the line), a bad spacing or `process_noise` (E7's checks).
    pub fn to_measurements(&self, model: &Model, process_noise: Real) -> Result<Measurements> {
        let frames = &self.frames;
        let count = frames.len();
        if count < 2 {
            return Err(Error::InvalidFile {
                field: "detections".into(),
                reason: format!(
                    "{count} frame(s); at least 2 are needed (the first starts the track)"
                ),
            });
        }
        if count > MAX_STEPS + 1 {
            return Err(Error::InvalidFile {
                field: "detections".into(),
                reason: format!("{count} frames, at most {} are allowed", MAX_STEPS + 1),
            });
        }
        let t0 = frames[0].timestamp_s;
        let dt = (frames[count - 1].timestamp_s - t0) / (count - 1) as Real;
        for k in 1..count {
            let gap = frames[k].timestamp_s - frames[k - 1].timestamp_s;
            if (gap - dt).abs() > limits::FRAME_UNIFORM_TOL * dt {
                return Err(at_frame(
                    &frames[k],
                    k,
                    "timestamp",
                    format!(
                        "frame {k} comes {} s after the previous one, the mean spacing is {} s: \
                         frames must be uniform in time within {} relative (the tracker has \
                         one step dt_s)",
                        Num(gap),
                        Num(dt),
                        Num(limits::FRAME_UNIFORM_TOL)
                    ),
                ));
            }
        }
        ConstantVelocity::validated(dt, process_noise).map_err(|e| match e.field() {
            Some("dt_s") => Error::InvalidFile {
                field: "timestamp".into(),
                reason: format!("the frames' mean spacing: {}", reason_of(&e)),
            },
            _ => e,
        })?;
        let links = &model.network.links;
        let mut steps = frames
            .iter()
            .map(|f| frame_step(f, links, model.beta2))
            .collect::<Result<Vec<RawStep>>>()?;
        let first = steps.remove(0);
        Ok(Measurements {
            dt_s: dt,
            process_noise,
            initial_state: None,
            initial_covariance: None,
            initial_snapshot: Some(first),
            sigma_s: None,
            steps: None,
            raw_steps: Some(steps),
        })
    }
}

/// One frame as a raw step: one list per scenario link (empty where the frame has no line).
fn frame_step(f: &DetectionFrame, links: &[LinkIndex], beta2: Real) -> Result<RawStep> {
    let mut step: RawStep = vec![Vec::new(); links.len()];
    for l in &f.lines {
        let p = links.iter().position(|&x| x == l.link).ok_or_else(|| {
            at(
                l.line,
                "link",
                format!(
                    "[{}, {}] (tx, rx) is not a link of the scenario ({} links: {})",
                    l.link.tx,
                    l.link.rx,
                    links.len(),
                    link_list(links)
                ),
            )
        })?;
        step[p] = (0..l.delay.len()).map(|i| l.estimate(i, beta2)).collect();
    }
    Ok(step)
}

/// `[0, 0], [0, 1], …` (the first 8, then `…`).
fn link_list(links: &[LinkIndex]) -> String {
    let mut s: Vec<String> = links
        .iter()
        .take(8)
        .map(|l| format!("[{}, {}]", l.tx, l.rx))
        .collect();
    if links.len() > 8 {
        s.push("…".into());
    }
    s.join(", ")
}
