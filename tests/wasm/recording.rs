//! `read_recording_summary` in the browser: the committed int16 I/Q CIR fixture
//! (scripts/make-recording-fixture.py) is summarised, and a malformed file throws the reader's
//! named message.

use wasm_bindgen_test::*;

use scatterloc::wasm;

use super::{err, get, num, ok};

#[wasm_bindgen_test]
fn recording_summary_of_the_int16_cir_fixture() {
    let bytes = include_bytes!("../data/recording-cir-int16.npz");
    let s = ok(wasm::read_recording_summary(bytes));
    assert_eq!(num(&s, "snapshots"), 3.0);
    assert_eq!(num(&s, "links"), 4.0);
    assert_eq!(get(&s, "layout").as_string().unwrap(), "cir");
    assert_eq!(num(&s, "samples_per_link"), 64.0);
    assert_eq!(num(&s, "duration_s"), 4.096e-3);
    let m = err(wasm::read_recording_summary(b"hello"));
    assert!(m.starts_with("npz: not a zip archive"), "{m}");
    let mut cut = bytes.to_vec();
    cut.truncate(cut.len() / 2);
    let m = err(wasm::read_recording_summary(&cut));
    assert!(m.starts_with("npz:"), "{m}");
}
