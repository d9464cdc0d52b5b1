//! Sharded studies merged from their part files (issue 24): the unsharded sums again, digests
//! that do not depend on the layout, and impossible sums and bad headers as named errors.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use super::*;
use crate::math::Shard;
use crate::track::{FilterKind, UkfParams};

use serde_json::Value;

/// The part files of a Monte Carlo study (EKF and UKF, trajectories I and II, 40 × 1 runs of
/// 4 steps) in `n` shards, as `(path, JSON)`, and the unsharded study's sums.
fn mc_parts(n: usize) -> (Vec<(String, Value)>, Vec<crate::track::StudySums>) {
    let m = model();
    let track = TrackStudy::new(
        "sensors2019".into(),
        presets::preset("sensors2019").unwrap(),
        vec![TrackScenario::I, TrackScenario::II],
        ConstantVelocity::validated(0.1, 1.0).unwrap(),
        4,
    )
    .unwrap();
    let kinds = [FilterKind::Ekf, FilterKind::Ukf(UkfParams::default())];
    let study = MonteCarloStudy::new(track, 40, 1, 3, false, &kinds).unwrap();
    let config = study.config_doc().unwrap();
    let total = study.chunk_count();
    let run = |range: core::ops::Range<usize>| {
        let runs: Vec<FilterStudy> = (0..2)
            .map(|k| {
                let mut r = study.filter_study(k).unwrap();
                r.run_range(&m, range.clone(), &mut Sequential::new(), &mut |_, _| {})
                    .unwrap();
                r
            })
            .collect();
        MonteCarloStudy::part_sums(&runs)
    };
    let parts = (0..n)
        .map(|i| {
            let shard = Shard::new(i, n).unwrap();
            let doc = ShardDoc::new(shard, "chunks", total);
            let timing = Timing {
                threads: 1,
                wall_time_s: vec![0.5, 0.25],
            };
            let sums = run(shard.range(total));
            let part = PartFile::new("montecarlo", &config, &doc, &timing, &sums);
            (
                format!("part{i}.json"),
                serde_json::to_value(&part).unwrap(),
            )
        })
        .collect();
    (parts, run(0..total))
}

/// `parts` as texts.
fn texts(parts: &[(String, Value)]) -> Vec<(String, String)> {
    parts
        .iter()
        .map(|(p, v)| (p.clone(), v.to_string()))
        .collect()
}

/// Merges Monte Carlo `parts` (read and checked as a set first): the message of the error.
fn mc_merge(parts: &[(String, Value)]) -> core::result::Result<Vec<FilterStudy>, String> {
    let files = texts(parts);
    let set = PartSet::check(&files).map_err(|e| e.to_string())?;
    let mut load = |path: &str| {
        let (_, text) = files.iter().find(|(p, _)| p == path).unwrap();
        Ok(text.clone())
    };
    MonteCarloStudy::merge(&set, &mut load)
        .map(|(_, runs, _)| runs)
        .map_err(|e| e.to_string())
}

/// Sets the digest of part `v` to that of its (edited) sums: a part edited consistently,
/// which only the range checks can refuse.
fn redigest(v: &mut Value) {
    v["digest"] = Value::from(sums_digest(&v["sums"]).unwrap());
}

#[test]
fn merged_parts_equal_the_unsharded_sums_and_digests_are_deterministic() {
    let (parts, whole) = mc_parts(3);
    let runs = mc_merge(&parts).unwrap();
    let merged: Vec<_> = runs.iter().flat_map(FilterStudy::sums).collect();
    assert_eq!(merged, whole);
    // The same shard gives the same digest; a reformatted part keeps it.
    let (again, _) = mc_parts(3);
    assert_eq!(parts[1].1["digest"], again[1].1["digest"]);
    let mut pretty = texts(&parts);
    pretty[1].1 = serde_json::to_string_pretty(&parts[1].1).unwrap();
    assert!(PartSet::check(&pretty).is_ok());
    // The CRLB part of every filter of a trajectory is the same (what check_sums relies on).
    assert_eq!(whole[0].fisher, whole[1].fisher);
    assert_eq!(whole[2].fisher, whole[3].fisher);
}

/// The error of merging the 2-shard set with part 1 edited by `edit`, its digest then
/// recomputed when `redo`.
fn edited(edit: impl Fn(&mut Value), redo: bool) -> String {
    let (mut parts, _) = mc_parts(2);
    edit(&mut parts[1].1);
    if redo {
        redigest(&mut parts[1].1);
    }
    mc_merge(&parts).unwrap_err()
}

#[test]
fn impossible_monte_carlo_sums_are_named_errors() {
    fn set(path: &str, x: Value) -> impl Fn(&mut Value) + '_ {
        move |v: &mut Value| {
            let mut at = &mut v["sums"];
            for k in path.split('/') {
                at = match k.parse::<usize>() {
                    Ok(i) => &mut at[i],
                    Err(_) => &mut at[k],
                };
            }
            *at = x.clone();
        }
    }
    let cases: Vec<(String, &str)> = vec![
        (
            edited(set("1/squared_error/3", serde_json::json!([-3.2])), true),
            "part1.json: sums[1].squared_error[3]: -3.2 is negative",
        ),
        (
            edited(set("0/nees/2", serde_json::json!("nan")), true),
            "part1.json: sums[0].nees[2]: NaN is not finite",
        ),
        (
            edited(set("2/nees/1", serde_json::json!("inf")), true),
            "part1.json: sums[2].nees[1]: inf is not finite",
        ),
        (
            edited(set("0/squared_error/4", serde_json::json!([])), true),
            "part1.json: sums[0].squared_error[4]: 0, but 24 runs were counted",
        ),
        (
            edited(set("3/fisher/2/0", serde_json::json!([-1.0])), true),
            "part1.json: sums[3].fisher[2]: diagonal [-1, ",
        ),
        (
            edited(set("0/fisher/1/1", serde_json::json!([12345.0])), true),
            "part1.json: sums[0].fisher[1]: not symmetric (F21 = 12345",
        ),
        (
            edited(
                |v| {
                    let big = serde_json::json!([1e30]);
                    set("0/fisher/1/1", big.clone())(v);
                    set("0/fisher/1/2", big)(v);
                },
                true,
            ),
            "part1.json: sums[0].fisher[1]: not positive semi-definite",
        ),
        (
            edited(
                |v| {
                    let zero = serde_json::json!([[], [], [], []]);
                    let n = v["sums"][0]["fisher"].as_array().unwrap().len();
                    for s in [0, 1] {
                        for k in 0..n {
                            set(&format!("{s}/fisher/{k}"), zero.clone())(v);
                        }
                    }
                },
                true,
            ),
            "part1.json: sums[0].fisher: zero at every step, but 24 trajectories were counted",
        ),
        (
            edited(set("0/fisher/0/0", serde_json::json!([1.0])), true),
            "part1.json: sums[0].fisher[0]: not zero (step 0 has no measurement)",
        ),
        (
            edited(set("3/fisher/2/3", serde_json::json!([1e12])), true),
            "part1.json: sums[3].fisher[2]: not the Fisher sum of sums[2]",
        ),
        (
            edited(set("1/failed_runs", serde_json::json!(2)), true),
            "part1.json: sums[1].failed_runs: 2 failed + 24 counted is not the 24 runs of chunks [1, 3)",
        ),
        (
            edited(
                |v| {
                    set("1/failed_runs", serde_json::json!(24))(v);
                    set("1/runs", serde_json::json!(0))(v);
                },
                true,
            ),
            "part1.json: sums[1].squared_error[0]",
        ),
        (
            edited(set("2/trajectories", serde_json::json!(23)), true),
            "part1.json: sums[2].trajectories: 23, not the 24 trajectories of chunks [1, 3)",
        ),
        (
            edited(set("0/runs", serde_json::json!(-1)), true),
            "part1.json: sums[0].runs: invalid value: integer `-1`",
        ),
        (
            edited(
                |v| {
                    let long = Value::Array(vec![serde_json::json!([]); 100]);
                    set("0/nees", long)(v);
                },
                false,
            ),
            "part1.json: sums[0].nees: more than 64 entries",
        ),
        (
            edited(
                |v| {
                    let s = v["sums"].as_array_mut().unwrap();
                    s.pop();
                },
                true,
            ),
            "part1.json: sums: 3 entries, not 2 trajectories × 2 filters",
        ),
        // Corruption: any change of the sums without a new digest.
        (
            edited(set("1/squared_error/3/0", serde_json::json!(1.5)), false),
            "part1.json: sums do not match their digest",
        ),
        (
            edited(set("1/squared_error/3", serde_json::json!([])), false),
            "part1.json: sums do not match their digest",
        ),
    ];
    for (got, want) in cases {
        assert!(got.starts_with("merge: inconsistent part "), "{got}");
        assert!(got.contains(want), "want {want:?} in\n{got}");
    }
}

#[test]
fn bad_part_headers_are_named_errors() {
    let (parts, _) = mc_parts(2);
    let with = |edit: &dyn Fn(&mut Value)| {
        let mut p = parts.clone();
        edit(&mut p[1].1);
        PartSet::check(&texts(&p)).unwrap_err().to_string()
    };
    for (edit, want) in [
        (
            &(|v: &mut Value| v["timing"]["wall_time_s"][1] = serde_json::json!(-1.0))
                as &dyn Fn(&mut Value),
            "part1.json (timing.wall_time_s[1]: -1 is not a wall time (finite, ≥ 0 s))",
        ),
        (
            &|v: &mut Value| v["timing"]["wall_time_s"][0] = serde_json::json!("NaN"),
            "part1.json (timing.wall_time_s[0]: invalid type: string",
        ),
        (
            &|v: &mut Value| v["timing"]["threads"] = serde_json::json!(0),
            "part1.json (timing.threads: 0, not a thread count ≥ 1)",
        ),
        (
            &|v: &mut Value| {
                v["timing"]["wall_time_s"] = Value::Array(vec![serde_json::json!(1.0); 17])
            },
            "part1.json (timing.wall_time_s: more than 16 entries",
        ),
        (
            &|v: &mut Value| v["digest"] = serde_json::json!("sha256:00"),
            "part1.json (digest \"sha256:00\" is not sha256: and 64 lowercase hex digits)",
        ),
        (
            &|v: &mut Value| {
                v.as_object_mut().unwrap().remove("digest");
            },
            "part1.json (missing field `digest`",
        ),
        (
            &|v: &mut Value| v["config"]["layout"] = Value::from("x".repeat(5 << 20)),
            "part1.json (config: 5243",
        ),
    ] {
        let got = with(edit);
        assert!(got.contains(want), "want {want:?} in\n{got}");
    }
    // Parts all of another version: one error naming it.
    let mut old = parts.clone();
    for (_, v) in &mut old {
        v["version"] = serde_json::json!(1);
    }
    let got = PartSet::check(&texts(&old)).unwrap_err().to_string();
    assert!(
        got.starts_with(
            "merge: the parts are of part format version 1; this scatterloc (scatterloc "
        ) && got.contains("reads version 2"),
        "{got}"
    );
    // A filter list with a duplicate (digest and all consistent) is refused by the study.
    let mut dup = parts.clone();
    for (_, v) in &mut dup {
        v["config"]["filters"]["names"] = serde_json::json!(["ekf", "ekf"]);
    }
    let got = mc_merge(&dup).unwrap_err();
    assert!(
        got.contains("part0.json: config") && got.contains("filters[1]"),
        "{got}"
    );
}

#[test]
fn impossible_roc_tallies_are_named_errors() {
    use crate::mtl::experiment::Experiment;
    let cfg = RocStudy::config(Experiment::Vb, Some(2), 5, false, false, None).unwrap();
    let config = RocConfig::of(&cfg);
    let parts: Vec<(String, Value)> = (0..2)
        .map(|i| {
            let shard = Shard::new(i, 2).unwrap();
            let tally =
                RocStudy::run_range(&cfg, shard.range(2), &mut Sequential::new(), &mut |_, _| {})
                    .unwrap();
            let doc = ShardDoc::new(shard, "realisations", 2);
            let timing = Timing {
                threads: 1,
                wall_time_s: vec![0.1],
            };
            let part = PartFile::new("mtl-roc", &config, &doc, &timing, &tally);
            (format!("roc{i}.json"), serde_json::to_value(&part).unwrap())
        })
        .collect();
    let merge = |parts: &[(String, Value)]| {
        let files = texts(parts);
        let set = PartSet::check(&files).map_err(|e| e.to_string())?;
        let mut load = |path: &str| Ok(files.iter().find(|(p, _)| p == path).unwrap().1.clone());
        RocStudy::merge(&set, &mut load)
            .map(|r| r.1)
            .map_err(|e| e.to_string())
    };
    let whole = RocStudy::run_range(&cfg, 0..2, &mut Sequential::new(), &mut |_, _| {}).unwrap();
    assert_eq!(merge(&parts).unwrap(), whole.finish(&cfg));
    let targets = parts[1].1["sums"]["targets"].as_u64().unwrap();
    let edit = |f: &dyn Fn(&mut Value), redo: bool| {
        let mut p = parts.clone();
        f(&mut p[1].1["sums"]);
        if redo {
            redigest(&mut p[1].1);
        }
        merge(&p).unwrap_err()
    };
    for (got, want) in [
        (
            edit(
                &|s| s["sums"][0][3]["detections"] = serde_json::json!(targets + 1),
                true,
            ),
            format!(
                "roc1.json: sums.sums[0][3].detections: {} is more than the {targets} targets",
                targets + 1
            ),
        ),
        (
            edit(
                &|s| s["sums"][1][2]["detection_ratio"] = serde_json::json!([-0.83]),
                true,
            ),
            "roc1.json: sums.sums[1][2].detection_ratio: -0.83 is not a sum of 1 ratios".into(),
        ),
        (
            edit(
                &|s| s["sums"][0][0]["false_alarm_ratio"] = serde_json::json!("nan"),
                true,
            ),
            "roc1.json: sums.sums[0][0].false_alarm_ratio: NaN is not a sum".into(),
        ),
        (
            edit(&|s| s["realisations"] = serde_json::json!(2), true),
            "roc1.json: sums.realisations: 2, not the shard's 1".into(),
        ),
        (
            edit(
                &|s| s["sums"][0][0]["false_alarms"] = serde_json::json!(-1),
                true,
            ),
            "roc1.json: sums.sums[0][0].false_alarms: invalid value: integer `-1`".into(),
        ),
        (
            edit(&|s| s["targets"] = serde_json::json!(targets + 7), false),
            "roc1.json: sums do not match their digest".into(),
        ),
    ] {
        assert!(got.contains(&want), "want {want:?} in\n{got}");
    }
}
