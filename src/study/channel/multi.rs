//! Several people in a recording (issue 41 §2, `cir track --targets auto`): the front end's
//! estimates ([`RecordingEstimates`], C5–C10) as the scans of unlabelled delays a measurements
//! file's `raw_steps` hold ([`recording_measurements`], the form `cir estimate --measurements`
//! writes), each σ̂_τ widened by the body's extent, tracked by [`track_multi`] with the statics'
//! clusters (E4) removing what is left of the static channel. The truth of a simulated recording
//! with further walkers reads as a [`MultiTruth`] ([`walkers_truth`]).
//!
//! The delays are weighted with the estimator's σ̂_τ (C4 at the fitted SNR) widened in
//! quadrature by the extent `σ_e/c` ([`super::ChannelRequest::extent_sigma_m`]), as `cir track` does:
//! a person's echo wanders over the body, a spread the estimator's σ̂ does not hold.

use alloc::vec::Vec;

use crate::channel::Snapshot;
use crate::error::{Cancel, Error, Result};
use crate::formats::Measurements;
use crate::math::{sqrt, Real, SPEED_OF_LIGHT};
use crate::measure::Model;
use crate::scenario::Area;
use crate::study::channel::RecordingEstimates;
use crate::study::multi::link_detections;
use crate::study::{track_scans, MultiSettings, MultiTrackOutput, MultiTruth, Scans, TruthTarget};
use crate::track::gating::Calibration;
use crate::track::multi::Scan;
use crate::track::ConstantVelocity;

/// `P_D` per link of a walker in a recording's estimates, the default of
/// [`recording_multi_settings`]: on the crossing walkers of `tests/tracking/cir_multi.rs`
/// (sensors2019, 20 Hz, background subtraction) an estimate lies within 1.5 ns of a walker's
/// bistatic delay in 0.51–0.78 of the link-snapshots (mean ≈ 0.62); a little above it, the
/// tracker keeps its tracks through a walker's fades.
pub const RECORDING_DETECTION: Real = 0.7;
/// Mean clutter delays per link and scan of a recording's estimates (the default of
/// [`recording_multi_settings`]), over [`RECORDING_CLUTTER_WINDOW_S`]. Measured on the same
/// recordings: 1.3–1.45 estimates per link-snapshot that are neither static nor within 1.5 ns
/// of a walker's delay, most of them within a few ns of a walker (an extended body fitted with
/// two paths): their density near the walkers is several times the uniform 1.45/150 ns, and the
/// tracker confirms more false targets with it, so the default is that density spread over
/// the window.
pub const RECORDING_CLUTTER: Real = 4.5;
/// The window of [`RECORDING_CLUTTER`], s: the estimates that are not static span ≈ 50–210 ns.
pub const RECORDING_CLUTTER_WINDOW_S: Real = 175e-9;

/// The body's extent as path length, m, that widens each estimate's σ̂ for the multi-target
/// tracker ([`cir_track_multi`]; `cir track --targets auto`'s default of `--extent-sigma-m`):
/// above the single-target track's [`super::EXTENT_SIGMA_M`], since two bodies' echoes also
/// pull each other's estimates (measured on the crossing walkers: the estimates within 1.5 ns
/// of a walker's delay scatter by 0.71–0.82 ns RMS, 0.21–0.25 m; with 0.3 m no label changed
/// after the first second in 7 of 10 seeds, with 0.2 m in 5).
pub const RECORDING_EXTENT_SIGMA_M: Real = 0.3;

/// The multi-target settings for a recording's estimates: [`MultiSettings::default`] with
/// [`RECORDING_DETECTION`], [`RECORDING_CLUTTER`] over [`RECORDING_CLUTTER_WINDOW_S`], and a
/// birth from at least four links' delays (all of `links` up to four; the default's `links − 2`
/// beyond six): a walker's echo via a wall, or two echoes of one body, fit three links' delays
/// too often.
pub fn recording_multi_settings(links: usize) -> MultiSettings {
    MultiSettings {
        detection_probability: RECORDING_DETECTION,
        clutter: RECORDING_CLUTTER,
        clutter_window_s: RECORDING_CLUTTER_WINDOW_S,
        birth_min_links: Some(links.saturating_sub(2).max(links.min(4)).max(3)),
        ..MultiSettings::default()
    }
}

/// The estimates as a measurements file (`cir estimate --measurements`): the first snapshot as
/// `initial_snapshot`, the others as `raw_steps` (`[delay, amplitude, σ]` where the estimate has
/// a σ), steps of `dt_s`, process noise `process_noise`. At least one snapshot.
pub fn recording_measurements(
    snapshots: &[Snapshot],
    dt_s: Real,
    process_noise: Real,
) -> Measurements {
    Measurements {
        dt_s,
        process_noise,
        initial_state: None,
        initial_covariance: None,
        initial_snapshot: snapshots.first().map(|s| Measurements::raw_step(s)),
        sigma_s: None,
        steps: None,
        raw_steps: Some(
            snapshots
                .iter()
                .skip(1)
                .map(|s| Measurements::raw_step(s))
                .collect(),
        ),
    }
}

/// The mean step of `t_s`, checked uniform within 1e-6 relative (a measurements file, and the
/// multi-target tracker, have one step; `cir estimate --measurements` checks with it too).
/// Errors name `t_s`.
pub fn uniform_step(t_s: &[Real]) -> Result<Real> {
    if t_s.len() < 2 {
        return Err(Error::InvalidFile {
            field: "t_s".into(),
            reason: alloc::format!("{} snapshots; at least 2 are needed (one step)", t_s.len()),
        });
    }
    let dt = (t_s[t_s.len() - 1] - t_s[0]) / (t_s.len() - 1) as Real;
    if let Some(k) = (1..t_s.len()).find(|&k| ((t_s[k] - t_s[k - 1]) - dt).abs() > 1e-6 * dt) {
        return Err(Error::InvalidFile {
            field: "t_s".into(),
            reason: alloc::format!(
                "the snapshots are not uniform in time (t_s[{k}] − t_s[{}] = {} s, the mean \
                 step is {dt} s)",
                k - 1,
                t_s[k] - t_s[k - 1]
            ),
        });
    }
    Ok(dt)
}

/// Tracks the people of a recording from its estimates (module docs): every snapshot (or CPI) a
/// scan, each estimate's σ̂ widened by `extent_sigma_m / c` (0: as estimated), with its range
/// rate and σ̂_ṙ where the front end read one over a CPI (issue 42 §3: a 2-D delay-and-rate
/// detection), the statics' clusters `calibration` removing static delays, the CV model of
/// intensity `process_noise`; the same scans `track_multi` would read from
/// [`recording_measurements`]'s file, plus the rates. The output's `t_s` are the estimates'
/// times. Asks `cancel` between scans.
///
/// Errors: a non-uniform or too short recording (`t_s`), a negative or non-finite
/// `extent_sigma_m`, and [`track_multi`]'s.
#[allow(clippy::too_many_arguments)]
pub fn cir_track_multi(
    model: &Model,
    area: &Area,
    calibration: &Calibration,
    est: &RecordingEstimates,
    settings: &MultiSettings,
    process_noise: Real,
    extent_sigma_m: Real,
    cancel: Cancel,
) -> Result<MultiTrackOutput> {
    if !(extent_sigma_m.is_finite() && extent_sigma_m >= 0.0) {
        return Err(Error::OutOfRange {
            field: "extent_sigma_m".into(),
            value: extent_sigma_m,
            allowed: "0 to 1e3 m",
        });
    }
    let dt = uniform_step(&est.t_s)?;
    let motion = ConstantVelocity::validated(dt, process_noise)?;
    let links = model.link_count();
    calibration.check_links(links)?;
    if est.len() > crate::track::MAX_STEPS {
        return Err(Error::InvalidFile {
            field: "t_s".into(),
            reason: alloc::format!(
                "{} scans, at most {} are allowed",
                est.len(),
                crate::track::MAX_STEPS
            ),
        });
    }
    let extent_s = extent_sigma_m / SPEED_OF_LIGHT;
    let mut removed = Vec::with_capacity(est.len());
    let scans: Vec<Scan> = est
        .paths
        .iter()
        .map(|snap| {
            let mut gone = 0;
            let scan = snap
                .iter()
                .take(links)
                .enumerate()
                .map(|(p, list)| {
                    let estimates = list.iter().map(|t| {
                        let e = &t.estimate;
                        (
                            e.delay_s,
                            Some(sqrt(e.sigma_s * e.sigma_s + extent_s * extent_s)),
                            e.range_rate.map(|r| (r.range_rate_mps, r.sigma_mps)),
                        )
                    });
                    link_detections(estimates, Some(&calibration.links[p]), &mut gone)
                })
                .collect();
            removed.push(gone);
            scan
        })
        .collect();
    let scans = Scans {
        scans: &scans,
        static_removed: removed,
        dt_s: dt,
    };
    let (mut out, _) = track_scans(
        model,
        area,
        motion,
        None,
        scans,
        settings,
        cancel,
        &|| 0.0,
        0.0,
    )?;
    out.t_s = est.t_s.clone();
    Ok(out)
}

/// The truth of a simulated recording with further walkers as a [`MultiTruth`]: label 0 the
/// main walker (`states`), label `i + 1` further walker `i` (`others[i]`), at every snapshot of
/// `t_s`. Errors: a walker whose states are not one per snapshot (`states`, `others[i]`).
pub fn walkers_truth(
    t_s: &[Real],
    states: &[[Real; 4]],
    others: &[Vec<[Real; 4]>],
) -> Result<MultiTruth> {
    let n = t_s.len();
    let walkers: Vec<&[[Real; 4]]> = core::iter::once(states)
        .chain(others.iter().map(Vec::as_slice))
        .collect();
    for (i, w) in walkers.iter().enumerate() {
        if w.len() != n {
            return Err(Error::InvalidFile {
                field: if i == 0 {
                    "states".into()
                } else {
                    alloc::format!("others[{}]", i - 1)
                },
                reason: alloc::format!("{} states for {n} snapshots", w.len()),
            });
        }
    }
    Ok(MultiTruth {
        t_s: t_s.to_vec(),
        targets: (0..n)
            .map(|k| {
                walkers
                    .iter()
                    .enumerate()
                    .map(|(label, w)| TruthTarget {
                        label: label as u64,
                        state: w[k],
                    })
                    .collect()
            })
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::channel::DelayEstimate;
    use crate::scenario::presets;
    use alloc::vec;

    fn est(t_s: Vec<Real>) -> RecordingEstimates {
        RecordingEstimates {
            t_s,
            recorded: vec![],
            paths: vec![],
            noise_var: vec![],
            alignment: vec![],
            work: vec![],
        }
    }

    /// The first snapshot is the initial one, the others the raw steps, each in
    /// [`Measurements::raw_step`]'s form (the σ kept where there is one).
    #[test]
    fn measurements_hold_every_snapshot_in_order() {
        let e = |d: Real, s: Option<Real>| DelayEstimate {
            delay_s: d,
            amplitude: 1.0,
            sigma_s: s,
        };
        let snaps = vec![
            vec![vec![e(1e-7, Some(1e-10))], vec![]],
            vec![vec![], vec![e(2e-7, None), e(3e-7, Some(2e-10))]],
            vec![vec![e(4e-7, None)], vec![]],
        ];
        let m = recording_measurements(&snaps, 0.05, 2.0);
        assert_eq!((m.dt_s, m.process_noise), (0.05, 2.0));
        assert_eq!(m.initial_snapshot, Some(Measurements::raw_step(&snaps[0])));
        let raw = m.raw_steps.unwrap();
        assert_eq!(raw.len(), 2);
        assert_eq!(raw[0], Measurements::raw_step(&snaps[1]));
        assert_eq!(raw[1], Measurements::raw_step(&snaps[2]));
        assert!(m.steps.is_none() && m.sigma_s.is_none() && m.initial_state.is_none());
    }

    /// The step is the mean one; a step off by more than 1e-6 relative, or a single snapshot,
    /// is an error naming `t_s`.
    #[test]
    fn the_step_must_be_uniform() {
        assert_eq!(uniform_step(&[0.0, 0.5, 1.0, 1.5]).unwrap(), 0.5);
        for bad in [&[0.0, 0.5, 1.1, 1.5][..], &[0.0][..], &[][..]] {
            let e = uniform_step(bad).unwrap_err();
            assert_eq!(e.field(), Some("t_s"), "{e}");
        }
        let e = uniform_step(&[0.0, 0.5, 1.1, 1.5]).unwrap_err().to_string();
        assert!(e.contains("t_s[2] − t_s[1]"), "{e}");
    }

    /// Label 0 the main walker, `i + 1` the further walker `i`; a walker without one state per
    /// snapshot is named.
    #[test]
    fn walkers_truth_labels_every_walker() {
        let a = [[1.0, 2.0, 0.0, 0.0], [1.1, 2.0, 1.0, 0.0]];
        let b = vec![[5.0, 6.0, 0.0, 1.0], [5.0, 6.1, 0.0, 1.0]];
        let t = walkers_truth(&[0.0, 0.1], &a, core::slice::from_ref(&b)).unwrap();
        assert_eq!(t.targets[1][0].label, 0);
        assert_eq!(t.targets[1][0].state, a[1]);
        assert_eq!(t.targets[1][1].label, 1);
        assert_eq!(t.targets[1][1].state, b[1]);
        let e = walkers_truth(&[0.0, 0.1], &a, &[b[..1].to_vec()]).unwrap_err();
        assert_eq!(e.field(), Some("others[0]"));
        let e = walkers_truth(&[0.0, 0.1, 0.2], &a, &[]).unwrap_err();
        assert_eq!(e.field(), Some("states"));
    }

    /// A bad extent, and a recording without a uniform step, are named before any tracking.
    #[test]
    fn bad_extent_and_steps_are_named() {
        let scenario = presets::preset("sensors2019").unwrap();
        let model = Model::new(&scenario).unwrap();
        let cal = Calibration {
            links: vec![Default::default(); model.link_count()],
        };
        let settings = recording_multi_settings(model.link_count());
        let run = |e: &RecordingEstimates, x: Real| {
            cir_track_multi(
                &model,
                &scenario.area_m,
                &cal,
                e,
                &settings,
                1.0,
                x,
                Cancel::NEVER,
            )
            .unwrap_err()
        };
        for x in [-0.1, Real::NAN, Real::INFINITY] {
            assert_eq!(run(&est(vec![0.0, 0.1]), x).field(), Some("extent_sigma_m"));
        }
        assert_eq!(run(&est(vec![0.0]), 0.3).field(), Some("t_s"));
        // Four links: a birth needs all four; eight: six (the default's links − 2).
        assert_eq!(settings.birth_min_links, Some(4));
        assert_eq!(recording_multi_settings(8).birth_min_links, Some(6));
        assert_eq!(recording_multi_settings(3).birth_min_links, Some(3));
    }
}
