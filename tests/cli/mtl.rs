//! End-to-end tests of `scatterloc mtl` (spec `multi-target.md`): `locate` on the V-A hexagon
//! with exact ranges for every blocking model, bad inputs naming their field or flag, Table II
//! (check 4) and small `roc` runs writing JSON and figures. Few realisations: fast in debug.
#![cfg(not(target_arch = "wasm32"))]

use crate::common;

use serde_json::{json, Value};

use common::cli::{fails, ok_json_line, read_json, run, TempDir};

/// The V-A hexagon of §7: TX at 90°, 210°, 330°, RX at 30°, 150°, 270° on radius 5 m about (5, 5).
fn hexagon() -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let at = |deg: f64| {
        let a = deg.to_radians();
        [5.0 + 5.0 * a.cos(), 5.0 + 5.0 * a.sin()]
    };
    (
        [90.0, 210.0, 330.0].map(at).to_vec(),
        [30.0, 150.0, 270.0].map(at).to_vec(),
    )
}

const TRUTH: [[f64; 2]; 2] = [[3.0, 4.0], [6.5, 6.0]];

/// Noise-free ranges of `TRUTH` in Table I order (TRP m: TX m mod 3, RX m div 3).
fn exact_ranges() -> Vec<Vec<f64>> {
    let (tx, rx) = hexagon();
    let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    (0..9)
        .map(|m| {
            TRUTH
                .iter()
                .map(|&x| d(tx[m % 3], x) + d(x, rx[m / 3]))
                .collect()
        })
        .collect()
}

/// Writes the network and ranges files; returns their paths.
fn inputs(dir: &TempDir) -> (String, String) {
    let (tx, rx) = hexagon();
    let net = dir.write(
        "net.json",
        &json!({"tx": tx, "rx": rx, "region": {"min_m": [0, 0], "max_m": [10, 10]}}),
    );
    let ranges = dir.write("ranges.json", &json!({ "ranges_m": exact_ranges() }));
    (net, ranges)
}

fn assert_finds_truth(v: &Value, model: &str) {
    assert_eq!(v["count"], 2, "{model}: {v}");
    let targets = v["targets"].as_array().unwrap();
    for x in TRUTH {
        let hit = targets.iter().any(|t| {
            let p = &t["position_m"];
            (p[0].as_f64().unwrap() - x[0]).abs() < 1e-6
                && (p[1].as_f64().unwrap() - x[1]).abs() < 1e-6
        });
        assert!(hit, "{model}: {x:?} not found in {v}");
    }
    for t in targets {
        assert_eq!(t["g"], json!([1, 1, 1, 1, 1, 1, 1, 1, 1]), "{model}");
        let matching = t["matching"].as_array().unwrap();
        assert_eq!(matching.len(), 9);
        // One MPC per TRP, in TRP order, as (trp, mpc) pairs.
        for (m, pair) in matching.iter().enumerate() {
            assert_eq!(pair[0], m);
        }
        assert!(t["j"].as_f64().unwrap().is_finite() && t["l_b"].as_f64().unwrap() >= 0.0);
    }
}

#[test]
fn locate_finds_both_exact_targets_with_every_model() {
    let dir = TempDir::new();
    let (net, ranges) = inputs(&dir);
    for model in ["icb", "ppp", "empirical"] {
        let mut args = vec![
            "mtl",
            "locate",
            "--network",
            &net,
            "--ranges",
            &ranges,
            "--model",
            model,
        ];
        if model == "empirical" {
            // A small table trained on the fly keeps the debug test fast.
            args.extend(["--cells", "10", "--scenes", "20"]);
        }
        let v = ok_json_line(&args);
        assert_eq!(v["model"]["kind"], model);
        assert_eq!(v["model"]["consistency"], model != "icb");
        assert_finds_truth(&v, model);
    }
    // --out writes the same document; the PPP model with (M11) and an empirical table file.
    let out = dir.path("targets.json");
    let line = ok_json_line(&[
        "mtl",
        "locate",
        "--network",
        &net,
        "--ranges",
        &ranges,
        "--model",
        "ppp",
        "--exact",
        "--out",
        &out,
    ]);
    assert_eq!(line["count"], 2);
    assert_finds_truth(&read_json(&out), "ppp exact");
    // Measured-like: all nodes LoS in every observation (pattern 63), so ghosts with missing
    // DPs have L_b of about 7 nats or more while the true targets have about 1.
    let mut counts = vec![vec![0u32; 64]; 4];
    counts.iter_mut().for_each(|c| c[63] = 1000);
    let table = dir.write(
        "table.json",
        &json!({"min_m": [0, 0], "max_m": [10, 10], "nx": 2, "ny": 2, "n_tx": 3, "n_rx": 3,
                "pseudo_count": 0.5, "counts": counts}),
    );
    let v = ok_json_line(&[
        "mtl",
        "locate",
        "--network",
        &net,
        "--ranges",
        &ranges,
        "--model",
        "empirical",
        "--table",
        &table,
        "--tb",
        "5",
    ]);
    assert_eq!(v["model"]["table_cells"], json!([2, 2]));
    assert_finds_truth(&v, "empirical table");
}

#[test]
fn locate_bad_inputs_name_the_field_or_flag() {
    let dir = TempDir::new();
    let (net, ranges) = inputs(&dir);
    let (tx, rx) = hexagon();
    let base = |n: &str, r: &str| {
        vec![
            "mtl".to_string(),
            "locate".into(),
            "--network".into(),
            n.into(),
            "--ranges".into(),
            r.into(),
        ]
    };
    let check = |args: Vec<String>, needles: &[&str]| {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        fails(&a, needles);
    };
    let empty = dir.write("empty.json", &json!({"tx": [], "rx": rx}));
    check(
        base(&empty, &ranges),
        &["--network", "tx", "at least one node"],
    );
    let mut bad = exact_ranges();
    bad[4][1] = f64::NAN;
    // serde_json writes NaN as null: the parser names the entry.
    let nan = dir.write_text(
        "nan.json",
        &json!({ "ranges_m": bad })
            .to_string()
            .replace("null", "NaN"),
    );
    check(base(&net, &nan), &["--ranges", "ranges_m[4][1]"]);
    let mut short = exact_ranges();
    short.pop();
    let short = dir.write("short.json", &json!({ "ranges_m": short }));
    check(
        base(&net, &short),
        &["--ranges", "ranges_m", "expected 9", "found 8"],
    );
    let mut args = base(&net, &ranges);
    args.extend(["--tb".into(), "-1".into()]);
    check(args, &["--tb", "negative"]);
    let mut args = base(&net, &ranges);
    args.extend(["--model".into(), "magic".into()]);
    check(args, &["--model", "magic", "icb, ppp or empirical"]);
    let mut args = base(&net, &ranges);
    args.extend(["--p-u".into(), "1.5".into()]);
    check(args, &["--p-u", "1.5"]);
    let mut args = base(&net, &ranges);
    args.extend(["--lambda".into(), "0.1".into()]);
    check(args, &["--lambda", "--model icb"]);
    let mut args = base(&net, &ranges);
    args.extend([
        "--model".into(),
        "ppp".into(),
        "--lambda".into(),
        "-1".into(),
    ]);
    check(args, &["--lambda", "-1"]);
    let unknown = dir.write("unknown.json", &json!({"tx": tx, "rx": rx, "sigma": 1}));
    check(base(&unknown, &ranges), &["--network", "sigma"]);
    check(
        vec![
            "mtl".into(),
            "locate".into(),
            "--ranges".into(),
            ranges.clone(),
        ],
        &["--network", "required"],
    );
    fails(
        &["mtl", "bogus"],
        &["mtl", "bogus", "locate, table2 or roc"],
    );
}

#[test]
fn table2_prints_the_icb_row_of_check_4() {
    let dir = TempDir::new();
    let js = dir.path("t2.json");
    let out = run(&["mtl", "table2", "--draws", "400", "--json", &js]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let icb = text
        .lines()
        .find(|l| l.starts_with("i.c.b "))
        .unwrap_or_else(|| panic!("no i.c.b row: {text}"));
    let want = "0.1267  0.1961  0.2578  0.2259  0.1320  0.0496  0.0109  0.0011";
    assert!(icb.ends_with(want), "{icb}");
    assert!(
        text.contains("0.3367*") && text.contains("0.6650"),
        "{text}"
    );
    let v = read_json(&js);
    assert_eq!(v["draws"], 400);
    let buckets: Vec<f64> = v["true"]["buckets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(buckets.len(), 8);
    assert!((buckets.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    // Weights 5, 7, 8 never occur (check 2).
    assert_eq!((buckets[3], buckets[5], buckets[6]), (0.0, 0.0, 0.0));
    fails(&["mtl", "table2", "--draws", "0"], &["--draws"]);
}

#[test]
fn roc_va_writes_svg_and_json_without_disagreements() {
    let dir = TempDir::new();
    let (js, svg) = (dir.path("va.json"), dir.path("va.svg"));
    let out = run(&[
        "mtl",
        "roc",
        "--experiment",
        "va",
        "--realizations",
        "4",
        "--json",
        &js,
        "--out",
        &svg,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("experiment va: 4 realisations"), "{text}");
    assert!(text.contains("(spec check 6): 0"), "{text}");
    let v = read_json(&js);
    assert_eq!(v["disagreements"], 0);
    assert_eq!(v["realisations"], 4);
    assert_eq!(v["config"]["n_u"], json!([2, 4, 6]));
    assert_eq!(v["config"]["settings"]["p_d"], 0.9);
    let curves = v["curves"].as_array().unwrap();
    assert_eq!(curves.len(), 6);
    for c in curves {
        let t: Vec<f64> = c["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["threshold"].as_f64().unwrap())
            .collect();
        assert_eq!(t.len(), 10);
        assert!(t.windows(2).all(|w| w[0] < w[1]), "{t:?}");
    }
    // Size rule and Bayesian i.c.b coincide (check 6).
    for pair in curves.chunks(2) {
        assert_eq!(pair[0]["points"], pair[1]["points"]);
    }
    let fig = std::fs::read_to_string(&svg).unwrap();
    assert!(fig.starts_with("<svg") && fig.contains("4 realisations") && fig.contains("P_FA"));
    assert_eq!(dir.files(), ["va.json", "va.svg"]);
}

#[test]
fn roc_vb_has_two_curves_and_png_works() {
    let dir = TempDir::new();
    let (js, png) = (dir.path("vb.json"), dir.path("vb.png"));
    let out = run(&[
        "mtl",
        "roc",
        "--experiment",
        "vb",
        "--realizations",
        "2",
        "--threads",
        "1",
        "--json",
        &js,
        "--out",
        &png,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = read_json(&js);
    let curves = v["curves"].as_array().unwrap();
    let methods: Vec<&str> = curves
        .iter()
        .map(|c| c["method"].as_str().unwrap())
        .collect();
    assert_eq!(methods, ["ppp", "icb"]);
    assert_eq!(curves[0]["points"].as_array().unwrap().len(), 81);
    assert_eq!(v["config"]["icb_p_u"], 0.5329);
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
}

#[test]
fn roc_bad_flags_name_the_flag() {
    fails(
        &["mtl", "roc", "--experiment", "vd"],
        &["--experiment", "vd", "va, vb or vc"],
    );
    fails(&["mtl", "roc"], &["--experiment", "required"]);
    fails(
        &[
            "mtl",
            "roc",
            "--experiment",
            "va",
            "--realizations",
            "100001",
        ],
        &["--realizations", "100000"],
    );
    fails(
        &["mtl", "roc", "--experiment", "va", "--realizations", "0"],
        &["--realizations"],
    );
    fails(
        &["mtl", "roc", "--experiment", "va", "--empirical"],
        &["--empirical", "va"],
    );
    fails(
        &["mtl", "roc", "--experiment", "vb", "--out", "fig.pdf"],
        &["--out", ".pdf"],
    );
}
