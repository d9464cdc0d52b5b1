//! The detections file (docs/detections.md): write → read gives the same bits; ranges in metres
//! are delays in seconds; the conversion to the tracker's raw steps (amplitude, σ by E8/C4,
//! missing links); every bad line a named error naming its line and field.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use crate::channel::{PathEstimate, TrackedPath};
use crate::error::limits;
use crate::formats::{DelayUnit, DetectionFrame, DetectionLine, Detections, RawEstimate};
use crate::math::{Complex, SPEED_OF_LIGHT};
use crate::scenario::{presets, LinkIndex};
use crate::Model;

/// A deterministic stream of doubles with all their bits (a 64-bit LCG's top 53 bits).
struct Bits(u64);

impl Bits {
    fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn model() -> Model {
    Model::new(&presets::sensors2019()).unwrap()
}

fn link(tx: usize, rx: usize) -> LinkIndex {
    LinkIndex { tx, rx }
}

/// Random detections: `frames` frames of the four L4 links, 0–5 detections each, every field.
fn random(frames: usize, seed: u64) -> Detections {
    let mut r = Bits(seed);
    Detections {
        frames: (0..frames)
            .map(|k| {
                let t = 0.1 * k as f64 + 1e-3 * r.unit();
                DetectionFrame {
                    timestamp_s: t,
                    lines: (0..4)
                        .map(|rx| {
                            let n = (r.unit() * 6.0) as usize;
                            DetectionLine {
                                line: 0,
                                timestamp_s: t,
                                link: link(0, rx),
                                unit: DelayUnit::Seconds,
                                delay: (0..n).map(|_| 1e-8 + 1e-7 * r.unit()).collect(),
                                snr_db: Some(
                                    (0..n)
                                        .map(|i| (i != 2).then(|| 60.0 * r.unit() - 10.0))
                                        .collect(),
                                ),
                                sigma: Some(
                                    (0..n)
                                        .map(|i| (i != 1).then(|| 1e-10 * r.unit() + 1e-12))
                                        .collect(),
                                ),
                                doppler_hz: (rx == 1)
                                    .then(|| (0..n).map(|_| 200.0 * r.unit() - 100.0).collect()),
                            }
                        })
                        .collect(),
                }
            })
            .collect(),
    }
}

/// The same detections with the line numbers of a read cleared.
fn without_lines(mut d: Detections) -> Detections {
    for f in &mut d.frames {
        for l in &mut f.lines {
            l.line = 0;
        }
    }
    d
}

#[test]
fn write_then_read_gives_the_same_bits() {
    for seed in [1, 2, 3] {
        let d = random(50, seed);
        let text = d.to_text();
        assert_eq!(text.lines().count(), 200);
        let back = Detections::from_text(&text).unwrap();
        // Line numbers: one per line, in order.
        assert_eq!(back.frames[3].lines[2].line, 3 * 4 + 3);
        assert_eq!(without_lines(back), d, "seed {seed}");
    }
    // The keys in the documented order, absent options left out, null = unknown.
    let one = Detections {
        frames: vec![DetectionFrame {
            timestamp_s: 0.5,
            lines: vec![DetectionLine {
                line: 0,
                timestamp_s: 0.5,
                link: link(0, 2),
                unit: DelayUnit::Metres,
                delay: vec![12.5, 30.0],
                snr_db: Some(vec![Some(20.0), None]),
                sigma: None,
                doppler_hz: None,
            }],
        }],
    };
    assert_eq!(
        one.to_text(),
        "{\"timestamp\":0.5,\"tx\":0,\"rx\":2,\"unit\":\"m\",\"delay\":[12.5,30.0],\"snr\":[20.0,null]}\n"
    );
}

#[test]
fn the_front_ends_paths_are_written_with_their_snr_in_db_and_sigma() {
    let path = |delay_s: f64, snr: f64, sigma_s: f64| TrackedPath {
        estimate: PathEstimate {
            delay_s,
            alpha: Complex::new(0.3, -0.4),
            sigma_s,
            snr,
            range_rate: None,
        },
        track_id: 0,
        confirmed: true,
        filtered_delay_s: delay_s,
        filtered_sigma_s: sigma_s,
    };
    let links = [link(0, 0), link(0, 1), link(0, 2)];
    let paths = vec![
        vec![
            vec![
                path(4.1e-8, 1000.0, 3e-11),
                path(5.3e-8, 0.0, f64::INFINITY),
            ],
            vec![path(9e-8, 10.0, 2e-10)],
            vec![],
        ],
        vec![vec![], vec![], vec![path(9.1e-8, 123.456, 2.5e-10)]],
    ];
    let d = Detections::from_paths(&links, &[0.25, 0.5], &[true, false, true], &paths);
    // One line per snapshot and recorded link (link 1 is not recorded).
    assert_eq!(d.frames.len(), 2);
    assert!(d.frames.iter().all(|f| f.lines.len() == 2));
    let l = &d.frames[0].lines[0];
    assert_eq!(l.delay, vec![4.1e-8, 5.3e-8]);
    // 10·log10(1000) = 30 dB; an SNR of 0 and an infinite σ are unknown (null).
    assert_eq!(l.snr_db, Some(vec![Some(30.0), None]));
    assert_eq!(l.sigma, Some(vec![Some(3e-11), None]));
    let back = without_lines(Detections::from_text(&d.to_text()).unwrap());
    assert_eq!(back, d);
    let snr = back.frames[1].lines[1].snr_db.as_ref().unwrap()[0].unwrap();
    assert!((snr - 20.915_122_016_277_72).abs() < 1e-12, "{snr}");
}

#[test]
fn ranges_in_metres_are_delays_in_seconds() {
    let model = model();
    let mut r = Bits(7);
    let mut metres = String::new();
    let mut seconds = String::new();
    for k in 0..5 {
        let t = 0.1 * k as f64;
        for rx in [2, 0, 3] {
            let ranges: Vec<f64> = (0..3).map(|_| 3.0 + 40.0 * r.unit()).collect();
            let sig_m: Vec<f64> = (0..3).map(|_| 0.01 + 0.2 * r.unit()).collect();
            let to_s = |v: &[f64]| -> Vec<f64> { v.iter().map(|x| x / SPEED_OF_LIGHT).collect() };
            metres.push_str(&format!(
                "{{\"timestamp\": {t}, \"link\": [0, {rx}], \"unit\": \"m\", \"delay\": {:?}, \"sigma\": {:?}, \"snr\": [10, 20, 30]}}\n",
                ranges, sig_m
            ));
            seconds.push_str(&format!(
                "{{\"timestamp\": {t}, \"tx\": 0, \"rx\": {rx}, \"delay\": {:?}, \"sigma\": {:?}, \"snr\": [10, 20, 30]}}\n",
                to_s(&ranges),
                to_s(&sig_m)
            ));
        }
    }
    let m = Detections::from_text(&metres)
        .unwrap()
        .to_measurements(&model, 0.5)
        .unwrap();
    let s = Detections::from_text(&seconds)
        .unwrap()
        .to_measurements(&model, 0.5)
        .unwrap();
    assert_eq!(m, s);
    // Link 1 ([0, 1]) is in no frame: no detection there.
    let raw = m.raw_steps.as_ref().unwrap();
    assert_eq!(raw.len(), 4);
    assert!(raw.iter().all(|step| step.len() == 4 && step[1].is_empty()));
    assert_eq!(m.initial_snapshot.as_ref().unwrap()[2].len(), 3);
}

#[test]
fn frames_become_the_trackers_raw_steps() {
    let model = model();
    let text = "# a comment, then a blank line\n\n\
        {\"timestamp\": 2.0, \"tx\": 0, \"rx\": 3, \"delay\": [5e-8, 6e-8], \"snr\": [20, null]}\n\
        {\"timestamp\": 2.0, \"tx\": 0, \"rx\": 0, \"delay\": [4e-8], \"sigma\": [1e-10], \"doppler\": [12.5]}\n\
        {\"timestamp\": 2.1, \"tx\": 0, \"rx\": 1, \"delay\": []}\n\
        {\"timestamp\": 2.2, \"tx\": 0, \"rx\": 1, \"delay\": [7e-8], \"snr\": [0], \"sigma\": [3e-10]}\n";
    let d = Detections::from_text(text).unwrap();
    assert_eq!(d.frames.len(), 3);
    assert_eq!(d.frames[0].lines[1].doppler_hz, Some(vec![12.5]));
    let m = d.to_measurements(&model, 0.1).unwrap();
    // dt = (2.2 − 2.0)/2, as `cir estimate --measurements` computes it.
    assert_eq!(m.dt_s, (2.2 - 2.0) / 2.0);
    assert_eq!(m.process_noise, 0.1);
    assert!(m.initial_state.is_none() && m.sigma_s.is_none() && m.steps.is_none());
    let first = m.initial_snapshot.as_ref().unwrap();
    // SNR 20 dB, no σ: amplitude 10^(20/20) = 10, σ = 1/√(8π²β²·100) with β² = B²/12, B =
    // 120 MHz: cσ = 9.7 cm (spec C4's example).
    let RawEstimate::WithSigma([d0, a0, s0]) = first[3][0] else {
        panic!("{:?}", first[3][0])
    };
    assert_eq!(d0, 5e-8);
    assert!((a0 - 10.0).abs() < 1e-13, "{a0}");
    let beta2 = 1.2e8 * 1.2e8 / 12.0;
    let reference = 1.0 / libm::sqrt(8.0 * core::f64::consts::PI.powi(2) * beta2 * 100.0);
    assert!((s0 / reference - 1.0).abs() < 1e-14, "{s0} {reference}");
    assert!(
        (SPEED_OF_LIGHT * s0 - 0.0975).abs() < 5e-4,
        "{}",
        SPEED_OF_LIGHT * s0
    );
    // Neither SNR nor σ: amplitude 1, no σ (the link budget at the prediction, E8).
    assert_eq!(first[3][1], RawEstimate::Pair([6e-8, 1.0]));
    // σ given: taken as given; no SNR: amplitude 1.
    assert_eq!(first[0], vec![RawEstimate::WithSigma([4e-8, 1.0, 1e-10])]);
    assert!(first[1].is_empty() && first[2].is_empty());
    let raw = m.raw_steps.as_ref().unwrap();
    assert!(raw[0].iter().all(Vec::is_empty));
    assert_eq!(raw[1][1], vec![RawEstimate::WithSigma([7e-8, 1.0, 3e-10])]);
}

/// The error of `text` as it reads.
fn error(text: &str) -> String {
    Detections::from_text(text).unwrap_err().to_string()
}

/// The error of converting `text` to measurements on the L4 model.
fn convert_error(text: &str) -> String {
    Detections::from_text(text)
        .unwrap()
        .to_measurements(&model(), 0.1)
        .unwrap_err()
        .to_string()
}

const OK: &str = r#"{"timestamp": 0, "tx": 0, "rx": 0, "delay": [4e-8]}"#;

#[test]
fn bad_lines_are_named_errors_with_their_line_and_field() {
    let two = |second: &str| format!("{OK}\n{second}\n");
    let cases: Vec<(String, &str)> =
        vec![
        (two("{\"timestamp\": 0.1, "), "line 2: EOF while parsing a value (column 18)"),
        (two("oops"), "line 2: expected value (column 1)"),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1}"#),
            "line 2: missing field `delay` (column",
        ),
        (
            two(r#"{"tx": 0, "rx": 1, "delay": []}"#),
            "line 2: missing field `timestamp`",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "delay": [], "range": 1}"#),
            "line 2: range: unknown field `range`",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "delay": []}"#),
            "line 2: link: give \"tx\" and \"rx\", or \"link\": [tx, rx] (not both)",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "link": [0, 1], "delay": []}"#),
            "line 2: link: give",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": -1, "rx": 1, "delay": []}"#),
            "line 2: tx: invalid value: integer `-1`",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "unit": "km", "delay": []}"#),
            "line 2: unit: unknown variant `km`, expected `s` or `m`",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "delay": [1e-8, NaN]}"#),
            "line 2: delay[1]: expected value (column",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "delay": [1e-8, 1e999]}"#),
            "line 2: delay[1]: number out of range (column",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "delay": [1e-8, "x"]}"#),
            "line 2: delay[1]: invalid type: string \"x\", expected f64",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "delay": [1e-8, -2e-8]}"#),
            "line 2: delay[1]: -2e-8 s is out of range (0 < delay <= 1 s)",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "unit": "m", "delay": [3e9]}"#),
            "line 2: delay[0]: 3000000000 m is out of range (0 < delay <= 1 s once divided by c)",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "delay": [1e-8, 2e-8], "snr": [3]}"#),
            "line 2: snr: 1 values, expected 2 (one per delay)",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "delay": [1e-8], "sigma": [1, 2]}"#),
            "line 2: sigma: 2 values, expected 1 (one per delay)",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "delay": [1e-8], "doppler": []}"#),
            "line 2: doppler: 0 values, expected 1 (one per delay)",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "delay": [1e-8], "snr": [400]}"#),
            "line 2: snr[0]: 400 is out of range (-300 to 300 dB)",
        ),
        (
            two(r#"{"timestamp": 0.1, "tx": 0, "rx": 1, "delay": [1e-8], "sigma": [0]}"#),
            "line 2: sigma[0]: must be > 0 (got 0 s)",
        ),
        (
            two(r#"{"timestamp": 0, "tx": 0, "rx": 0, "delay": []}"#),
            "line 2: link: [0, 0] appears twice in the frame at 0 s (first on line 1)",
        ),
        (
            two(r#"{"timestamp": -0.1, "tx": 0, "rx": 1, "delay": []}"#),
            "line 2: timestamp: -0.1 s is before the previous frame's 0 s",
        ),
    ];
    let mut wrong = Vec::new();
    for (text, want) in &cases {
        let got = error(text);
        if !got.starts_with(want) || got.contains('\n') || got.len() > 400 {
            wrong.push(format!("{text}\n  got:  {got}\n  want: {want}"));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // A non-finite value built in memory is named too.
    let mut line = Detections::from_text(OK).unwrap().frames[0].lines[0].clone();
    line.delay[0] = f64::NAN;
    assert_eq!(
        line.check().unwrap_err().to_string(),
        "line 1: delay[0]: not a finite number"
    );
    line.delay[0] = 1e-8;
    line.doppler_hz = Some(vec![f64::INFINITY]);
    assert_eq!(
        line.check().unwrap_err().to_string(),
        "line 1: doppler[0]: not a finite number"
    );
}

#[test]
fn the_caps_are_named() {
    // Line length.
    let long = format!(
        "{OK}\n{{\"timestamp\": 1, \"tx\": 0, \"rx\": 0, \"delay\": [{}1e-8]}}",
        " ".repeat(limits::MAX_DETECTION_LINE_BYTES)
    );
    assert!(
        error(&long).starts_with("line 2: ")
            && error(&long).contains("bytes, a line may have at most 1048576"),
        "{}",
        error(&long)
    );
    // Detections per line.
    let many = format!(
        "{{\"timestamp\": 1, \"tx\": 0, \"rx\": 0, \"delay\": [{}1e-8]}}",
        "1e-8,".repeat(limits::MAX_DETECTIONS_PER_LINE)
    );
    assert_eq!(
        error(&many),
        "line 1: delay: 4097 detections, at most 4096 are allowed per line"
    );
    // Lines (blank ones count; the last line's `\n` ends it, it starts none).
    let lines = "\n".repeat(limits::MAX_DETECTION_LINES + 1);
    assert_eq!(
        error(&lines),
        "line 4194305: more than 4194304 lines are not allowed"
    );
    assert!(Detections::from_text(&lines[1..])
        .unwrap()
        .frames
        .is_empty());
}

#[test]
fn conversion_errors_name_the_frame_and_the_link() {
    // One frame only.
    assert_eq!(
        convert_error(OK),
        "detections: 1 frame(s); at least 2 are needed (the first starts the track)"
    );
    // A link not in the scenario (L4: one Tx, four Rx).
    let unknown = format!("{OK}\n{{\"timestamp\": 0.1, \"link\": [1, 0], \"delay\": []}}\n");
    assert_eq!(
        convert_error(&unknown),
        "line 2: link: [1, 0] (tx, rx) is not a link of the scenario (4 links: [0, 0], [0, 1], \
         [0, 2], [0, 3])"
    );
    // Non-uniform frames: the third frame comes 0.2 s after the second, the mean is 0.15 s.
    let uneven = format!(
        "{OK}\n{}\n{}\n",
        OK.replace("\"timestamp\": 0", "\"timestamp\": 0.1"),
        OK.replace("\"timestamp\": 0", "\"timestamp\": 0.3")
    );
    let e = convert_error(&uneven);
    assert!(
        e.starts_with(
            "line 2: timestamp: frame 1 comes 0.1 s after the previous one, the mean spacing is \
             0.15 s: frames must be uniform in time within 1e-6 relative"
        ),
        "{e}"
    );
    // Within 1e-6 relative: uniform.
    let close = format!(
        "{OK}\n{}\n{}\n",
        OK.replace("\"timestamp\": 0", "\"timestamp\": 0.1"),
        OK.replace("\"timestamp\": 0", "\"timestamp\": 0.20000001")
    );
    let m = Detections::from_text(&close)
        .unwrap()
        .to_measurements(&model(), 0.1)
        .unwrap();
    assert_eq!(m.dt_s, 0.20000001 / 2.0);
    // A bad process noise is E7's error.
    let two = format!(
        "{OK}\n{}\n",
        OK.replace("\"timestamp\": 0", "\"timestamp\": 0.1")
    );
    let e = Detections::from_text(&two)
        .unwrap()
        .to_measurements(&model(), -1.0)
        .unwrap_err();
    assert_eq!(e.field(), Some("process_noise"), "{e}");
    // A frame built in memory is named by its index.
    let mut d = Detections::from_text(&uneven).unwrap();
    for f in &mut d.frames {
        f.lines[0].line = 0;
    }
    let e = d.to_measurements(&model(), 0.1).unwrap_err().to_string();
    assert!(e.starts_with("frame 1: timestamp: frame 1 comes"), "{e}");
    let _ = ToString::to_string(&0);
}
