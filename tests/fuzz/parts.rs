//! Tampered part files (issue 24): the parts of a small sharded Monte Carlo study (EKF and
//! UKF, trajectory II, 40 × 1 runs of 3 steps, 2 shards), mutated like every other input
//! (`mutate.rs`: keys, types, extreme numbers, grown arrays), then optionally given a matching
//! digest (an edit the digest cannot see) or truncated, and merged in process
//! ([`PartSet::check`], [`MonteCarloStudy::merge`]). The invariant: a named error, or a merge
//! with finite curves — and sums changed without a new digest are never merged.

use std::sync::OnceLock;

use proptest::prelude::*;
use serde_json::Value;

use scatterloc::math::Shard;
use scatterloc::scenario::presets;
use scatterloc::study::{
    sums_digest, FilterStudy, MonteCarloStudy, PartFile, PartSet, RunTime, Sequential, ShardDoc,
    Timing, TrackStudy,
};
use scatterloc::track::{ConstantVelocity, FilterKind, TrackScenario, UkfParams};

use super::check::{core_err, fail, guarded, nonfinite_in_debug, Class, Pass, Verdict};
use super::mutate::{apply, mutations, MAX_GROW};
use super::runner::{fuzz, Case};
use super::KNOWN;

/// The two part files of the study, as JSON.
fn bases() -> &'static [Value; 2] {
    static BASES: OnceLock<[Value; 2]> = OnceLock::new();
    BASES.get_or_init(|| {
        let track = TrackStudy::new(
            "sensors2019".into(),
            presets::preset("sensors2019").unwrap(),
            vec![TrackScenario::II],
            ConstantVelocity::validated(0.1, 1.0).unwrap(),
            3,
        )
        .unwrap();
        let kinds = [FilterKind::Ekf, FilterKind::Ukf(UkfParams::default())];
        let study = MonteCarloStudy::new(track, 40, 1, 5, false, &kinds).unwrap();
        let config = study.config_doc().unwrap();
        let total = study.chunk_count();
        [0, 1].map(|i| {
            let shard = Shard::new(i, 2).unwrap();
            let mut run: FilterStudy = study.filter_study(0).unwrap();
            run.run_range(
                &study.track.model,
                shard.range(total),
                &mut Sequential::new(),
                &mut |_, _| {},
            )
            .unwrap();
            let sums = MonteCarloStudy::part_sums(&[run]);
            let doc = ShardDoc::new(shard, "chunks", total);
            let timing = Timing {
                threads: 1,
                wall_time_s: vec![0.5],
            };
            serde_json::to_value(PartFile::new("montecarlo", &config, &doc, &timing, &sums))
                .unwrap()
        })
    })
}

/// Merges `texts` (part 0 and part 1) in process; `changed`: part 1's sums differ from the
/// written ones while its digest was not recomputed (such a merge must fail).
fn run_merge(texts: &[(String, String); 2], changed: bool) -> Verdict {
    let set = match PartSet::check(texts) {
        Ok(s) => s,
        Err(e) => return core_err(&e),
    };
    let mut load = |path: &str| Ok(texts.iter().find(|(p, _)| p == path).unwrap().1.clone());
    let (study, runs, _) = match MonteCarloStudy::merge(&set, &mut load) {
        Ok(r) => r,
        Err(e) => return core_err(&e),
    };
    if changed {
        return Err(fail(
            Class::BadOutput,
            "sums changed without a new digest were merged",
        ));
    }
    for (k, r) in runs.iter().enumerate() {
        match r.results() {
            Ok(res) => {
                let time = RunTime {
                    wall_s: 1.0,
                    thread_s: 1.0,
                    threads: 1,
                };
                let doc = study.doc(k, &res, time);
                nonfinite_in_debug("merged curves", &format!("{:?}", doc.rmse_ekf_m))?;
                nonfinite_in_debug("merged NEES", &format!("{:?}", doc.nees))?;
            }
            Err(e) => return core_err(&e),
        }
    }
    Ok(Pass::Ok)
}

#[test]
fn fuzz_tampered_parts() {
    let strategy = (
        mutations(3, MAX_GROW),
        any::<bool>(),
        prop::option::weighted(0.2, 0.0..1.0f64),
    );
    fuzz(
        file!(),
        "tampered_parts",
        60,
        KNOWN,
        strategy,
        |(muts, redigest, cut)| {
            let base = &bases()[1];
            let m = apply(base, muts);
            let mut text = m.text.clone();
            let mut changed = false;
            if let Ok(mut v) = serde_json::from_str::<Value>(&text) {
                changed = v.get("sums") != base.get("sums");
                if *redigest && v.get("sums").is_some() {
                    v["digest"] = Value::from(sums_digest(&v["sums"]).unwrap());
                    text = v.to_string();
                    changed = false;
                }
            }
            if let Some(f) = cut {
                let mut at = (text.len() as f64 * f) as usize;
                while !text.is_char_boundary(at) {
                    at -= 1;
                }
                text.truncate(at);
            }
            let texts = [
                ("part0.json".to_string(), bases()[0].to_string()),
                ("part1.json".to_string(), text.clone()),
            ];
            let what = format!(
                "{} | redigest {redigest} | cut {cut:?} | part: {}",
                m.what.join("; "),
                super::check::clip(&text, 400)
            );
            Case {
                verdict: guarded(&what, || run_merge(&texts, changed)),
                what,
            }
        },
    );
}
