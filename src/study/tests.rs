//! The use cases against their own contract: any driver, any order of work items and any
//! split into shards give the same sums bit for bit (the sums are exact); the lead and widest
//! rules; the particle budget's closed form; the part set's named errors.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use super::*;
use crate::math::Shard;
use crate::measure::Model;
use crate::scenario::presets;
use crate::track::{
    paper_initial_covariance, ConstantVelocity, FilterKind, MonteCarloConfig, PfConfig,
    TrackScenario, UkfParams,
};

fn model() -> Model {
    Model::new(&presets::preset("sensors2019").unwrap()).unwrap()
}

fn config(trajectories: usize, noise_runs: usize, steps: usize, seed: u64) -> MonteCarloConfig {
    MonteCarloConfig {
        motion: ConstantVelocity::validated(0.1, 1.0).unwrap(),
        steps,
        mean_state: TrackScenario::II.mean_state(),
        initial_covariance: paper_initial_covariance(),
        trajectories,
        noise_runs,
        seed,
        oracle_noise: false,
    }
}

const PF: FilterKind = FilterKind::Pf(PfConfig {
    particles: 40,
    roughening: None,
    regularized: true,
});

#[test]
fn work_items_ranges_and_shards_give_the_same_sums() {
    let m = model();
    for seed in [1, 2, 3] {
        let cfg = config(40, 2, 6, seed);
        let kinds = [FilterKind::Ukf(UkfParams::default()), FilterKind::Ekf, PF];
        // Page order: chunk by chunk, the filters interleaved, two items per call.
        let mut items = FilterStudy::new(cfg, &kinds).unwrap();
        while !items.run_items(&m, 2).unwrap() {}
        // CLI order: filter by filter, the whole range.
        let mut whole = FilterStudy::new(cfg, &kinds).unwrap();
        whole
            .run_range(
                &m,
                0..cfg.chunk_count(),
                &mut Sequential::new(),
                &mut |_, _| {},
            )
            .unwrap();
        assert_eq!(items.sums(), whole.sums());
        // Three shards merged.
        let mut merged = FilterStudy::new(cfg, &kinds).unwrap();
        for i in 0..3 {
            let r = Shard::new(i, 3).unwrap().range(cfg.chunk_count());
            let mut part = FilterStudy::new(cfg, &kinds).unwrap();
            part.run_range(&m, r.clone(), &mut Sequential::new(), &mut |_, _| {})
                .unwrap();
            for (f, s) in part.sums().iter().enumerate() {
                merged.add_sums(f, s, r.len());
            }
        }
        assert_eq!(merged.sums(), whole.sums());
        assert_eq!(merged.results().unwrap(), whole.results().unwrap());
        // The EKF of the list is the EKF study alone.
        let mut ekf = FilterStudy::new(cfg, &[FilterKind::Ekf]).unwrap();
        ekf.run_items(&m, usize::MAX).unwrap();
        assert_eq!(ekf.sums()[0], whole.sums()[1]);
    }
}

#[cfg(all(feature = "parallel", not(target_arch = "wasm32")))]
#[test]
fn parallel_driver_equals_sequential() {
    use core::sync::atomic::AtomicBool;
    let m = model();
    let cfg = config(70, 2, 5, 9);
    let kinds = [FilterKind::Ekf, FilterKind::Ukf(UkfParams::default())];
    let cancel = AtomicBool::new(false);
    let mut seq = FilterStudy::new(cfg, &kinds).unwrap();
    seq.run_range(&m, 1..5, &mut Sequential::new(), &mut |_, _| {})
        .unwrap();
    for threads in [1, 2, 3] {
        let mut par = FilterStudy::new(cfg, &kinds).unwrap();
        let mut last = (0, 0);
        par.run_range(
            &m,
            1..5,
            &mut crate::native::Parallel::new(threads, &cancel),
            &mut |d, t| last = (d, t),
        )
        .unwrap();
        assert_eq!(par.sums(), seq.sums());
        // Progress ends at every run of both filters: chunks 1..5 are trajectories 16..70,
        // 2 filters × 54 trajectories × 2 noise runs.
        assert_eq!(last, (216, 216));
    }
}

#[test]
fn lead_is_the_ekf_else_the_first_and_the_bound_comes_from_the_widest() {
    let m = model();
    let cfg = config(48, 1, 4, 5);
    let ukf = FilterKind::Ukf(UkfParams::default());
    let lead = |kinds: &[FilterKind]| {
        let mut s = FilterStudy::new(cfg, kinds).unwrap();
        s.run_items(&m, usize::MAX).unwrap();
        let r = s.results().unwrap();
        (kinds[r.curves[r.lead].0].name(), r)
    };
    assert_eq!(lead(&[ukf, FilterKind::Ekf]).0, "ekf");
    assert_eq!(lead(&[ukf, PF]).0, "ukf");
    // The particle filter held to one chunk of three: it leads alone, the widest is the UKF,
    // whose bound (48 trajectories) the top-level curves carry.
    let budget = 16 * 4 * 40; // one chunk's runs × steps × particles
    let mut s = FilterStudy::with_particle_budget(cfg, &[PF, ukf], budget).unwrap();
    assert_eq!(s.filters()[0].chunks, 1);
    assert_eq!(s.filters()[0].runs_planned(&cfg), 16);
    assert_eq!(s.item_count(), 4);
    s.run_items(&m, usize::MAX).unwrap();
    let r = s.results().unwrap();
    assert_eq!((r.lead, r.widest), (0, 1));
    let top = r.top();
    assert_eq!(top.rmse_m, r.curves[0].1.rmse_m);
    assert_eq!(top.rmse_pcrlb_m, r.curves[1].1.rmse_pcrlb_m);
    assert_ne!(r.curves[0].1.rmse_pcrlb_m, r.curves[1].1.rmse_pcrlb_m);
}

#[test]
fn particle_chunks_is_the_whole_chunks_that_fit() {
    // 100 trajectories = 7 chunks; a chunk is 16 × 2 runs of 10 steps × 100 particles.
    let cfg = config(100, 2, 10, 1);
    let chunk = 16 * 2 * 10 * 100;
    for (budget, want) in [
        (0, 1),
        (chunk - 1, 1),
        (chunk, 1),
        (3 * chunk, 3),
        (3 * chunk + chunk / 2, 3),
        (7 * chunk, 7),
        (usize::MAX, 7),
    ] {
        assert_eq!(particle_chunks(&cfg, 100, budget), want, "budget {budget}");
    }
}

#[test]
fn bad_filter_lists_are_named_errors() {
    let cfg = config(16, 1, 3, 1);
    let e = FilterStudy::new(cfg, &[]).unwrap_err();
    assert_eq!(e.field(), Some("filters"));
    let e = FilterStudy::new(cfg, &[FilterKind::Ekf, FilterKind::Ekf]).unwrap_err();
    assert_eq!(e.field(), Some("filters[1]"));
    let bad_pf = FilterKind::Pf(PfConfig {
        particles: 0,
        roughening: None,
        regularized: true,
    });
    assert_eq!(
        FilterStudy::new(cfg, &[bad_pf]).unwrap_err().field(),
        Some("particles")
    );
    let mut s = FilterStudy::new(cfg, &[FilterKind::Ekf]).unwrap();
    let e = s
        .run_range(&model(), 0..2, &mut Sequential::new(), &mut |_, _| {})
        .unwrap_err();
    assert_eq!(e.field(), Some("chunks"));
    assert_eq!(s.results().unwrap_err().field(), Some("runs (successful)"));
}

/// `n` part files of a study of `total` units, as `(path, text)`.
fn parts(n: usize, total: usize, seed: u64) -> Vec<(String, String)> {
    (0..n)
        .map(|i| {
            let shard = ShardDoc::new(Shard::new(i, n).unwrap(), "chunks", total);
            let timing = Timing {
                threads: 2,
                wall_time_s: vec![1.0 + i as f64],
            };
            let config = serde_json::json!({ "seed": seed });
            let text =
                serde_json::to_string(&PartFile::new("montecarlo", &config, &shard, &timing, &[i]))
                    .unwrap();
            (format!("p{i}.json"), text)
        })
        .collect()
}

#[test]
fn part_sets_are_checked_as_one_study() {
    let good = parts(3, 10, 1);
    let mut shuffled = good.clone();
    shuffled.reverse();
    let set = PartSet::check(&shuffled).unwrap();
    let ranges: Vec<[usize; 2]> = set.parts.iter().map(|p| p.shard.range).collect();
    assert_eq!(ranges, [[0, 3], [3, 6], [6, 10]]);
    let (timing, thread_s) = merged_timing(&set.parts, 1).unwrap();
    assert_eq!(
        (timing.threads, timing.wall_time_s[0], thread_s[0]),
        (2, 6.0, 12.0)
    );
    assert!(merged_timing(&set.parts, 2).is_err());

    let msg = |files: &[(String, String)]| PartSet::check(files).unwrap_err().to_string();
    // Missing and duplicate shards.
    assert_eq!(
        msg(&good[..2]),
        "merge: missing parts: shard 2 of 3 (2 of 3 given)"
    );
    let mut dup = good.clone();
    dup.push(("again.json".into(), good[1].1.clone()));
    assert_eq!(
        msg(&dup),
        "merge: duplicate parts (shards of 3): shard 1 in p1.json, again.json"
    );
    // A foreign part (another seed) and another shard count.
    let mut foreign = good.clone();
    foreign[2] = parts(3, 10, 2).swap_remove(2);
    assert!(msg(&foreign).starts_with("merge: foreign parts, not of the study of p0.json"));
    let mut counts = good[..2].to_vec();
    counts.push(parts(2, 10, 1).swap_remove(1));
    counts[2].0 = "two.json".into();
    assert!(msg(&counts).starts_with("merge: the parts disagree on the shard count: 2 shards: two.json; 3 shards: p0.json, p1.json"));
    // Not part files: another format, another version, not JSON.
    let other = good[0].1.replace("scatterloc-part", "other");
    let newer = good[0].1.replace("\"version\":2", "\"version\":3");
    let bad = [
        ("a".to_string(), other),
        ("b".to_string(), newer),
        ("c".to_string(), "{".to_string()),
    ];
    let m = msg(&bad);
    assert!(m.starts_with("merge: not scatterloc part files (format \"scatterloc-part\", version 2): a (format \"other\""), "{m}");
    assert!(
        m.contains("b (version 3, this scatterloc reads version 2)"),
        "{m}"
    );
    assert!(m.contains("c (invalid JSON"), "{m}");
    // A part whose range is not its index's.
    let mut wrong = good.clone();
    wrong[1].1 = wrong[1].1.replace("\"range\":[3,6]", "\"range\":[3,7]");
    assert!(matches!(
        PartSet::check(&wrong).unwrap_err(),
        crate::Error::InconsistentPart { ref path, .. } if path == "p1.json"
    ));
    assert_eq!(msg(&[]), "merge: no part files given");
}

#[test]
fn monte_carlo_config_rebuilds_the_study_and_refuses_an_edited_one() {
    let track = TrackStudy::new(
        "sensors2019".into(),
        presets::preset("sensors2019").unwrap(),
        vec![TrackScenario::I, TrackScenario::III],
        ConstantVelocity::validated(0.1, 1.0).unwrap(),
        5,
    )
    .unwrap();
    let kinds = [FilterKind::Ekf, PF];
    let study = MonteCarloStudy::new(track, 20, 2, 11, false, &kinds).unwrap();
    let doc = serde_json::to_value(study.config_doc().unwrap()).unwrap();
    assert_eq!(doc["filters"]["names"], serde_json::json!(["ekf", "pf"]));
    assert_eq!(doc["filters"]["particles"], 40);
    let again = MonteCarloStudy::from_config(&doc).unwrap();
    assert_eq!(again.configs, study.configs);
    assert_eq!(again.filters, study.filters);
    let mut edited = doc.clone();
    edited["noise_runs"] = serde_json::json!(3);
    let ok = MonteCarloStudy::from_config(&edited).unwrap();
    assert_eq!(ok.noise_runs, 3);
    edited["filters"]["ukf"] = serde_json::json!([1.0, 2.0, 0.0]);
    let e = MonteCarloStudy::from_config(&edited)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("config is not as this scatterloc writes it (filters.ukf"),
        "{e}"
    );
    // The EKF alone records no filters.
    let ekf =
        MonteCarloStudy::new(study.track.clone(), 20, 2, 11, false, &[FilterKind::Ekf]).unwrap();
    assert!(ekf.config_doc().unwrap().filters.is_none());
}

// ------------------------------------------------------------------ part contents (issue 24)

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

// Issue 24, "Long work".

/// A driver whose jobs' [`crate::error::Cancel`] asks to stop after `after` questions: the
/// in-run check of the chunk loop (not only the driver's between jobs) ends the study.
struct StopAfter {
    after: usize,
    asked: core::sync::atomic::AtomicUsize,
}

impl Driver for StopAfter {
    fn run<T: Send>(
        &mut self,
        jobs: usize,
        _batch: usize,
        job: &(dyn Fn(usize, crate::error::Cancel) -> crate::Result<T> + Sync),
        merge: &mut dyn FnMut(T),
        progress: &mut dyn FnMut(usize),
    ) -> crate::Result<()> {
        use core::sync::atomic::Ordering;
        let stop = || self.asked.fetch_add(1, Ordering::Relaxed) >= self.after;
        for i in 0..jobs {
            merge(job(i, crate::error::Cancel::when(&stop))?);
            progress(i + 1);
        }
        Ok(())
    }
}

#[test]
fn a_run_is_cancelled_inside_its_steps() {
    use core::sync::atomic::{AtomicUsize, Ordering};
    // One chunk of one run of a particle filter: 200 steps of 20 000 particles, ≈ 1.2 ms per
    // step predicted (step_ns), so every step asks (check_every = 1).
    let pf = FilterKind::Pf(PfConfig {
        particles: 20_000,
        roughening: None,
        regularized: true,
    });
    let links = model().link_count();
    assert_eq!(
        crate::error::check_every(crate::track::step_ns(pf, links)),
        1
    );
    let cfg = config(1, 1, 200, 3);
    let mut s = FilterStudy::new(cfg, &[pf]).unwrap();
    let mut driver = StopAfter {
        after: 3,
        asked: AtomicUsize::new(0),
    };
    let e = s
        .run_range(&model(), 0..1, &mut driver, &mut |_, _| {})
        .unwrap_err();
    assert_eq!(e, crate::Error::Cancelled);
    // Asked at steps 0, 1, 2 (go on) and 3 (stop): inside the one run, 196 steps before its end.
    assert_eq!(driver.asked.load(Ordering::Relaxed), 4);
    // The EKF's lanes ask every check_every(4 × step_ns) steps: 1 ms / (4 × 140 ns) = 1785.
    let ekf_ns = 4.0 * crate::track::step_ns(FilterKind::Ekf, links);
    assert_eq!(crate::error::check_every(ekf_ns), (1e6 / ekf_ns) as usize);
    // Never asked to stop: the sums are those of the plain driver, bit for bit.
    let mut never = StopAfter {
        after: usize::MAX,
        asked: AtomicUsize::new(0),
    };
    let cfg = config(16, 2, 20, 3);
    let kinds = [FilterKind::Ekf, FilterKind::Ukf(UkfParams::default())];
    let (mut a, mut b) = (
        FilterStudy::new(cfg, &kinds).unwrap(),
        FilterStudy::new(cfg, &kinds).unwrap(),
    );
    a.run_range(&model(), 0..1, &mut never, &mut |_, _| {})
        .unwrap();
    b.run_range(&model(), 0..1, &mut Sequential::new(), &mut |_, _| {})
        .unwrap();
    assert_eq!(a.sums(), b.sums());
}

#[test]
fn a_filter_failing_every_run_keeps_the_others_results() {
    // One particle: its covariance is zero, so no run has a NEES (every run fails).
    let pf = FilterKind::Pf(PfConfig {
        particles: 1,
        roughening: None,
        regularized: true,
    });
    let cfg = config(16, 1, 5, 1);
    let mut s = FilterStudy::new(cfg, &[FilterKind::Ekf, pf]).unwrap();
    s.run_range(&model(), 0..1, &mut Sequential::new(), &mut |_, _| {})
        .unwrap();
    let r = s.results().unwrap();
    assert_eq!(r.curves.len(), 1);
    assert_eq!(r.curves[0].0, 0, "the EKF's curves are kept");
    assert_eq!(r.curves[0].1.runs, 16);
    assert_eq!(r.failed.len(), 1);
    let (i, e) = &r.failed[0];
    assert_eq!(*i, 1);
    assert_eq!(e.field(), Some("particles"));
    let text = e.to_string();
    assert!(
        text.starts_with("particles: every run of the PF failed (16 of 16); the first: "),
        "{text}"
    );
    // The PF alone: no result, the same named error.
    let mut alone = FilterStudy::new(cfg, &[pf]).unwrap();
    alone
        .run_range(&model(), 0..1, &mut Sequential::new(), &mut |_, _| {})
        .unwrap();
    assert_eq!(alone.results().unwrap_err().to_string(), text);
}

#[test]
fn predicted_cost_is_runs_times_steps_times_the_step_cost() {
    use crate::track::step_ns;
    let links = model().link_count();
    let pf = PfConfig {
        particles: 1000,
        roughening: None,
        regularized: true,
    };
    let cfg = config(40, 3, 50, 1);
    // The particle filter held to 1 chunk of the 3 (16 × 3 runs × 50 steps × 1000 ≤ 2.4e6).
    let s =
        FilterStudy::with_particle_budget(cfg, &[FilterKind::Ekf, FilterKind::Pf(pf)], 2_400_000)
            .unwrap();
    let ekf = 120.0 * 50.0 * step_ns(FilterKind::Ekf, links) * 1e-9;
    let pf_s = 48.0 * 50.0 * step_ns(FilterKind::Pf(pf), links) * 1e-9;
    let got = s.predicted_cpu_s(links, &(0..3));
    assert!((got - (ekf + pf_s)).abs() <= 1e-12 * got, "{got}");
    // A shard's chunks only: chunk 2 holds 8 trajectories, and no PF chunk.
    let shard = s.predicted_cpu_s(links, &(2..3));
    assert!((shard - 24.0 * 50.0 * step_ns(FilterKind::Ekf, links) * 1e-9).abs() <= 1e-15);
    // The model's large-link terms (docs/benchmarks.md "Cost model"): a 4096-link UKF step
    // ≈ 16 s (16 s measured in issue 24), a 1024-link one ≈ 0.25 s (measured 0.25 s).
    let ukf = FilterKind::Ukf(UkfParams::default());
    assert!((15.0e9..17.5e9).contains(&step_ns(ukf, 4096)));
    assert!((0.2e9..0.3e9).contains(&step_ns(ukf, 1024)));
    // The page (issue 24): a UKF or PF track on a 64 × 64 mesh is refused on its main thread
    // from the first step; its default tracks on sensors2019 (100 steps; the PF 1000
    // particles) are not.
    let pf1000 = FilterKind::Pf(pf);
    assert!(track_cpu_s(ukf, 4096, 1) > PAGE_TRACK_CPU_S);
    assert!(track_cpu_s(pf1000, 4096, 1) > PAGE_TRACK_CPU_S);
    for kind in [FilterKind::Ekf, ukf, pf1000] {
        assert!(track_cpu_s(kind, links, 100) < 0.01 * PAGE_TRACK_CPU_S);
    }
    // The cap: a named error with both times.
    let e = check_cost("runs", 90_000.0, MAX_CPU_S).unwrap_err();
    assert_eq!(e.field(), Some("runs"));
    assert!(
        e.to_string()
            .contains("90000 s of CPU time, over the cap of 86400 s"),
        "{e}"
    );
    assert!(check_cost("runs", MAX_CPU_S, MAX_CPU_S).is_ok());
}
