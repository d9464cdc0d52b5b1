//! What every CSI reader gives ([`CsiCapture`]) and its conversion to a [`Recording`] (C1 with a
//! mask): the subcarriers a card reports sit on a uniform grid of its subcarrier spacing, from
//! the lowest reported index to the highest; a subcarrier not reported (null, DC, guard, the
//! ones a grouping skips) gets `P[n] = 0` and `H[n] = 0`, so the estimator's periodogram, its
//! noise estimate and the C4 bound (`β_N²` weighted by `|P[n]|²`) use exactly the subcarriers
//! present.

use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use crate::channel::{Layout, Recording};
use crate::error::limits::{MAX_BINS_PER_LINK, MAX_LINKS, MAX_RECORDING_SAMPLES, MAX_SNAPSHOTS};
use crate::error::{Error, Result};
use crate::math::{Complex, Real};

/// The CSI tools whose files scatterloc reads (docs/recording.md, "CSI files").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CsiFormat {
    /// The Linux 802.11n CSI Tool (Intel 5300) `.dat` log.
    Intel5300,
    /// Nexmon CSI in a pcap capture (Broadcom; the 4366c0/4375/43455c0/4358 payloads).
    Nexmon,
    /// PicoScenes `.csi` (its RXS frames; the CSI segment).
    PicoScenes,
    /// FeitCSI `.csi` (Intel AX200/AX210).
    FeitCsi,
    /// The ESP32 CSI tool's CSV lines (`CSI_DATA,…`).
    Esp32,
}

impl CsiFormat {
    /// Every format, in the order of the `--format` flag.
    pub const ALL: [CsiFormat; 5] = [
        CsiFormat::Intel5300,
        CsiFormat::Nexmon,
        CsiFormat::PicoScenes,
        CsiFormat::FeitCsi,
        CsiFormat::Esp32,
    ];

    /// The name of the `--format` flag's value.
    pub fn name(self) -> &'static str {
        match self {
            CsiFormat::Intel5300 => "intel5300",
            CsiFormat::Nexmon => "nexmon",
            CsiFormat::PicoScenes => "picoscenes",
            CsiFormat::FeitCsi => "feitcsi",
            CsiFormat::Esp32 => "esp32",
        }
    }

    /// The format of a `--format` value; [`Error::OutOfRange`]-like [`Error::InvalidFile`]
    /// naming `format` otherwise.
    pub fn parse(name: &str) -> Result<CsiFormat> {
        CsiFormat::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| Error::InvalidFile {
                field: "format".into(),
                reason: format!(
                    "unknown CSI format {name:?}: one of auto, intel5300, nexmon, picoscenes, \
                     feitcsi, esp32"
                ),
            })
    }
}

/// One file of a CSI tool, as its reader found it: per frame the time and per antenna pair the
/// raw complex CSI on the reported subcarriers (the values the tool wrote, unscaled), plus what
/// the format says about the frame (bandwidth, subcarrier map, gain).
#[derive(Debug, Clone, PartialEq)]
pub struct CsiCapture {
    /// The tool.
    pub format: CsiFormat,
    /// The card or chip, e.g. `Intel 5300`, `BCM4366c0`, `Intel AX210`, `ESP32`.
    pub device: String,
    /// The PHY format of the frames: `legacy`, `HT`, `VHT`, `HE-SU`, … .
    pub frame_format: String,
    /// The carrier (centre) frequency, Hz, where the format states it.
    pub center_hz: Option<Real>,
    /// The channel bandwidth, Hz (20, 40, 80 or 160 MHz).
    pub bandwidth_hz: Real,
    /// The subcarrier spacing, Hz (312.5 kHz for legacy/HT/VHT, 78.125 kHz for HE).
    pub spacing_hz: Real,
    /// The reported subcarriers' indices `k` (frequency `k·spacing_hz` from the carrier),
    /// strictly increasing; the same for every frame.
    pub subcarriers: Vec<i32>,
    /// The indices among `subcarriers` that are pilots (kept: the training field covers them).
    pub pilots: Vec<i32>,
    /// Receive antennas (chains).
    pub n_rx: usize,
    /// Transmit antennas (spatial streams measured).
    pub n_tx: usize,
    /// Per frame the time, s, from the device's clock (as written; the conversion drops frames
    /// whose time does not increase, see [`Conversion::dropped`]).
    pub t_s: Vec<Real>,
    /// The CSI, `csi[((f·n_rx + r)·n_tx + t)·K + k]` for frame `f`, receive antenna `r`,
    /// transmit antenna `t`, subcarrier `k` of `subcarriers` — the raw values of the file.
    pub csi: Vec<Complex>,
    /// Per frame the amplitude factor the format reports (RSSI/AGC scaling to √mW-like units;
    /// `None` where the format reports none); applied by [`to_recording`] when asked.
    pub gain: Option<Vec<Real>>,
    /// What the format does not calibrate or correct, in words (e.g. "antenna phase offsets
    /// not calibrated"), for the summary and the docs' format table.
    pub notes: Vec<String>,
    /// Frames the reader skipped (not CSI, or of another antenna/bandwidth configuration),
    /// with the reason: `(frame index in the file, reason)`.
    pub skipped: Vec<(usize, String)>,
}

impl CsiCapture {
    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.t_s.len()
    }

    /// The CSI of frame `f`, receive antenna `r`, transmit antenna `t` (one value per
    /// subcarrier of [`CsiCapture::subcarriers`]).
    pub fn pair(&self, f: usize, r: usize, t: usize) -> &[Complex] {
        let k = self.subcarriers.len();
        let start = ((f * self.n_rx + r) * self.n_tx + t) * k;
        &self.csi[start..start + k]
    }

    /// Checks the promises of the struct (used by every reader before it returns): at least
    /// one frame, antenna and subcarrier, indices strictly increasing, pilots among them, the
    /// CSI length `frames·n_rx·n_tx·K`, finite values and times, spacing and bandwidth > 0,
    /// and the caps of the `.npz` reader ([`MAX_SNAPSHOTS`], [`MAX_LINKS`],
    /// [`MAX_BINS_PER_LINK`], [`MAX_RECORDING_SAMPLES`]).
    pub fn validate(&self) -> Result<()> {
        let bad = |field: &str, reason: String| Error::InvalidFile {
            field: field.into(),
            reason,
        };
        size("frames", self.t_s.len(), 1, MAX_SNAPSHOTS)?;
        size("antenna pairs", self.n_rx * self.n_tx, 1, MAX_LINKS)?;
        size("subcarriers", self.subcarriers.len(), 2, MAX_BINS_PER_LINK)?;
        if self.subcarriers.windows(2).any(|w| w[1] <= w[0]) {
            return Err(bad("subcarriers", "indices not strictly increasing".into()));
        }
        let span = (self.subcarriers[self.subcarriers.len() - 1] as i64
            - self.subcarriers[0] as i64) as usize
            + 1;
        size("subcarrier span", span, 2, MAX_BINS_PER_LINK)?;
        if let Some(p) = self.pilots.iter().find(|p| !self.subcarriers.contains(p)) {
            return Err(bad(
                "pilots",
                format!("pilot {p} is not a reported subcarrier"),
            ));
        }
        let want = self.t_s.len() * self.n_rx * self.n_tx * self.subcarriers.len();
        size("CSI values", want, 1, MAX_RECORDING_SAMPLES)?;
        if self.csi.len() != want {
            return Err(Error::LengthMismatch {
                field: "csi",
                expected: want,
                found: self.csi.len(),
            });
        }
        if let Some(i) = self
            .csi
            .iter()
            .position(|z| !(z.re.is_finite() && z.im.is_finite()))
        {
            let per = self.n_rx * self.n_tx * self.subcarriers.len();
            return Err(Error::NonFinite {
                field: format!("frame {}: csi[{}]", i / per, i % per),
            });
        }
        if let Some(f) = self.t_s.iter().position(|t| !t.is_finite()) {
            return Err(Error::NonFinite {
                field: format!("frame {f}: timestamp"),
            });
        }
        if let Some(g) = &self.gain {
            if g.len() != self.t_s.len() {
                return Err(Error::LengthMismatch {
                    field: "gain",
                    expected: self.t_s.len(),
                    found: g.len(),
                });
            }
            if let Some(f) = g.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(bad(
                    &format!("frame {f}: gain"),
                    "not finite and > 0".into(),
                ));
            }
        }
        for (field, v) in [
            ("spacing_hz", self.spacing_hz),
            ("bandwidth_hz", self.bandwidth_hz),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(field, format!("{v}: must be finite and > 0")));
            }
        }
        Ok(())
    }
}

fn size(field: &'static str, value: usize, min: usize, max: usize) -> Result<()> {
    if value < min || value > max {
        return Err(Error::SizeLimit {
            field,
            value,
            min,
            max,
        });
    }
    Ok(())
}

/// Which antenna pair becomes which link of the scenario: receive antenna `rx`, transmit
/// antenna `tx` → `(transmitter index, receiver index)` of the scenario.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PairLink {
    /// Receive antenna (0-based).
    pub rx: usize,
    /// Transmit antenna (0-based).
    pub tx: usize,
    /// The scenario's `(transmitter, receiver)` indices.
    pub link: [usize; 2],
}

impl PairLink {
    /// Parses `--links`: comma-separated `rxR.txT=A:B` (receive antenna R and transmit antenna
    /// T of the capture are the link from transmitter A to receiver B of the scenario), e.g.
    /// `rx0.tx0=0:0,rx1.tx0=0:1`. Errors name the item.
    pub fn parse_list(text: &str) -> Result<Vec<PairLink>> {
        let mut out = Vec::new();
        for (i, item) in text.split(',').map(str::trim).enumerate() {
            let bad = || Error::InvalidFile {
                field: format!("links[{i}]"),
                reason: format!(
                    "{item:?}: expected rxR.txT=A:B (receive antenna R, transmit antenna T → \
                     transmitter A, receiver B of the scenario), e.g. rx0.tx0=0:1"
                ),
            };
            let (pair, link) = item.split_once('=').ok_or_else(bad)?;
            let (rx, tx) = pair.split_once('.').ok_or_else(bad)?;
            let rx = rx.strip_prefix("rx").ok_or_else(bad)?;
            let tx = tx.strip_prefix("tx").ok_or_else(bad)?;
            let (a, b) = link.split_once(':').ok_or_else(bad)?;
            let num = |s: &str| s.trim().parse::<usize>().map_err(|_| bad());
            let p = PairLink {
                rx: num(rx)?,
                tx: num(tx)?,
                link: [num(a)?, num(b)?],
            };
            if out
                .iter()
                .any(|q: &PairLink| (q.rx, q.tx) == (p.rx, p.tx) || q.link == p.link)
            {
                return Err(Error::InvalidFile {
                    field: format!("links[{i}]"),
                    reason: format!("{item:?}: this antenna pair or link is already mapped"),
                });
            }
            out.push(p);
        }
        Ok(out)
    }

    /// The default map: every pair, receive antenna `r` and transmit antenna `t` → the link
    /// from transmitter `t` to receiver `r`, in the order of [`CsiCapture::pair`].
    pub fn all(n_rx: usize, n_tx: usize) -> Vec<PairLink> {
        (0..n_rx)
            .flat_map(|r| {
                (0..n_tx).map(move |t| PairLink {
                    rx: r,
                    tx: t,
                    link: [t, r],
                })
            })
            .collect()
    }
}

/// How to turn a capture into a recording. The default is the CLI's, the page's and Python's:
/// every antenna pair, the format's gain applied, unoccupied subcarriers left out.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvertOptions {
    /// The antenna pairs to keep and their links (`None`: [`PairLink::all`]).
    pub links: Option<Vec<PairLink>>,
    /// Multiply each frame by the format's reported gain ([`CsiCapture::gain`]), where it has
    /// one.
    pub apply_gain: bool,
    /// Keep every reported subcarrier, also those no frame occupies ([`occupied`]): `false`
    /// (the default) leaves them out.
    pub keep_unoccupied: bool,
}

impl Default for ConvertOptions {
    fn default() -> Self {
        ConvertOptions {
            links: None,
            apply_gain: true,
            keep_unoccupied: false,
        }
    }
}

/// A block of the subcarrier grid is unoccupied when its mean power is this far below the
/// strongest block's, dB.
pub const UNOCCUPIED_BLOCK_DB: Real = 20.0;
/// Within the occupied blocks, a subcarrier is unoccupied when its mean power is this far below
/// their median subcarrier's, dB.
pub const UNOCCUPIED_TONE_DB: Real = 30.0;

/// The reported subcarriers the frames actually occupy (positions into
/// [`CsiCapture::subcarriers`]). A card may report a wider band than the frames it hears use —
/// Nexmon reports its chanspec's 80 MHz for a 20 MHz legacy frame on one of its sub-channels,
/// leaving three quarters of the subcarriers at noise — and noise-only bins fitted as signal
/// spoil the delay estimate. Rule: the mean power of each subcarrier over all frames and antenna
/// pairs; the 20 MHz blocks of the grid (64 subcarriers at 312.5 kHz, 256 at 78.125 kHz, aligned
/// on index 0) whose mean power is more than [`UNOCCUPIED_BLOCK_DB`] below the strongest block
/// are unoccupied, and so is a subcarrier of an occupied block more than [`UNOCCUPIED_TONE_DB`]
/// below the median subcarrier of the occupied blocks (a null or guard tone of the narrower
/// frame). At least two subcarriers are always kept (the strongest ones).
pub fn occupied(cap: &CsiCapture) -> Vec<usize> {
    let k = cap.subcarriers.len();
    let mut power = vec![0.0; k];
    for chunk in cap.csi.chunks_exact(k) {
        for (p, z) in power.iter_mut().zip(chunk) {
            *p += z.norm_sqr();
        }
    }
    let block_len = (20e6 / cap.spacing_hz).round().max(1.0) as i64;
    let block = |i: usize| (cap.subcarriers[i] as i64).div_euclid(block_len);
    let mut blocks: Vec<(i64, Real, usize)> = Vec::new();
    for (i, &p) in power.iter().enumerate() {
        match blocks.iter_mut().find(|b| b.0 == block(i)) {
            Some(b) => {
                b.1 += p;
                b.2 += 1;
            }
            None => blocks.push((block(i), p, 1)),
        }
    }
    let mean = |b: &(i64, Real, usize)| b.1 / b.2 as Real;
    let top = blocks.iter().map(mean).fold(0.0, Real::max);
    let floor = top * crate::math::db_to_linear(-UNOCCUPIED_BLOCK_DB);
    let live: Vec<i64> = blocks
        .iter()
        .filter(|b| mean(b) >= floor && mean(b) > 0.0)
        .map(|b| b.0)
        .collect();
    let in_live: Vec<usize> = (0..k).filter(|&i| live.contains(&block(i))).collect();
    let mut sorted: Vec<Real> = in_live.iter().map(|&i| power[i]).collect();
    sorted.sort_by(Real::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let tone_floor = median * crate::math::db_to_linear(-UNOCCUPIED_TONE_DB);
    let keep: Vec<usize> = in_live
        .into_iter()
        .filter(|&i| power[i] >= tone_floor && power[i] > 0.0)
        .collect();
    if keep.len() >= 2 {
        return keep;
    }
    // Degenerate (all zero, or one strong tone): the two strongest.
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|&a, &b| power[b].total_cmp(&power[a]).then(a.cmp(&b)));
    let mut two: Vec<usize> = order.into_iter().take(2).collect();
    two.sort_unstable();
    two
}

/// A capture converted: the recording and what the conversion did.
#[derive(Debug, Clone, PartialEq)]
pub struct Conversion {
    /// The recording (C1 with the mask `P[n] ∈ {0, 1}`, `synchronized = false`).
    pub recording: Recording,
    /// Frames dropped because their time did not increase: `(frame index, time s)`.
    pub dropped: Vec<(usize, Real)>,
    /// Whether the format's gain was applied.
    pub gain_applied: bool,
    /// The reported subcarriers left out as unoccupied ([`occupied`]).
    pub unoccupied: Vec<i32>,
}

/// The recording of a capture (docs/recording.md, "CSI files"): the uniform grid from the
/// lowest to the highest occupied subcarrier ([`occupied`], unless
/// [`ConvertOptions::keep_unoccupied`]) at the capture's spacing, `P[n] = 1` where an occupied
/// subcarrier is reported and 0 elsewhere (`H[n] = 0` there), the times relative to the first
/// frame, frames whose time does not increase dropped (listed), `synchronized = false` (a
/// Wi-Fi receiver's clock is its own: C10). Errors: an antenna index in `links` beyond the
/// capture ([`Error::OutOfRange`]), no frame left, and [`Recording::validate`]'s.
pub fn to_recording(cap: &CsiCapture, options: &ConvertOptions) -> Result<Conversion> {
    cap.validate()?;
    let grid = Grid::of(cap, options)?;
    let mut t_s = Vec::with_capacity(cap.frame_count());
    let mut dropped = Vec::new();
    let mut samples = Vec::with_capacity(cap.frame_count() * grid.pairs.len() * grid.span);
    grid.frames(cap, cap.t_s[0], &mut t_s, &mut dropped, &mut samples);
    let recording = grid.recording(t_s, samples);
    recording.validate()?;
    Ok(Conversion {
        recording,
        dropped,
        gain_applied: grid.gain_applied,
        unoccupied: grid.unoccupied,
    })
}

/// The grid of a conversion ([`to_recording`]): the antenna pairs kept, the reported
/// subcarriers kept and their slots on the uniform grid, whether the gain is applied. A stream
/// fixes it by its first frame and converts every later frame on it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Grid {
    pub(crate) pairs: Vec<PairLink>,
    /// Positions into the capture's subcarriers kept, and their bins on the grid.
    kept: Vec<usize>,
    slot: Vec<usize>,
    pub(crate) span: usize,
    freq_hz: Vec<Real>,
    response: Vec<Complex>,
    pub(crate) gain_applied: bool,
    pub(crate) unoccupied: Vec<i32>,
}

impl Grid {
    /// The grid of `cap` (checked) under `options`. Errors: an antenna index in `links` beyond
    /// the capture ([`Error::OutOfRange`]), no pair mapped.
    pub(crate) fn of(cap: &CsiCapture, options: &ConvertOptions) -> Result<Grid> {
        let pairs = match &options.links {
            Some(p) => p.clone(),
            None => PairLink::all(cap.n_rx, cap.n_tx),
        };
        if pairs.is_empty() {
            return Err(Error::InvalidFile {
                field: "links".into(),
                reason: "no antenna pair mapped".into(),
            });
        }
        for (i, p) in pairs.iter().enumerate() {
            if p.rx >= cap.n_rx || p.tx >= cap.n_tx {
                return Err(Error::OutOfRange {
                    field: format!("links[{i}]"),
                    value: if p.rx >= cap.n_rx { p.rx } else { p.tx } as Real,
                    allowed: "an antenna the capture has (rx < n_rx, tx < n_tx)",
                });
            }
        }
        let kept: Vec<usize> = if options.keep_unoccupied {
            (0..cap.subcarriers.len()).collect()
        } else {
            occupied(cap)
        };
        let unoccupied: Vec<i32> = (0..cap.subcarriers.len())
            .filter(|i| !kept.contains(i))
            .map(|i| cap.subcarriers[i])
            .collect();
        let k0 = cap.subcarriers[kept[0]];
        let span = (cap.subcarriers[kept[kept.len() - 1]] - k0) as usize + 1;
        let freq_hz: Vec<Real> = (0..span)
            .map(|n| (k0 as Real + n as Real) * cap.spacing_hz)
            .collect();
        let mut response = vec![Complex::new(0.0, 0.0); span];
        let slot: Vec<usize> = kept
            .iter()
            .map(|&i| (cap.subcarriers[i] - k0) as usize)
            .collect();
        for &n in &slot {
            response[n] = Complex::new(1.0, 0.0);
        }
        Ok(Grid {
            pairs,
            kept,
            slot,
            span,
            freq_hz,
            response,
            gain_applied: options.apply_gain && cap.gain.is_some(),
            unoccupied,
        })
    }

    /// Appends `cap`'s frames on this grid: the time relative to `t0`, a frame whose time does
    /// not increase over the last of `t_s` dropped (into `dropped`), the gain when applied, the
    /// kept subcarriers of each pair into its slots (0 elsewhere). `cap` must have this grid's
    /// subcarriers and antennas (the caller checks).
    pub(crate) fn frames(
        &self,
        cap: &CsiCapture,
        t0: Real,
        t_s: &mut Vec<Real>,
        dropped: &mut Vec<(usize, Real)>,
        samples: &mut Vec<Complex>,
    ) {
        for f in 0..cap.frame_count() {
            let t = cap.t_s[f] - t0;
            if let Some(&last) = t_s.last() {
                if t <= last {
                    dropped.push((f, cap.t_s[f]));
                    continue;
                }
            }
            t_s.push(t);
            let g = match (&cap.gain, self.gain_applied) {
                (Some(g), true) => g[f],
                _ => 1.0,
            };
            for p in &self.pairs {
                let start = samples.len();
                samples.resize(start + self.span, Complex::new(0.0, 0.0));
                let h = cap.pair(f, p.rx, p.tx);
                for (&i, &n) in self.kept.iter().zip(&self.slot) {
                    samples[start + n] = h[i] * g;
                }
            }
        }
    }

    /// The recording of converted frames (`synchronized = false`, the mask as the system
    /// response).
    pub(crate) fn recording(&self, t_s: Vec<Real>, samples: Vec<Complex>) -> Recording {
        Recording {
            t_s,
            links: self.pairs.iter().map(|p| p.link).collect(),
            layout: Layout::Cfr {
                freq_hz: self.freq_hz.clone(),
                system_response: Some(self.response.clone()),
            },
            samples,
            noise_var: None,
            synchronized: Some(false),
        }
    }
}
