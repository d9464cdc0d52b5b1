//! The file formats: what they write (key order, absent options left out, as the CLI's files
//! always were) and the named errors of their checks.

use alloc::string::ToString;
use alloc::vec;

use super::*;
use crate::error::Error;
use crate::track::MAX_STEPS;

/// `simulate-walk`'s measurements (raw form, LM start) and truth, written as before the
/// formats moved into the core: these exact bytes.
#[test]
fn written_files_keep_their_keys_and_order() {
    let m = Measurements {
        dt_s: 0.1,
        process_noise: 0.1,
        initial_state: None,
        initial_covariance: None,
        initial_snapshot: Some(vec![vec![RawEstimate::Pair([1e-7, 2.0])], vec![]]),
        sigma_s: None,
        steps: None,
        raw_steps: Some(vec![vec![vec![], vec![RawEstimate::Pair([9e-8, 1.5])]]]),
    };
    let text = serde_json::to_string(&m).unwrap();
    assert_eq!(
        text,
        r#"{"dt_s":0.1,"process_noise":0.1,"initial_snapshot":[[[1e-7,2.0]],[]],"raw_steps":[[[],[[9e-8,1.5]]]]}"#
    );
    assert_eq!(Measurements::from_json(&text).unwrap(), m);
    let t = Truth {
        t_s: vec![0.1],
        states: vec![[1.0, 2.0, 0.0, 0.5]],
        resolved: vec![vec![true, false]],
    };
    assert_eq!(
        serde_json::to_string(&t).unwrap(),
        r#"{"t_s":[0.1],"states":[[1.0,2.0,0.0,0.5]],"resolved":[[true,false]]}"#
    );
}

#[test]
fn bad_files_are_named_errors() {
    let base = r#""dt_s": 0.1, "process_noise": 0.1"#;
    let parse = |rest: &str| Measurements::from_json(&alloc::format!("{{{base}{rest}}}")).unwrap();
    // Both forms, neither form.
    for rest in [r#", "steps": [], "raw_steps": []"#, ""] {
        let e = parse(rest).steps().unwrap_err();
        assert!(
            matches!(e, Error::InvalidFile { ref field, .. } if field == "steps"),
            "{e}"
        );
    }
    // Too many steps.
    let mut m = parse(r#", "steps": []"#);
    m.steps = Some(vec![vec![]; MAX_STEPS + 1]);
    assert!(m.steps().unwrap_err().to_string().contains("at most"));
    // A snapshot start needs the raw form; a state needs its covariance.
    let snap = parse(r#", "initial_snapshot": [[]], "steps": [[null]]"#);
    assert!(matches!(snap.start(), Err(Error::InvalidFile { .. })));
    let half = parse(r#", "initial_state": [0, 0, 0, 0], "steps": [[null]]"#);
    assert!(matches!(half.start(), Err(Error::InvalidFile { .. })));
    // An unknown key is a parse error naming it.
    let e = Measurements::from_json(&alloc::format!("{{{base}, \"stepz\": []}}")).unwrap_err();
    assert!(
        matches!(e, Error::Parse { ref message } if message.contains("stepz")),
        "{e}"
    );
    // σ per link, the wrong count; a raw step with the wrong number of lists.
    let m = parse(r#", "sigma_s": [1e-9, 1e-9], "steps": [[null]]"#);
    assert!(matches!(
        m.sigmas(3),
        Err(Error::LengthMismatch {
            field: "sigma_s",
            ..
        })
    ));
    let e = Measurements::estimates("raw_steps[2]", &vec![vec![]], 2).unwrap_err();
    assert_eq!(
        e.to_string(),
        "raw_steps[2]: expected 2 lists (one per link), found 1"
    );
    // Snapshots: none, and a non-finite truth state.
    let none = CalibrationSnapshots::from_json(r#"{"snapshots": []}"#).unwrap();
    assert!(
        matches!(none.check(1), Err(Error::InvalidFile { ref field, .. }) if field == "snapshots")
    );
    let t = Truth {
        t_s: vec![0.1],
        states: vec![[f64::NAN, 0.0, 0.0, 0.0]],
        resolved: vec![],
    };
    assert_eq!(
        t.check_times(&[0.1]).unwrap_err().to_string(),
        "states[0]: not a finite number"
    );
}

/// The channel simulator's truth (`cir simulate`'s `truth.json`: `channel::ChannelTruth`) reads
/// as a [`Truth`] (`track --truth`): its `t_s` and `states`, its other keys ignored.
#[test]
fn channel_truth_reads_as_truth() {
    use crate::channel::{ChannelTruth, ClockState, PathKind, TruePath};
    let truth = ChannelTruth {
        t_s: vec![0.0, 0.1],
        states: vec![[1.0, 2.0, 0.5, 0.0], [1.05, 2.0, 0.5, 0.0]],
        paths: vec![
            vec![vec![TruePath {
                kind: PathKind::Body,
                delay_s: 1e-7,
                power_w: 1e-12,
            }]];
            2
        ],
        shadowed: vec![vec![true]; 2],
        clock: vec![
            vec![ClockState {
                delay_s: 1e-9,
                phase_rad: 0.5,
                gain_db: 0.0,
            }];
            2
        ],
    };
    let t = Truth::from_json(&serde_json::to_string(&truth).unwrap()).unwrap();
    assert_eq!(t.t_s, truth.t_s);
    assert_eq!(t.states, truth.states);
    assert!(t.resolved.is_empty());
    t.check_times(&truth.t_s).unwrap();
}

mod detections;
