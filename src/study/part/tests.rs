//! The part set's named errors: missing, duplicate and foreign parts, shard counts that
//! disagree, files that are not part files of this version, a part that is not its shard; and
//! the merged run time.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use super::*;
use crate::math::Shard;

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
