//! The six real Wi-Fi CSI recordings of tests/data/csi (CSIKit's, MIT; issue 40) through the
//! library: each read, converted to a recording on its masked subcarrier grid, and its direct
//! path found per snapshot with the timing offset removed (C10,
//! `study::direct_paths`). Asserted: the recording's shape (frames, links, grid and masked
//! bins, from the independent readers' counts in tests/data/csi/README.md), finite statistics,
//! and the direct path found in ≥ 95 % of the frames of every link. The stability (the share
//! within a quarter of the resolution cell of the median) and the spread are printed
//! (`--nocapture`) and reported in docs/recording.md: they are what the data gives, not a
//! target.

use scatterloc::csi::{open_recording, OpenOptions};
use scatterloc::error::{limits, Cancel};
use scatterloc::math::SPEED_OF_LIGHT;
use scatterloc::study::direct_paths;

/// (file, format, frames in the recording, links, grid bins). PicoScenes: 112 frames, 13 of
/// another antenna configuration skipped (99 kept). Nexmon: 20 MHz frames on the lowest
/// sub-channel of an 80 MHz chanspec: 52 occupied tones, grid 53. ESP32: 60 CSI lines, each
/// packet printed twice with the same `local_timestamp` (and the same CSI): 27 repeats dropped.
const FILES: [(&str, &str, usize, usize, usize); 6] = [
    ("intel/example.dat", "intel5300", 26, 6, 57),
    (
        "pico/picoscenes_iwl5300_example.csi",
        "picoscenes",
        99,
        2,
        57,
    ),
    ("nexmon/example_4366c0.pcap", "nexmon", 293, 1, 53),
    ("feitcsi/VHT80_5500.csi", "feitcsi", 40, 2, 245),
    ("feitcsi/HESU160_5500.csi", "feitcsi", 26, 2, 2025),
    ("esp32/example_data.csv", "esp32", 33, 1, 53),
];

fn read(name: &str) -> Vec<u8> {
    std::fs::read(format!(
        "{}/tests/data/csi/{name}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

#[test]
fn every_file_reads_and_its_direct_path_is_found() {
    for (name, format, frames, links, grid) in FILES {
        let opts = OpenOptions {
            max_npz_bytes: limits::MAX_RECORDING_BYTES,
            ..OpenOptions::default()
        };
        let o = open_recording(&read(name), &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
        let s = o.csi.as_ref().expect("a CSI file");
        assert_eq!(s.capture.format.name(), format, "{name}");
        let rec = &o.recording;
        assert_eq!(rec.t_s.len(), frames, "{name}: frames");
        assert_eq!(rec.links.len(), links, "{name}: links");
        assert_eq!(rec.samples_per_link(), grid, "{name}: grid bins");
        assert_eq!(rec.synchronized, Some(false));
        let direct = direct_paths(rec, s.capture.bandwidth_hz, Cancel::NEVER)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        for d in &direct {
            for v in [d.median_s, d.std_s, d.robust_std_s, d.half_range_90_s] {
                assert!(v.is_finite(), "{name}: {d:?}");
            }
            println!(
                "{name} link {:?}: {} frames, direct path found {:.1} %, stable {:.1} % \
                 (window {:.2} m), spread σ {:.3} m, robust σ {:.3} m, 90 % half-range {:.3} m",
                d.link,
                d.snapshots,
                100.0 * d.found_fraction,
                100.0 * d.stable_fraction,
                d.window_s * SPEED_OF_LIGHT,
                d.std_s * SPEED_OF_LIGHT,
                d.robust_std_s * SPEED_OF_LIGHT,
                d.half_range_90_s * SPEED_OF_LIGHT
            );
            assert!(d.found_fraction >= 0.95, "{name} link {:?}: {d:?}", d.link);
        }
    }
}
