//! The conversion of a capture to a recording (the masked grid, the link map, dropped frames,
//! the gain) on a hand-made capture, and `open_recording`'s dispatch.

use super::*;
use crate::channel::Layout;
use crate::math::Complex;

/// 3 frames, 2 Rx × 1 Tx, subcarriers −3, −1, 2 at 312.5 kHz; value = frame + rx/10 + k/100 j.
fn capture() -> CsiCapture {
    let ks = vec![-3, -1, 2];
    let mut csi = Vec::new();
    for f in 0..3 {
        for r in 0..2 {
            for &k in &ks {
                csi.push(Complex::new(f as f64 + r as f64 / 10.0, k as f64 / 100.0));
            }
        }
    }
    CsiCapture {
        format: CsiFormat::Intel5300,
        device: "test".into(),
        frame_format: "HT".into(),
        center_hz: Some(5.5e9),
        bandwidth_hz: 20e6,
        spacing_hz: 312.5e3,
        subcarriers: ks,
        pilots: vec![],
        n_rx: 2,
        n_tx: 1,
        t_s: vec![10.0, 10.5, 10.5],
        csi,
        gain: Some(vec![2.0, 3.0, 4.0]),
        notes: vec![],
        skipped: vec![],
    }
}

#[test]
fn grid_mask_links_and_dropped_frames() {
    let opts = ConvertOptions {
        apply_gain: false,
        ..ConvertOptions::default()
    };
    let c = to_recording(&capture(), &opts).unwrap();
    let r = &c.recording;
    // Frame 2 repeats frame 1's time: dropped and listed.
    assert_eq!(c.dropped, vec![(2, 10.5)]);
    assert_eq!(r.t_s, vec![0.0, 0.5]);
    assert_eq!(r.links, vec![[0, 0], [0, 1]]);
    assert_eq!(r.synchronized, Some(false));
    let Layout::Cfr {
        freq_hz,
        system_response,
    } = &r.layout
    else {
        panic!("CFR expected");
    };
    let want_f: Vec<f64> = (-3..=2).map(|k| k as f64 * 312.5e3).collect();
    assert_eq!(freq_hz, &want_f);
    let mask: Vec<f64> = system_response
        .as_ref()
        .unwrap()
        .iter()
        .map(|p| p.re)
        .collect();
    assert_eq!(mask, vec![1.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    // Gain not asked for: the raw values at their bins, zeros elsewhere.
    let h = r.response(1, 1);
    assert_eq!(h[0], Complex::new(1.1, -0.03));
    assert_eq!(h[1], Complex::new(0.0, 0.0));
    assert_eq!(h[2], Complex::new(1.1, -0.01));
    assert_eq!(h[5], Complex::new(1.1, 0.02));
    assert!(!c.gain_applied);
}

#[test]
fn gain_and_an_explicit_link_map() {
    let opts = ConvertOptions {
        links: Some(PairLink::parse_list("rx1.tx0=2:5").unwrap()),
        apply_gain: true,
        keep_unoccupied: true,
    };
    let c = to_recording(&capture(), &opts).unwrap();
    assert!(c.gain_applied);
    assert_eq!(c.recording.links, vec![[2, 5]]);
    // Frame 1, rx 1, k = 2 (grid bin 5) times the frame's gain 3.
    let h = c.recording.response(1, 0);
    assert!((h[5] - Complex::new(1.1, 0.02) * 3.0).norm() < 1e-12);
}

#[test]
fn link_map_errors_are_named() {
    for (text, want) in [
        ("rx0.tx0", "links[0]"),
        ("rx0.tx0=0:1,rx0.tx0=0:2", "links[1]"),
        ("rx0.tx0=0:1,rx1.tx0=0:1", "links[1]"),
        ("rxa.tx0=0:1", "links[0]"),
        ("rx0-tx0=0:1", "links[0]"),
    ] {
        let e = PairLink::parse_list(text).unwrap_err().to_string();
        assert!(e.contains(want), "{text}: {e}");
    }
    let opts = ConvertOptions {
        links: Some(PairLink::parse_list("rx2.tx0=0:0").unwrap()),
        apply_gain: false,
        keep_unoccupied: true,
    };
    let e = to_recording(&capture(), &opts).unwrap_err().to_string();
    assert!(e.contains("links[0]"), "{e}");
}

#[test]
fn capture_checks_are_named() {
    let mut c = capture();
    c.subcarriers = vec![2, -1, -3];
    assert!(c
        .validate()
        .unwrap_err()
        .to_string()
        .contains("subcarriers"));
    let mut c = capture();
    c.csi[7] = Complex::new(f64::NAN, 0.0);
    let e = c.validate().unwrap_err().to_string();
    assert!(e.contains("frame 1"), "{e}");
    let mut c = capture();
    c.csi.pop();
    assert!(c.validate().is_err());
    let mut c = capture();
    c.subcarriers = vec![-40000, 40000, 40001];
    assert!(c
        .validate()
        .unwrap_err()
        .to_string()
        .contains("subcarrier span"));
}

#[test]
fn open_dispatches_npz_and_refuses_unknown_bytes() {
    let rec = to_recording(&capture(), &ConvertOptions::default())
        .unwrap()
        .recording;
    let bytes = crate::npz::write_recording(&rec).unwrap();
    let opts = OpenOptions {
        max_npz_bytes: 1 << 30,
        ..OpenOptions::default()
    };
    let o = open_recording(&bytes, &opts).unwrap();
    assert!(o.csi.is_none());
    assert_eq!(o.recording, rec);
    let e = open_recording(b"hello world, not a recording", &opts)
        .unwrap_err()
        .to_string();
    // The `.npz` reader's message first (a damaged .npz), then that no CSI reader took it.
    assert!(e.starts_with("npz: not a zip archive"), "{e}");
    assert!(e.contains("nor a CSI file"), "{e}");
    let e = open_recording(
        &bytes,
        &OpenOptions {
            format: Some("pdf".into()),
            ..opts.clone()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("unknown CSI format"), "{e}");
}
