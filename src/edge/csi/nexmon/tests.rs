use alloc::vec::Vec;

use super::{read, sniff};
use crate::edge::csi::capture::CsiFormat;
use crate::math::Complex;

const FILE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/csi/nexmon/example_4366c0.pcap"
);

fn real() -> Vec<u8> {
    std::fs::read(FILE).unwrap()
}

fn err(bytes: &[u8]) -> String {
    match read(bytes) {
        Ok(c) => panic!("expected an error, got {} frames", c.frame_count()),
        Err(e) => e.to_string(),
    }
}

/// One Ethernet/IPv4/UDP frame to `port` carrying `payload`.
fn udp(port: u16, payload: &[u8]) -> Vec<u8> {
    let mut f = Vec::new();
    f.extend_from_slice(&[0xff; 6]);
    f.extend_from_slice(b"NEXMON");
    f.extend_from_slice(&[0x08, 0x00]);
    let total = (20 + 8 + payload.len()) as u16;
    f.extend_from_slice(&[
        0x45,
        0,
        (total >> 8) as u8,
        total as u8,
        0,
        1,
        0,
        0,
        1,
        17,
        0,
        0,
    ]);
    f.extend_from_slice(&[10, 10, 10, 10, 255, 255, 255, 255]);
    let ul = (8 + payload.len()) as u16;
    f.extend_from_slice(&[0x15, 0x7c]);
    f.extend_from_slice(&port.to_be_bytes());
    f.extend_from_slice(&[(ul >> 8) as u8, ul as u8, 0, 0]);
    f.extend_from_slice(payload);
    f
}

/// A Nexmon payload: 4-byte magic (`old`) or 2-byte magic + RSSI −40 + fc; 20 MHz on 5 GHz
/// channel 36 (chanspec 0xd024) unless `chanspec` says otherwise; words `w(bin)`.
fn nexmon(
    old: bool,
    seq: u16,
    core: u16,
    ss: u16,
    chanspec: u16,
    chip: u16,
    w: &dyn Fn(usize) -> u32,
) -> Vec<u8> {
    let mut p = Vec::new();
    if old {
        p.extend_from_slice(&[0x11; 4]);
    } else {
        p.extend_from_slice(&[0x11, 0x11, (-40i8) as u8, 0x08]);
    }
    p.extend_from_slice(&[1, 2, 3, 4, 5, 6]);
    for v in [seq, core | ss << 3, chanspec, chip] {
        p.extend_from_slice(&v.to_le_bytes());
    }
    let nfft = match (chanspec >> 11) & 7 {
        3 => 128,
        4 => 256,
        _ => 64,
    };
    for b in 0..nfft {
        p.extend_from_slice(&w(b).to_le_bytes());
    }
    p
}

/// A classic pcap (little-endian µs unless `big`/`nano`) of `(sec, frac, data)` records.
fn pcap(big: bool, nano: bool, records: &[(u32, u32, Vec<u8>)]) -> Vec<u8> {
    let w32 = |v: u32| {
        if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let w16 = |v: u16| {
        if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let mut f = Vec::new();
    f.extend_from_slice(&w32(if nano { 0xa1b2_3c4d } else { 0xa1b2_c3d4 }));
    f.extend_from_slice(&w16(2));
    f.extend_from_slice(&w16(4));
    for v in [0, 0, 65535, 1] {
        f.extend_from_slice(&w32(v));
    }
    for (s, frac, d) in records {
        for v in [*s, *frac, d.len() as u32, d.len() as u32] {
            f.extend_from_slice(&w32(v));
        }
        f.extend_from_slice(d);
    }
    f
}

const CS20: u16 = 0xd024; // 5 GHz, 20 MHz, channel 36
const INT_CHIP: u16 = 101; // BCM43455c0

#[test]
fn real_file_matches_csiread() {
    let cap = read(&real()).unwrap();
    assert_eq!(cap.format, CsiFormat::Nexmon);
    assert_eq!(cap.device, "BCM4366c0");
    assert_eq!(cap.frame_format, "VHT");
    assert_eq!(cap.frame_count(), 293);
    assert!(cap.skipped.is_empty());
    assert_eq!((cap.n_rx, cap.n_tx), (1, 1));
    assert_eq!(cap.bandwidth_hz, 80e6);
    assert_eq!(cap.spacing_hz, 312.5e3);
    // chanspec 0xe06a: 5 GHz, 80 MHz, sideband LLL, centre channel 106 (control 100).
    assert_eq!(cap.center_hz, Some(5530e6));
    let want: Vec<i32> = (-122..=-2).chain(2..=122).collect();
    assert_eq!(cap.subcarriers, want);
    assert_eq!(cap.pilots, [-103, -75, -39, -11, 11, 39, 75, 103]);
    // csiread 1.4.1: d = csiread.Nexmon(FILE, chip='4366c0', bw=80, if_report=False);
    // d.read(); d.csi[f][k % 256] (raw FFT order); d.sec/d.usec for the times.
    let expect: [(usize, i32, f64, f64); 16] = [
        (0, -122, -859.0, -584.0),
        (0, -100, 33.0, 108.0),
        (0, -96, 7.0, -14.0),
        (0, -70, -61.0, -439.0),
        (0, 2, -1.0, 0.0),
        (0, 122, 3.0, 1.0),
        (1, -122, 457.0, 855.0),
        (1, -70, 86.0, 352.0),
        (1, -2, 6.0, -1.0),
        (146, -122, -176.0, 1077.0),
        (146, -100, -7.0, -222.0),
        (146, 2, -1.0, -1.0),
        (292, -122, 799.0, 648.0),
        (292, -70, -249.0, 363.0),
        (292, -96, 0.0, 12.0),
        (292, 122, 0.0, 4.0),
    ];
    for (f, k, re, im) in expect {
        let i = cap.subcarriers.iter().position(|&s| s == k).unwrap();
        assert_eq!(
            cap.pair(f, 0, 0)[i],
            Complex::new(re, im),
            "frame {f}, k {k}"
        );
    }
    assert!((cap.t_s[0] - 1_525_572_014.747_919).abs() < 1e-6);
    assert!((cap.t_s[292] - 1_525_572_044.648_93).abs() < 1e-6);
    // gain = 2^-shift, one power of two per frame
    let g = cap.gain.as_ref().unwrap();
    assert!(g.iter().all(|g| g.log2().fract() == 0.0));
    assert!(cap.notes.iter().any(|n| n.contains("guard and DC bins")));
}

#[test]
fn truncated_real_file_never_panics() {
    let bytes = real();
    let rec = 16 + 1084;
    for n in 0..24 + 2 * rec + 1 {
        let r = read(&bytes[..n]);
        if n == 24 + rec || n == 24 + 2 * rec {
            assert_eq!(r.unwrap().frame_count(), (n - 24) / rec);
        } else {
            let e = r.unwrap_err().to_string();
            if n < 24 {
                assert!(e.starts_with("pcap header:"), "{n}: {e}");
            } else if n > 24 {
                let frame = (n - 24) / rec;
                assert!(
                    e.starts_with(&format!("frame {frame}: pcap record")),
                    "{n}: {e}"
                );
            }
        }
    }
}

#[test]
fn huge_incl_len_and_bad_fraction_are_named() {
    let mut b = real();
    b[24 + 8..24 + 12].copy_from_slice(&0xffff_fff0u32.to_le_bytes());
    let e = err(&b);
    assert!(
        e.starts_with("frame 0: pcap record: incl_len 4294967280 bytes"),
        "{e}"
    );
    let mut b = real();
    b[24 + 1100 + 4..24 + 1100 + 8].copy_from_slice(&1_000_000u32.to_le_bytes());
    assert!(err(&b).starts_with("frame 1: timestamp"));
}

#[test]
fn unknown_chip_and_bandwidth_are_named() {
    let mut b = real();
    b[24 + 16 + 42 + 16] = 0x34; // chip version 0x0034
    let e = err(&b);
    assert!(e.starts_with("frame 0: chip version: 52 (0x0034)"), "{e}");
    assert!(
        e.contains("106 (BCM4366c0)") && e.contains("101 (BCM43455c0)"),
        "{e}"
    );
    let mut b = real();
    b[24 + 16 + 42 + 15] = 0xe8; // chanspec 0xe86a: bandwidth code 5, 160 MHz
    let e = err(&b);
    assert!(
        e.starts_with("frame 0: chanspec: 0xe86a: bandwidth code 5 (160 MHz"),
        "{e}"
    );
}

#[test]
fn non_csi_packets_and_short_payloads_are_skipped() {
    let good = |seq| {
        udp(
            5500,
            &nexmon(false, seq, 0, 0, CS20, INT_CHIP, &|b| b as u32),
        )
    };
    let mut magic = nexmon(false, 3, 0, 0, CS20, INT_CHIP, &|_| 0);
    magic[0] = 0x22;
    let mut short = good(5);
    short.truncate(short.len() - 4);
    let recs = [
        (1, 0, good(1)),
        (1, 10, udp(53, b"dns")),
        (1, 20, good(2)),
        (1, 30, udp(5500, &magic)),
        (1, 40, short),
        (1, 50, vec![0u8; 10]),
        (1, 60, good(6)),
    ];
    let cap = read(&pcap(false, false, &recs)).unwrap();
    assert_eq!(cap.frame_count(), 3);
    let reasons: Vec<(usize, &str)> = cap.skipped.iter().map(|(i, r)| (*i, r.as_str())).collect();
    assert_eq!(reasons[0], (1, "UDP to port 53, not 5500"));
    assert_eq!(reasons[1].0, 3);
    assert!(reasons[1].1.starts_with("magic 0x1122"), "{}", reasons[1].1);
    assert_eq!(reasons[2].0, 4);
    assert!(
        reasons[2]
            .1
            .starts_with("CSI 252 bytes: 20 MHz needs 64 words"),
        "{}",
        reasons[2].1
    );
    assert_eq!(reasons[3].0, 5);
    // only non-CSI packets: a named error with the first reason
    let e = err(&pcap(false, false, &[(1, 0, udp(53, b"x"))]));
    assert!(
        e.starts_with("capture: no Nexmon CSI packet") && e.contains("frame 0: UDP to port 53"),
        "{e}"
    );
    // no records at all
    assert!(err(&pcap(false, false, &[])).starts_with("capture: no Nexmon CSI packet"));
}

#[test]
fn int16_both_firmware_versions_and_byte_orders() {
    // word of bin b: low half 100 + b, high half −b
    let w =
        |b: usize| ((100 + b as u32) & 0xffff) | ((b as i16).wrapping_neg() as u16 as u32) << 16;
    let new = pcap(
        false,
        false,
        &[(
            7,
            250_000,
            udp(5500, &nexmon(false, 9, 0, 0, CS20, INT_CHIP, &w)),
        )],
    );
    let cap = read(&new).unwrap();
    assert_eq!(cap.device, "BCM43455c0");
    assert_eq!(cap.frame_format, "HT");
    assert_eq!(cap.center_hz, Some(5180e6));
    assert!(cap.gain.is_none());
    // newer firmware: subcarrier 28 carries PHY status and is dropped
    let want: Vec<i32> = (-28..=-1).chain(1..=27).collect();
    assert_eq!(cap.subcarriers, want);
    assert_eq!(cap.pilots, [-21, -7, 7, 21]);
    assert_eq!(cap.pair(0, 0, 0)[0], Complex::new(136.0, -36.0)); // k = −28: bin 36
    assert_eq!(cap.pair(0, 0, 0)[28], Complex::new(101.0, -1.0)); // k = 1
    assert!((cap.t_s[0] - 7.25).abs() < 1e-12);
    // old firmware (4-byte magic): I in the high half; all 56 subcarriers; big-endian ns pcap
    let old = pcap(
        true,
        true,
        &[(
            7,
            250_000_000,
            udp(5500, &nexmon(true, 9, 0, 0, CS20, INT_CHIP, &w)),
        )],
    );
    assert!(sniff(&old));
    let cap = read(&old).unwrap();
    assert_eq!(cap.subcarriers.len(), 56);
    assert_eq!(cap.pair(0, 0, 0)[55], Complex::new(-28.0, 128.0)); // k = 28
    assert!((cap.t_s[0] - 7.25).abs() < 1e-12);
}

#[test]
fn frames_group_antenna_pairs_and_skip_incomplete_ones() {
    // 2 cores × 2 streams, newer firmware (I in the low half): I = 10·core + ss + 1, Q = 0 on
    // every bin; frame 101 lacks core 1/stream 0.
    let pkt = |seq, core: u16, ss: u16| {
        let v = (10 * core + ss + 1) as u32;
        udp(
            5500,
            &nexmon(false, seq, core, ss, CS20, INT_CHIP, &move |_| v),
        )
    };
    let mut recs = Vec::new();
    for (t, seq) in [(1u32, 100u16), (2, 101), (3, 102)] {
        for (c, s) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            if !(seq == 101 && (c, s) == (1, 0)) {
                recs.push((t, 0, pkt(seq, c, s)));
            }
        }
    }
    let cap = read(&pcap(false, false, &recs)).unwrap();
    assert_eq!((cap.n_rx, cap.n_tx, cap.frame_count()), (2, 2, 2));
    assert_eq!(cap.t_s, [1.0, 3.0]);
    assert_eq!(cap.skipped.len(), 1);
    assert_eq!(cap.skipped[0].0, 4);
    assert!(cap.skipped[0]
        .1
        .starts_with("sequence number 101: 3 of the 4 antenna pairs"));
    for f in 0..2 {
        for (r, t) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            let want = Complex::new(f64::from(10 * r as u16 + t as u16 + 1), 0.0);
            assert!(cap.pair(f, r, t).iter().all(|z| *z == want), "{f} {r} {t}");
        }
    }
    // every frame incomplete: a named error
    let e = err(&pcap(false, false, &recs[4..7]));
    assert!(e.starts_with("capture: no complete frame"), "{e}");
}

#[test]
fn float_words_of_one_frame_share_the_shift() {
    // BCM4366c0 at 20 MHz on 2.4 GHz channel 6 (chanspec 0x1006), two streams of one core:
    // stream 0 has 1·2^0 on every bin, stream 1 has 1000·2^0; the frame shift is 10 − 9 = 1.
    let word = |re: u32, neg: bool| (re << 18) | if neg { 1 << 29 } else { 0 };
    let recs = [
        (
            1,
            0,
            udp(
                5500,
                &nexmon(true, 1, 0, 0, 0x1006, 106, &move |_| word(1, true)),
            ),
        ),
        (
            1,
            0,
            udp(
                5500,
                &nexmon(true, 1, 0, 1, 0x1006, 106, &move |_| word(1000, false)),
            ),
        ),
    ];
    let cap = read(&pcap(false, false, &recs)).unwrap();
    assert_eq!(cap.center_hz, Some(2437e6));
    assert_eq!(cap.gain.as_deref(), Some(&[0.5][..]));
    assert_eq!(cap.pair(0, 0, 0)[0], Complex::new(-2.0, 0.0));
    assert_eq!(cap.pair(0, 0, 1)[0], Complex::new(2000.0, 0.0));
}

#[test]
fn pcapng_and_link_types_are_named() {
    let mut ng = vec![0x0a, 0x0d, 0x0d, 0x0a, 28, 0, 0, 0, 0x4d, 0x3c, 0x2b, 0x1a];
    ng.resize(28, 0);
    assert!(sniff(&ng));
    assert!(err(&ng).starts_with("capture: a pcapng file"));
    let mut b = pcap(false, false, &[]);
    b[20] = 127; // radiotap
    assert!(err(&b).starts_with("pcap header: link type: 127"));
}

#[test]
fn sniff_claims_only_pcap() {
    assert!(sniff(&real()));
    for f in [
        "intel/example.dat",
        "pico/picoscenes_iwl5300_example.csi",
        "feitcsi/HESU160_5500.csi",
        "feitcsi/VHT80_5500.csi",
        "esp32/example_data.csv",
        "../recording-cir-int16.npz",
    ] {
        let path = format!("{}/tests/data/csi/{f}", env!("CARGO_MANIFEST_DIR"));
        assert!(!sniff(&std::fs::read(&path).unwrap()), "{f}");
    }
    assert!(!sniff(&[]) && !sniff(&[0xd4, 0xc3]));
}

#[test]
fn mutated_headers_never_panic_and_cooked_capture_reads() {
    let bytes = real();
    for at in 0..24 + 16 + 42 + 18 + 8 {
        for v in [0x00, 0x07, 0x11, 0x80, 0xff] {
            let mut b = bytes[..24 + 2 * 1100].to_vec();
            b[at] = v;
            let _ = read(&b);
        }
    }
    // Linux cooked capture (link type 113): 16-byte header, protocol at bytes 14–15
    let eth = udp(5500, &nexmon(false, 1, 0, 0, CS20, INT_CHIP, &|_| 5));
    let mut sll = vec![0u8; 14];
    sll.extend_from_slice(&eth[12..]);
    let mut b = pcap(false, false, &[(1, 0, sll)]);
    b[20] = 113;
    let cap = read(&b).unwrap();
    assert_eq!(cap.pair(0, 0, 0)[0], Complex::new(5.0, 0.0));
}
