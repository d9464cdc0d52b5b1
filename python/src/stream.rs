//! `track_stream`: the live chain of `scatterloc cir track --follow` (issue 40 §3) as a Python
//! iterator — frames in, one state per frame out, computed when the frame is pulled — over the
//! library's `study::LiveFront` + `study::LiveRun` (the same core run as the CLI's). This file
//! only converts types; the run borrows the model, the area and the statics, which the iterator
//! owns beside it (`self_cell`).

use numpy::Complex64;
use pyo3::prelude::*;

use scatterloc::channel::{FrameHeader, Recording};
use scatterloc::scenario::Area;
use scatterloc::study::{ChannelRequest, ChannelStatics, LiveFront, LiveRun};
use scatterloc::Model;

use crate::channel::{complex_arg, PyRecording, SampleDtypes};
use crate::convert::to_python;
use crate::errors::{arg_error, Core};
use crate::scenario::scenario_arg;

/// What the run borrows.
struct Owned {
    model: Model,
    area: Area,
    statics: ChannelStatics,
    req: ChannelRequest,
}

self_cell::self_cell!(
    /// The owned parts and the run that borrows them.
    struct Live {
        owner: Owned,
        #[not_covariant]
        dependent: LiveRun,
    }
);

/// Before the first frame: what the run will be made of.
struct Pending {
    model: Model,
    area: Area,
    bandwidth_hz: f64,
    header: FrameHeader,
    calibration: Option<Recording>,
}

/// The iterator of [`track_stream`].
#[pyclass(unsendable, module = "scatterloc")]
pub struct TrackStream {
    frames: Py<PyAny>,
    pending: Option<Pending>,
    live: Option<Live>,
    /// (links, bins) of every frame.
    shape: [usize; 2],
    k: usize,
}

impl TrackStream {
    /// Frame `k` of the Python iterator: `(t, samples)` with samples of shape (P, N).
    fn frame(&mut self, py: Python<'_>) -> PyResult<Option<(f64, Vec<Complex64>)>> {
        let it = self.frames.bind(py);
        let Some(item) = it.call_method0("__next__").map(Some).or_else(|e| {
            if e.is_instance_of::<pyo3::exceptions::PyStopIteration>(py) {
                Ok(None)
            } else {
                Err(e)
            }
        })?
        else {
            return Ok(None);
        };
        let field = format!("frames[{}]", self.k);
        let (t, samples): (f64, Bound<'_, PyAny>) = item
            .extract()
            .map_err(|_| arg_error(&field, "expected a (t, samples) pair"))?;
        let want = self.shape;
        let check = |shape: &[usize]| {
            if shape != want {
                return Err(arg_error(
                    &field,
                    format!("samples of shape {shape:?}, expected {want:?} (links, bins)"),
                ));
            }
            Ok(())
        };
        let (_, data) = complex_arg(&samples, &field, SampleDtypes::Complex, check)?;
        Ok(Some((t, data)))
    }
}

#[pymethods]
impl TrackStream {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__(&mut self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        let Some((t, samples)) = self.frame(py)? else {
            return Ok(None);
        };
        self.k += 1;
        if let Some(p) = self.pending.take() {
            let req = ChannelRequest::default();
            let cfg = req.front_end(p.header.synchronized);
            let (statics, front) = LiveFront::new(
                &p.model,
                p.bandwidth_hz,
                &p.header,
                t,
                &samples,
                p.calibration.as_ref(),
                &cfg,
            )
            .py()?;
            let owned = Owned {
                model: p.model,
                area: p.area,
                statics,
                req,
            };
            let live = Live::try_new(owned, |o| {
                LiveRun::new(&o.req, &o.model, &o.area, &o.statics, front)
            })
            .py()?;
            self.live = Some(live);
        }
        let live = self.live.as_mut().expect("made at the first frame");
        let state = live
            .with_dependent_mut(|_, run| run.push(t, &samples))
            .py()?;
        Ok(Some(to_python(py, &state)?.unbind()))
    }
}

/// Tracks frames as they come (`scatterloc cir track --follow` in Python; issue 40 §3): a
/// generator of one dict per frame — `t_s`, `state` ([x, y, vx, vy] or None), `covariance`,
/// `segment`, `links_used`, `delays_s`, `snapshot`, `event`, `end`, `dropped_hypotheses` —
/// computed when the frame is pulled. `header`: a `Recording` whose links, frequency bins,
/// system response, noise variances and clock flag the frames share (its samples are not
/// used; e.g. a short capture read with `read_recording`); `frames`: an iterable of
/// `(t, samples)`, samples complex of shape (links, bins), times increasing; `calibration`:
/// the empty area's recording (default: a recursive background from the first frame). The
/// front end and the tracker take the library's defaults (as `cir track --follow` without
/// flags).
#[pyfunction]
#[pyo3(signature = (scenario, header, frames, *, calibration = None))]
pub fn track_stream(
    py: Python<'_>,
    scenario: &Bound<'_, PyAny>,
    header: &PyRecording,
    frames: &Bound<'_, PyAny>,
    calibration: Option<&PyRecording>,
) -> PyResult<TrackStream> {
    let s = scenario_arg(scenario)?;
    let header = FrameHeader::of_recording(&header.rec).py()?;
    let frames = frames
        .try_iter()
        .map_err(|_| arg_error("frames", "not iterable"))?;
    let _ = py;
    let shape = [header.links.len(), header.freq_hz.len()];
    Ok(TrackStream {
        shape,
        frames: frames.into_any().unbind(),
        pending: Some(Pending {
            model: s.model().clone(),
            area: s.scenario().area_m,
            bandwidth_hz: s.scenario().radio.bandwidth_hz,
            header,
            calibration: calibration.map(|c| c.rec.clone()),
        }),
        live: None,
        k: 0,
    })
}
