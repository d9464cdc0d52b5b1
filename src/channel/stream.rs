//! The frame stream of `scatterloc cir track --follow` (docs/recording.md, "Streaming frames"):
//! a recording that arrives snapshot by snapshot. One line of JSON, the [`FrameHeader`] (the
//! recording's links, its CFR bins `freq_hz` (C1), the optional system response, per-link noise
//! variances and `synchronized` flag), ended by `\n`; then frames, each a `u32` little-endian
//! payload length `L` followed by `L` bytes: the snapshot time (`f64` LE, s) and the `P·N`
//! complex samples of the snapshot as `f32` LE pairs (re, im), link-major (link 0's `N` bins,
//! then link 1's, …). `L` must be `8 + 8·P·N` ([`FrameHeader::payload_len`]); `L = 0` is the
//! clean end of the stream ([`END_MARKER`]).
//!
//! The core parses and checks (no I/O): [`FrameHeader::from_json`] (format, version, the
//! `.npz` reader's caps and checks through [`Recording::validate`]), [`FrameHeader::check_length`]
//! (before anything is allocated: a huge length is refused at once), [`FrameHeader::parse_frame`]
//! (finite time, finite samples of magnitude at most [`MAX_SAMPLE_MAGNITUDE`]); every error names
//! the frame (`frames[k]`). [`FrameHeader::of_recording`], [`FrameHeader::encode`] and
//! [`encode_frame`] write a stream (`scatterloc cir stream`, the tests).

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::channel::{Layout, Recording};
use crate::error::limits::{
    MAX_BINS_PER_LINK, MAX_LINKS, MAX_RECORDING_SAMPLES, MAX_SAMPLE_MAGNITUDE,
    MAX_STREAM_HEADER_BYTES,
};
use crate::error::{Error, Result};
use crate::math::{Complex, Real};

/// The header's `format`.
pub const STREAM_FORMAT: &str = "scatterloc-frames";
/// The header's `version`.
pub const STREAM_VERSION: u32 = 1;
/// The length field that ends a stream cleanly (a frame of length 0).
pub const END_MARKER: [u8; 4] = [0; 4];
/// Bytes of a frame's length field.
pub const LENGTH_BYTES: usize = 4;

/// The first line of a frame stream (module docs): what every frame holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameHeader {
    /// `scatterloc-frames`.
    pub format: String,
    /// 1.
    pub version: u32,
    /// Per recorded link `[transmitter, receiver]`, 0-based into the scenario.
    pub links: Vec<[usize; 2]>,
    /// The CFR's baseband frequencies, Hz, uniformly spaced (C1).
    pub freq_hz: Vec<Real>,
    /// `P[n]` of C1 as `[re, im]` (absent: 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub system_response: Option<Vec<[Real; 2]>>,
    /// Per recorded link the per-bin noise variance, W (absent: estimated from the data).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_var: Option<Vec<Real>>,
    /// Whether the receivers share the transmitter's clock (C10; `null`: not stated).
    #[serde(default)]
    pub synchronized: Option<bool>,
}

/// The field that names frame `k` in an error.
fn frame_field(k: u64) -> String {
    format!("frames[{k}]")
}

impl FrameHeader {
    /// Parses and checks a header line (the bytes before the first `\n`, at most
    /// [`MAX_STREAM_HEADER_BYTES`]). Errors ([`Error::InvalidFile`] of `header`, or the recording
    /// checks' named field): not UTF-8 or not JSON of this shape, another format or version,
    /// the caps of the `.npz` reader (links ≤ [`MAX_LINKS`], 2 ≤ bins ≤ [`MAX_BINS_PER_LINK`],
    /// `P·N` ≤ [`MAX_RECORDING_SAMPLES`]), bins not finite or not uniform, a system response or
    /// noise variances of the wrong length or not finite.
    pub fn from_json(line: &[u8]) -> Result<FrameHeader> {
        let bad = |reason: String| Error::InvalidFile {
            field: "header".into(),
            reason,
        };
        if line.len() > MAX_STREAM_HEADER_BYTES {
            return Err(Error::SizeLimit {
                field: "header",
                value: line.len(),
                min: 2,
                max: MAX_STREAM_HEADER_BYTES,
            });
        }
        let text = core::str::from_utf8(line).map_err(|e| {
            bad(format!(
                "not UTF-8 text ({e}): a stream starts with a JSON line"
            ))
        })?;
        let h: FrameHeader = serde_json::from_str(text.trim_end_matches(['\r', '\n']))
            .map_err(|e| bad(format!("not a frame-stream header ({e})")))?;
        if h.format != STREAM_FORMAT {
            return Err(bad(format!(
                "format '{}' is not '{STREAM_FORMAT}'",
                crate::error::Clip(&h.format)
            )));
        }
        if h.version != STREAM_VERSION {
            return Err(bad(format!(
                "version {} is not supported (this reader reads {STREAM_VERSION})",
                h.version
            )));
        }
        h.check()?;
        Ok(h)
    }

    /// The caps and the recording's checks ([`Recording::validate`] on one snapshot of zeros).
    fn check(&self) -> Result<()> {
        let size = |field, value, min, max| {
            if (min..=max).contains(&value) {
                Ok(())
            } else {
                Err(Error::SizeLimit {
                    field,
                    value,
                    min,
                    max,
                })
            }
        };
        size("links", self.links.len(), 1, MAX_LINKS)?;
        size("freq_hz", self.freq_hz.len(), 2, MAX_BINS_PER_LINK)?;
        size("cfr", self.samples(), 1, MAX_RECORDING_SAMPLES)?;
        let zeros = alloc::vec![Complex::new(0.0, 0.0); self.samples()];
        self.recording(0.0, zeros).validate()
    }

    /// `P·N`: complex samples per frame.
    pub fn samples(&self) -> usize {
        self.links.len().saturating_mul(self.freq_hz.len())
    }

    /// The payload length `L` of every frame: `8 + 8·P·N` bytes.
    pub fn payload_len(&self) -> usize {
        8 + 8 * self.samples()
    }

    /// Checks frame `k`'s length field `len` before its payload is read: `Ok(None)` for the end
    /// marker (0), `Ok(Some(L))` for a frame; any other length (a truncated writer, another
    /// header, a huge field) is an [`Error::InvalidFile`] naming `frames[k]`.
    pub fn check_length(&self, k: u64, len: u32) -> Result<Option<usize>> {
        if len == 0 {
            return Ok(None);
        }
        let want = self.payload_len();
        if len as usize != want {
            return Err(Error::InvalidFile {
                field: frame_field(k),
                reason: format!(
                    "payload length {len} bytes, expected 8 + 8·P·N = 8 + 8·{}·{} = {want} \
                     (f64 time + P·N complex f32 samples)",
                    self.links.len(),
                    self.freq_hz.len()
                ),
            });
        }
        Ok(Some(want))
    }

    /// Parses frame `k`'s payload (after its length field): its time, and its samples into
    /// `samples` (replaced; link-major). Errors naming `frames[k]`: a payload of another length,
    /// a time that is not finite, a sample not finite or larger than
    /// [`MAX_SAMPLE_MAGNITUDE`] (named `[link, bin]`).
    pub fn parse_frame(&self, k: u64, payload: &[u8], samples: &mut Vec<Complex>) -> Result<Real> {
        let bad = |reason: String| Error::InvalidFile {
            field: frame_field(k),
            reason,
        };
        let want = self.payload_len();
        if payload.len() != want {
            return Err(bad(format!(
                "truncated: {} of its {want} payload bytes",
                payload.len()
            )));
        }
        let (head, body) = payload.split_at(8);
        let mut t = [0u8; 8];
        t.copy_from_slice(head);
        let t_s = f64::from_le_bytes(t);
        if !t_s.is_finite() {
            return Err(bad("its time is not a finite number".into()));
        }
        let n = self.freq_hz.len().max(1);
        samples.clear();
        samples.reserve(self.samples());
        for (i, c) in body.chunks_exact(8).enumerate() {
            let re = f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as Real;
            let im = f32::from_le_bytes([c[4], c[5], c[6], c[7]]) as Real;
            let ok = re.is_finite()
                && im.is_finite()
                && re.abs() <= MAX_SAMPLE_MAGNITUDE
                && im.abs() <= MAX_SAMPLE_MAGNITUDE;
            if !ok {
                return Err(bad(format!(
                    "sample [{}, {}] (link, bin) is not finite",
                    i / n,
                    i % n
                )));
            }
            samples.push(Complex::new(re, im));
        }
        Ok(t_s)
    }

    /// The one-snapshot recording of a frame (time `t_s`, its samples) with this header's
    /// links, bins and flags: what the front end's statics are built from.
    pub fn recording(&self, t_s: Real, samples: Vec<Complex>) -> Recording {
        Recording {
            t_s: alloc::vec![t_s],
            links: self.links.clone(),
            layout: Layout::Cfr {
                freq_hz: self.freq_hz.clone(),
                system_response: self
                    .system_response
                    .as_ref()
                    .map(|p| p.iter().map(|z| Complex::new(z[0], z[1])).collect()),
            },
            samples,
            noise_var: self.noise_var.clone(),
            synchronized: self.synchronized,
        }
    }

    /// The header of `rec`'s frames. Errors: a CIR recording ([`Error::InvalidFile`] of `cir`:
    /// a stream holds CFR frames; its bins are the recording's, `H[n]` of C1).
    pub fn of_recording(rec: &Recording) -> Result<FrameHeader> {
        let Layout::Cfr {
            freq_hz,
            system_response,
        } = &rec.layout
        else {
            return Err(Error::InvalidFile {
                field: "cir".into(),
                reason: "a frame stream holds frequency responses (cfr); this recording holds \
                         impulse responses"
                    .into(),
            });
        };
        Ok(FrameHeader {
            format: STREAM_FORMAT.into(),
            version: STREAM_VERSION,
            links: rec.links.clone(),
            freq_hz: freq_hz.clone(),
            system_response: system_response
                .as_ref()
                .map(|p| p.iter().map(|z| [z.re, z.im]).collect()),
            noise_var: rec.noise_var.clone(),
            synchronized: rec.synchronized,
        })
    }

    /// The header line, `\n` included.
    pub fn encode(&self) -> Result<Vec<u8>> {
        let mut v = serde_json::to_vec(self).map_err(|e| Error::InvalidFile {
            field: "header".into(),
            reason: format!("cannot encode: {e}"),
        })?;
        v.push(b'\n');
        Ok(v)
    }
}

/// One frame (length field and payload) of time `t_s` and samples `samples` (link-major; each
/// part rounded to `f32`).
pub fn encode_frame(t_s: Real, samples: &[Complex]) -> Vec<u8> {
    let len = 8 + 8 * samples.len();
    let mut v = Vec::with_capacity(LENGTH_BYTES + len);
    v.extend_from_slice(&(len as u32).to_le_bytes());
    v.extend_from_slice(&t_s.to_le_bytes());
    for z in samples {
        v.extend_from_slice(&(z.re as f32).to_le_bytes());
        v.extend_from_slice(&(z.im as f32).to_le_bytes());
    }
    v
}

/// `rec` with every sample rounded to `f32` as a stream carries it (so a batch run on it and a
/// live run on its frames read the same numbers).
pub fn rounded_to_f32(rec: &Recording) -> Recording {
    let mut r = rec.clone();
    for z in &mut r.samples {
        *z = Complex::new(z.re as f32 as Real, z.im as f32 as Real);
    }
    r
}

#[cfg(test)]
mod tests;
