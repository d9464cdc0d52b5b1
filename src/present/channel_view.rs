//! What the channel front end's figures show (issue 25 §4), as plain data: the \[S\] Fig. 4
//! picture per link ([`DelayFigure`]: the response's delay profile as an image, the path
//! estimates coloured by amplitude, the static clusters, the true paths, all against time with
//! delay shown as path length `c·τ`) and the track's position error ([`TrackErrorView`]: the
//! error over time, its empirical CDF and [`ErrorStats`], \[S\] Figs. 5–6). The only maths here
//! is the delay profile of C1 ([`delay_image`], a chirp-z transform per column) and order
//! statistics; `chart::channel` draws these views.

use alloc::string::String;
use alloc::vec::Vec;

use crate::channel::ChirpZ;
use crate::error::limits::{DELAY_IMAGE_DR_DB, MAX_DELAY_IMAGE_COLS, MAX_DELAY_IMAGE_ROWS};
use crate::error::{check_finite, check_len, Error, Result};
use crate::math::{log10, sqrt, Complex, Real, SPEED_OF_LIGHT};

mod points;

use crate::study::CirTrackOutput;
use crate::track::gating::LinkCalibration;
pub use points::{delay_points, DelayPoint, DrawnEstimate};

/// The delay profile of one link as an image: `db[j·cols + i]` is the power at range
/// `r0_m + j·dr_m` (row `j`, ascending range) in the snapshot of column `i` (time `t_s[i]`),
/// dB, within `db_range`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DelayImage {
    /// Time of each column's snapshot, s (ascending; `cols = t_s.len()`).
    pub t_s: Vec<Real>,
    /// Range (path length `c·τ`) of row 0, m.
    pub r0_m: Real,
    /// Row spacing, m (> 0).
    pub dr_m: Real,
    /// Number of rows.
    pub rows: usize,
    /// `rows × cols` values, row-major, dB re 1 W (`10·log10(p/N²)`: a lone path of amplitude
    /// `|α|` √W peaks at `20·log10|α|`), each within `db_range`. Serialised to 0.01 dB (the
    /// figure shows 32 grey levels over 40 dB): the page's worker sends this text to the page,
    /// a third of the full digits' size (issue 38 item 9).
    #[serde(serialize_with = "serialize_centi_db")]
    pub db: Vec<Real>,
    /// `[lo, hi]`, dB: `hi` the largest value, `lo = hi − dynamic range` (values below are
    /// clipped to `lo`).
    pub db_range: [Real; 2],
}

/// `db` with each value rounded to 0.01 dB (non-finite values as they are).
fn serialize_centi_db<S: serde::Serializer>(
    db: &[Real],
    s: S,
) -> core::result::Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = s.serialize_seq(Some(db.len()))?;
    for &v in db {
        let r = if v.is_finite() {
            crate::math::round(v * 100.0) / 100.0
        } else {
            v
        };
        seq.serialize_element(&if r.is_finite() { r } else { v })?;
    }
    seq.end()
}

impl DelayImage {
    /// Number of columns.
    pub fn cols(&self) -> usize {
        self.t_s.len()
    }
}

/// Where the dynamic range of a [`DelayImage`] is measured from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ImageFloor {
    /// Below the image's largest value (one scale for the whole link).
    #[default]
    Global,
    /// Below each column's largest value (every snapshot shows its own strongest paths; the
    /// values stay absolute, dB re 1 W).
    Column,
}

/// How [`delay_image`] samples the profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageConfig {
    /// `[lo, hi]` range (path length) of the rows, m.
    pub range_m: [Real; 2],
    /// Most columns (1 ..= [`MAX_DELAY_IMAGE_COLS`]): more snapshots are decimated.
    pub max_cols: usize,
    /// Rows (1 ..= [`MAX_DELAY_IMAGE_ROWS`]).
    pub rows: usize,
    /// Dynamic range shown, dB ([`DELAY_IMAGE_DR_DB`]).
    pub dynamic_range_db: Real,
    /// Where the dynamic range is measured from.
    pub floor: ImageFloor,
}

impl ImageConfig {
    /// Defaults over `range_m`: 600 columns, 300 rows, 40 dB below the global maximum.
    pub fn new(range_m: [Real; 2]) -> ImageConfig {
        ImageConfig {
            range_m,
            max_cols: MAX_DELAY_IMAGE_COLS,
            rows: MAX_DELAY_IMAGE_ROWS,
            dynamic_range_db: 40.0,
            floor: ImageFloor::Global,
        }
    }
}

/// The snapshot index shown in column `i` of `cols` over `s` snapshots (the middle of its
/// share: `⌊(i + ½)·s/cols⌋`).
fn column_snapshot(i: usize, cols: usize, s: usize) -> usize {
    ((2 * i + 1) * s / (2 * cols)).min(s - 1)
}

/// The delay profile image of one link (C1): for each shown snapshot `s` with response `H[n]` at
/// the uniform frequencies `f_n = f_0 + n·Δf` (`freq_hz`), the power
/// `p(τ) = |Σ_n H[n]·e^{j2πf_nτ}|² / N²` (the C5 periodogram with `P = 1`) at `τ = r/c` on
/// `cfg.rows` ranges `r` evenly over `cfg.range_m` (cell centres), in dB re 1 W, clipped to the
/// dynamic range. `|e^{j2πf_0τ}| = 1`, and the rows are a uniform delay grid, so each column is
/// one chirp-z transform (Bluestein: two FFTs of the power of two `L ≥ N + rows − 1`, `O(L log
/// L)` instead of `N·rows` multiply-adds; exact up to rounding, within `1e-12·(Σ|H|)²/N²` of the
/// direct sum, tested; the same bits natively and in wasm).
/// More snapshots than `cfg.max_cols` are decimated (each column shows the snapshot at the
/// middle of its share; no averaging). `response(s)` gives snapshot `s`'s `N` samples, `t_s` the
/// snapshot times (ascending).
///
/// Errors: fewer than 2 frequencies or a non-uniform or non-finite `freq_hz`
/// (`InvalidFile { field: "freq_hz" }`), no snapshot or a size outside the caps (`SizeLimit`), a
/// response of the wrong length (`LengthMismatch`), a non-finite sample or time (`NonFinite`), an
/// empty or non-finite range (`OutOfRange`), a dynamic range outside [`DELAY_IMAGE_DR_DB`].
pub fn delay_image<'a>(
    freq_hz: &[Real],
    t_s: &[Real],
    response: impl Fn(usize) -> &'a [Complex],
    cfg: &ImageConfig,
) -> Result<DelayImage> {
    let n = freq_hz.len();
    let df = check_uniform(freq_hz)?;
    let s = t_s.len();
    if s == 0 {
        return Err(Error::SizeLimit {
            field: "snapshots of the delay image",
            value: 0,
            min: 1,
            max: usize::MAX,
        });
    }
    for (field, v, max) in [
        ("delay image columns", cfg.max_cols, MAX_DELAY_IMAGE_COLS),
        ("delay image rows", cfg.rows, MAX_DELAY_IMAGE_ROWS),
    ] {
        if v == 0 || v > max {
            return Err(Error::SizeLimit {
                field,
                value: v,
                min: 1,
                max,
            });
        }
    }
    DELAY_IMAGE_DR_DB.check("dynamic_range_db", cfg.dynamic_range_db)?;
    let [lo, hi] = cfg.range_m;
    check_finite("range_m[0]", lo)?;
    check_finite("range_m[1]", hi)?;
    if hi <= lo {
        return Err(Error::OutOfRange {
            field: "range_m[1]".into(),
            value: hi,
            allowed: "greater than range_m[0]",
        });
    }
    let cols = cfg.max_cols.min(s);
    let rows = cfg.rows;
    let dr = (hi - lo) / rows as Real;
    let r0 = lo + 0.5 * dr;
    let plan = ChirpZ::new(n, rows, df, r0 / SPEED_OF_LIGHT, dr / SPEED_OF_LIGHT);
    let norm = (n * n) as Real;
    let mut power = alloc::vec![0.0 as Real; rows * cols];
    let mut column = alloc::vec![0.0 as Real; rows];
    let mut work = Vec::with_capacity(plan.len());
    let mut times = Vec::with_capacity(cols);
    for i in 0..cols {
        let k = column_snapshot(i, cols, s);
        check_finite("t_s", t_s[k])?;
        times.push(t_s[k]);
        let h = response(k);
        check_len("response samples (one per freq_hz)", n, h.len())?;
        if h.iter().any(|c| !(c.re.is_finite() && c.im.is_finite())) {
            return Err(Error::NonFinite {
                field: alloc::format!("response of snapshot {k}"),
            });
        }
        plan.power(h, &mut work, &mut column);
        for (j, p) in column.iter().enumerate() {
            let p = p / norm;
            // A sum of finite samples can still overflow: show it as the largest finite power.
            power[j * cols + i] = if p.is_finite() { p } else { Real::MAX };
        }
    }
    Ok(to_db(power, times, r0, dr, rows, cfg))
}

/// The spacing `Δf` of uniform frequencies (relative tolerance 1e-6 of `Δf` per bin).
fn check_uniform(freq_hz: &[Real]) -> Result<Real> {
    let bad = |reason: String| Error::InvalidFile {
        field: "freq_hz".into(),
        reason,
    };
    if freq_hz.len() < 2 {
        return Err(bad(alloc::format!(
            "{} frequencies; at least 2 are needed",
            freq_hz.len()
        )));
    }
    if let Some(k) = freq_hz.iter().position(|f| !f.is_finite()) {
        return Err(bad(alloc::format!("freq_hz[{k}] is not finite")));
    }
    let n = freq_hz.len();
    let df = (freq_hz[n - 1] - freq_hz[0]) / (n - 1) as Real;
    if !(df.is_finite() && df > 0.0) {
        return Err(bad("not increasing".into()));
    }
    for (k, f) in freq_hz.iter().enumerate() {
        let expected = freq_hz[0] + k as Real * df;
        if (f - expected).abs() > 1e-6 * df {
            return Err(bad(alloc::format!(
                "not uniformly spaced at freq_hz[{k}] ({f} Hz, expected {expected} Hz)"
            )));
        }
    }
    Ok(df)
}

/// Powers (W) to clipped dB.
fn to_db(
    power: Vec<Real>,
    t_s: Vec<Real>,
    r0_m: Real,
    dr_m: Real,
    rows: usize,
    cfg: &ImageConfig,
) -> DelayImage {
    let cols = t_s.len();
    // 10·log10 of the tiniest positive power is about −3240 dB; zero becomes that floor too.
    let db_of = |p: Real| {
        if p > 0.0 {
            10.0 * log10(p)
        } else {
            10.0 * log10(Real::MIN_POSITIVE)
        }
    };
    let mut db: Vec<Real> = power.into_iter().map(db_of).collect();
    let top = db.iter().copied().fold(Real::MIN, Real::max);
    let dr = cfg.dynamic_range_db;
    match cfg.floor {
        ImageFloor::Global => db.iter_mut().for_each(|v| *v = v.max(top - dr)),
        ImageFloor::Column => {
            for i in 0..cols {
                let col_top = (0..rows)
                    .map(|j| db[j * cols + i])
                    .fold(Real::MIN, Real::max);
                for j in 0..rows {
                    let v = &mut db[j * cols + i];
                    *v = v.max(col_top - dr);
                }
            }
        }
    }
    let bottom = db.iter().copied().fold(Real::MAX, Real::min);
    DelayImage {
        t_s,
        r0_m,
        dr_m,
        rows,
        db,
        db_range: [bottom.min(top - dr), top],
    }
}

/// A static cluster as drawn: a band at its mean path length, as wide as its 3σ gate (E4).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StaticBand {
    /// `c·τ̄`, m.
    pub mean_m: Real,
    /// `3·c·σ̄`, m.
    pub halfwidth_m: Real,
}

/// A true path over time (built by the caller from its truth file).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TruthCurve {
    /// What the path is, e.g. `pedestrian`, `pedestrian-wall`, `los` (shown in the legend).
    pub kind: String,
    /// Drawn dashed and strong (the pedestrian's paths); otherwise lighter.
    pub primary: bool,
    /// `(t, c·τ)` points, s and m, in time order; a non-finite range breaks the line.
    pub points: Vec<(Real, Real)>,
}

/// One link's panel of the delay figure.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LinkDelays {
    /// Panel title, e.g. `Tx → Rx2`.
    pub name: String,
    /// Range axis `[lo, hi]`, m.
    pub range_m: [Real; 2],
    /// The response's delay profile (`None`: not drawn, e.g. no recording at hand).
    pub image: Option<DelayImage>,
    /// The path estimates of every snapshot.
    pub estimates: Vec<DelayPoint>,
    /// The static clusters (calibration).
    pub statics: Vec<StaticBand>,
    /// The true paths.
    pub truth: Vec<TruthCurve>,
}

/// The \[S\] Fig. 4 figure: one panel per link on a shared time axis and a shared amplitude
/// colour scale.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DelayFigure {
    /// Time axis `[t_first, t_last]`, s.
    pub t_range_s: [Real; 2],
    /// Colour scale of the estimates, `[lo, hi]` dB (`None`: no estimate anywhere).
    pub amplitude_db_range: Option<[Real; 2]>,
    /// The panels.
    pub links: Vec<LinkDelays>,
}

impl DelayFigure {
    /// The figure of `links` over the times `t_s` (its first and last; `[0, 1]` if empty): the
    /// amplitude scale spans every estimate (widened to at least 1 dB).
    pub fn new(t_s: &[Real], links: Vec<LinkDelays>) -> DelayFigure {
        let t_range_s = match (t_s.first(), t_s.last()) {
            (Some(&a), Some(&b)) if a.is_finite() && b.is_finite() && b > a => [a, b],
            (Some(&a), _) if a.is_finite() => [a - 0.5, a + 0.5],
            _ => [0.0, 1.0],
        };
        let amps = links
            .iter()
            .flat_map(|l| l.estimates.iter().map(|e| e.amplitude_db));
        let (lo, hi) = amps.fold((Real::INFINITY, Real::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let amplitude_db_range = (lo.is_finite() && hi.is_finite()).then(|| {
            if hi - lo < 1.0 {
                let mid = 0.5 * (lo + hi);
                [mid - 0.5, mid + 0.5]
            } else {
                [lo, hi]
            }
        });
        DelayFigure {
            t_range_s,
            amplitude_db_range,
            links,
        }
    }
}

/// The static clusters of one link's calibration as bands (mean ± 3σ, E4, as path lengths).
pub fn static_bands(cal: &LinkCalibration) -> Vec<StaticBand> {
    cal.clusters
        .iter()
        .filter(|c| c.mean_s.is_finite() && c.sigma_s.is_finite())
        .map(|c| StaticBand {
            mean_m: SPEED_OF_LIGHT * c.mean_s,
            halfwidth_m: 3.0 * SPEED_OF_LIGHT * c.sigma_s,
        })
        .collect()
}

/// The estimates a range axis must hold, robust to outliers: the 1st to 99th percentile of
/// their path lengths widened by a quarter of that span on each side; estimates beyond are
/// outliers (drawn clipped at the axis' edge and marked). `None` without an estimate.
pub fn robust_estimate_span_m(estimates: &[DelayPoint]) -> Option<[Real; 2]> {
    let mut r: Vec<Real> = estimates
        .iter()
        .map(|e| e.range_m)
        .filter(|v| v.is_finite())
        .collect();
    if r.is_empty() {
        return None;
    }
    r.sort_by(Real::total_cmp);
    let (p1, p99) = (quantile_pct(&r, 1), quantile_pct(&r, 99));
    let pad = 0.25 * (p99 - p1);
    let (lo, hi) = (p1 - pad, p99 + pad);
    // The extreme estimates inside the widened span (so the axis ends at data, not at a pad).
    let first = r.iter().copied().find(|&v| v >= lo).unwrap_or(p1);
    let last = r.iter().rev().copied().find(|&v| v <= hi).unwrap_or(p99);
    Some([first, last])
}

/// A range axis `[lo, hi]` (m) holding the bands, the true paths and the estimates (those
/// within [`robust_estimate_span_m`]: one stray estimate does not stretch the axis, issue 38
/// item 7) with a 5 % margin (at least 1 m), starting no lower than 0 and ending no higher than
/// `max_m` (e.g. the unambiguous range `c/Δf` of a recording; pass `Real::INFINITY` for none).
/// `[0, 10]` when there is nothing to show.
pub fn suggest_range_m(
    estimates: &[DelayPoint],
    statics: &[StaticBand],
    truth: &[TruthCurve],
    max_m: Real,
) -> [Real; 2] {
    let values = robust_estimate_span_m(estimates)
        .into_iter()
        .flatten()
        .chain(
            statics
                .iter()
                .flat_map(|b| [b.mean_m - b.halfwidth_m, b.mean_m + b.halfwidth_m]),
        )
        .chain(truth.iter().flat_map(|c| c.points.iter().map(|p| p.1)))
        .filter(|v| v.is_finite());
    let (lo, hi) = values.fold((Real::INFINITY, Real::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let cap = if max_m.is_finite() && max_m > 0.0 {
        max_m
    } else {
        Real::MAX
    };
    if !(lo.is_finite() && hi.is_finite()) {
        return [0.0, (10.0 as Real).min(cap)];
    }
    let margin = (0.05 * (hi - lo)).max(1.0);
    let (lo, hi) = ((lo - margin).max(0.0), (hi + margin).min(cap));
    if hi > lo {
        [lo, hi]
    } else {
        // Everything lies beyond the cap: show the last metre below it.
        let hi = cap.min(lo + 1.0);
        [(hi - 1.0).max(0.0), hi.max(1.0)]
    }
}

/// Summary statistics of position errors (the table of \[S\] §5.3: median, 90 %, max, share
/// below 1 m). Quantiles are the empirical distribution's: the `q`-quantile is the smallest
/// error `e` with `F(e) ≥ q`, `F(e) = #{e_k ≤ e}/n` — the `⌈q·n⌉`-th smallest error (so the
/// median of an even count is the lower middle value).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ErrorStats {
    /// Errors counted (the finite ones).
    pub count: usize,
    /// The 50 % quantile, m.
    pub median_m: Real,
    /// The 90 % quantile, m.
    pub p90_m: Real,
    /// The largest error, m.
    pub max_m: Real,
    /// Root mean square error, m.
    pub rms_m: Real,
    /// Share of errors strictly below 1 m, in [0, 1].
    pub fraction_below_1m: Real,
}

/// The `⌈pct·n/100⌉`-th smallest of `sorted` (ascending, not empty): the smallest `e` with
/// `F(e) ≥ pct %`, computed in integers so that no rounding moves it.
pub fn quantile_pct(sorted: &[Real], pct: u32) -> Real {
    let n = sorted.len();
    let k = (pct.min(100) as usize * n).div_ceil(100).max(1);
    sorted[k.min(n) - 1]
}

impl ErrorStats {
    /// The statistics of the finite values of `errors_m`; `None` if there is none.
    pub fn of(errors_m: &[Real]) -> Option<ErrorStats> {
        let mut e: Vec<Real> = errors_m.iter().copied().filter(|v| v.is_finite()).collect();
        if e.is_empty() {
            return None;
        }
        e.sort_by(Real::total_cmp);
        let n = e.len();
        let below = e.iter().filter(|v| **v < 1.0).count();
        let ss = e.iter().map(|v| v * v).sum::<Real>();
        Some(ErrorStats {
            count: n,
            median_m: quantile_pct(&e, 50),
            p90_m: quantile_pct(&e, 90),
            max_m: e[n - 1],
            rms_m: sqrt(ss / n as Real),
            fraction_below_1m: below as Real / n as Real,
        })
    }
}

/// The track figure's data (\[S\] Figs. 5–6): the estimated and true paths on the map, the
/// position error over time and its empirical CDF.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TrackErrorView {
    /// Snapshot times, s.
    pub t_s: Vec<Real>,
    /// The estimated positions as runs of consecutive snapshots with a state, m.
    pub track_m: Vec<Vec<[Real; 2]>>,
    /// The true positions as runs of consecutive snapshots with a truth, m.
    pub truth_m: Vec<Vec<[Real; 2]>>,
    /// `‖r̂ − r‖` per snapshot, m (`None` where the track or the truth is missing).
    pub error_m: Vec<Option<Real>>,
    /// The empirical CDF as its steps `(e_(k), k/n)`, errors ascending.
    pub cdf: Vec<(Real, Real)>,
    /// The statistics (`None`: no error to count, e.g. the track never starts).
    pub stats: Option<ErrorStats>,
    /// The first snapshot with a state (`None`: the track never starts).
    pub track_start: Option<usize>,
    /// The track's segments (C11) in time order (empty: not given, and the figures mark none;
    /// [`TrackErrorView::with_segments`]).
    #[serde(default)]
    pub segments: Vec<SegmentSpan>,
}

/// One segment of a track as the figures mark it (C11): its snapshots and times, why it ended,
/// and when and where it was lost.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SegmentSpan {
    /// Its first snapshot.
    pub first: usize,
    /// Its last snapshot with a state.
    pub last: usize,
    /// The time of its first snapshot, s.
    pub t_first_s: Real,
    /// The time of its last snapshot, s.
    pub t_last_s: Real,
    /// Why it ended: `innovation`, `misses`, `outside_area`, `filter` (a numerical failure of
    /// the filter) or `end` (the recording ended).
    pub end: String,
    /// When it was lost: the time of the snapshot after its last (of its last when there is
    /// none), s (`None`: `end` is `end`).
    pub lost_s: Option<Real>,
    /// Where it was lost: its last estimated position, m (`None`: not lost, or no finite
    /// position).
    pub lost_m: Option<[Real; 2]>,
}

impl SegmentSpan {
    /// Why it ended, in words: `innovation`, `misses`, `outside area`, `end of the recording`.
    pub fn end_name(&self) -> String {
        match self.end.as_str() {
            "end" => "end of the recording".into(),
            other => other.replace('_', " "),
        }
    }

    /// The label of its loss, e.g. `lost: outside area` (`None`: it lasted to the end).
    pub fn loss_label(&self) -> Option<String> {
        self.lost_s
            .map(|_| alloc::format!("lost: {}", self.end_name()))
    }
}

impl TrackErrorView {
    /// The view with the segments of `track` (the track it was made of: its `states` and
    /// `segments`, C11): the map's track becomes one line per segment (none across a gap, nor
    /// from one segment into the next), and the figures shade the time outside them and mark
    /// each start and each loss. Errors: `track` not one entry per time of the view
    /// (`LengthMismatch`); a segment outside the snapshots, ending before it starts or not after
    /// the one before (`InvalidFile { field: "segments[i]" }`).
    pub fn with_segments(mut self, track: &CirTrackOutput) -> Result<TrackErrorView> {
        let n = self.t_s.len();
        check_len("track states (one per t_s)", n, track.states.len())?;
        let segments = &track.segments;
        let mut next = 0;
        let mut spans = Vec::with_capacity(segments.len());
        let mut track_m = Vec::new();
        for (i, g) in segments.iter().enumerate() {
            if g.first < next || g.last < g.first || g.last >= n {
                return Err(Error::InvalidFile {
                    field: alloc::format!("segments[{i}]"),
                    reason: alloc::format!(
                        "snapshots {} … {} are not after the previous segment (from {next}) \
                         within 0 … {}",
                        g.first,
                        g.last,
                        n.saturating_sub(1)
                    ),
                });
            }
            next = g.last + 1;
            let runs = runs(&track.states[g.first..=g.last]);
            let lost = g.end != "end";
            spans.push(SegmentSpan {
                first: g.first,
                last: g.last,
                t_first_s: g.t_first_s,
                t_last_s: g.t_last_s,
                end: g.end.into(),
                lost_s: lost.then(|| self.t_s[(g.last + 1).min(n - 1)]),
                lost_m: runs.last().and_then(|r| r.last()).copied().filter(|_| lost),
            });
            track_m.extend(runs);
        }
        self.segments = spans;
        self.track_m = track_m;
        Ok(self)
    }
}

/// Runs of consecutive finite positions.
fn runs(states: &[Option<[Real; 4]>]) -> Vec<Vec<[Real; 2]>> {
    let mut out = Vec::new();
    let mut run = Vec::new();
    for x in states {
        match x {
            Some(x) if x[0].is_finite() && x[1].is_finite() => run.push([x[0], x[1]]),
            _ if !run.is_empty() => out.push(core::mem::take(&mut run)),
            _ => {}
        }
    }
    if !run.is_empty() {
        out.push(run);
    }
    out
}

/// The view of a track: `states[s]` the filter's `[x, y, vx, vy]` at `t_s[s]` (`None` before
/// the track starts), `truth[s]` the true state when known (an empty `truth`: none); no
/// segments ([`TrackErrorView::with_segments`] adds a recording's).
/// Errors: `states` or a non-empty `truth` not one per time (`LengthMismatch`).
pub fn track_errors(
    t_s: &[Real],
    states: &[Option<[Real; 4]>],
    truth: &[Option<[Real; 4]>],
) -> Result<TrackErrorView> {
    check_len("track states (one per t_s)", t_s.len(), states.len())?;
    if !truth.is_empty() {
        check_len("truth states (one per t_s)", t_s.len(), truth.len())?;
    }
    let error_m: Vec<Option<Real>> = (0..t_s.len())
        .map(|s| {
            let (x, r) = (states[s]?, (*truth.get(s)?)?);
            let (dx, dy) = (x[0] - r[0], x[1] - r[1]);
            let e = sqrt(dx * dx + dy * dy);
            e.is_finite().then_some(e)
        })
        .collect();
    let mut sorted: Vec<Real> = error_m.iter().flatten().copied().collect();
    sorted.sort_by(Real::total_cmp);
    let n = sorted.len();
    let cdf = sorted
        .iter()
        .enumerate()
        .map(|(k, &e)| (e, (k + 1) as Real / n as Real))
        .collect();
    Ok(TrackErrorView {
        t_s: t_s.to_vec(),
        track_m: runs(states),
        truth_m: runs(truth),
        stats: ErrorStats::of(&sorted),
        error_m,
        cdf,
        track_start: states.iter().position(Option::is_some),
        segments: Vec::new(),
    })
}

#[cfg(test)]
mod tests;
