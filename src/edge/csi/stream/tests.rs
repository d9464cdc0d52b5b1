//! The splitter and the per-frame conversion against the whole-file read and conversion.

use alloc::vec::Vec;

use super::*;
use crate::edge::csi::test_file as file;
use crate::edge::csi::{read_capture, to_recording};

const FILES: [(&str, CsiFormat); 6] = [
    ("intel/example.dat", CsiFormat::Intel5300),
    ("nexmon/example_4366c0.pcap", CsiFormat::Nexmon),
    ("esp32/example_data.csv", CsiFormat::Esp32),
    ("feitcsi/VHT80_5500.csi", CsiFormat::FeitCsi),
    ("feitcsi/HESU160_5500.csi", CsiFormat::FeitCsi),
    ("pico/picoscenes_iwl5300_example.csi", CsiFormat::PicoScenes),
];

/// Every subcarrier kept: the grid is then the same whether fixed by the first frame or by all.
fn all_subcarriers() -> ConvertOptions {
    ConvertOptions {
        keep_unoccupied: true,
        ..ConvertOptions::default()
    }
}

/// The frames of `bytes` pushed in the pieces cut at `cuts`, then the end.
fn frames(bytes: &[u8], format: CsiFormat, cuts: &[usize]) -> Result<Vec<CsiFrame>> {
    let mut s = CsiStream::new(format, all_subcarriers())?;
    let mut out = Vec::new();
    let mut from = 0;
    for &c in cuts.iter().chain([bytes.len()].iter()) {
        s.push(&bytes[from..c], &mut out)?;
        from = c;
    }
    s.end(&mut out)?;
    Ok(out)
}

#[test]
fn one_push_equals_the_whole_file_conversion() {
    for (name, format) in FILES {
        let bytes = file(name);
        let got = frames(&bytes, format, &[]).unwrap();
        // The reference: the whole-file reader and conversion.
        let rec = to_recording(
            &read_capture(&bytes, Some(format)).unwrap(),
            &all_subcarriers(),
        )
        .unwrap()
        .recording;
        assert_eq!(got.len(), rec.t_s.len(), "{name}");
        let per = rec.links.len() * rec.samples_per_link();
        for (k, f) in got.iter().enumerate() {
            assert_eq!(f.t_s.to_bits(), rec.t_s[k].to_bits(), "{name} frame {k}");
            assert_eq!(
                f.samples,
                rec.samples[k * per..(k + 1) * per],
                "{name} frame {k}"
            );
        }
    }
}

/// The frames of `bytes` cut at `cuts` and the end's error, if any (frames kept up to it).
fn outcome(bytes: &[u8], format: CsiFormat, cuts: &[usize]) -> (Vec<CsiFrame>, Option<String>) {
    let mut s = CsiStream::new(format, all_subcarriers()).unwrap();
    let mut out = Vec::new();
    let mut from = 0;
    for &c in cuts.iter().chain([bytes.len()].iter()) {
        if let Err(e) = s.push(&bytes[from..c], &mut out) {
            return (out, Some(e.to_string()));
        }
        from = c;
    }
    let end = s.end(&mut out).err().map(|e| e.to_string());
    (out, end)
}

#[test]
fn a_split_at_every_byte_boundary_gives_the_same_frames() {
    // Per file the bytes cut (a prefix of the large ones: its last record may be incomplete,
    // and then both runs end in the same truncation error).
    for ((name, format), prefix) in
        FILES
            .into_iter()
            .zip([usize::MAX, 8 << 10, 8 << 10, 8 << 10, 34 << 10, 8 << 10])
    {
        let all = file(name);
        let bytes = &all[..all.len().min(prefix)];
        let whole = outcome(bytes, format, &[]);
        assert!(!whole.0.is_empty(), "{name}");
        // Every boundary, but the HE 160 MHz file's (16 KB frames): the first two frames'
        // headers and their neighbourhood, a stride elsewhere.
        let cuts: Vec<usize> = if name.contains("HESU") {
            let second = feitcsi::record_len(bytes).unwrap();
            (1..600)
                .chain(second - 300..second + 600)
                .chain((600..bytes.len()).step_by(97))
                .collect()
        } else {
            (1..bytes.len()).collect()
        };
        for c in cuts {
            assert_eq!(outcome(bytes, format, &[c]), whole, "{name} cut at {c}");
        }
        // One byte at a time.
        let each: Vec<usize> = (1..bytes.len()).collect();
        assert_eq!(outcome(bytes, format, &each), whole, "{name} bytewise");
    }
}

#[test]
fn nexmon_frame_completes_on_the_next_sequence_number() {
    let bytes = file("nexmon/example_4366c0.pcap");
    let mut s = CsiStream::new(CsiFormat::Nexmon, all_subcarriers()).unwrap();
    let mut out = Vec::new();
    s.push(&bytes, &mut out).unwrap();
    let before_end = out.len();
    s.end(&mut out).unwrap();
    // The last frame is held until the end: nothing tells it is complete before.
    assert_eq!(out.len(), before_end + 1);
}

#[test]
fn a_truncated_last_record_is_a_named_error() {
    for (name, format) in FILES {
        let bytes = file(name);
        let cut = &bytes[..bytes.len() - 1];
        let mut s = CsiStream::new(format, all_subcarriers()).unwrap();
        let mut out = Vec::new();
        s.push(cut, &mut out).unwrap();
        let e = s.end(&mut out).unwrap_err().to_string();
        assert!(
            e.contains("record") && e.contains("truncated"),
            "{name}: {e}"
        );
    }
}

#[test]
fn a_huge_record_is_refused_before_it_is_read() {
    // A PicoScenes frame announcing 4 GiB.
    let mut s = CsiStream::new(CsiFormat::PicoScenes, all_subcarriers()).unwrap();
    let e = s.push(&[0xff; 8], &mut Vec::new()).unwrap_err();
    assert!(
        matches!(
            e,
            Error::SizeLimit {
                field: "record",
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(s.pending_bytes(), 8);
    // An ESP32 line longer than the cap without its end.
    let mut s = CsiStream::new(CsiFormat::Esp32, all_subcarriers()).unwrap();
    let e = s
        .push(
            &alloc::vec![b'x'; MAX_CSI_RECORD_BYTES + 1],
            &mut Vec::new(),
        )
        .unwrap_err();
    assert!(
        matches!(
            e,
            Error::SizeLimit {
                field: "record",
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn a_later_frame_of_another_grid_is_a_named_error() {
    // Two Intel 5300 logs: the example's first record (3×2), then one with Nrx = 1 … cannot be
    // built without the bfee encoder; ESP32 lines of another channel are skipped by the reader,
    // so the grid check is shown on FeitCSI: a VHT80 frame after the HE160 file's first.
    let he = file("feitcsi/HESU160_5500.csi");
    let vht = file("feitcsi/VHT80_5500.csi");
    let first_he = feitcsi::record_len(&he).unwrap();
    let first_vht = feitcsi::record_len(&vht).unwrap();
    let mut s = CsiStream::new(CsiFormat::FeitCsi, all_subcarriers()).unwrap();
    let mut out = Vec::new();
    s.push(&he[..first_he], &mut out).unwrap();
    assert_eq!(out.len(), 1);
    // The FeitCSI reader skips a frame of another configuration (as the whole-file read
    // does): no frame, no error.
    s.push(&vht[..first_vht], &mut out).unwrap();
    assert_eq!(out.len(), 1);
    // A capture of another grid reaching the conversion is an error naming the frame.
    let mut cap = read_capture(&vht, Some(CsiFormat::FeitCsi)).unwrap();
    cap.t_s[0] += 1e3;
    let e = s.convert(&cap, &mut out).unwrap_err().to_string();
    assert!(e.contains("frames[1]") && e.contains("first frame"), "{e}");
}
