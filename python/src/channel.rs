//! The channel front end and its track (spec `channel-estimation.md`, C1–C11): `Recording` (the
//! `.npz` format of docs/recording.md, read and written by the library's `npz` edge),
//! `simulate_recording` (`scatterloc cir simulate`, the core's `SimulationRequest`), `estimate`
//! (C5 + C6 on responses without a scenario), `estimate_recording` (`scatterloc cir estimate`)
//! and `cir_track` (`scatterloc cir track`). The keywords fill the core's `ChannelRequest`
//! (every default and check is there); this file only converts types.

use std::borrow::Cow;

use numpy::{
    Complex64, PyArray1, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use scatterloc::channel::{ChannelScene, Layout, Pulse, Recording, SimulationRequest, TrackedPath};
use scatterloc::error::{limits, Cancel};
use scatterloc::formats::{Detections, Truth};
use scatterloc::native::Parallel;
use scatterloc::npz;
use scatterloc::present::{estimates_doc, track_doc, track_errors};
use scatterloc::study::{
    cir_track as track_recording, estimate_link, estimate_recording as estimate_all,
    ChannelRequest, ChannelStatics, DelayReference, DelaySigma, FrontEndConfig, RecordingEstimates,
    StaticMode,
};
use scatterloc::track::gating::AssociationRule;

use crate::convert::{
    array, asarray, dtype_name, f64_array, masked, path_string, to_python, too_many, JsonDoc, Len,
};
use crate::detections::PyDetections;
use crate::errors::{arg_error, Core};
use crate::run::{check_threads, run_job, run_quick};
use crate::scenario::scenario_arg;

/// The dtypes a sample array may have: the `.npz` reader's (docs/recording.md), so an array
/// `Recording` takes is one the reader takes from a file and the other way round.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum SampleDtypes {
    /// complex64 or complex128 (`cfr`, `system_response`, `pulse`, `estimate`'s `response`).
    Complex,
    /// Those, or int16/int32 (I, Q) pairs on a last axis of length 2 (`cir`).
    ComplexOrIq,
}

/// A complex sample argument as (shape, row-major values), under the reader's dtype rule
/// ([`SampleDtypes`]; any other dtype — real, int8, float16, complex256, object — is refused
/// by name, never converted). A list or other non-array goes through `numpy.asarray(x)` and
/// its dtype is checked the same way (a list of complex numbers is complex128). `check` sees
/// the shape (for I/Q pairs without their last axis) before anything is copied or converted:
/// it checks the shape and the size caps, so a broadcast view of 10¹⁰ samples is refused
/// without being copied.
pub(crate) fn complex_arg(
    obj: &Bound<'_, PyAny>,
    field: &str,
    dtypes: SampleDtypes,
    check: impl FnOnce(&[usize]) -> PyResult<()>,
) -> PyResult<(Vec<usize>, Vec<Complex64>)> {
    let py = obj.py();
    let converted;
    let a = match crate::convert::ndarray(obj) {
        Some(a) => a,
        None => {
            converted = asarray(py)?
                .call1((obj,))
                .map_err(|e| arg_error(field, format!("not an array of complex numbers ({e})")))?;
            converted
                .cast::<PyUntypedArray>()
                .map_err(|_| arg_error(field, "not an array of complex numbers"))?
        }
    };
    let (kind, size) = (a.dtype().kind(), a.dtype().itemsize());
    let shape = a.shape().to_vec();
    let complex = kind == b'c' && (size == 8 || size == 16);
    let iq = dtypes == SampleDtypes::ComplexOrIq && kind == b'i' && (size == 2 || size == 4);
    if !complex && !iq {
        let expected = match dtypes {
            SampleDtypes::Complex => "complex64 or complex128",
            SampleDtypes::ComplexOrIq => "complex64, complex128, or int16/int32 (I, Q)",
        };
        return Err(arg_error(
            field,
            format!("wrong dtype {}, expected {expected}", dtype_name(a)),
        ));
    }
    let kwargs = pyo3::types::PyDict::new(py);
    if iq {
        let logical = match shape.split_last() {
            Some((2, lead)) => lead.to_vec(),
            _ => {
                return Err(arg_error(
                    field,
                    format!(
                        "int16/int32 samples are (I, Q) pairs on a last axis of length 2, \
                         got shape {shape:?}"
                    ),
                ))
            }
        };
        check(&logical)?;
        // Exact: every int32 is a float64.
        kwargs.set_item("dtype", "float64")?;
        let f = asarray(py)?
            .call((a,), Some(&kwargs))?
            .cast_into::<PyArrayDyn<f64>>()
            .map_err(|_| arg_error(field, "not an array of (I, Q) pairs"))?;
        let v = crate::convert::logical_order(&f)
            .chunks_exact(2)
            .map(|q| Complex64::new(q[0], q[1]))
            .collect();
        return Ok((logical, v));
    }
    check(&shape)?;
    let c = match a.cast::<PyArrayDyn<Complex64>>() {
        Ok(c) => c.clone(),
        // complex64, or complex128 of the other byte order: converted exactly.
        Err(_) => {
            kwargs.set_item("dtype", "complex128")?;
            asarray(py)?
                .call((a,), Some(&kwargs))?
                .cast_into::<PyArrayDyn<Complex64>>()
                .map_err(|_| arg_error(field, "not an array of complex numbers"))?
        }
    };
    Ok((shape, crate::convert::logical_order(&c)))
}

/// A 1-D complex argument of at most `max` samples (`system_response`, `pulse`).
fn complex_vec(obj: &Bound<'_, PyAny>, field: &str, max: usize) -> PyResult<Vec<Complex64>> {
    let check = |shape: &[usize]| match shape {
        [n] if *n <= max => Ok(()),
        [n] => Err(too_many(field, *n, max, "samples")),
        _ => Err(arg_error(
            field,
            format!("expected a 1-D array, got shape {shape:?}"),
        )),
    };
    Ok(complex_arg(obj, field, SampleDtypes::Complex, check)?.1)
}

/// A channel recording (docs/recording.md): per snapshot and link a channel frequency response
/// (`cfr`, C1) at `freq_hz`, or a band-limited impulse response (`cir`, C2) of taps at
/// `tap0_s + m·tap_spacing_s`; snapshot times `t` (s), links as (transmitter, receiver)
/// indices into the scenario, and optionally the system response, the pulse, the noise
/// variance per link and whether the links share the transmitter's clock (`synchronized`).
/// Amplitudes are √W at the receiver input (C3).
#[pyclass(module = "scatterloc", name = "Recording", frozen)]
#[derive(Clone)]
pub struct PyRecording {
    pub(crate) rec: Recording,
}

#[pymethods]
impl PyRecording {
    /// A recording from arrays (checked as the reader checks a file): `t` (S,), `links` (P, 2)
    /// and exactly one of `cfr` (S, P, N) with `freq_hz` (N,) (and `system_response` (N,)) or
    /// `cir` (S, P, M) with `tap0_s`, `tap_spacing_s` (and `pulse` (K,) at `pulse_spacing_s`);
    /// the samples in the reader's dtypes — complex64 or complex128, for `cir` also int16/int32
    /// (I, Q) pairs (S, P, M, 2) — any other dtype refused by name; sizes checked against the
    /// reader's caps before anything is copied;
    /// `noise_var` (P,), W; `synchronized`: whether the receivers share the transmitter's
    /// clock (None: unknown; `False` makes the front end read delays relative to each link's
    /// direct path, C10).
    #[new]
    #[pyo3(signature = (
        t, links, *, cfr = None, freq_hz = None, system_response = None, cir = None,
        tap0_s = None, tap_spacing_s = None, pulse = None, pulse_spacing_s = None,
        noise_var = None, synchronized = None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        t: &Bound<'_, PyAny>,
        links: &Bound<'_, PyAny>,
        cfr: Option<&Bound<'_, PyAny>>,
        freq_hz: Option<&Bound<'_, PyAny>>,
        system_response: Option<&Bound<'_, PyAny>>,
        cir: Option<&Bound<'_, PyAny>>,
        tap0_s: Option<f64>,
        tap_spacing_s: Option<f64>,
        pulse: Option<&Bound<'_, PyAny>>,
        pulse_spacing_s: Option<f64>,
        noise_var: Option<&Bound<'_, PyAny>>,
        synchronized: Option<bool>,
    ) -> PyResult<PyRecording> {
        let t_s = crate::convert::f64_vec(t, "t", Len::AtMost(limits::MAX_SNAPSHOTS))?;
        let l = f64_array(links, "links", 2 * limits::MAX_LINKS)?;
        if l.shape.len() != 2 || l.shape[1] != 2 {
            return Err(arg_error(
                "links",
                format!("expected shape (P, 2), got {:?}", l.shape),
            ));
        }
        let links: Vec<[usize; 2]> = l
            .data
            .chunks_exact(2)
            .map(|p| {
                let ok = |v: f64| v >= 0.0 && v.fract() == 0.0 && v < 1e9;
                if ok(p[0]) && ok(p[1]) {
                    Ok([p[0] as usize, p[1] as usize])
                } else {
                    Err(arg_error("links", "indices must be whole numbers >= 0"))
                }
            })
            .collect::<PyResult<_>>()?;
        let (layout, samples) = match (cfr, cir) {
            (Some(h), None) => {
                for (f, g) in [
                    ("tap0_s", tap0_s.is_some()),
                    ("tap_spacing_s", tap_spacing_s.is_some()),
                    ("pulse", pulse.is_some()),
                ] {
                    if g {
                        return Err(arg_error(f, "only for a cir recording"));
                    }
                }
                let f = freq_hz.ok_or_else(|| arg_error("freq_hz", "required with cfr"))?;
                let (_, data) = complex_arg(h, "cfr", SampleDtypes::Complex, |shape| {
                    check_samples("cfr", shape, t_s.len(), links.len())
                })?;
                let sys = system_response
                    .map(|p| complex_vec(p, "system_response", limits::MAX_BINS_PER_LINK))
                    .transpose()?;
                (
                    Layout::Cfr {
                        freq_hz: crate::convert::f64_vec(
                            f,
                            "freq_hz",
                            Len::AtMost(limits::MAX_BINS_PER_LINK),
                        )?,
                        system_response: sys,
                    },
                    data,
                )
            }
            (None, Some(h)) => {
                for (f, g) in [
                    ("freq_hz", freq_hz.is_some()),
                    ("system_response", system_response.is_some()),
                ] {
                    if g {
                        return Err(arg_error(f, "only for a cfr recording"));
                    }
                }
                let (_, data) = complex_arg(h, "cir", SampleDtypes::ComplexOrIq, |shape| {
                    check_samples("cir", shape, t_s.len(), links.len())
                })?;
                let pulse = match pulse {
                    Some(p) => {
                        let mut p = Pulse {
                            samples: complex_vec(p, "pulse", limits::MAX_PULSE_SAMPLES)?,
                            spacing_s: pulse_spacing_s.ok_or_else(|| {
                                arg_error("pulse_spacing_s", "required with pulse")
                            })?,
                        };
                        p.normalise().py()?;
                        Some(p)
                    }
                    None => None,
                };
                (
                    Layout::Cir {
                        tap0_s: tap0_s.ok_or_else(|| arg_error("tap0_s", "required with cir"))?,
                        tap_spacing_s: tap_spacing_s
                            .ok_or_else(|| arg_error("tap_spacing_s", "required with cir"))?,
                        pulse,
                    },
                    data,
                )
            }
            _ => return Err(arg_error("cfr", "give exactly one of cfr and cir")),
        };
        let rec = Recording {
            t_s,
            links,
            layout,
            samples,
            noise_var: noise_var
                .map(|v| crate::convert::f64_vec(v, "noise_var", Len::AtMost(limits::MAX_LINKS)))
                .transpose()?,
            synchronized,
        };
        rec.validate().py()?;
        Ok(PyRecording { rec })
    }

    /// Snapshot times, s, shape (S,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        array(py, self.rec.t_s.clone(), &[self.rec.t_s.len()])
    }

    /// Links as (transmitter, receiver) indices, shape (P, 2).
    #[getter]
    fn links<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let l = &self.rec.links;
        array(
            py,
            l.iter().flat_map(|p| [p[0] as i64, p[1] as i64]).collect(),
            &[l.len(), 2],
        )
    }

    /// `"cfr"` or `"cir"`.
    #[getter]
    fn layout(&self) -> &'static str {
        self.rec.layout.array()
    }

    /// The samples: the CFR (S, P, N) or the CIR (S, P, M), complex128, √W.
    #[getter]
    fn samples<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let r = &self.rec;
        array(
            py,
            r.samples.clone(),
            &[r.snapshot_count(), r.link_count(), r.samples_per_link()],
        )
    }

    /// The baseband frequencies of a CFR, Hz (N,); None for a CIR.
    #[getter]
    fn freq_hz<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match &self.rec.layout {
            Layout::Cfr { freq_hz, .. } => {
                Some(array(py, freq_hz.clone(), &[freq_hz.len()])).transpose()
            }
            Layout::Cir { .. } => Ok(None),
        }
    }

    /// A CIR's tap 0 delay and tap spacing, s; None for a CFR.
    #[getter]
    fn taps(&self) -> Option<(f64, f64)> {
        match &self.rec.layout {
            Layout::Cir {
                tap0_s,
                tap_spacing_s,
                ..
            } => Some((*tap0_s, *tap_spacing_s)),
            Layout::Cfr { .. } => None,
        }
    }

    /// The noise variance per link, W (P,); None when the estimator estimates it.
    #[getter]
    fn noise_var<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.rec
            .noise_var
            .as_ref()
            .map(|v| array(py, v.clone(), &[v.len()]))
            .transpose()
    }

    /// Whether the receivers share the transmitter's clock (the file's `synchronized`); None
    /// when unknown.
    #[getter]
    fn synchronized(&self) -> Option<bool> {
        self.rec.synchronized
    }

    /// The snapshots with `t0 ≤ t ≤ t1` as a recording of their own (e.g. a stretch of the
    /// empty area for calibration).
    fn between(&self, t0: f64, t1: f64) -> PyResult<PyRecording> {
        Ok(PyRecording {
            rec: self.rec.between("t", t0, t1).py()?,
        })
    }

    fn __len__(&self) -> usize {
        self.rec.snapshot_count()
    }

    fn __repr__(&self) -> String {
        let r = &self.rec;
        format!(
            "Recording({}, snapshots={}, links={}, samples_per_link={})",
            r.layout.array(),
            r.snapshot_count(),
            r.link_count(),
            r.samples_per_link()
        )
    }
}

/// `shape` must be (S, P, N) for `s` snapshots and `p` links, with S·P·N within the reader's
/// cap ([`limits::MAX_RECORDING_SAMPLES`]); checked before the samples are copied.
fn check_samples(field: &str, shape: &[usize], s: usize, p: usize) -> PyResult<()> {
    match shape {
        [a, b, _] if *a == s && *b == p => {
            let n = crate::convert::count(shape);
            if n > limits::MAX_RECORDING_SAMPLES {
                return Err(too_many(
                    field,
                    n,
                    limits::MAX_RECORDING_SAMPLES,
                    "complex samples",
                ));
            }
            Ok(())
        }
        _ => Err(arg_error(
            field,
            format!("expected shape ({s}, {p}, N) (snapshots, links, samples), got {shape:?}"),
        )),
    }
}

/// Reads a recording: a `.npz` (docs/recording.md) or a Wi-Fi CSI tool's file converted as
/// `scatterloc cir convert` does (at most the CLI's cap of 1 GiB + 64 MiB). `format`: `auto`
/// (default: by the first bytes), `npz`, `intel5300`, `nexmon`, `picoscenes`, `feitcsi`,
/// `esp32`; `links`: the antenna pairs' links `rxR.txT=A:B,…` (default: every pair, link
/// (T, R)); `raw_gain`: keep the CSI unscaled (default: the format's RSSI/AGC gain applied);
/// `all_subcarriers`: keep the subcarriers no frame occupies (default: left out).
#[pyfunction]
#[pyo3(signature = (path, *, format = None, links = None, raw_gain = false, all_subcarriers = false))]
pub fn read_recording(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    format: Option<String>,
    links: Option<String>,
    raw_gain: bool,
    all_subcarriers: bool,
) -> PyResult<PyRecording> {
    let rec = crate::csi::open(py, path, format, links, raw_gain, all_subcarriers)?.recording;
    Ok(PyRecording { rec })
}

/// Writes `recording` to `path` as `.npz` (docs/recording.md; `numpy.load` reads it),
/// atomically as the CLI writes its outputs: into an exclusive temporary with a random name in
/// the target's directory, synced, then renamed into place (`crate::output`). A symbolic link,
/// a directory or another special file at `path` is refused by name.
#[pyfunction]
pub fn write_recording(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    recording: &PyRecording,
) -> PyResult<()> {
    let p = std::path::PathBuf::from(path_string(path)?);
    let bytes = run_quick(py, || npz::write_recording(&recording.rec))?;
    crate::output::write_file(py, "path", &p, &bytes)
}

/// Signal-level recordings of a walk through a scene (C1, C3; `scatterloc cir simulate`): the
/// LoS, walls with first- and second-order reflections, point scatterers, a walking person, with
/// thermal noise from the link budget. `scene` is the scene dict (`scene.json` of the CLI;
/// default the hangar of docs/reproduction.md); `walk` ((x, y) waypoints), `speed` (m/s),
/// `duration` (s) and `dt` (s) override it. `calibration_duration`: the length of the empty
/// area's recording, s (default 1); `seed` (default 1). Every keyword left at None takes the
/// library's default (`channel::SimulationRequest`). Returns `(recording, calibration,
/// truth)`: the walk, the empty area (same seed, no person), and the truth as the CLI's
/// `truth.json` dict. Errors name the request's field (`walk`, `speed_mps`, `duration_s`,
/// `dt_s`, `calibration_duration_s`) or the scene's own (`scene.…`).
#[pyfunction]
#[pyo3(signature = (
    scenario, *, scene = None, walk = None, speed = None, duration = None, dt = None,
    calibration_duration = None, seed = None
))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_recording<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    scene: Option<&Bound<'py, PyAny>>,
    walk: Option<&Bound<'py, PyAny>>,
    speed: Option<f64>,
    duration: Option<f64>,
    dt: Option<f64>,
    calibration_duration: Option<f64>,
    seed: Option<u64>,
) -> PyResult<(PyRecording, PyRecording, Bound<'py, PyAny>)> {
    let sc = scenario_arg(scenario)?;
    let scene: Option<ChannelScene> = match scene {
        Some(d) => Some(
            scatterloc::scenario::parse_json(&crate::convert::to_json_text(d, "scene")?).py()?,
        ),
        None => None,
    };
    let walk = match walk {
        Some(w) => {
            let (pts, lead) = crate::convert::points(w, "walk", limits::MAX_WAYPOINTS)?;
            if lead.len() != 1 {
                return Err(arg_error("walk", "expected waypoints of shape (K, 2)"));
            }
            Some(pts)
        }
        None => None,
    };
    let mut req = SimulationRequest {
        scene,
        walk,
        speed_mps: speed,
        duration_s: duration,
        dt_s: dt,
        ..SimulationRequest::default()
    };
    if let Some(d) = calibration_duration {
        req.calibration_duration_s = d;
    }
    if let Some(s) = seed {
        req.seed = s;
    }
    let (s, m) = (sc.scenario(), sc.model());
    let sim = run_job(py, 1, None, |job| {
        let stop = || job.cancelled();
        req.run(s, m, Cancel::when(&stop))
    })?;
    Ok((
        PyRecording { rec: sim.recording },
        PyRecording {
            rec: sim.calibration,
        },
        to_python(py, &sim.truth)?,
    ))
}

/// Paths in long format: one row per path, with the snapshot (and link) it belongs to.
#[pyclass(module = "scatterloc", frozen)]
pub struct Paths {
    /// The snapshot of each path, shape (K,).
    #[pyo3(get)]
    snapshot: Py<PyAny>,
    /// The scenario link of each path (`estimate_recording`), shape (K,); None for `estimate`.
    #[pyo3(get)]
    link: Py<PyAny>,
    /// Delay τ̂, s, shape (K,).
    #[pyo3(get)]
    delay: Py<PyAny>,
    /// Complex amplitude α̂ (√W for recordings), shape (K,).
    #[pyo3(get)]
    amplitude: Py<PyAny>,
    /// The delay's standard deviation σ̂_τ (C4 at the fitted SNR), s, shape (K,).
    #[pyo3(get)]
    sigma: Py<PyAny>,
    /// The fitted SNR, dB, shape (K,), masked at SNR ≤ 0.
    #[pyo3(get)]
    snr_db: Py<PyAny>,
    /// The path track's id (C6), shape (K,).
    #[pyo3(get)]
    track: Py<PyAny>,
    /// Whether the path track is confirmed, shape (K,).
    #[pyo3(get)]
    confirmed: Py<PyAny>,
    /// The noise variance the estimator used per snapshot (and link), W: shape (S,) or (S, L).
    #[pyo3(get)]
    noise_var: Py<PyAny>,
    /// Snapshot times, s (S,).
    #[pyo3(get)]
    t: Py<PyAny>,
    doc: Option<JsonDoc>,
    /// `estimate_recording`'s paths as detections (`cir estimate --detections-out`).
    detections: Option<Detections>,
}

#[pymethods]
impl Paths {
    /// `EST.json` as `scatterloc cir estimate --out` writes it (from `estimate_recording`);
    /// None for `estimate`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        match &self.doc {
            Some(d) => d.to_python(py),
            None => Ok(py.None().into_bound(py)),
        }
    }

    /// The paths as detections, as `scatterloc cir estimate --detections-out` writes them
    /// (docs/detections.md: per snapshot and recorded link every path's delay, SNR and σ̂_τ);
    /// from `estimate_recording` only (`estimate`'s paths have no scenario links).
    fn to_detections(&self) -> PyResult<PyDetections> {
        match &self.detections {
            Some(d) => Ok(PyDetections { d: d.clone() }),
            None => Err(arg_error(
                "paths",
                "detections need the scenario's links: estimate_recording's paths, not estimate's",
            )),
        }
    }

    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.delay.bind(py).len()
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!("Paths(paths={})", self.delay.bind(py).len().unwrap_or(0))
    }
}

/// The long-format [`Paths`] of `paths[s][l]` (`links`: whether the second index is a link).
fn paths_object(
    py: Python<'_>,
    t: &[f64],
    paths: &[Vec<Vec<TrackedPath>>],
    noise: Vec<f64>,
    noise_shape: &[usize],
    links: bool,
    doc: Option<JsonDoc>,
) -> PyResult<Paths> {
    let (mut snap, mut link, mut delay, mut amp, mut sigma, mut snr, mut track, mut conf) = (
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
    );
    for (s, per) in paths.iter().enumerate() {
        for (l, ps) in per.iter().enumerate() {
            for p in ps {
                let e = &p.estimate;
                snap.push(s as i64);
                link.push(l as i64);
                delay.push(e.delay_s);
                amp.push(e.alpha);
                sigma.push(e.sigma_s);
                snr.push((e.snr > 0.0).then(|| 10.0 * scatterloc::math::log10(e.snr)));
                track.push(p.track_id as i64);
                conf.push(p.confirmed);
            }
        }
    }
    let k = delay.len();
    Ok(Paths {
        snapshot: array(py, snap, &[k])?.unbind(),
        link: if links {
            array(py, link, &[k])?.unbind()
        } else {
            py.None()
        },
        delay: array(py, delay, &[k])?.unbind(),
        amplitude: array(py, amp, &[k])?.unbind(),
        sigma: array(py, sigma, &[k])?.unbind(),
        snr_db: masked(py, &snr, &[k])?.unbind(),
        track: array(py, track, &[k])?.unbind(),
        confirmed: array(py, conf, &[k])?.unbind(),
        noise_var: array(py, noise, noise_shape)?.unbind(),
        t: array(py, t.to_vec(), &[t.len()])?.unbind(),
        doc,
        detections: None,
    })
}

/// The front end's keywords of `estimate_recording`, `cir_track` and `track_stream` (None: the
/// core's default).
#[derive(Default)]
pub(crate) struct FrontEndKw<'a> {
    pub max_paths: Option<usize>,
    pub pfa: Option<f64>,
    pub statics: Option<&'a str>,
    pub delay_reference: Option<&'a str>,
    pub background_time: Option<f64>,
    pub calibration_range: Option<[f64; 2]>,
}

/// The tracker's keywords of `cir_track` and `track_stream` (None: the core's default).
pub(crate) struct TrackKw<'a> {
    pub filter: Option<&'a str>,
    pub process_noise: Option<f64>,
    pub association: Option<&'a str>,
    pub sigma: Option<&'a str>,
    pub extent_sigma: Option<f64>,
    pub seed: Option<u64>,
    pub particles: Option<usize>,
    pub roughening: Option<f64>,
    pub bootstrap: Option<bool>,
    pub ukf: [Option<f64>; 3],
}

/// The core's [`ChannelRequest`] of the given keywords (the others at its defaults), checked
/// by the core ([`ChannelRequest::check`]: errors name the request's field).
pub(crate) fn request(
    fe: &FrontEndKw<'_>,
    track: Option<&TrackKw<'_>>,
) -> PyResult<ChannelRequest> {
    let mut r = ChannelRequest::default();
    if let Some(k) = fe.max_paths {
        r.max_paths = k;
    }
    if let Some(p) = fe.pfa {
        r.pfa = p;
    }
    if let Some(s) = fe.statics {
        r.statics = StaticMode::named("statics", s).py()?;
    }
    if let Some(d) = fe.delay_reference {
        r.delay_reference = Some(DelayReference::named("delay_reference", d).py()?);
    }
    if let Some(t) = fe.background_time {
        r.background_time_s = t;
    }
    if fe.calibration_range.is_some() {
        r.calibration_range_s = fe.calibration_range;
    }
    if let Some(t) = track {
        if let Some(f) = t.filter {
            r.filter = f.to_string();
        }
        [r.ukf_alpha, r.ukf_beta, r.ukf_kappa] = t.ukf;
        r.particles = t.particles;
        r.roughening = t.roughening;
        if let Some(b) = t.bootstrap {
            r.bootstrap = b;
        }
        r.seed = t.seed;
        if let Some(q) = t.process_noise {
            r.process_noise = q;
        }
        if let Some(a) = t.association {
            r.association = AssociationRule::named("association", a).py()?;
        }
        if let Some(s) = t.sigma {
            r.sigma = DelaySigma::named("sigma", s).py()?;
        }
        if let Some(x) = t.extent_sigma {
            r.extent_sigma_m = x;
        }
    }
    r.check().py()?;
    Ok(r)
}

/// Every snapshot's paths (C5: greedy ML with SAGE refinement, joint amplitudes and a CFAR stop
/// at `pfa` per snapshot, at most `max_paths`; C6: paths tracked over snapshots) in responses
/// without a scenario. `response`: one CFR (N,) or snapshots (S, N) at `freq_hz` (N,), Hz
/// (with `system_response` (N,) when the system is not flat); or CIR taps (N,) / (S, N) at
/// `tap0_s + m·tap_spacing_s` with the `pulse` (K,) at `pulse_spacing_s` or, without it, the
/// ideal sinc of `bandwidth_hz`. `t` (S,) are the snapshot times (default 0, 1, 2, … s);
/// `noise_var` (W per sample) fixes the noise instead of estimating it. Returns the paths in
/// long format.
#[pyfunction]
#[pyo3(signature = (
    response, *, freq_hz = None, system_response = None, tap0_s = None, tap_spacing_s = None,
    pulse = None, pulse_spacing_s = None, bandwidth_hz = None, t = None, noise_var = None,
    max_paths = None, pfa = None, progress = None
))]
#[allow(clippy::too_many_arguments)]
pub fn estimate(
    py: Python<'_>,
    response: &Bound<'_, PyAny>,
    freq_hz: Option<&Bound<'_, PyAny>>,
    system_response: Option<&Bound<'_, PyAny>>,
    tap0_s: Option<f64>,
    tap_spacing_s: Option<f64>,
    pulse: Option<&Bound<'_, PyAny>>,
    pulse_spacing_s: Option<f64>,
    bandwidth_hz: Option<f64>,
    t: Option<&Bound<'_, PyAny>>,
    noise_var: Option<f64>,
    max_paths: Option<usize>,
    pfa: Option<f64>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Paths> {
    let cfg = request(
        &FrontEndKw {
            max_paths,
            pfa,
            ..FrontEndKw::default()
        },
        None,
    )?
    .front_end(None);
    let dims = |shape: &[usize]| match shape {
        [n] => Ok((1, *n)),
        [s, n] => Ok((*s, *n)),
        other => Err(arg_error(
            "response",
            format!("expected shape (N,) or (S, N), got {other:?}"),
        )),
    };
    let check = |shape: &[usize]| {
        dims(shape)?;
        let n = crate::convert::count(shape);
        if n > limits::MAX_RECORDING_SAMPLES {
            return Err(too_many(
                "response",
                n,
                limits::MAX_RECORDING_SAMPLES,
                "complex samples",
            ));
        }
        Ok(())
    };
    let (shape, data) = complex_arg(response, "response", SampleDtypes::Complex, check)?;
    let (s, n) = dims(&shape)?;
    let t_s = match t {
        Some(t) => crate::convert::f64_vec(t, "t", Len::Exactly(s))?,
        None => (0..s).map(|k| k as f64).collect(),
    };
    let is_cir = tap0_s.is_some() || tap_spacing_s.is_some();
    let py_rec = |cfr: Option<&Bound<'_, PyAny>>, cir: Option<&Bound<'_, PyAny>>| {
        let arr = PyArray1::from_vec(py, data.clone()).reshape(vec![s, 1, n])?;
        let links = array(py, vec![0, 0], &[1, 2])?;
        let tt = array(py, t_s.clone(), &[s])?;
        let (cfr, cir) = match (cfr, cir) {
            (Some(_), _) => (Some(arr.as_any().clone()), None),
            _ => (None, Some(arr.as_any().clone())),
        };
        let nv = noise_var
            .map(|v| vec![v])
            .map(|v| array(py, v, &[1]))
            .transpose()?;
        PyRecording::new(
            &tt,
            &links,
            cfr.as_ref(),
            freq_hz,
            system_response,
            cir.as_ref(),
            tap0_s,
            tap_spacing_s,
            pulse,
            pulse_spacing_s,
            nv.as_ref(),
            None,
        )
    };
    let rec = if is_cir {
        py_rec(None, Some(response))?
    } else {
        py_rec(Some(response), None)?
    }
    .rec;
    let b = bandwidth_hz.unwrap_or(0.0);
    if is_cir && bandwidth_hz.is_none() && pulse.is_none() {
        return Err(arg_error(
            "bandwidth_hz",
            "required for a CIR without a pulse (the ideal sinc of the band)",
        ));
    }
    let (paths, noise) = run_job(py, s, progress, |job| {
        let stop = || job.cancelled();
        estimate_link(&rec, b, 0, &cfg, Cancel::when(&stop), &|k| job.add_done(k))
    })?;
    let per: Vec<Vec<Vec<TrackedPath>>> = paths.into_iter().map(|p| vec![p]).collect();
    paths_object(py, &rec.t_s, &per, noise, &[s], false, None)
}

/// The recording of the empty area ([`ChannelRequest::empty_area`]): `calibration`, or the
/// snapshots of `rec` in the request's `calibration_range_s`, or neither (None: a recursive
/// background); not both.
fn empty_area<'a>(
    calibration: Option<&'a PyRecording>,
    req: &ChannelRequest,
    rec: &Recording,
) -> PyResult<Option<Cow<'a, Recording>>> {
    req.empty_area(calibration.map(|c| &c.rec), rec).py()
}

/// The estimates of a recording on `scenario`'s links (`scatterloc cir estimate`; spec C5, C6,
/// C9/C7, C10): per recorded link its statics, then every snapshot estimated, on `threads`
/// workers (0 = all cores), without the GIL; Ctrl-C stops it; `progress(done, total)` counts
/// link-snapshots. Every keyword left at None takes the library's default
/// (`study::ChannelRequest`, as the CLI's flags do):
///
/// - `calibration`: the recording of the empty area (`--calibration`); None: a recursive
///   background of the walk itself (`statics="background"`; `"clusters"` needs one).
/// - `max_paths` (default 12), `pfa` (default 1e-3): the estimator's path budget and
///   false-alarm probability per snapshot (C5).
/// - `statics`: `"background"` (default: the empty area's background subtracted, C9) or
///   `"clusters"` (the empty area's path clusters only, C7).
/// - `delay_reference`: `"absolute"` or `"los"` (relative to each link's direct path, C10);
///   default from the recording's `synchronized` flag (absolute unless it is False).
/// - `background_time`: the recursive background's time constant, s (default 10).
/// - `calibration_range`: `(t0, t1)`, s: the recording's snapshots in it are the empty area
///   (instead of `calibration`).
///
/// Errors (`ScatterlocError`) name the request's field (`statics`, `background_time_s`, …).
/// `to_dict()` is the CLI's `EST.json` for the same inputs (with `alignment`, `front_end` and
/// the static `calibration` clusters).
#[pyfunction]
#[pyo3(signature = (
    scenario, recording, *, calibration = None, max_paths = None, pfa = None, statics = None,
    delay_reference = None, background_time = None, calibration_range = None, threads = 0,
    progress = None
))]
#[allow(clippy::too_many_arguments)]
pub fn estimate_recording(
    py: Python<'_>,
    scenario: &Bound<'_, PyAny>,
    recording: &PyRecording,
    calibration: Option<&PyRecording>,
    max_paths: Option<usize>,
    pfa: Option<f64>,
    statics: Option<&str>,
    delay_reference: Option<&str>,
    background_time: Option<f64>,
    calibration_range: Option<[f64; 2]>,
    threads: usize,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Paths> {
    check_threads(threads)?;
    let sc = scenario_arg(scenario)?;
    let fe = FrontEndKw {
        max_paths,
        pfa,
        statics,
        delay_reference,
        background_time,
        calibration_range,
    };
    let req = request(&fe, None)?;
    let rec = &recording.rec;
    let empty = empty_area(calibration, &req, rec)?;
    let cfg = req.front_end(rec.synchronized);
    let (statics, est) = estimate_on(py, &sc, rec, empty.as_deref(), &cfg, threads, progress)?;
    let doc = JsonDoc::of(&estimates_doc(sc.model(), &est, &cfg, &statics))?;
    let l = sc.model().link_count();
    let noise: Vec<f64> = est.noise_var.iter().flatten().copied().collect();
    let mut paths = paths_object(
        py,
        &est.t_s,
        &est.paths,
        noise,
        &[est.len(), l],
        true,
        Some(doc),
    )?;
    let links = &sc.model().network.links;
    paths.detections = Some(Detections::from_paths(
        links,
        &est.t_s,
        &est.recorded,
        &est.paths,
    ));
    Ok(paths)
}

/// [`estimate_all`] off the GIL with Ctrl-C and progress.
fn estimate_on(
    py: Python<'_>,
    sc: &crate::scenario::PyScenario,
    rec: &Recording,
    empty: Option<&Recording>,
    cfg: &FrontEndConfig,
    threads: usize,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<(ChannelStatics, RecordingEstimates)> {
    let total = rec.snapshot_count() * rec.link_count();
    run_job(py, total, progress, |job| {
        estimate_all(
            sc.model(),
            sc.scenario().radio.bandwidth_hz,
            rec,
            empty,
            cfg,
            &mut Parallel::new(threads, &job.cancel),
            &|k| job.add_done(k),
        )
    })
}

/// A recording's track (returned by `cir_track`).
#[pyclass(module = "scatterloc", frozen)]
pub struct ChannelTrack {
    /// Snapshot times, s (S,).
    #[pyo3(get)]
    t: Py<PyAny>,
    /// States [x, y, vx, vy], shape (S, 4), masked outside the track's segments.
    #[pyo3(get)]
    states: Py<PyAny>,
    /// Covariances (S, 4, 4), masked outside the segments.
    #[pyo3(get)]
    covariances: Py<PyAny>,
    /// Links used per snapshot (S,).
    #[pyo3(get)]
    links_used: Py<PyAny>,
    /// The delay taken per snapshot and link, s (S, L), masked where absent.
    #[pyo3(get)]
    delays_used: Py<PyAny>,
    /// With `truth`: the position error per snapshot, m (S,), masked where there is no
    /// estimate; else None.
    #[pyo3(get)]
    error: Py<PyAny>,
    /// The track's segments (C11) in time order, as `TRACK.json`'s `segments`: per segment a
    /// dict with `first` and `last` (its first and last snapshot with a state), `t_first_s`,
    /// `t_last_s`, `end` (why it ended: `innovation`, `misses`, `outside_area` or `end`),
    /// `confirmed_at`, `hits` and `start` (the fix that started it).
    #[pyo3(get)]
    segments: Py<PyAny>,
    doc: JsonDoc,
}

#[pymethods]
impl ChannelTrack {
    /// `TRACK.json` as `scatterloc cir track --out` writes it for the same inputs.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.doc.to_python(py)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "ChannelTrack(snapshots={}, segments={})",
            self.t.bind(py).len().unwrap_or(0),
            self.segments.bind(py).len().unwrap_or(0)
        )
    }
}

/// The whole chain from a recording to a track (`scatterloc cir track`): the recording's
/// estimates as `estimate_recording` makes them (the front-end keywords `calibration`,
/// `max_paths`, `pfa`, `statics`, `delay_reference`, `background_time`, `calibration_range`
/// are its own), then each snapshot gated against the static clusters (E4) and associated,
/// through a tracker that starts the track by itself (an LM fix confirmed over snapshots),
/// ends it when it is lost and starts it again (C11); states are masked between the segments.
/// Every keyword left at None takes the library's default (`study::ChannelRequest`, as the
/// CLI's flags do):
///
/// - `filter`: `"ekf"` (default), `"ukf"` or `"pf"`; with `ukf_alpha`, `ukf_beta`,
///   `ukf_kappa` (ukf only), `particles` (default 1000), `roughening`, `bootstrap` and `seed`
///   (default 1) (pf only).
/// - `process_noise`: q̃ of the CV model, m²/s³ (default 1).
/// - `association`: `"gated"` (default) or `"spec"`.
/// - `sigma`: `"estimator"` (default: the estimator's σ̂_τ widened by the scatterer's extent
///   `extent_sigma`, m of path length, default 0.2) or `"budget"` (the link budget's σ).
///
/// `truth` (a dict as `truth.json`, or a path) adds the error statistics. Work runs without
/// the GIL on `threads` workers (0 = all cores); Ctrl-C stops it; `progress(done, total)`
/// counts the estimated link-snapshots. Errors (`ScatterlocError`) name the request's field
/// (`filter`, `extent_sigma_m`, …). `to_dict()` is the CLI's `TRACK.json`.
#[pyfunction]
#[pyo3(signature = (
    scenario, recording, calibration = None, *, truth = None, filter = None,
    process_noise = None, association = None, sigma = None, extent_sigma = None, seed = None,
    particles = None, roughening = None, bootstrap = None, ukf_alpha = None, ukf_beta = None,
    ukf_kappa = None, max_paths = None, pfa = None, statics = None, delay_reference = None,
    background_time = None, calibration_range = None, threads = 0, progress = None
))]
#[allow(clippy::too_many_arguments)]
pub fn cir_track(
    py: Python<'_>,
    scenario: &Bound<'_, PyAny>,
    recording: &PyRecording,
    calibration: Option<&PyRecording>,
    truth: Option<&Bound<'_, PyAny>>,
    filter: Option<&str>,
    process_noise: Option<f64>,
    association: Option<&str>,
    sigma: Option<&str>,
    extent_sigma: Option<f64>,
    seed: Option<u64>,
    particles: Option<usize>,
    roughening: Option<f64>,
    bootstrap: Option<bool>,
    ukf_alpha: Option<f64>,
    ukf_beta: Option<f64>,
    ukf_kappa: Option<f64>,
    max_paths: Option<usize>,
    pfa: Option<f64>,
    statics: Option<&str>,
    delay_reference: Option<&str>,
    background_time: Option<f64>,
    calibration_range: Option<[f64; 2]>,
    threads: usize,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<ChannelTrack> {
    check_threads(threads)?;
    let sc = scenario_arg(scenario)?;
    let fe = FrontEndKw {
        max_paths,
        pfa,
        statics,
        delay_reference,
        background_time,
        calibration_range,
    };
    let tk = TrackKw {
        filter,
        process_noise,
        association,
        sigma,
        extent_sigma,
        seed,
        particles,
        roughening,
        bootstrap,
        ukf: [ukf_alpha, ukf_beta, ukf_kappa],
    };
    let req = request(&fe, Some(&tk))?;
    let rec = &recording.rec;
    let truth: Option<Truth> = match truth {
        None => None,
        Some(t) => {
            let text = if t.cast::<pyo3::types::PyDict>().is_ok() {
                crate::convert::to_json_text(t, "truth")?
            } else {
                crate::scenario::read_text(&path_string(t)?, "truth")?
            };
            let t = Truth::from_json(&text).py()?;
            t.check_times(&rec.t_s).py()?;
            Some(t)
        }
    };
    let empty = empty_area(calibration, &req, rec)?;
    let cfg = req.front_end(rec.synchronized);
    let (model, scen) = (sc.model(), sc.scenario());
    let (statics, est) = estimate_on(py, &sc, rec, empty.as_deref(), &cfg, threads, progress)?;
    let track = run_job(py, est.len(), None, |job| {
        let stop = || job.cancelled();
        track_recording(
            &req,
            model,
            &scen.area_m,
            &statics.calibration,
            &est,
            Cancel::when(&stop),
        )
    })?;
    let truth_states: Vec<Option<[f64; 4]>> = truth
        .as_ref()
        .map(|t| t.states.iter().map(|s| Some(*s)).collect())
        .unwrap_or_default();
    let view = track_errors(&track.t_s, &track.states, &truth_states).py()?;
    let stats = truth.as_ref().and(view.stats);
    let doc = JsonDoc::of(&track_doc(&track, &req, &cfg, &statics, &est, stats).py()?)?;
    let s = track.t_s.len();
    let l = model.link_count();
    let states: Vec<Option<f64>> = track
        .states
        .iter()
        .flat_map(|st| match st {
            Some(v) => v.map(Some),
            None => [None; 4],
        })
        .collect();
    let covs: Vec<Option<f64>> = track
        .covariances
        .iter()
        .flat_map(|c| match c {
            Some(m) => m.iter().flatten().map(|v| Some(*v)).collect::<Vec<_>>(),
            None => vec![None; 16],
        })
        .collect();
    let used: Vec<Option<f64>> = track.delays_used_s.iter().flatten().copied().collect();
    let error = match &truth {
        Some(_) => masked(py, &view.error_m, &[s])?.unbind(),
        None => py.None(),
    };
    Ok(ChannelTrack {
        t: array(py, track.t_s.clone(), &[s])?.unbind(),
        states: masked(py, &states, &[s, 4])?.unbind(),
        covariances: masked(py, &covs, &[s, 4, 4])?.unbind(),
        links_used: array(
            py,
            track.links_used.iter().map(|&n| n as i64).collect(),
            &[s],
        )?
        .unbind(),
        delays_used: masked(py, &used, &[s, l])?.unbind(),
        error,
        segments: to_python(py, &track.segments)?.unbind(),
        doc,
    })
}
