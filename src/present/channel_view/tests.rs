use super::*;
use crate::channel::{DelayEstimate, PathEstimate, RateEstimate};
use crate::math::{cos, sin, PI};
use crate::track::gating::StaticCluster;

/// `α·e^{−j2πf_nτ}` (C1 with `P = 1`, no noise) at `n` frequencies centred on 0, spacing `df`.
fn one_path(n: usize, df: Real, alpha: Real, range_m: Real) -> (Vec<Real>, Vec<Complex>) {
    let f: Vec<Real> = (0..n)
        .map(|k| (k as Real - (n - 1) as Real / 2.0) * df)
        .collect();
    let tau = range_m / SPEED_OF_LIGHT;
    let h = f
        .iter()
        .map(|f| {
            let ph = -2.0 * PI * f * tau;
            Complex::new(alpha * cos(ph), alpha * sin(ph))
        })
        .collect();
    (f, h)
}

#[test]
fn hand_computed_error_statistics() {
    // Sorted: 0.1 0.2 0.3 0.4 0.5 0.8 1.0 2.0 3.0 5.0 (n = 10): the 50 % quantile is the
    // ⌈5⌉-th = 0.5, the 90 % the ⌈9⌉-th = 3.0; 6 of 10 are strictly below 1 m (1.0 is not).
    let e = [0.5, 2.0, 0.1, 1.0, 3.0, 0.2, 0.4, 0.3, 0.8, 5.0, Real::NAN];
    let s = ErrorStats::of(&e).unwrap();
    assert_eq!(s.count, 10);
    assert_eq!((s.median_m, s.p90_m, s.max_m), (0.5, 3.0, 5.0));
    assert_eq!(s.fraction_below_1m, 0.6);
    // Σe² = 40.19.
    assert!((s.rms_m - (40.19 as Real / 10.0).sqrt()).abs() < 1e-12);
    // n = 3: ⌈1.5⌉ = 2nd, ⌈2.7⌉ = 3rd; F(2) = 2/3 < 0.9, so 3 is the smallest e with F ≥ 0.9.
    let s = ErrorStats::of(&[3.0, 1.0, 2.0]).unwrap();
    assert_eq!((s.median_m, s.p90_m), (2.0, 3.0));
    assert_eq!(quantile_pct(&[1.0, 2.0], 0), 1.0);
    assert_eq!(quantile_pct(&[1.0, 2.0], 100), 2.0);
    assert!(ErrorStats::of(&[]).is_none());
    assert!(ErrorStats::of(&[Real::INFINITY]).is_none());
}

#[test]
fn one_path_peaks_at_its_range_and_power() {
    // N = 241 bins of 0.5 MHz (B ≈ 120 MHz); the path at 30 m, |α| = 0.01 √W: the profile's
    // peak is |α|²·N²/N² = 10⁻⁴ W = −40 dB, on the row at 30 m (rows at 0, 0.25, … m).
    let (f, h) = one_path(241, 0.5e6, 0.01, 30.0);
    let t: Vec<Real> = (0..5).map(|k| k as Real * 0.1).collect();
    let mut cfg = ImageConfig::new([-0.125, 59.875]);
    cfg.rows = 240;
    let img = delay_image(&f, &t, |_| h.as_slice(), &cfg).unwrap();
    assert_eq!((img.cols(), img.rows, img.db.len()), (5, 240, 1200));
    assert!(img.r0_m.abs() < 1e-12 && (img.dr_m - 0.25).abs() < 1e-12);
    let (j, peak) = (0..240)
        .map(|j| (j, img.db[j * 5 + 2]))
        .fold((0, Real::MIN), |a, b| if b.1 > a.1 { b } else { a });
    assert_eq!(j, 120);
    assert!((peak + 40.0).abs() < 1e-9, "{peak}");
    // Clipped 40 dB below the maximum; all values finite.
    assert!((img.db_range[0] + 80.0).abs() < 1e-9 && (img.db_range[1] + 40.0).abs() < 1e-9);
    assert!(img.db.iter().all(|v| v.is_finite() && *v >= -80.0 - 1e-9));
    // The first sidelobe of the Dirichlet kernel is ≈ 13.3 dB down, 1.5 resolution cells
    // (1.5·c/(N·Δf) ≈ 3.73 m) away: the row at 33.75 m.
    let side = img.db[(120 + 15) * 5 + 2] - peak;
    assert!((side + 13.3).abs() < 0.5, "{side}");
}

/// The image by the direct sum (the Horner evaluation `delay_image` used before the chirp-z
/// transform): powers per cell, row-major.
fn direct_powers(f: &[Real], hs: &[Vec<Complex>], range_m: [Real; 2], rows: usize) -> Vec<Real> {
    let n = f.len();
    let df = (f[n - 1] - f[0]) / (n - 1) as Real;
    let dr = (range_m[1] - range_m[0]) / rows as Real;
    let cols = hs.len();
    let z: Vec<Complex> = (0..rows)
        .map(|j| {
            let phase = 2.0 * PI * df * (range_m[0] + (j as Real + 0.5) * dr) / SPEED_OF_LIGHT;
            Complex::new(cos(phase), sin(phase))
        })
        .collect();
    let mut out = vec![0.0; rows * cols];
    for (i, h) in hs.iter().enumerate() {
        for (j, zj) in z.iter().enumerate() {
            let mut acc = h[n - 1];
            for hn in h[..n - 1].iter().rev() {
                acc = acc * zj + hn;
            }
            out[j * cols + i] = acc.norm_sqr() / (n * n) as Real;
        }
    }
    out
}

/// Four paths 6 to 46 dB above a noise floor, over ranges inside and beyond the unambiguous
/// range: every value of the image equals the direct sum's, clipped the same way, to 1e-6 dB
/// within 60 dB of the image's maximum (the chirp-z transform is exact up to rounding), and the
/// powers to 1e-12 of the largest.
#[test]
fn image_equals_the_direct_sum() {
    let n = 241;
    let df = 0.5e6;
    let f: Vec<Real> = (0..n).map(|k| 2.4e9 + k as Real * df).collect();
    let t: Vec<Real> = (0..7).map(|k| k as Real * 0.1).collect();
    let hs: Vec<Vec<Complex>> = t
        .iter()
        .enumerate()
        .map(|(s, &ts)| {
            let mut h = vec![Complex::new(0.0, 0.0); n];
            for (r, a) in [
                (12.0, 0.02),
                (20.3, 0.01),
                (25.0 + 9.0 * ts, 0.003),
                (31.7, 1e-4),
            ] {
                let (_, p) = one_path(n, df, a, r);
                h.iter_mut().zip(&p).for_each(|(x, y)| *x += y);
            }
            for (k, x) in h.iter_mut().enumerate() {
                let u = ((k * 7919 + s * 104729) % 1000) as Real / 1000.0 - 0.5;
                let v = ((k * 6007 + s * 7727) % 1000) as Real / 1000.0 - 0.5;
                *x += Complex::new(1e-4 * u, 1e-4 * v);
            }
            h
        })
        .collect();
    for (range_m, rows, floor) in [
        ([5.0, 45.0], 300, ImageFloor::Global),
        ([0.0, 60.0], 37, ImageFloor::Column),
        ([-700.0, 1300.0], 300, ImageFloor::Global),
        ([29.0, 29.5], 1, ImageFloor::Global),
    ] {
        let mut cfg = ImageConfig::new(range_m);
        cfg.rows = rows;
        cfg.floor = floor;
        cfg.dynamic_range_db = 60.0;
        let img = delay_image(&f, &t, |s| hs[s].as_slice(), &cfg).unwrap();
        let direct = direct_powers(&f, &hs, range_m, rows);
        let top = direct.iter().copied().fold(0.0, Real::max);
        let want = to_db(direct.clone(), t.clone(), img.r0_m, img.dr_m, rows, &cfg);
        for (k, (a, b)) in img.db.iter().zip(&want.db).enumerate() {
            assert!((a - b).abs() < 1e-6, "{range_m:?} cell {k}: {a} vs {b} dB");
        }
        assert!((img.db_range[1] - want.db_range[1]).abs() < 1e-6);
        // The powers themselves (before dB and clipping).
        let mut again = cfg;
        again.dynamic_range_db = DELAY_IMAGE_DR_DB.max;
        let img = delay_image(&f, &t, |s| hs[s].as_slice(), &again).unwrap();
        for (v, d) in img.db.iter().zip(&direct) {
            let p = crate::math::db_to_linear(*v);
            assert!((p - d).abs() <= 1e-12 * top, "{range_m:?}: {p} vs {d}");
        }
    }
}

#[test]
fn many_snapshots_are_decimated_and_bad_input_is_named() {
    let (f, h) = one_path(16, 1e6, 1.0, 10.0);
    let t: Vec<Real> = (0..1000).map(|k| k as Real * 2.048e-3).collect();
    let mut cfg = ImageConfig::new([0.0, 100.0]);
    cfg.max_cols = 100;
    cfg.rows = 10;
    let img = delay_image(&f, &t, |_| h.as_slice(), &cfg).unwrap();
    assert_eq!(img.cols(), 100);
    // Column i shows snapshot ⌊(i + ½)·10⌋ = 10i + 5.
    assert_eq!(img.t_s[0], t[5]);
    assert_eq!(img.t_s[99], t[995]);
    let mut bent = f.clone();
    bent[3] += 0.1e6;
    let e = delay_image(&bent, &t, |_| h.as_slice(), &cfg).unwrap_err();
    assert_eq!(e.field(), Some("freq_hz"), "{e}");
    let e = delay_image(&f, &t, |_| &h[..3], &cfg).unwrap_err();
    assert!(matches!(e, Error::LengthMismatch { .. }), "{e}");
    cfg.rows = 301;
    assert!(matches!(
        delay_image(&f, &t, |_| h.as_slice(), &cfg),
        Err(Error::SizeLimit { max: 300, .. })
    ));
    cfg.rows = 10;
    let e = delay_image(&f, &[], |_| h.as_slice(), &cfg).unwrap_err();
    assert!(matches!(e, Error::SizeLimit { value: 0, .. }), "{e}");
    let zero = vec![Complex::new(0.0, 0.0); 16];
    let img = delay_image(&f, &t[..3], |_| zero.as_slice(), &cfg).unwrap();
    assert!(img.db.iter().all(|v| v.is_finite()));
}

#[test]
fn points_bands_and_ranges() {
    let t = [0.0, 1.0];
    let est = vec![
        vec![DelayEstimate {
            delay_s: 20.0 / SPEED_OF_LIGHT,
            amplitude: 0.1,
            sigma_s: None,
        }],
        vec![
            DelayEstimate {
                delay_s: Real::NAN,
                amplitude: 1.0,
                sigma_s: None,
            },
            DelayEstimate {
                delay_s: 1e-7,
                amplitude: 0.0,
                sigma_s: None,
            },
        ],
    ];
    let p = delay_points(&t, &est);
    assert_eq!(p.len(), 1);
    assert!((p[0].range_m - 20.0).abs() < 1e-12 && (p[0].amplitude_db + 20.0).abs() < 1e-12);
    assert_eq!(p[0].range_rate_mps, None);
    let cal = LinkCalibration {
        clusters: vec![StaticCluster {
            mean_s: 10.0 / SPEED_OF_LIGHT,
            sigma_s: 0.1 / SPEED_OF_LIGHT,
            count: 3,
            snapshots: 3,
            amplitude_db_mean: None,
            amplitude_db_sigma: None,
        }],
    };
    let b = static_bands(&cal);
    assert!((b[0].mean_m - 10.0).abs() < 1e-12 && (b[0].halfwidth_m - 0.3).abs() < 1e-12);
    // Values from 9.7 to 20 m: margin max(0.05·10.3, 1) = 1 m.
    let r = suggest_range_m(&p, &b, &[], Real::INFINITY);
    assert!(
        (r[0] - 8.7).abs() < 1e-9 && (r[1] - 21.0).abs() < 1e-9,
        "{r:?}"
    );
    assert_eq!(suggest_range_m(&[], &[], &[], 5.0), [0.0, 5.0]);
    let fig = DelayFigure::new(&[], Vec::new());
    assert_eq!((fig.t_range_s, fig.amplitude_db_range), ([0.0, 1.0], None));
}

#[test]
fn track_errors_before_the_start_and_without_a_start() {
    let t = [0.0, 1.0, 2.0, 3.0];
    let truth: Vec<Option<[Real; 4]>> = (0..4).map(|k| Some([k as Real, 0.0, 1.0, 0.0])).collect();
    let states = [
        None,
        Some([1.0, 0.3, 1.0, 0.0]),
        Some([2.0, -0.4, 1.0, 0.0]),
        Some([6.0, 4.0, 1.0, 0.0]),
    ];
    let v = track_errors(&t, &states, &truth).unwrap();
    assert_eq!(v.track_start, Some(1));
    assert_eq!(v.error_m[0], None);
    assert!((v.error_m[3].unwrap() - 5.0).abs() < 1e-12);
    assert_eq!(v.cdf.len(), 3);
    assert_eq!(v.cdf[2], (5.0, 1.0));
    let s = v.stats.unwrap();
    assert_eq!((s.count, s.p90_m, s.median_m), (3, 5.0, 0.4));
    assert_eq!(
        (v.track_m.len(), v.truth_m.len(), v.track_m[0].len()),
        (1, 1, 3)
    );
    let never = track_errors(&t, &[None; 4], &truth).unwrap();
    assert!(never.stats.is_none() && never.cdf.is_empty() && never.track_start.is_none());
    let no_truth = track_errors(&t, &states, &[]).unwrap();
    assert!(no_truth.stats.is_none() && no_truth.truth_m.is_empty());
    assert!(matches!(
        track_errors(&t, &states[..2], &truth),
        Err(Error::LengthMismatch { .. })
    ));
}

/// A track of `states` at `t` with `segments` `(first, last, end)` (the other fields empty).
fn track_with(
    t: &[Real],
    states: &[Option<[Real; 4]>],
    segments: &[(usize, usize, &'static str)],
) -> CirTrackOutput {
    use crate::study::{CirStart, SegmentDoc, TrackStart};
    let fix = |k: usize| CirStart {
        snapshot: k,
        t_s: t.get(k).copied().unwrap_or(Real::NAN),
        fix: TrackStart {
            position_m: [0.0; 2],
            covariance_m2: [[1.0, 0.0], [0.0, 1.0]],
            termination: "converged",
            links_used: 4,
            delays_used_s: Vec::new(),
            choices: Vec::new(),
        },
    };
    CirTrackOutput {
        t_s: t.to_vec(),
        states: states.to_vec(),
        covariances: vec![None; t.len()],
        links_used: vec![0; t.len()],
        delays_used_s: vec![Vec::new(); t.len()],
        sigmas_used_s: vec![Vec::new(); t.len()],
        choices: vec![Vec::new(); t.len()],
        static_removed: vec![Vec::new(); t.len()],
        start: segments.first().map(|g| fix(g.0)),
        segments: segments
            .iter()
            .map(|&(first, last, end)| SegmentDoc {
                first,
                last,
                t_first_s: t.get(first).copied().unwrap_or(Real::NAN),
                t_last_s: t.get(last).copied().unwrap_or(Real::NAN),
                end,
                confirmed_at: first,
                hits: 6,
                start: fix(first),
            })
            .collect(),
    }
}

/// Two segments (2…6 lost by innovation, 10…19 to the end): the map's track is one line per
/// segment (none across the gap), the loss is at the snapshot after the first's last, where
/// its last position was; errors stay as `track_errors` gave them. Overlapping, reversed or
/// out-of-range segments and a track of another length are named errors.
#[test]
fn segments_split_the_track_and_mark_the_loss() {
    let t: Vec<Real> = (0..20).map(|k| k as Real * 0.5).collect();
    let truth: Vec<Option<[Real; 4]>> = t.iter().map(|&ts| Some([ts, 0.0, 2.0, 0.0])).collect();
    let states: Vec<Option<[Real; 4]>> = (0..20)
        .map(|k| (2..=6).contains(&k) || k >= 10)
        .zip(&t)
        .map(|(on, &ts)| on.then_some([ts, 0.3, 2.0, 0.0]))
        .collect();
    let plain = track_errors(&t, &states, &truth).unwrap();
    let track = track_with(&t, &states, &[(2, 6, "innovation"), (10, 19, "end")]);
    let view = plain.clone().with_segments(&track).unwrap();
    assert_eq!(view.error_m, plain.error_m);
    assert_eq!(view.stats, plain.stats);
    assert_eq!(view.track_m.len(), 2);
    assert_eq!(view.track_m[0].len(), 5);
    assert_eq!(view.track_m[1].len(), 10);
    assert_eq!(view.track_m[0][4], [3.0, 0.3]);
    let lost = &view.segments[0];
    assert_eq!((lost.first, lost.last), (2, 6));
    assert_eq!(lost.lost_s, Some(3.5));
    assert_eq!(lost.lost_m, Some([3.0, 0.3]));
    assert_eq!(lost.loss_label().as_deref(), Some("lost: innovation"));
    let last = &view.segments[1];
    assert_eq!(
        (last.lost_s, last.lost_m, last.loss_label()),
        (None, None, None)
    );
    assert_eq!(last.end_name(), "end of the recording");
    for bad in [
        vec![(2, 6, "misses"), (5, 19, "end")],
        vec![(6, 2, "misses")],
        vec![(2, 20, "end")],
    ] {
        let err = plain
            .clone()
            .with_segments(&track_with(&t, &states, &bad))
            .unwrap_err();
        assert!(
            matches!(&err, Error::InvalidFile { field, .. } if field.starts_with("segments[")),
            "{bad:?}: {err:?}"
        );
    }
    let short = track_with(&t[..10], &states[..10], &[]);
    assert!(matches!(
        plain.with_segments(&short),
        Err(Error::LengthMismatch { .. })
    ));
}

/// Issue 38 item 7: one stray estimate (370 m among a thousand within 10–50 m) does not stretch
/// the range axis; a cluster of estimates at the edge of the bulk is kept.
#[test]
fn the_range_axis_is_robust_to_outliers() {
    let mut p: Vec<DelayPoint> = (0..1000)
        .map(|k| DelayPoint {
            t_s: k as Real * 0.05,
            range_m: 10.0 + 40.0 * (k % 100) as Real / 99.0,
            amplitude_db: -80.0,
            range_rate_mps: None,
        })
        .collect();
    let clean = suggest_range_m(&p, &[], &[], Real::INFINITY);
    assert!(
        (clean[0] - 8.0).abs() < 1e-9 && (clean[1] - 52.0).abs() < 1e-9,
        "{clean:?}"
    );
    p.push(DelayPoint {
        t_s: 3.0,
        range_m: 370.0,
        amplitude_db: -90.0,
        range_rate_mps: None,
    });
    assert_eq!(suggest_range_m(&p, &[], &[], Real::INFINITY), clean);
    // A truth beyond the estimates still widens it (the truth is never an outlier).
    let truth = [TruthCurve {
        kind: "person".into(),
        primary: true,
        points: vec![(0.0, 70.0)],
    }];
    let r = suggest_range_m(&p, &[], &truth, Real::INFINITY);
    assert!((r[1] - 73.0).abs() < 1e-9, "{r:?}");
}

/// A front end's path estimates (issue 42 §2) keep their range rate and σ as points; a
/// non-finite rate is dropped (the point stays), and the JSON of a point without a rate has no
/// `range_rate_mps` key (figures made before Doppler read back unchanged).
#[test]
fn points_carry_the_range_rates() {
    let path = |range_m: Real, rate: Option<(Real, Real)>| PathEstimate {
        delay_s: range_m / SPEED_OF_LIGHT,
        alpha: Complex::new(0.0, 0.01),
        sigma_s: 1e-10,
        snr: 100.0,
        range_rate: rate.map(|(r, s)| RateEstimate {
            range_rate_mps: r,
            sigma_mps: s,
            doppler_hz: -r / 0.05,
        }),
    };
    let est = vec![vec![
        path(20.0, Some((1.25, 0.125))),
        path(30.0, None),
        path(40.0, Some((Real::NAN, 0.1))),
    ]];
    let p = delay_points(&[0.5], &est);
    assert_eq!(p.len(), 3);
    assert_eq!(p[0].range_rate_mps, Some([1.25, 0.125]));
    assert!((p[0].amplitude_db + 40.0).abs() < 1e-12);
    assert_eq!((p[1].range_rate_mps, p[2].range_rate_mps), (None, None));
    let json = serde_json::to_string(&p).unwrap();
    assert_eq!(json.matches("range_rate_mps").count(), 1, "{json}");
    let back: Vec<DelayPoint> = serde_json::from_str(&json).unwrap();
    assert_eq!(back, p);
}
