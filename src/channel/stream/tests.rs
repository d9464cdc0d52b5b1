use super::*;

fn header() -> FrameHeader {
    FrameHeader {
        format: STREAM_FORMAT.into(),
        version: STREAM_VERSION,
        links: alloc::vec![[0, 0], [0, 1]],
        freq_hz: (0..4).map(|n| -1.5e6 + n as Real * 1e6).collect(),
        system_response: None,
        noise_var: None,
        synchronized: Some(true),
    }
}

fn field(e: &Error) -> String {
    e.field().unwrap_or_default().into()
}

/// A header and a frame written then read give the same header, the time and the samples
/// rounded to `f32`.
#[test]
fn a_frame_round_trips() {
    let h = header();
    let line = h.encode().unwrap();
    assert_eq!(*line.last().unwrap(), b'\n');
    let back = FrameHeader::from_json(&line[..line.len() - 1]).unwrap();
    assert_eq!(back, h);
    let x: Vec<Complex> = (0..8)
        .map(|i| Complex::new(0.1 * i as Real, -1.0 / (i + 1) as Real))
        .collect();
    let f = encode_frame(0.125, &x);
    let len = u32::from_le_bytes([f[0], f[1], f[2], f[3]]);
    assert_eq!(h.check_length(0, len).unwrap(), Some(h.payload_len()));
    assert_eq!(h.payload_len(), 8 + 8 * 8);
    let mut got = Vec::new();
    let t = h.parse_frame(0, &f[4..], &mut got).unwrap();
    assert_eq!(t, 0.125);
    for (a, b) in got.iter().zip(&x) {
        assert_eq!(a.re, b.re as f32 as Real);
        assert_eq!(a.im, b.im as f32 as Real);
    }
    assert_eq!(h.check_length(7, 0).unwrap(), None);
}

/// Each malformed piece is a named error naming the frame (or the header).
#[test]
fn malformed_streams_are_named_errors() {
    let h = header();
    // Wrong length, a huge length field.
    for len in [8u32, 71, 80, u32::MAX] {
        let e = h.check_length(3, len).unwrap_err();
        assert_eq!(field(&e), "frames[3]", "{e}");
        assert!(e.to_string().contains("payload length"), "{e}");
    }
    // Truncated payload.
    let f = encode_frame(1.0, &[Complex::new(1.0, 0.0); 8]);
    let e = h.parse_frame(5, &f[4..40], &mut Vec::new()).unwrap_err();
    assert_eq!(field(&e), "frames[5]");
    assert!(e.to_string().contains("truncated"), "{e}");
    // A NaN time, an infinite sample.
    let f = encode_frame(Real::NAN, &[Complex::new(1.0, 0.0); 8]);
    let e = h.parse_frame(1, &f[4..], &mut Vec::new()).unwrap_err();
    assert!(e.to_string().contains("frames[1]: its time"), "{e}");
    let mut x = [Complex::new(1.0, 0.0); 8];
    x[6] = Complex::new(0.0, Real::INFINITY);
    let f = encode_frame(1.0, &x);
    let e = h.parse_frame(2, &f[4..], &mut Vec::new()).unwrap_err();
    assert!(e.to_string().contains("sample [1, 2]"), "{e}");
    // Headers: not JSON, another format, version, too few bins, not uniform, unknown field.
    let bad: [(&[u8], &str); 7] = [
        (b"\x00\x01binary", "header"),
        (b"{}", "header"),
        (
            br#"{"format":"x","version":1,"links":[[0,0]],"freq_hz":[0,1]}"#,
            "header",
        ),
        (
            br#"{"format":"scatterloc-frames","version":2,"links":[[0,0]],"freq_hz":[0,1]}"#,
            "header",
        ),
        (
            br#"{"format":"scatterloc-frames","version":1,"links":[[0,0]],"freq_hz":[0]}"#,
            "freq_hz",
        ),
        (
            br#"{"format":"scatterloc-frames","version":1,"links":[[0,0]],"freq_hz":[0,1,5]}"#,
            "freq_hz",
        ),
        (
            br#"{"format":"scatterloc-frames","version":1,"links":[],"freq_hz":[0,1],"x":1}"#,
            "header",
        ),
    ];
    for (line, f) in bad {
        let e = FrameHeader::from_json(line).unwrap_err();
        assert_eq!(field(&e), f, "{e}");
    }
    let e = FrameHeader::from_json(
        br#"{"format":"scatterloc-frames","version":1,"links":[],"freq_hz":[0,1]}"#,
    )
    .unwrap_err();
    assert_eq!(field(&e), "links", "{e}");
}
