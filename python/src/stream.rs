//! `track_stream`: the live chain of `scatterloc cir track --follow` (issue 40 §3) as a Python
//! iterator — frames in, one state per frame out, computed when the frame is pulled — over the
//! library's `study::LiveFront` + `study::LiveRun` (the same core run as the CLI's). The
//! settings are the keywords of `cir_track` that `--follow` accepts, filled into one
//! `ChannelRequest` by `channel::request` (checked when `track_stream` is called). This file
//! only converts types; the run borrows the model, the area and the statics, which the iterator
//! owns beside it (`self_cell`).

use numpy::Complex64;
use pyo3::prelude::*;

use scatterloc::channel::{FrameHeader, Recording};
use scatterloc::scenario::Area;
use scatterloc::study::{ChannelRequest, ChannelStatics, LiveFront, LiveRun};
use scatterloc::Model;

use crate::channel::{complex_arg, request, FrontEndKw, PyRecording, SampleDtypes, TrackKw};
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
    req: ChannelRequest,
}

/// Where the frames come from.
enum Frames {
    /// A Python iterable of `(t, samples)`.
    Iter(Py<PyAny>),
    /// The snapshots of a recording, in order.
    Recording(Py<PyRecording>),
}

/// The iterator of [`track_stream`].
#[pyclass(unsendable, module = "scatterloc")]
pub struct TrackStream {
    frames: Frames,
    pending: Option<Pending>,
    live: Option<Live>,
    /// (links, bins) of every frame.
    shape: [usize; 2],
    k: usize,
}

impl TrackStream {
    /// Frame `k` of the Python iterator: `(t, samples)` with samples of shape (P, N).
    fn frame(&mut self, py: Python<'_>) -> PyResult<Option<(f64, Vec<Complex64>)>> {
        let it = match &self.frames {
            Frames::Iter(it) => it.bind(py),
            Frames::Recording(r) => {
                let rec = &r.get().rec;
                let k = self.k;
                if k >= rec.snapshot_count() {
                    return Ok(None);
                }
                let n = self.shape[0] * self.shape[1];
                return Ok(Some((rec.t_s[k], rec.samples[k * n..(k + 1) * n].to_vec())));
            }
        };
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
            let req = p.req;
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
/// system response, noise variances and clock flag the frames share (e.g. a short capture read
/// with `read_recording`); `frames`: an iterable of `(t, samples)`, samples complex of shape
/// (links, bins), times increasing; without `frames` the header's own snapshots are the frames
/// (a recording replayed live). `calibration`: the empty area's recording (default: a
/// recursive background from the first frame). The other keywords are `cir_track`'s that `cir
/// track --follow` accepts (every one left at None is the library's default): the tracker's
/// `filter`, `process_noise`, `association`, `sigma`, `extent_sigma`, `seed`, `particles`,
/// `roughening`, `bootstrap`, `ukf_alpha`, `ukf_beta`, `ukf_kappa`, and the front end's
/// `max_paths`, `pfa`, `statics`, `delay_reference`, `background_time`; they are checked here,
/// before any frame (`ScatterlocError` naming the request's field).
#[pyfunction]
#[pyo3(signature = (
    scenario, header, frames = None, *, calibration = None, filter = None, process_noise = None,
    association = None, sigma = None, extent_sigma = None, seed = None, particles = None,
    roughening = None, bootstrap = None, ukf_alpha = None, ukf_beta = None, ukf_kappa = None,
    max_paths = None, pfa = None, statics = None, delay_reference = None, background_time = None
))]
#[allow(clippy::too_many_arguments)]
pub fn track_stream(
    scenario: &Bound<'_, PyAny>,
    header: &Bound<'_, PyRecording>,
    frames: Option<&Bound<'_, PyAny>>,
    calibration: Option<&PyRecording>,
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
) -> PyResult<TrackStream> {
    let s = scenario_arg(scenario)?;
    let fe = FrontEndKw {
        max_paths,
        pfa,
        statics,
        delay_reference,
        background_time,
        calibration_range: None,
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
    let head = FrameHeader::of_recording(&header.get().rec).py()?;
    let frames = match frames {
        Some(f) => Frames::Iter(
            f.try_iter()
                .map_err(|_| arg_error("frames", "not iterable"))?
                .into_any()
                .unbind(),
        ),
        None => Frames::Recording(header.clone().unbind()),
    };
    let shape = [head.links.len(), head.freq_hz.len()];
    Ok(TrackStream {
        shape,
        frames,
        pending: Some(Pending {
            model: s.model().clone(),
            area: s.scenario().area_m,
            bandwidth_hz: s.scenario().radio.bandwidth_hz,
            header: head,
            calibration: calibration.map(|c| c.rec.clone()),
            req,
        }),
        live: None,
        k: 0,
    })
}
