//! `scatterloc cir convert` and `cir estimate` on the six real Wi-Fi CSI files of
//! tests/data/csi (issue 40): every file converts (one JSON line saying what it found), the
//! `.npz` written is the recording the library opens from the CSI file directly, `cir estimate`
//! reads the CSI file with finite output and reports its direct path, and bad input is exit 2
//! with one line naming the flag or the frame and field.

use crate::common::cli::{fails, ok_json_line, read_json, TempDir};
use scatterloc::csi::{open_recording, OpenOptions};
use scatterloc::error::limits;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/csi");

const FILES: [(&str, &str); 6] = [
    ("intel/example.dat", "intel5300"),
    ("pico/picoscenes_iwl5300_example.csi", "picoscenes"),
    ("nexmon/example_4366c0.pcap", "nexmon"),
    ("feitcsi/VHT80_5500.csi", "feitcsi"),
    ("feitcsi/HESU160_5500.csi", "feitcsi"),
    ("esp32/example_data.csv", "esp32"),
];

fn file(name: &str) -> String {
    format!("{DIR}/{name}")
}

#[test]
fn convert_writes_what_the_library_opens() {
    let dir = TempDir::new();
    for (name, format) in FILES {
        let out = dir.path("rec.npz");
        let s = ok_json_line(&["cir", "convert", &file(name), &out]);
        assert_eq!(s["format"], format, "{name}");
        assert_eq!(s["out"], out.as_str());
        let frames = s["frames"].as_u64().unwrap() as usize;
        let written = scatterloc::npz::read_recording(&std::fs::read(&out).unwrap()).unwrap();
        let opts = OpenOptions {
            max_npz_bytes: limits::MAX_RECORDING_BYTES,
            ..OpenOptions::default()
        };
        let direct = open_recording(&std::fs::read(file(name)).unwrap(), &opts).unwrap();
        assert_eq!(written, direct.recording, "{name}");
        assert_eq!(written.t_s.len(), frames);
        assert_eq!(
            s["grid_bins"].as_u64().unwrap() as usize,
            written.samples_per_link()
        );
        assert_eq!(written.synchronized, Some(false));
        // Forcing the right format gives the same; a .npz in is copied through.
        let forced = dir.path("forced.npz");
        ok_json_line(&["cir", "convert", &file(name), &forced, "--format", format]);
        assert_eq!(
            std::fs::read(&forced).unwrap(),
            std::fs::read(&out).unwrap()
        );
        let again = dir.path("again.npz");
        let s2 = ok_json_line(&["cir", "convert", &out, &again]);
        assert_eq!(s2["format"], "npz");
        assert_eq!(std::fs::read(&again).unwrap(), std::fs::read(&out).unwrap());
    }
}

#[test]
fn estimate_reads_csi_files_and_reports_the_direct_path() {
    let dir = TempDir::new();
    let scenario = file("room.json");
    for (name, _) in FILES {
        let est = dir.path("est.json");
        let s = ok_json_line(&[
            "cir",
            "estimate",
            "--scenario",
            &scenario,
            "--cir",
            &file(name),
            "--out",
            &est,
        ]);
        assert_eq!(
            s["delay_reference"], "los",
            "{name}: a CSI file is not synchronized"
        );
        let direct = s["direct_path"].as_array().unwrap();
        assert_eq!(direct.len(), s["links"].as_u64().unwrap() as usize);
        for d in direct {
            assert!(d["found_fraction"].as_f64().unwrap() >= 0.95, "{name}: {d}");
        }
        // EST.json: finite numbers only (serde_json writes NaN as null; none expected).
        let doc = read_json(&est);
        let text = doc.to_string();
        assert!(
            !text.contains("null,\"sigma_s\"") && !text.contains("NaN"),
            "{name}"
        );
    }
}

#[test]
fn bad_input_is_named() {
    let dir = TempDir::new();
    let intel = file("intel/example.dat");
    fails(
        &["cir", "convert", &intel, &dir.path("rec.json")],
        &["OUT", ".npz"],
    );
    fails(
        &[
            "cir",
            "convert",
            &intel,
            &dir.path("rec.npz"),
            "--links",
            "rx0=0:1",
        ],
        &["--links", "links[0]"],
    );
    fails(
        &[
            "cir",
            "convert",
            &intel,
            &dir.path("rec.npz"),
            "--links",
            "rx7.tx0=0:1",
        ],
        &["links[0]"],
    );
    // The wrong reader forced: a named error of that format, naming the frame and the field.
    fails(
        &[
            "cir",
            "convert",
            &intel,
            &dir.path("rec.npz"),
            "--format",
            "feitcsi",
        ],
        &["IN", "frame 0"],
    );
    let junk = dir.write_text("junk.bin", "neither a zip nor CSI\n");
    fails(
        &["cir", "convert", &junk, &dir.path("rec.npz")],
        &["IN", "not a zip archive", "nor a CSI file"],
    );
    // A truncated Intel 5300 log: the frame and the field.
    let bytes = std::fs::read(&intel).unwrap();
    let cut = dir.path("cut.dat");
    std::fs::write(&cut, &bytes[..300]).unwrap();
    let err = crate::common::cli::run(&[
        "cir",
        "convert",
        &cut,
        &dir.path("rec.npz"),
        "--format",
        "intel5300",
    ]);
    let text = String::from_utf8_lossy(&err.stderr);
    if err.status.code() == Some(2) {
        assert!(text.contains("frame"), "{text}");
    } else {
        // A cut exactly at a record boundary reads the complete frames before it.
        assert!(err.status.success(), "{text}");
    }
    assert!(
        dir.files().iter().all(|f| f != "rec.npz"),
        "nothing written on error"
    );
}
