use super::*;
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
