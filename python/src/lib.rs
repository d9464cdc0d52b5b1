//! `scatterloc._scatterloc`, the native module of the Python package `scatterloc` (issue 27):
//! PyO3 + rust-numpy bindings that only convert types and call the library's use cases — the
//! same functions the CLI and the page call — so a notebook gets the CLI's numbers bit for bit,
//! as numpy arrays. One file per family, like the CLI's `cmd/`:
//!
//! - `errors`: the core's `Error` as `ScatterlocError` (a `ValueError` with `field` and `kind`).
//! - `convert`: arrays in and out, documents as the dicts the CLI's JSON parses to.
//! - `run`: long work on a worker thread without the GIL, Ctrl-C and progress; the one guard
//!   that turns a panic into a `ScatterlocError` (kind `"Panic"`); the `threads` cap.
//! - `output`: the one atomic file writer (`write_recording`, `Scenario.save`), as the CLI's.
//! - `scenario`: `Scenario` (the core's `present::Session`).
//! - `snapshot`: `crlb`, `crlb_map`, `locate`.
//! - `doppler`: `crlb_doppler`, `doppler_map`, `range_rates`, `sigma_range_rates` (issue 42).
//! - `tracking`: `track`, `calibrate` and the filter settings; `track_doppler`: range rates in
//!   `track` (issue 42 §5).
//! - `studies`: `montecarlo`, `pcrlb`.
//! - `planning`: `plan`.
//! - `mtl`: `mtl_locate`.
//! - `multi`: `track_multi`, `simulate_people` (several targets, issue 41).
//! - `channel`: `Recording`, `read_recording`, `write_recording`, `simulate_recording`,
//!   `estimate`, `estimate_recording`, `cir_track`.
//! - `csi`: `read_csi` and the CSI keywords of `read_recording` (Wi-Fi CSI tools' files).
//! - `stream`: `track_stream`, the live chain of `cir track --follow` as an iterator.
//! - `detections`: `Detections`, `read_detections`, `write_detections` (JSON lines).
//! - `bench`: native timings for the package's benchmark (docs/benchmarks.md).
//!
//! The Python side (`python/scatterloc/`) re-exports these, adds the Stone Soup model and
//! carries the type stubs.

mod bench;
mod channel;
mod convert;
mod csi;
mod detections;
mod doppler;
mod errors;
mod gospa;
mod mtl;
mod multi;
mod output;
mod planning;
mod run;
mod scenario;
mod snapshot;
mod stream;
mod studies;
mod track_doppler;
mod tracking;

use pyo3::prelude::*;

/// The native module; `scatterloc/__init__.py` re-exports it.
#[pymodule]
fn _scatterloc(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ScatterlocError", py.get_type::<errors::ScatterlocError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<scenario::PyScenario>()?;
    m.add_class::<snapshot::Crlb>()?;
    m.add_class::<snapshot::CrlbMap>()?;
    m.add_class::<snapshot::Fix>()?;
    m.add_class::<tracking::Track>()?;
    m.add_class::<tracking::StaticCalibration>()?;
    m.add_class::<track_doppler::TrackDoppler>()?;
    m.add_class::<studies::Curves>()?;
    m.add_class::<studies::StudyResult>()?;
    m.add_class::<planning::Plan>()?;
    m.add_class::<mtl::MtlResult>()?;
    m.add_class::<multi::MultiTrack>()?;
    m.add_class::<channel::PyRecording>()?;
    m.add_class::<channel::Paths>()?;
    m.add_class::<channel::ChannelTrack>()?;
    m.add_class::<stream::TrackStream>()?;
    m.add_class::<detections::PyDetections>()?;
    for f in [
        wrap_pyfunction!(gospa::gospa, m)?,
        wrap_pyfunction!(snapshot::crlb, m)?,
        wrap_pyfunction!(doppler::crlb_doppler, m)?,
        wrap_pyfunction!(doppler::doppler_map, m)?,
        wrap_pyfunction!(doppler::range_rates, m)?,
        wrap_pyfunction!(doppler::sigma_range_rates, m)?,
        wrap_pyfunction!(snapshot::crlb_map, m)?,
        wrap_pyfunction!(snapshot::locate, m)?,
        wrap_pyfunction!(tracking::track, m)?,
        wrap_pyfunction!(tracking::calibrate, m)?,
        wrap_pyfunction!(studies::montecarlo, m)?,
        wrap_pyfunction!(studies::pcrlb, m)?,
        wrap_pyfunction!(planning::plan, m)?,
        wrap_pyfunction!(mtl::mtl_locate, m)?,
        wrap_pyfunction!(multi::track_multi, m)?,
        wrap_pyfunction!(multi::simulate_people, m)?,
        wrap_pyfunction!(channel::read_recording, m)?,
        wrap_pyfunction!(csi::read_csi, m)?,
        wrap_pyfunction!(stream::track_stream, m)?,
        wrap_pyfunction!(detections::read_detections, m)?,
        wrap_pyfunction!(detections::write_detections, m)?,
        wrap_pyfunction!(channel::write_recording, m)?,
        wrap_pyfunction!(channel::simulate_recording, m)?,
        wrap_pyfunction!(channel::estimate, m)?,
        wrap_pyfunction!(channel::estimate_recording, m)?,
        wrap_pyfunction!(channel::cir_track, m)?,
    ] {
        m.add_function(f)?;
    }
    let bench = PyModule::new(py, "_bench")?;
    bench::register(&bench)?;
    m.add_submodule(&bench)?;
    Ok(())
}
