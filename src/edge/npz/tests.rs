use std::io::{Cursor, Write};

use super::*;
use crate::channel::{Layout, Pulse, Recording};
use crate::math::{Complex, Real};

fn cfr() -> Recording {
    let (s, p, n) = (3, 4, 5);
    Recording {
        t_s: (0..s).map(|k| 0.1 + k as Real * 2.048e-3).collect(),
        links: (0..p).map(|r| [0, r]).collect(),
        layout: Layout::Cfr {
            freq_hz: (0..n).map(|k| -1e6 + k as Real * 0.5e6).collect(),
            system_response: Some((0..n).map(|k| Complex::new(1.0, k as Real * 0.1)).collect()),
        },
        samples: (0..s * p * n)
            .map(|k| Complex::new(k as Real * 1e-7 + 1e-9 / 3.0, -(k as Real) * 3e-8))
            .collect(),
        noise_var: Some(vec![1e-13, 2e-13, 3e-13, 4e-13]),
        synchronized: None,
    }
}

fn cir(pulse: bool) -> Recording {
    Recording {
        layout: Layout::Cir {
            tap0_s: -1e-8,
            tap_spacing_s: 1e-9,
            pulse: pulse.then(|| Pulse {
                samples: vec![
                    Complex::new(0.25, 0.1),
                    Complex::new(1.0, 0.0),
                    Complex::new(0.25, -0.1),
                ],
                spacing_s: 0.5e-9,
            }),
        },
        noise_var: None,
        synchronized: None,
        ..cfr()
    }
}

fn err(bytes: &[u8]) -> String {
    format!("{}", read_recording(bytes).unwrap_err())
}

/// Bytes of a zip of `members` (name, npy bytes), stored or deflated.
fn zip_of(members: &[(&str, Vec<u8>)], deflate: bool) -> Vec<u8> {
    let mut z = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let opts = zip::write::SimpleFileOptions::default().compression_method(if deflate {
        zip::CompressionMethod::Deflated
    } else {
        zip::CompressionMethod::Stored
    });
    for (n, d) in members {
        z.start_file(*n, opts).unwrap();
        z.write_all(d).unwrap();
    }
    z.finish().unwrap().into_inner()
}

/// The members of a written recording, to edit one and zip them again.
fn members_of(rec: &Recording) -> Vec<(String, Vec<u8>)> {
    let bytes = write_recording(rec).unwrap();
    let mut z = zip::ZipArchive::new(Cursor::new(bytes)).unwrap();
    (0..z.len())
        .map(|k| {
            let mut f = z.by_index(k).unwrap();
            let mut d = Vec::new();
            std::io::Read::read_to_end(&mut f, &mut d).unwrap();
            (f.name().to_owned(), d)
        })
        .collect()
}

fn rezip(m: &[(String, Vec<u8>)]) -> Vec<u8> {
    let v: Vec<(&str, Vec<u8>)> = m.iter().map(|(n, d)| (n.as_str(), d.clone())).collect();
    zip_of(&v, false)
}

fn replace(rec: &Recording, name: &str, npy: Option<Vec<u8>>) -> Vec<u8> {
    let mut m = members_of(rec);
    m.retain(|(n, _)| n != &format!("{name}.npy"));
    if let Some(d) = npy {
        m.push((format!("{name}.npy"), d));
    }
    rezip(&m)
}

#[test]
fn round_trip_is_bit_exact() {
    for rec in [cfr(), cir(true), cir(false)] {
        let back = read_recording(&write_recording(&rec).unwrap()).unwrap();
        assert_eq!(back, rec);
    }
    let mut r = cfr();
    r.layout = Layout::Cfr {
        freq_hz: vec![0.0, 1.0, 2.0, 3.0, 4.0],
        system_response: None,
    };
    r.noise_var = None;
    assert_eq!(read_recording(&write_recording(&r).unwrap()).unwrap(), r);
}

#[test]
fn other_dtypes_and_byte_orders_are_read() {
    let rec = cfr();
    // complex64 big-endian cfr, int32 links, big-endian float64 t_s.
    let c64: Vec<u8> = rec
        .samples
        .iter()
        .flat_map(|z| {
            (z.re as f32)
                .to_be_bytes()
                .into_iter()
                .chain((z.im as f32).to_be_bytes())
        })
        .collect();
    let mut m = members_of(&rec);
    for (n, d) in m.iter_mut() {
        match n.as_str() {
            "cfr.npy" => *d = npy::write(">c8", &[3, 4, 5], &c64),
            "links.npy" => {
                let b: Vec<u8> = (0..4i32)
                    .flat_map(|r| 0i32.to_le_bytes().into_iter().chain(r.to_le_bytes()))
                    .collect();
                *d = npy::write("<i4", &[4, 2], &b)
            }
            "t_s.npy" => {
                let b: Vec<u8> = rec.t_s.iter().flat_map(|t| t.to_be_bytes()).collect();
                *d = npy::write(">f8", &[3], &b)
            }
            _ => {}
        }
    }
    let back = read_recording(&rezip(&m)).unwrap();
    assert_eq!(back.t_s, rec.t_s);
    assert_eq!(back.links, rec.links);
    for (a, b) in back.samples.iter().zip(&rec.samples) {
        assert_eq!(a.re, b.re as f32 as Real);
        assert_eq!(a.im, b.im as f32 as Real);
    }
    // int16 I/Q cir [S, P, M, 2].
    let r = cir(false);
    let iq: Vec<u8> = (0..3 * 4 * 5 * 2)
        .flat_map(|k| (k as i16 - 50).to_le_bytes())
        .collect();
    let back = read_recording(&replace(
        &r,
        "cir",
        Some(npy::write("<i2", &[3, 4, 5, 2], &iq)),
    ))
    .unwrap();
    assert_eq!(back.samples[7], Complex::new(-36.0, -35.0));
    let back = read_recording(&replace(
        &r,
        "cir",
        Some(npy::write(
            ">i4",
            &[3, 4, 5, 2],
            &(0..120i32)
                .flat_map(|k| k.to_be_bytes())
                .collect::<Vec<_>>(),
        )),
    ))
    .unwrap();
    assert_eq!(back.samples[1], Complex::new(2.0, 3.0));
}

#[test]
fn malformed_recordings_name_the_array() {
    let rec = cfr();
    let f8 = |v: &[f64]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (replace(&rec, "t_s", None), "t_s: missing array"),
        (
            replace(&rec, "cfr", None),
            "cfr: missing array (give exactly one of cfr and cir)",
        ),
        (replace(&rec, "freq_hz", None), "freq_hz: missing array"),
        (
            replace(&rec, "bogus", Some(npy::write("<f8", &[1], &f8(&[1.0])))),
            "bogus.npy: unknown array",
        ),
        (
            replace(&rec, "t_s", Some(npy::write("<f4", &[3], &[0u8; 12]))),
            "t_s: wrong dtype float32, expected float64",
        ),
        (
            replace(&rec, "links", Some(npy::write("<f8", &[4, 2], &[0u8; 64]))),
            "links: wrong dtype float64, expected int64 (or int32)",
        ),
        (
            replace(
                &rec,
                "cfr",
                Some(npy::write("<f8", &[3, 4, 5], &[0u8; 480])),
            ),
            "cfr: wrong dtype float64, expected complex64 or complex128",
        ),
        (
            replace(
                &rec,
                "cfr",
                Some(npy::write("<c16", &[3, 4, 4], &[0u8; 768])),
            ),
            "cfr: wrong shape (3, 4, 4), expected (S, P, N) = (3, 4, 5)",
        ),
        (
            replace(
                &rec,
                "noise_var",
                Some(npy::write("<f8", &[3], &f8(&[1.0; 3]))),
            ),
            "noise_var: wrong shape (3,), expected (P,) = (4,)",
        ),
        (
            replace(
                &rec,
                "t_s",
                Some(npy::write("<f8", &[3], &f8(&[0.0, 1.0, 1.0]))),
            ),
            "t_s: not strictly increasing: t_s[2]",
        ),
        (
            replace(
                &rec,
                "freq_hz",
                Some(npy::write("<f8", &[5], &f8(&[0.0, 1.0, 2.0, 3.5, 4.0]))),
            ),
            "freq_hz: not uniformly spaced",
        ),
        (
            replace(
                &rec,
                "t_s",
                Some(npy::write("<f8", &[3], &f8(&[0.0, f64::NAN, 1.0]))),
            ),
            "t_s: t_s[1] is not a finite number",
        ),
        (
            replace(&rec, "tap0_s", Some(npy::write("<f8", &[], &f8(&[0.0])))),
            "tap0_s: only with cir",
        ),
        (
            replace(&rec, "t_s", Some(b"not an npy".to_vec())),
            "t_s: not a .npy array",
        ),
        (
            replace(&rec, "t_s", Some(npy::write("<f8", &[4], &f8(&[0.0; 3])))),
            "t_s: the data holds 24 bytes, the shape (4,) of float64 needs 32",
        ),
        (b"PK\x03\x04 nonsense".to_vec(), "npz: not a zip archive"),
        (b"hello".to_vec(), "npz: not a zip archive"),
    ];
    for (bytes, want) in cases {
        let got = err(&bytes);
        assert!(got.starts_with(want), "got {got:?}, want {want:?}");
    }
    // A non-finite sample: [s, p, i] = [1, 2, 3].
    let mut bad = cfr();
    bad.samples[(4 + 2) * 5 + 3].im = f64::INFINITY;
    let mut c = bad
        .samples
        .iter()
        .flat_map(|z| z.re.to_le_bytes().into_iter().chain(z.im.to_le_bytes()))
        .collect::<Vec<u8>>();
    let got = err(&replace(
        &rec,
        "cfr",
        Some(npy::write("<c16", &[3, 4, 5], &c)),
    ));
    assert_eq!(got, "cfr: sample [1, 2, 3] is not finite");
    // Fortran order refused by name.
    c.truncate(0);
    let mut f = npy::write("<c16", &[3, 4, 5], &[0u8; 960]);
    let h = String::from_utf8_lossy(&f[10..]).replace("False", "True ");
    f.splice(10.., h.into_bytes());
    assert!(err(&replace(&rec, "cfr", Some(f)))
        .starts_with("cfr: fortran_order = True is not supported"));
    // Both cfr and cir.
    let cir_rec = cir(false);
    let mut m = members_of(&cir_rec);
    m.push(("cfr.npy".into(), members_of(&rec)[2].1.clone()));
    assert!(err(&rezip(&m)).starts_with("cfr: both cfr and cir"));
    // A pulse with p(0) = 0, a pulse without its spacing.
    let prec = cir(true);
    let z = npy::write("<c16", &[3], &[0u8; 48]);
    assert!(
        err(&replace(&prec, "pulse", Some(z))).starts_with("pulse: the middle sample p(0) is 0")
    );
    assert!(
        err(&replace(&prec, "pulse_spacing_s", None)).starts_with("pulse_spacing_s: missing array")
    );
}

/// Offsets of the local and central headers' uncompressed-size fields of a one-member zip.
fn set_declared_size(z: &mut [u8], size: u32) {
    let find = |z: &[u8], sig: &[u8]| z.windows(4).position(|w| w == sig).unwrap();
    let local = find(z, b"PK\x03\x04");
    z[local + 22..local + 26].copy_from_slice(&size.to_le_bytes());
    let central = find(z, b"PK\x01\x02");
    z[central + 24..central + 28].copy_from_slice(&size.to_le_bytes());
}

#[test]
fn zip_bombs_are_refused_before_inflating() {
    // A member declaring 4·10⁹ bytes (over MAX_RECORDING_BYTES = 1.06·10⁹; the largest a zip
    // without zip64 can declare) is refused before inflating.
    let mut z = zip_of(&[("cfr.npy", vec![0u8; 1000])], true);
    set_declared_size(&mut z, 4_000_000_000);
    let got = err(&z);
    assert!(got.starts_with("cfr: 4000000000 is"), "{got}");
    // A member declaring 1000 bytes that inflates to 200 MB (200 kB compressed) is refused after
    // reading 1001 bytes of it.
    let mut z = zip_of(&[("cir.npy", vec![0u8; 200 << 20])], true);
    assert!(z.len() < 400_000, "{}", z.len());
    set_declared_size(&mut z, 1000);
    let got = err(&z);
    assert!(
        got.starts_with("cir: the member inflates to more than its declared 1000 bytes"),
        "{got}"
    );
    // That message is only reached through `take(declared + 1)` (read.rs `members`): at most
    // 1001 bytes were inflated. No wall-clock bound (issue 39: tests do not time the clock).
}

#[test]
fn a_smaller_cap_refuses_larger_files_and_members() {
    let rec = cfr();
    let bytes = write_recording(&rec).unwrap();
    let n = bytes.len() as u64;
    assert_eq!(read_recording_within(&bytes, n).unwrap(), rec);
    let got = format!("{}", read_recording_within(&bytes, n - 1).unwrap_err());
    assert_eq!(
        got,
        format!("npz: {n} is outside the allowed range 0..={}", n - 1)
    );
    // 2 MiB of zeros deflated to a few kB: the member declares more than a 1 MiB cap.
    let z = zip_of(&[("cfr.npy", vec![0u8; 2 << 20])], true);
    assert!(z.len() < 20_000, "{}", z.len());
    let got = format!("{}", read_recording_within(&z, 1 << 20).unwrap_err());
    assert!(
        got.starts_with("cfr: 2097152 is outside the allowed range 0..=1048576"),
        "{got}"
    );
}

/// The optional scalar `synchronized` (docs/recording.md): written as a numpy bool by
/// `write_recording` and read back (`true`, `false`, absent); numpy's bool and 0/1 integers of
/// any width are accepted; any other value, another dtype or a non-scalar is refused by name.
#[test]
fn synchronized_is_read_and_written() {
    for sync in [Some(true), Some(false), None] {
        for mut rec in [cfr(), cir(true)] {
            rec.synchronized = sync;
            let bytes = write_recording(&rec).unwrap();
            assert_eq!(read_recording(&bytes).unwrap(), rec);
            let member = members_of(&rec)
                .into_iter()
                .find(|(n, _)| n == "synchronized.npy");
            match sync {
                // numpy's bool scalar: `|b1`, shape (), one byte 0 or 1.
                Some(s) => {
                    let (_, d) = member.expect("synchronized.npy written");
                    let a = npy::parse("synchronized", d).unwrap();
                    assert_eq!(a.dtype.name(), "bool");
                    assert!(a.shape.is_empty());
                    assert_eq!(a.data, vec![u8::from(s)]);
                }
                None => assert!(member.is_none(), "absent when unknown"),
            }
        }
    }
    let rec = cfr();
    let read = |descr: &str, shape: &[usize], data: &[u8]| {
        read_recording(&replace(
            &rec,
            "synchronized",
            Some(npy::write(descr, shape, data)),
        ))
        .map(|r| r.synchronized)
    };
    // bool, uint8, int8, int16, int32, int64 (both byte orders): 0 and 1.
    for (descr, size, big) in [
        ("|b1", 1, false),
        ("|u1", 1, false),
        ("|i1", 1, false),
        ("<i2", 2, false),
        ("<i4", 4, false),
        ("<i8", 8, false),
        (">i8", 8, true),
    ] {
        for v in [0u8, 1] {
            let mut d = vec![0u8; size];
            d[if big { size - 1 } else { 0 }] = v;
            assert_eq!(read(descr, &[], &d).unwrap(), Some(v == 1), "{descr} {v}");
        }
    }
    let err = |descr: &str, shape: &[usize], data: &[u8]| {
        format!("{}", read(descr, shape, data).unwrap_err())
    };
    let must = "must be 0 (free-running) or 1 (a common clock)";
    assert_eq!(
        err("<i8", &[], &2i64.to_le_bytes()),
        format!("synchronized: 2: {must}")
    );
    assert_eq!(
        err("|i1", &[], &[0xff]),
        format!("synchronized: -1: {must}")
    );
    assert_eq!(err("|u1", &[], &[2]), format!("synchronized: 2: {must}"));
    assert_eq!(err("|b1", &[], &[2]), format!("synchronized: 2: {must}"));
    assert_eq!(
        err("<f8", &[], &1f64.to_le_bytes()),
        "synchronized: wrong dtype float64, expected bool or int"
    );
    assert_eq!(
        err("<c16", &[], &[0u8; 16]),
        "synchronized: wrong dtype complex128, expected bool or int"
    );
    // Not a scalar: one per link, or a 1-element vector.
    assert_eq!(
        err("|b1", &[4], &[1; 4]),
        "synchronized: wrong shape (4,), expected a scalar = ()"
    );
    assert_eq!(
        err("|b1", &[1], &[1]),
        "synchronized: wrong shape (1,), expected a scalar = ()"
    );
}

/// A `descr` whose characters after the byte-order mark are several bytes long (`'<é'`: `é`
/// is two bytes of UTF-8) used to panic slicing the string inside a character; the header
/// parser compares bytes, so it and every other non-ASCII header is a named error.
#[test]
fn a_multi_byte_descr_is_a_named_error() {
    let rec = cfr();
    assert_eq!(
        err(&replace(
            &rec,
            "t_s",
            Some(npy::write("<é", &[3], &[0u8; 24]))
        )),
        "t_s: unsupported dtype descr '<é'"
    );
    for descr in ["<é8", "é<f8", "<fé", "é", "<f8é", "<\u{1F600}", "\u{1F600}"] {
        let got = err(&replace(
            &rec,
            "t_s",
            Some(npy::write(descr, &[3], &[0u8; 24])),
        ));
        assert!(got.starts_with("t_s: "), "{descr}: {got}");
        assert!(
            got.contains("descr") || got.contains("not a .npy"),
            "{descr}: {got}"
        );
    }
    // Non-ASCII elsewhere in the header: a key, the shape, fortran_order.
    let header = |h: &str| {
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        let h = format!("{h}\n");
        b.extend_from_slice(&(h.len() as u16).to_le_bytes());
        b.extend_from_slice(h.as_bytes());
        b.extend_from_slice(&[0u8; 24]);
        b
    };
    for h in [
        "{'déscr': '<f8', 'fortran_order': False, 'shape': (3,), }",
        "{'descr': '<f8', 'fortran_order': Fålse, 'shape': (3,), }",
        "{'descr': '<f8', 'fortran_order': False, 'shape': (3é,), }",
        "{é'descr': '<f8', 'fortran_order': False, 'shape': (3,), }",
        "{'descr': 'é', 'fortran_order': False, 'shape': (3,), }",
    ] {
        let got = err(&replace(&rec, "t_s", Some(header(h))));
        assert!(got.starts_with("t_s: "), "{h}: {got}");
    }
}

/// Issue 37 item 15: a member named twice in the central directory (the zip reader keys
/// members by name and kept one silently) is refused by name; the bytes are patched after
/// writing, since a zip writer refuses duplicate names.
#[test]
fn duplicate_members_are_refused() {
    let rec = cfr();
    let mut m = members_of(&rec);
    let t = m.iter().find(|(n, _)| n == "t_s.npy").unwrap().1.clone();
    m.push(("u_s.npy".into(), t));
    let mut z = rezip(&m);
    assert!(read_recording(&z).is_err_and(|e| e.to_string().contains("u_s")));
    let at: Vec<usize> = z
        .windows(7)
        .enumerate()
        .filter(|(_, w)| w == b"u_s.npy")
        .map(|(i, _)| i)
        .collect();
    assert_eq!(at.len(), 2, "a local and a central header");
    for i in at {
        z[i..i + 3].copy_from_slice(b"t_s");
    }
    assert_eq!(err(&z), "t_s.npy: the member appears twice in the archive");
}

/// Issue 37 item 6: a member declaring more than it inflates to is refused by name (a
/// truncated or forged archive), and its declared size is not reserved up front (a 2 KB file
/// declaring gigabytes aborted under an address-space limit; `tests/cli/cir.rs` runs one
/// under `ulimit -v`).
#[test]
fn a_member_declaring_more_than_it_holds_is_refused() {
    let mut z = zip_of(&[("cfr.npy", vec![0u8; 1000])], true);
    set_declared_size(&mut z, 1_000_000_000);
    assert_eq!(
        err(&z),
        "cfr: the member inflates to 1000 bytes, fewer than its declared 1000000000 (a \
         truncated or corrupt archive)"
    );
}

/// Issue 37 item 16: a long member name is clipped in the error, as elsewhere (the
/// longest a zip can hold, 64 KB, of one-byte, two-byte and control characters).
#[test]
fn a_long_member_name_is_clipped_in_the_error() {
    for unit in ["x", "é", "\n\u{1b}[2J"] {
        let name = format!("{}.npy", unit.repeat(60_000 / unit.len()));
        let z = zip_of(&[(name.as_str(), vec![0u8; 10])], false);
        let got = err(&z);
        assert!(
            got.contains("unknown array"),
            "{}",
            &got[..200.min(got.len())]
        );
        assert!(got.len() < 1000, "{} bytes", got.len());
        assert!(!got.contains('\u{1b}'), "control characters escaped");
    }
}
