//! Tests of the FeitCSI reader: the real files against CSIKit, malformed inputs, sniffing.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;

use super::maps::{map, rate, Phy};
use super::reader::{header, HEADER};
use super::{read, sniff};
use crate::edge::csi::capture::CsiCapture;
use crate::math::Real;

use crate::edge::csi::test_file as file;

fn tones(ranges: &[(i32, i32)], pilots: &[i32]) -> Vec<i32> {
    let all = ranges.iter().flat_map(|&(a, b)| a..=b);
    all.filter(|k| !pilots.contains(&k.abs())).collect()
}

/// One synthetic frame: `k` values per antenna pair, value `n` of a pair = (n, −n).
fn frame(flags: u32, rx: u8, tx: u8, k: u32, ftm: u32, mu: u32) -> Vec<u8> {
    let mut b = vec![0u8; HEADER];
    let len = 4 * u32::from(rx) * u32::from(tx) * k;
    b[0..4].copy_from_slice(&len.to_le_bytes());
    b[8..12].copy_from_slice(&ftm.to_le_bytes());
    b[46] = rx;
    b[47] = tx;
    b[52..56].copy_from_slice(&k.to_le_bytes());
    b[88..92].copy_from_slice(&mu.to_le_bytes());
    b[92..96].copy_from_slice(&flags.to_le_bytes());
    for _ in 0..u32::from(rx) * u32::from(tx) {
        for n in 0..k as i16 {
            b.extend(n.to_le_bytes());
            b.extend((-n).to_le_bytes());
        }
    }
    b
}

/// Rate flags: format code, width code.
fn flags(format: u32, width: u32) -> u32 {
    (format << 8) | (width << 11) | (3 << 14)
}

fn err(bytes: &[u8]) -> String {
    read(bytes).unwrap_err().to_string()
}

/// The independent reader: CSIKit 2.5, `get_reader(f).read_file(f, scaled=False,
/// interpolate=False)` (CSIKit's default `interpolate=True` replaces the pilot tones by
/// interpolated values), `frames[f].csi_matrix[position of k in the full map, rx, 0]`;
/// times `timestamps[-1]` (relative to the first frame; ours add the first `ftm_clock`).
#[test]
fn he160_file_matches_csikit() {
    let cap = read(&file("feitcsi/HESU160_5500.csi")).unwrap();
    assert_eq!(cap.frame_count(), 26);
    assert_eq!((cap.n_rx, cap.n_tx), (2, 1));
    assert_eq!(cap.bandwidth_hz, 160e6);
    assert_eq!(cap.spacing_hz, 78_125.0);
    assert_eq!(cap.frame_format, "HE-SU");
    assert_eq!(cap.center_hz, None);
    assert!(cap.pilots.is_empty() && cap.skipped.is_empty() && cap.gain.is_none());
    // CSIKit's 1992 subcarriers = the HE 160 map; the 32 zeroed pilot tones left out.
    let map = [(-1012, -515), (-509, -12), (12, 509), (515, 1012)];
    assert_eq!(tones(&map, &[]).len(), 1992);
    let pilots = [
        44, 112, 178, 246, 286, 354, 420, 488, 536, 604, 670, 738, 778, 846, 912, 980,
    ];
    assert_eq!(cap.subcarriers, tones(&map, &pilots));
    assert_eq!(cap.subcarriers.len(), 1960);
    let truth = [
        (0, 0, -1012, -45, -88),
        (0, 0, -1011, -36, -93),
        (0, 0, -12, 48, -124),
        (0, 0, 12, 128, 53),
        (0, 0, 1012, -2, 54),
        (0, 1, -1012, 91, -70),
        (0, 1, -12, 207, -91),
        (0, 1, 12, 74, 199),
        (0, 1, 1012, 8, 80),
        (13, 0, -1011, 99, -5),
        (13, 1, -12, 150, -185),
        (25, 0, -1012, 38, -86),
        (25, 0, 12, 17, 122),
        (25, 1, -1011, -112, -46),
        (25, 1, 1012, 71, -11),
    ];
    check(&cap, &truth);
    // ftm_clock 806346444 and 1408974812 ticks of 3.125 ns; CSIKit: last − first 1.88321365 s.
    assert!((cap.t_s[0] - 806_346_444.0 * 3.125e-9).abs() < 1e-12);
    assert!((cap.t_s[25] - cap.t_s[0] - 1.883_213_65).abs() < 1e-9);
}

fn check(cap: &CsiCapture, truth: &[(usize, usize, i32, i32, i32)]) {
    for &(f, r, k, re, im) in truth {
        let j = cap.subcarriers.iter().position(|&s| s == k).unwrap();
        let z = cap.pair(f, r, 0)[j];
        assert_eq!(
            (z.re, z.im),
            (re as Real, im as Real),
            "frame {f} rx {r} k {k}"
        );
    }
}

/// CSIKit as above, VHT 80: 242 subcarriers (the map), 8 pilots left out.
#[test]
fn vht80_file_matches_csikit() {
    let cap = read(&file("feitcsi/VHT80_5500.csi")).unwrap();
    assert_eq!(cap.frame_count(), 40);
    assert_eq!((cap.n_rx, cap.n_tx), (2, 1));
    assert_eq!((cap.bandwidth_hz, cap.spacing_hz), (80e6, 312_500.0));
    assert_eq!(cap.frame_format, "VHT");
    let map = [(-122, -2), (2, 122)];
    assert_eq!(tones(&map, &[]).len(), 242);
    assert_eq!(cap.subcarriers, tones(&map, &[11, 39, 75, 103]));
    let truth = [
        (0, 0, -122, -74, 91),
        (0, 0, -121, -107, 74),
        (0, 0, -2, -168, 103),
        (0, 0, 2, -223, -107),
        (0, 0, 122, 61, 38),
        (0, 1, -122, -143, -31),
        (0, 1, 122, 91, 109),
        (20, 0, 2, -39, -245),
        (20, 1, -121, -72, -128),
        (39, 0, -122, -83, 77),
        (39, 0, 2, 244, 19),
        (39, 1, -2, -160, 119),
        (39, 1, 122, -146, 13),
    ];
    check(&cap, &truth);
    assert!((cap.t_s[0] - 750_633_892.0 * 3.125e-9).abs() < 1e-12);
    assert!((cap.t_s[39] - cap.t_s[0] - 2.095_110_55).abs() < 1e-9);
}

/// The raw files hold exactly 0 at every pilot tone (why they are left out).
#[test]
fn raw_pilot_tones_are_zero() {
    for name in ["feitcsi/HESU160_5500.csi", "feitcsi/VHT80_5500.csi"] {
        let b = file(name);
        let mut pos = 0;
        while pos < b.len() {
            let h = header(&b[pos..]).unwrap();
            let (phy, w) = rate(h.rate_flags).unwrap();
            let m = map(phy, w).unwrap();
            let data = &b[pos + HEADER..pos + HEADER + h.csi_length];
            for block in data.chunks_exact(4 * h.num_subcarriers as usize) {
                for (k, v) in m.tones().iter().zip(block.chunks_exact(4)) {
                    assert_eq!(m.is_pilot(*k), v == [0, 0, 0, 0], "{name} k {k}");
                }
            }
            pos += HEADER + h.csi_length;
        }
    }
}

/// The pilots' positions in each map are FeitCSI's `*_PILOT_INDICES` (include/Csi.h).
#[test]
fn pilot_positions_are_feitcsis() {
    let feit: [(Phy, u32, &[usize]); 9] = [
        (Phy::Legacy, 20, &[5, 19, 32, 46]),
        (Phy::Ht, 20, &[7, 21, 34, 48]),
        (Phy::Vht, 40, &[5, 33, 47, 66, 80, 108]),
        (Phy::Vht, 80, &[19, 47, 83, 111, 130, 158, 194, 222]),
        (
            Phy::Vht,
            160,
            &[
                19, 47, 83, 111, 130, 158, 194, 222, 261, 289, 325, 353, 372, 400, 436, 464,
            ],
        ),
        (Phy::He, 20, &[6, 32, 74, 100, 141, 167, 209, 235]),
        (
            Phy::He,
            40,
            &[
                6, 32, 74, 100, 140, 166, 208, 234, 249, 275, 317, 343, 383, 409, 451, 477,
            ],
        ),
        (
            Phy::He,
            80,
            &[
                32, 100, 166, 234, 274, 342, 408, 476, 519, 587, 653, 721, 761, 829, 895, 963,
            ],
        ),
        (
            Phy::He,
            160,
            &[
                32, 100, 166, 234, 274, 342, 408, 476, 519, 587, 653, 721, 761, 829, 895, 963,
                1028, 1096, 1162, 1230, 1270, 1338, 1404, 1472, 1515, 1583, 1649, 1717, 1757, 1825,
                1891, 1959,
            ],
        ),
    ];
    let sizes = [52, 56, 114, 242, 484, 242, 484, 996, 1992];
    for ((phy, w, want), size) in feit.into_iter().zip(sizes) {
        let m = map(phy, w).unwrap();
        let t = m.tones();
        let got: Vec<usize> = (0..t.len()).filter(|&n| m.is_pilot(t[n])).collect();
        assert_eq!((got.as_slice(), t.len()), (want, size), "{phy:?} {w}");
    }
}

#[test]
fn truncated_files_fail_with_the_frame_and_field() {
    let b = file("feitcsi/VHT80_5500.csi");
    let one = HEADER + 1936;
    for cut in 1..2 * one {
        match read(&b[..cut]) {
            Ok(cap) => assert_eq!((cut, cap.frame_count()), (one, 1)),
            Err(e) => {
                let (f, text) = (cut / one, e.to_string());
                let field = if cut % one < HEADER {
                    "header"
                } else {
                    "csi_length"
                };
                assert!(
                    text.starts_with(&format!("frame {f}: {field}:")),
                    "{cut}: {text}"
                );
            }
        }
    }
    assert_eq!(
        read(&[]).unwrap_err().to_string(),
        "frame 0: header: an empty file"
    );
}

#[test]
fn any_header_byte_changed_never_panics() {
    let b = file("feitcsi/VHT80_5500.csi");
    let two = 2 * (HEADER + 1936);
    for at in (0..HEADER).chain(HEADER + 1936..HEADER + 1936 + HEADER) {
        for v in [0x00, 0x01, 0x7f, 0xff] {
            let mut c = b[..two].to_vec();
            c[at] = v;
            let _ = read(&c);
            let _ = sniff(&c);
        }
    }
}

#[test]
fn bad_headers_are_named() {
    let he160 = flags(4, 3);
    let mut b = frame(he160, 2, 1, 1992, 0, 0);
    b[0..4].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(err(&b).starts_with("frame 0: csi_length: 4294967295 bytes, only 15936"));
    let mut two = frame(he160, 2, 1, 1992, 0, 0);
    let mut c = frame(he160, 2, 1, 1992, 1, 1);
    c[0..4].copy_from_slice(&15932u32.to_le_bytes());
    two.extend(c);
    assert!(err(&two).starts_with("frame 1: csi_length: 15932 bytes, not 4 · 2 rx"));
    for (at, v, field) in [(46, 0, "num_rx"), (46, 9, "num_rx"), (47, 0, "num_tx")] {
        let mut b = frame(he160, 2, 1, 1992, 0, 0);
        b[at] = v;
        assert!(err(&b).starts_with(&format!("frame 0: {field}: {v}: impossible")));
    }
    let b = frame(he160, 2, 1, 1000, 0, 0);
    let e = err(&b);
    assert!(
        e.starts_with("frame 0: num_subcarriers: 1000: HE-SU at 160 MHz has 1992"),
        "{e}"
    );
    let b = frame(flags(0, 0), 1, 1, 52, 0, 0);
    assert!(err(&b).starts_with("frame 0: rate_flags: no frame of a format"));
}

#[test]
fn other_configurations_are_skipped_and_the_160_bug_is_fixed() {
    // VHT 160 written with the firmware bug: 498 values, entries 242..256 padding.
    let mut b = frame(flags(3, 3), 1, 1, 498, 100, 0);
    b.extend(frame(flags(0, 0), 1, 1, 52, 200, 1));
    b.extend(frame(flags(3, 2), 1, 1, 242, 300, 2));
    b.extend(frame(flags(3, 3), 1, 1, 484, 400, 3));
    let cap = read(&b).unwrap();
    assert_eq!(cap.frame_count(), 2);
    assert_eq!(cap.subcarriers.len(), 484 - 16);
    let skipped: Vec<usize> = cap.skipped.iter().map(|s| s.0).collect();
    assert_eq!(skipped, [1, 2]);
    assert!(cap.skipped[1]
        .1
        .contains("VHT 80 MHz 1×1, the capture is VHT 160 MHz 1×1"));
    // Entry 256 (after the padding) is tone 6 (the 122nd of the map); entry 241 tone −6.
    let j = |k: i32| cap.subcarriers.iter().position(|&s| s == k).unwrap();
    assert_eq!(cap.pair(0, 0, 0)[j(-6)].re, 241.0);
    assert_eq!(cap.pair(0, 0, 0)[j(6)].re, 256.0);
    assert_eq!(cap.pair(1, 0, 0)[j(6)].re, 242.0);
    assert!(cap.notes.iter().any(|n| n.contains("firmware bug")));
    assert_eq!(cap.t_s[1] - cap.t_s[0], 300.0 * 3.125e-9);
}

#[test]
fn ftm_clock_wraps_are_counted_with_mu_clock() {
    let f = flags(4, 0);
    let mut b = frame(f, 1, 1, 242, 0xFFFF_FF00, 1000);
    b.extend(frame(f, 1, 1, 242, 0x100, 1001));
    // 20 s later: the tick counter wrapped once (13.4 s), mu_clock says 20 s.
    let ticks = 0x100u64 + 20 * 320_000_000;
    b.extend(frame(f, 1, 1, 242, ticks as u32, 20_001_001));
    let cap = read(&b).unwrap();
    assert!((cap.t_s[1] - cap.t_s[0] - 512.0 * 3.125e-9).abs() < 1e-15);
    assert!((cap.t_s[2] - cap.t_s[1] - 20.0).abs() < 1e-9);
}

#[test]
fn sniff_claims_only_feitcsi() {
    assert!(sniff(&file("feitcsi/HESU160_5500.csi")));
    assert!(sniff(&file("feitcsi/VHT80_5500.csi")));
    for other in [
        "intel/example.dat",
        "nexmon/example_4366c0.pcap",
        "pico/picoscenes_iwl5300_example.csi",
        "esp32/example_data.csv",
        "../recording-cir-int16.npz",
    ] {
        assert!(!sniff(&file(other)), "{other}");
    }
    assert!(!sniff(&[]));
}
