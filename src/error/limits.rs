//! The documented range of every physical parameter and the size caps that are not local to one
//! module, each with its reason (docs/cli.md, "Limits"). A value outside its range is a named
//! [`Error::OutOfRange`]; a size past its cap a named [`Error::SizeLimit`].

use crate::error::{check_finite, Error, Result};

/// A closed interval of allowed values, with the words an error shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Smallest allowed value.
    pub min: f64,
    /// Largest allowed value.
    pub max: f64,
    /// The interval in words, with its unit (shown in errors and in docs/cli.md).
    pub allowed: &'static str,
}

impl Range {
    /// `Ok` when `v` is finite and in `[min, max]`; else [`Error::NonFinite`] or
    /// [`Error::OutOfRange`] naming `field`.
    pub fn check(&self, field: &str, v: f64) -> Result<()> {
        check_finite(field, v)?;
        if (self.min..=self.max).contains(&v) {
            Ok(())
        } else {
            Err(Error::OutOfRange {
                field: field.into(),
                value: v,
                allowed: self.allowed,
            })
        }
    }

    /// Whether `v` lies in the range (false for NaN).
    pub fn contains(&self, v: f64) -> bool {
        (self.min..=self.max).contains(&v)
    }
}

/// An interval with both ends excluded (`min < v < max`), for a quantity that may come
/// arbitrarily close to its ends (a probability), with the words an error shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OpenRange {
    /// The excluded lower end.
    pub min: f64,
    /// The excluded upper end.
    pub max: f64,
    /// The interval in words (shown in errors).
    pub allowed: &'static str,
}

impl OpenRange {
    /// `Ok` when `min < v < max`; else [`Error::OutOfRange`] naming `field` (NaN included).
    pub fn check(&self, field: &str, v: f64) -> Result<()> {
        if v > self.min && v < self.max {
            Ok(())
        } else {
            Err(Error::OutOfRange {
                field: field.into(),
                value: v,
                allowed: self.allowed,
            })
        }
    }
}

/// Any coordinate (node positions, area and region bounds): `|x| ≤ 10⁷ m`. The model is planar
/// free-space propagation; 10 000 km is past any ground network, and every derived length
/// (spans, bistatic ranges up to 4·√2·10⁷ m) stays far from overflow.
pub const COORDINATE_M: Range = Range {
    min: -1e7,
    max: 1e7,
    allowed: "-1e7 to 1e7 m",
};

/// The smallest span of an area side, m: a grid cell of a 4096-cell side is then ≥ 0.24 µm, far
/// above the spacing of doubles at 10⁷ m (1.9 nm).
pub const MIN_AREA_SPAN_M: f64 = 1e-3;

/// Carrier frequency `f_c`: 1 kHz (VLF) to 1 THz (sub-millimetre radio). Only the wavelength of
/// the free-space budget depends on it.
pub const CARRIER_HZ: Range = Range {
    min: 1e3,
    max: 1e12,
    allowed: "1e3 to 1e12 Hz",
};

/// Bandwidth `B`: 1 kHz to 1 THz. It sets `β = B/√12`, the noise power and the resolution 1/B.
pub const BANDWIDTH_HZ: Range = Range {
    min: 1e3,
    max: 1e12,
    allowed: "1e3 to 1e12 Hz",
};

/// Transmit power: −100 dBm (0.1 pW) to 100 dBm (10 MW, beyond the peak power of any radar).
pub const POWER_DBM: Range = Range {
    min: -100.0,
    max: 100.0,
    allowed: "-100 to 100 dBm",
};

/// Antenna gain: −60 dBi (a deep null) to 80 dBi (beyond the largest radio-telescope dishes).
pub const GAIN_DBI: Range = Range {
    min: -60.0,
    max: 80.0,
    allowed: "-60 to 80 dBi",
};

/// Radar cross section: 10⁻⁸ m² (below an insect) to 10⁸ m² (beyond a ship or a mountain face).
pub const RCS_M2: Range = Range {
    min: 1e-8,
    max: 1e8,
    allowed: "1e-8 to 1e8 m²",
};

/// Receiver noise figure `F`: 0 to 100 dB.
pub const NOISE_FIGURE_DB: Range = Range {
    min: 0.0,
    max: 100.0,
    allowed: "0 to 100 dB",
};

/// Explicit noise power: −250 dBm to 50 dBm (k_B·T₀·1 kHz is −144 dBm).
pub const NOISE_POWER_DBM: Range = Range {
    min: -250.0,
    max: 50.0,
    allowed: "-250 to 50 dBm",
};

/// Processing gain `B·T_p`: 0 to 200 dB (1 THz × 10⁸ s).
pub const PROCESSING_GAIN_DB: Range = Range {
    min: 0.0,
    max: 200.0,
    allowed: "0 to 200 dB",
};

/// Antenna boresight azimuth: one turn either way.
pub const BORESIGHT_DEG: Range = Range {
    min: -360.0,
    max: 360.0,
    allowed: "-360 to 360 degrees",
};

/// Maximum attenuation `A_m` of a parabolic pattern: 0 to 200 dB.
pub const PATTERN_FLOOR_DB: Range = Range {
    min: 0.0,
    max: 200.0,
    allowed: "0 to 200 dB",
};

/// A measured bistatic delay: > 0 and at most 1 s. Coordinates within [`COORDINATE_M`] give
/// delays below 0.19 s; a delay ≤ 0 is not a propagation delay.
pub const DELAY_S: Range = Range {
    min: f64::MIN_POSITIVE,
    max: 1.0,
    allowed: "0 < delay <= 1 s",
};

/// A delay standard deviation: 10⁻¹⁵ s (0.3 µm) to 10⁻³ s (300 km). Larger σ make every squared
/// normalised residual underflow, so the fit could not tell positions apart.
pub const DELAY_SIGMA_S: Range = Range {
    min: 1e-15,
    max: 1e-3,
    allowed: "1e-15 to 1e-3 s",
};

/// Range noise `cσ` of multi-target localization: 1 mm to 1 km.
pub const C_SIGMA_M: Range = Range {
    min: 1e-3,
    max: 1e3,
    allowed: "1e-3 to 1e3 m",
};

/// The false-alarm probability per snapshot `P_fa` of a channel run's estimator (C5, the
/// request's `pfa`): `0 < pfa < 1`.
pub const FALSE_ALARM_PROBABILITY: OpenRange = OpenRange {
    min: 0.0,
    max: 1.0,
    allowed: "0 < pfa < 1",
};

/// The person's extent `σ_e` that widens the delays of a channel track (`extent_sigma_m`):
/// 0 to 1 km — beyond, a delay says nothing about a position (1e300 was accepted and gave no
/// track, issue 37 item 8).
pub const PERSON_EXTENT_M: Range = Range {
    min: 0.0,
    max: 1e3,
    allowed: "0 to 1e3 m",
};

/// Largest number of links of a scenario. The CRLB map costs links × cells: at 4096 links a
/// 256² map takes 0.46 s on the 2-core reference machine and the grid-search start of `locate`
/// 0.10 s; 1000 × 1000 nodes (10⁶ links) took about 2 minutes per map.
pub const MAX_LINKS: usize = 4096;

/// Largest number of transmitters, and of receivers, in a scenario (a node without a link adds
/// nothing but cost; a full mesh already reaches [`MAX_LINKS`] at 64 × 64).
pub const MAX_NODES: usize = 4096;

/// Longest name, bytes of UTF-8: the scenario's, each node's, and the node names a link or a
/// plan's movable list refers to. 256 bytes holds any label a figure, a legend or a table shows
/// legibly (the presets use 2–12); names are copied into every figure, legend, JSON output and
/// error message, and a 100 MB name made a PNG figure take minutes and froze the page for
/// seconds (issue 24).
pub const MAX_NAME_BYTES: usize = 256;

/// `Ok` when `name` has at most [`MAX_NAME_BYTES`] bytes; else [`Error::NameTooLong`] naming
/// `field` (checked before any copy of the name is made).
pub fn check_name(field: &str, name: &str) -> Result<()> {
    if name.len() > MAX_NAME_BYTES {
        return Err(Error::NameTooLong {
            field: field.into(),
            bytes: name.len(),
            max: MAX_NAME_BYTES,
        });
    }
    Ok(())
}

/// Largest input file the CLI reads, bytes (`--scenario`, `--delays`, `--measurements`, …):
/// 256 MiB. The largest legitimate input, a `simulate-walk` raw-steps file, is capped at the
/// same size when written.
pub const MAX_INPUT_BYTES: u64 = 256 << 20;

/// Most calibration snapshots of the empty area a simulated §9.6 walk draws
/// ([`crate::track::gating::WalkRequest`]): 100 000 (200 s of [S]'s snapshots; the clusterer
/// needs tens).
pub const MAX_WALK_CALIBRATION_SNAPSHOTS: usize = 100_000;

/// Largest expected number of estimates a simulated §9.6 walk writes
/// ([`crate::track::gating::WalkRequest`]): at most 46 bytes each (a `[delay, amplitude]` pair
/// with a comma), so each of its files stays below [`MAX_INPUT_BYTES`] and can be read back.
pub const MAX_WALK_ESTIMATES: f64 = 5e6;

/// The tracker's time step `Δt`: 1 µs to 1 h.
pub const DT_S: Range = Range {
    min: 1e-6,
    max: 3600.0,
    allowed: "1e-6 to 3600 s",
};

/// The process-noise intensity `q` of the constant-velocity model (E7): up to 10⁶ m²/s³ (a
/// random acceleration of ~1000 m/s² over one second; people and cars need 0.01–10).
pub const PROCESS_NOISE: Range = Range {
    min: f64::MIN_POSITIVE,
    max: 1e6,
    allowed: "0 < q <= 1e6 m²/s³",
};

/// The largest variance on the diagonal of an initial covariance: 10¹² (σ = 1000 km or
/// 1000 km/s, a prior that knows nothing on any ground network). Wider priors would overflow
/// the first prediction's products with the links' information.
pub const MAX_INITIAL_VARIANCE: f64 = 1e12;

/// A velocity component of a tracker state: ±10⁶ m/s (1000 km/s, beyond any vehicle).
pub const VELOCITY_M_S: Range = Range {
    min: -1e6,
    max: 1e6,
    allowed: "-1e6 to 1e6 m/s",
};

/// A measured bistatic range rate: ±2·10⁶ m/s (twice [`VELOCITY_M_S`]: `|ṙ| ≤ 2|v|`, D1).
pub const RANGE_RATE_M_S: Range = Range {
    min: -2e6,
    max: 2e6,
    allowed: "-2e6 to 2e6 m/s",
};

/// A range-rate standard deviation: 10⁻⁶ m/s to 10⁶ m/s.
pub const RANGE_RATE_SIGMA_M_S: Range = Range {
    min: 1e-6,
    max: 1e6,
    allowed: "1e-6 to 1e6 m/s",
};

/// A bistatic range (path length) of multi-target localization, and the clutter's `r_max`:
/// `0 … 10⁸ m`. Nodes and targets within [`COORDINATE_M`] give paths below 5.7·10⁷ m; far larger
/// ranges gave ellipses with infinite axes.
pub const RANGE_M: Range = Range {
    min: 0.0,
    max: 1e8,
    allowed: "0 to 1e8 m",
};

/// Largest `max_paths` of the snapshot estimator (C5): the joint amplitude fit and the joint
/// Fisher matrix are `K × K` and `3K × 3K` dense solves per snapshot, so `K` beyond a few tens
/// only costs time ([S] resolves fewer than 20 paths per link).
pub const MAX_PATHS: usize = 64;

/// Most refinement steps of the snapshot estimator (C5) after one new path: a cyclic sweep
/// (every coupled path by one Newton step) or a joint Gauss–Newton step of up to three coupled
/// paths; they stop earlier once no delay moves by more than 10⁻³/B or a step gains less than
/// 0.05 in log-likelihood. A snapshot that reaches the bound keeps its paths
/// and is counted (`EstimateWork::sweeps_capped`).
pub const ESTIMATOR_SWEEPS: usize = 6;

/// Most Newton iterations of one new path of the snapshot estimator (C5), from the parabola
/// through the periodogram's peak (quadratic convergence: two or three suffice).
pub const NEWTON_ITERATIONS: usize = 8;

/// Most Levenberg–Marquardt iterations of a snapshot's joint alignment (C9 step 2 with the
/// dynamic paths, C10): started from the separate alignment and the first fit, it converges in
/// three to six; one that reaches the bound keeps its best point.
pub const JOINT_ALIGN_ITERATIONS: usize = 16;

/// Most dynamic paths refined together with a snapshot's alignment (the strongest first; the
/// others stay in the residual).
pub const JOINT_ALIGN_PATHS: usize = 8;

/// The estimator's dynamic range (C5), dB: the noise variance is never taken below the
/// response's mean bin power this far down. 20 dB is a coarse receiver; 300 dB is beyond the
/// rounding of float64 samples.
pub const ESTIMATOR_DYNAMIC_RANGE_DB: Range = Range {
    min: 20.0,
    max: 300.0,
    allowed: "20 to 300 dB",
};

/// The largest magnitude of a response sample the estimator takes (either part, any unit):
/// `10¹⁰⁰`. Its sums of squares over up to [`MAX_PERIODOGRAM`] cells stay finite (a response
/// of `10³⁰⁰` gave an infinite noise variance, issue 37 item 7); float32 recordings end at
/// `3.4·10³⁸`, raw integer CSI at `2³¹`. A given noise variance is capped at its square.
pub const MAX_SAMPLE_MAGNITUDE: f64 = 1e100;

/// Path entries in a simulated recording's truth (true paths × links × snapshots): 2²⁰, about
/// 100 MB of `truth.json`, below what `cir track --truth` reads ([`MAX_INPUT_BYTES`]). A scene of
/// 4096 scatterers made a 278 MB truth in 2 s of walk (issue 37 item 4).
pub const MAX_TRUTH_PATHS: usize = 1 << 20;

/// The simulator's work: path × bin products over the whole recording, `2³⁴` (tens of seconds
/// on one core); the sample cap alone allowed hours with thousands of scatterers.
pub const MAX_SIMULATION_WORK: u64 = 1 << 34;

/// The recursive background's time constant `τ_bg` (C9), s: 1 ms (a few snapshots at [S]'s
/// rate) to 10⁶ s (a background that never forgets).
pub const BACKGROUND_TIME_S: Range = Range {
    min: 1e-3,
    max: 1e6,
    allowed: "1e-3 to 1e6 s",
};

/// Largest zero-padded periodogram of the snapshot estimator (C5): `2^20` cells (16 MiB of
/// complex scratch), e.g. 16 384 bins oversampled 64×.
pub const MAX_PERIODOGRAM: usize = 1 << 20;

/// Most columns (snapshots) of a delay figure's magnitude image (`present::delay_image`): more
/// snapshots are decimated to this many. 600 columns × [`MAX_DELAY_IMAGE_ROWS`] rows × N = 241
/// bins is 4.3·10⁷ complex multiply-adds per link, about 0.1 s in release.
pub const MAX_DELAY_IMAGE_COLS: usize = 600;

/// Most rows (range cells) of a delay figure's magnitude image (`present::delay_image`).
pub const MAX_DELAY_IMAGE_ROWS: usize = 300;

/// Largest dynamic range of a delay figure's magnitude image, dB (smallest: 1 dB).
pub const DELAY_IMAGE_DR_DB: Range = Range {
    min: 1.0,
    max: 200.0,
    allowed: "1 to 200 dB",
};

/// Largest channel recording, complex samples in all (`S·P·N` or `S·P·M`, docs/recording.md):
/// 64 Mi = 1 GiB of complex128 in memory. A 10-minute walk at [S]'s rate (4 links every
/// 2.048 ms) with N = 241 subcarriers is 2.8·10⁸: record it in pieces of ≤ 2 minutes.
pub const MAX_RECORDING_SAMPLES: usize = 64 << 20;

/// Largest header line of a frame stream (`cir track --follow`, docs/recording.md "Streaming
/// frames"), bytes: 16 MiB, room for [`MAX_LINKS`] links and [`MAX_BINS_PER_LINK`] bins with
/// their system response as JSON; a stream whose first 16 MiB hold no `\n` is refused.
pub const MAX_STREAM_HEADER_BYTES: usize = 16 << 20;

/// Largest `.npz` recording file, and the largest total of its members once inflated, bytes:
/// the samples' cap as complex128 plus 64 MiB for the other arrays and the headers. A member
/// that declares more is refused before inflating, one that inflates to more while inflating
/// (zip bombs).
pub const MAX_RECORDING_BYTES: u64 = (1 << 30) + (64 << 20);

/// Most snapshots of a recording: 2²⁴ (9.5 h at [S]'s 2.048 ms).
pub const MAX_SNAPSHOTS: usize = 1 << 24;

/// Most frequency bins (`N`) or taps (`M`) per link and snapshot: 65 536 (a 20 MHz Wi-Fi CSI has
/// 56–242, [S]'s sounder 241, a UWB CIR accumulator 1016).
pub const MAX_BINS_PER_LINK: usize = 65_536;

/// Most samples of a recording's system pulse (`pulse`, K): 65 537.
pub const MAX_PULSE_SAMPLES: usize = 65_537;

/// Relative tolerance of the uniform spacing of `freq_hz`: every step `f[n+1] − f[n]` is within
/// `1e-6·Δf` of `Δf = (f[N−1] − f[0])/(N−1)` (float64 bins written as `f0 + n·Δf` or by
/// `numpy.linspace` are within 1e-12).
pub const FREQ_UNIFORM_TOL: f64 = 1e-6;

/// Tolerance of the pulse's normalisation `p(0) = 1` (its middle sample) in a validated
/// recording: `|p(0) − 1| ≤ 1e-9` (the reader divides by `p(0)`).
pub const PULSE_NORM_TOL: f64 = 1e-9;

/// Largest number of live path tracks of one link's path tracker (C6, `paths.max_tracks`; the
/// default is 64): association costs tracks × estimates per snapshot, and the estimator
/// refines one seed per track.
pub const MAX_PATH_TRACKS: usize = 4096;

/// Channel simulator: total complex samples of a recording (snapshots × links × subcarriers),
/// 64 Mi = 1 GiB of `Complex<f64>`; an hour of [S]'s 2.048 ms snapshots on 4 links × 241 bins
/// is past it, a minute is far below.
pub const MAX_CHANNEL_SAMPLES: usize = 64 << 20;
/// Channel simulator: subcarriers per link (a sounder's FFT size).
pub const MAX_SUBCARRIERS: usize = 1 << 16;
/// Channel simulator: walls of a scene (second-order paths grow with its square).
pub const MAX_SCENE_WALLS: usize = 64;
/// Channel simulator: point scatterers of a scene.
pub const MAX_SCENE_SCATTERERS: usize = 4096;
/// Channel simulator: scattering centres of the walker's body.
pub const MAX_BODY_CENTRES: usize = 64;
/// Channel simulator: waypoints of a walk.
pub const MAX_WAYPOINTS: usize = 4096;

/// Largest recording (or calibration) file the page reads, bytes, checked before parsing, and
/// the largest total of its members once inflated (the page's `.npz` reader cap, a zip bomb is
/// refused at it): 256 MiB, 16 Mi complex128 samples (a 300-snapshot, 4-link, 241-bin
/// recording is 4.6 MB). The page holds the recording, its inflated arrays and the estimator's
/// scratch in one 4 GiB wasm memory.
pub const MAX_PAGE_RECORDING_BYTES: u64 = 256 << 20;

/// Largest truth or scenario text the page's channel view reads, bytes: 64 MiB.
pub const MAX_PAGE_TEXT_BYTES: usize = 64 << 20;

/// Detections files (JSON lines, docs/detections.md, issue 40): the longest line, bytes. A line
/// of [`MAX_DETECTIONS_PER_LINE`] detections with delay, SNR, σ and Doppler at 25 bytes each is
/// 410 kB; 1 MiB bounds what one line's parse may allocate.
pub const MAX_DETECTION_LINE_BYTES: usize = 1 << 20;

/// Detections files: most lines (blank and `#` lines counted), 2²²: 10⁶ frames of 4 links, the
/// tracker's [`crate::track::MAX_STEPS`], fit; the file itself is read up to
/// [`MAX_INPUT_BYTES`].
pub const MAX_DETECTION_LINES: usize = 1 << 22;

/// Detections files: most detections of one link in one frame (a CFAR detector's list; the
/// channel front end gives at most [`MAX_PATHS`]).
pub const MAX_DETECTIONS_PER_LINE: usize = 4096;

/// Detections files: an SNR, dB: −300 to 300 dB (its linear value and the σ_τ of E8 stay
/// finite and > 0).
pub const DETECTION_SNR_DB: Range = Range {
    min: -300.0,
    max: 300.0,
    allowed: "-300 to 300 dB",
};

/// Detections files: relative tolerance of the uniform frame spacing (as [`FREQ_UNIFORM_TOL`]
/// of a recording's bins and `cir estimate --measurements`' snapshot times): every
/// `t[k] − t[k−1]` within `1e-6·T` of `T = (t[K−1] − t[0])/(K−1)`.
pub const FRAME_UNIFORM_TOL: f64 = 1e-6;
