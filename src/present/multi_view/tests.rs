//! The several-people documents read back, drawn as a map view and written as data files: every
//! number of the CSV and JSON compared bit for bit with the run's.

use super::*;
use crate::study::TruthTarget;

/// Awkward doubles: no short decimal, tiny, huge, negative zero.
fn awkward(k: usize, i: usize, j: usize) -> f64 {
    let base = (k as f64 + 1.0) / 3.0 + (i as f64) * 0.1 + (j as f64) * 1e-7;
    match (k + i + j) % 7 {
        0 => -0.0,
        1 => base * 1e-300,
        2 => base * 1e300 / 7.0,
        3 => -base,
        _ => base + 0.2,
    }
}

/// A run of `scans` scans: two people (labels 10, 11; 11 leaves after scan 3), tracks 4 (all
/// scans but scan 2), 7 (from scan 1) and 9 (scans 3 … 4), so track 4's line is split.
fn run(scans: usize) -> PeopleRun {
    let t_s: Vec<f64> = (0..scans).map(|k| k as f64 * 0.1).collect();
    let truth = MultiTruth {
        t_s: t_s.clone(),
        targets: (0..scans)
            .map(|k| {
                [10u64, 11]
                    .iter()
                    .filter(|&&l| l == 10 || k <= 3)
                    .map(|&label| TruthTarget {
                        label,
                        state: core::array::from_fn(|j| awkward(k, label as usize, j)),
                    })
                    .collect()
            })
            .collect(),
    };
    let present = |label: u64, k: usize| match label {
        4 => k != 2,
        7 => k >= 1,
        _ => (3..=4).contains(&k),
    };
    let targets: Vec<Vec<TargetDoc>> = (0..scans)
        .map(|k| {
            [4u64, 7, 9]
                .iter()
                .filter(|&&l| present(l, k))
                .map(|&label| TargetDoc {
                    label,
                    state: [
                        1.0 + label as f64 + k as f64 * 0.3,
                        2.0 - k as f64 * 0.01,
                        0.5,
                        -0.25,
                    ],
                    covariance: core::array::from_fn(|i| {
                        core::array::from_fn(|j| {
                            if i == j {
                                0.01 * (i + 1) as f64 + awkward(k, i, j).abs() * 1e-9
                            } else if (i, j) == (0, 1) || (i, j) == (1, 0) {
                                0.002
                            } else {
                                awkward(k, i, j) * 1e-12
                            }
                        })
                    }),
                    existence: 1.0 - 1.0 / (k as f64 + 3.0),
                })
                .collect()
        })
        .collect();
    let tracks = crate::study::lives(&targets);
    let n = scans;
    let score = MultiScoreDoc {
        c_m: 1.0,
        gospa_m: (0..n).map(|k| awkward(k, 1, 2).abs()).collect(),
        localisation_m2: (0..n).map(|k| awkward(k, 2, 2).abs()).collect(),
        missed_m2: (0..n).map(|k| awkward(k, 3, 2).abs()).collect(),
        false_m2: (0..n).map(|k| awkward(k, 4, 2).abs()).collect(),
        mean_gospa_m: 1.0 / 7.0,
        switches: 1,
        mean_cardinality_error: 2.0 / 3.0,
    };
    PeopleRun {
        truth,
        track: MultiTrackOutput {
            method: "pmb".into(),
            settings: MultiSettings::default(),
            t_s,
            targets,
            tracks,
            static_removed: vec![0; n],
        },
        score,
    }
}

/// The run as the page's document: `{walkers, truth, track, score, ellipses, gospa_label}`.
fn doc_text(r: &PeopleRun) -> String {
    serde_json::json!({
        "walkers": 2, "seed": 1, "truth": r.truth, "track": r.track, "score": r.score,
        "ellipses": [], "gospa_label": "GOSPA",
    })
    .to_string()
}

#[test]
fn the_document_reads_back_as_the_run() {
    let r = run(6);
    let back = people_doc_from_json(&doc_text(&r)).unwrap();
    assert_eq!(back, r);
    // Bit for bit (PartialEq takes −0 for +0): the documents' JSON texts are equal.
    assert_eq!(doc_text(&back), doc_text(&r));
    assert_eq!(r.track.tracks.len(), 3, "{:?}", r.track.tracks);
}

#[test]
fn csv_rows_read_back_bit_for_bit() {
    let r = run(6);
    let text = people_data_text(&r, "csv").unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(head.len(), 25);
    assert_eq!(
        head[..9],
        [
            "scan",
            "t_s",
            "kind",
            "label",
            "x_m",
            "y_m",
            "vx_mps",
            "vy_mps",
            "existence"
        ]
    );
    assert_eq!(head[9], "P_0_0");
    assert_eq!(head[24], "P_3_3");
    let bits = |s: &str| s.parse::<f64>().unwrap().to_bits();
    let (mut truth_rows, mut track_rows) = (0, 0);
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 25, "{line}");
        let k: usize = f[0].parse().unwrap();
        let label: u64 = f[3].parse().unwrap();
        match f[2] {
            "truth" => {
                truth_rows += 1;
                assert_eq!(bits(f[1]), r.truth.t_s[k].to_bits());
                let t = r.truth.targets[k]
                    .iter()
                    .find(|t| t.label == label)
                    .unwrap();
                for j in 0..4 {
                    assert_eq!(bits(f[4 + j]), t.state[j].to_bits(), "{line}");
                }
                assert!(f[8..].iter().all(|c| c.is_empty()), "{line}");
            }
            "track" => {
                track_rows += 1;
                assert_eq!(bits(f[1]), r.track.t_s[k].to_bits());
                let t = r.track.targets[k]
                    .iter()
                    .find(|t| t.label == label)
                    .unwrap();
                for j in 0..4 {
                    assert_eq!(bits(f[4 + j]), t.state[j].to_bits(), "{line}");
                }
                assert_eq!(bits(f[8]), t.existence.to_bits());
                for c in 0..16 {
                    assert_eq!(
                        bits(f[9 + c]),
                        t.covariance[c / 4][c % 4].to_bits(),
                        "{line}"
                    );
                }
            }
            other => panic!("kind {other}"),
        }
    }
    let count = |v: &[Vec<TruthTarget>]| v.iter().map(Vec::len).sum::<usize>();
    assert_eq!(truth_rows, count(&r.truth.targets));
    assert_eq!(
        track_rows,
        r.track.targets.iter().map(Vec::len).sum::<usize>()
    );
    assert!(text.contains("-0,"), "negative zero written as -0");
}

#[test]
fn json_data_holds_the_truth_track_and_score() {
    let r = run(5);
    let text = people_data_text(&r, "json").unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["truth"], serde_json::to_value(&r.truth).unwrap());
    assert_eq!(v["track"], serde_json::to_value(&r.track).unwrap());
    assert_eq!(v["score"], serde_json::to_value(&r.score).unwrap());
    // And read back as a document: the same run.
    assert_eq!(people_doc_from_json(&text).unwrap(), r);
}

#[test]
fn the_map_view_follows_the_tracks_up_to_the_scan() {
    let r = run(6);
    let v = people_map_view(&r.track, &r.truth, 4).unwrap();
    assert_eq!((v.step, v.t_s), (4, r.track.t_s[4]));
    assert_eq!(v.truth.len(), 2);
    assert_eq!(v.truth[0].len(), 6);
    assert_eq!(v.truth[1].len(), 4);
    let labels: Vec<u64> = v.tracks.iter().map(|t| t.label).collect();
    assert_eq!(labels, [4, 7, 9]);
    for (i, t) in v.tracks.iter().enumerate() {
        assert_eq!(t.colour, i);
        let now = r.track.targets[4]
            .iter()
            .find(|x| x.label == t.label)
            .unwrap();
        assert_eq!(t.position, Some([now.state[0], now.state[1]]));
        let cov = Mat4::from_fn(|i, j| now.covariance[i][j]);
        assert_eq!(
            t.ellipse,
            position_ellipse(&Vec4::from(now.state), &cov, 1.0)
        );
        assert!(t.ellipse.is_some());
    }
    // Track 4 missed scan 2: two runs, scans 0–1 and 3–4.
    let t4 = &v.tracks[0];
    assert_eq!(t4.runs.len(), 2);
    assert_eq!((t4.runs[0].len(), t4.runs[1].len()), (2, 2));
    assert_eq!(
        t4.runs[1][1],
        [
            r.track.targets[4][0].state[0],
            r.track.targets[4][0].state[1]
        ]
    );
    // Before track 9 starts, it is not drawn; past the end is the last scan.
    assert_eq!(
        people_map_view(&r.track, &r.truth, 2).unwrap().tracks.len(),
        2
    );
    let last = people_map_view(&r.track, &r.truth, 1000).unwrap();
    assert_eq!(last.step, 5);
    assert_eq!(last.tracks[2].position, None, "track 9 ended at scan 4");
}

#[test]
fn bad_documents_and_formats_are_named_errors() {
    let r = run(3);
    let e = people_data_text(&r, "xml").unwrap_err().to_string();
    assert!(
        e.contains("format: \\\"xml\\\"") || e.contains("format: \"xml\""),
        "{e}"
    );
    assert!(matches!(
        people_doc_from_json("{"),
        Err(Error::Parse { .. })
    ));
    assert!(matches!(
        people_doc_from_json("{}"),
        Err(Error::Parse { .. })
    ));
    let mut bad = r.clone();
    bad.track.targets.pop();
    let e = people_doc_from_json(&doc_text(&bad)).unwrap_err();
    assert!(matches!(e, Error::LengthMismatch { .. }), "{e}");
    let mut bad = r.clone();
    bad.track.tracks[0].last_scan = 3;
    let e = people_doc_from_json(&doc_text(&bad))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("track.tracks[0]:"), "{e}");
    let mut bad = r.clone();
    bad.score.gospa_m.push(0.0);
    let e = people_doc_from_json(&doc_text(&bad))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("score.gospa_m:"), "{e}");
    let empty = run(0);
    let e = people_map_view(&empty.track, &empty.truth, 0)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("track.t_s:"), "{e}");
}
