//! `scatterloc.Scenario`: the core's [`Session`] (a validated scenario and its compiled model,
//! kept in step) with constructors from a preset, a dict, JSON text or a file, conversions back,
//! validated edits (a rejected edit raises and leaves the scenario unchanged) and the
//! measurement model at points (delays E1, their Jacobian E3, the link budget E8).

use pyo3::prelude::*;
use pyo3::types::PyString;

use scatterloc::error::limits;
use scatterloc::present::Session;
use scatterloc::scenario::{presets, Area};
use scatterloc::{Scenario, Vec2};

use crate::convert::{array, path_string, point, to_json_text, to_python};
use crate::errors::{arg_error, Core};

/// Largest scenario file read, bytes (the CLI's input cap, docs/cli.md "Size caps").
const MAX_FILE_BYTES: u64 = 256 << 20;

/// A scenario: the nodes, links, radio, target and area of `scatterloc`'s scenario JSON (schema
/// v1, docs/cli.md "Scenario JSON"), validated, with its measurement model compiled.
///
/// Build one with `Scenario.preset("sensors2019")`, `Scenario.from_dict(d)`,
/// `Scenario.from_json(text)` or `Scenario.from_file(path)`; `Scenario(x)` takes any of these
/// (a preset name, a dict, JSON text or a path). Edits (`move_receiver`, `set_bandwidth_hz`, …)
/// are validated: a rejected edit raises `ScatterlocError` and leaves the scenario unchanged.
#[pyclass(module = "scatterloc", name = "Scenario", from_py_object)]
#[derive(Clone)]
pub struct PyScenario {
    pub(crate) session: Session,
}

impl PyScenario {
    /// The scenario.
    pub fn scenario(&self) -> &Scenario {
        self.session.scenario()
    }

    /// Its model.
    pub fn model(&self) -> &scatterloc::Model {
        self.session.model()
    }

    fn of(s: Scenario) -> PyResult<PyScenario> {
        Ok(PyScenario {
            session: Session::new(s).py()?,
        })
    }

    fn from_text(text: &str) -> PyResult<PyScenario> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        PyScenario::of(Scenario::from_json(text).py()?)
    }

    fn edit(&mut self, f: impl FnOnce(&mut Scenario) -> scatterloc::Result<()>) -> PyResult<()> {
        self.session.edit(f).py()
    }
}

/// Reads a text file of at most [`MAX_FILE_BYTES`] (OSError when it cannot be read).
pub fn read_text(path: &str, field: &str) -> PyResult<String> {
    use std::io::Read;
    let f = std::fs::File::open(path)?;
    let mut bytes = Vec::new();
    f.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(arg_error(
            field,
            format!("'{path}' is larger than {MAX_FILE_BYTES} bytes"),
        ));
    }
    String::from_utf8(bytes).map_err(|_| arg_error(field, format!("'{path}' is not UTF-8 text")))
}

/// A scenario argument: a [`PyScenario`] or anything `Scenario(...)` takes.
pub fn scenario_arg(obj: &Bound<'_, PyAny>) -> PyResult<PyScenario> {
    if let Ok(s) = obj.cast::<PyScenario>() {
        return Ok(s.borrow().clone());
    }
    PyScenario::new(obj)
}

#[pymethods]
impl PyScenario {
    /// `Scenario(source)`: `source` is a preset name (`"sensors2019"`, `"iclgnss2019"`), a dict
    /// in the scenario schema, JSON text (starting with `{`) or a path to a JSON file.
    #[new]
    fn new(source: &Bound<'_, PyAny>) -> PyResult<PyScenario> {
        if let Ok(s) = source.cast::<PyString>() {
            let text = s.to_cow()?;
            let trimmed = text.trim_start_matches('\u{feff}').trim_start();
            if trimmed.starts_with('{') {
                return PyScenario::from_text(&text);
            }
            if presets::PRESET_NAMES.contains(&trimmed) {
                return PyScenario::of(presets::preset(trimmed).py()?);
            }
            return PyScenario::from_text(&read_text(&text, "source")?);
        }
        if source.cast::<pyo3::types::PyDict>().is_ok() {
            return PyScenario::from_text(&to_json_text(source, "source")?);
        }
        if source.hasattr("__fspath__")? {
            let path = path_string(source)?;
            return PyScenario::from_text(&read_text(&path, "source")?);
        }
        Err(arg_error(
            "source",
            "expected a preset name, a dict, JSON text or a path",
        ))
    }

    /// The preset scenario `name`: `sensors2019` ([S], layout L4) or `iclgnss2019` ([I], L3).
    #[staticmethod]
    fn preset(name: &str) -> PyResult<PyScenario> {
        PyScenario::of(presets::preset(name).py()?)
    }

    /// The names of the presets.
    #[staticmethod]
    fn presets() -> Vec<&'static str> {
        presets::PRESET_NAMES.to_vec()
    }

    /// A scenario from a dict in the scenario schema (as `json.load` gives it).
    #[staticmethod]
    fn from_dict(d: &Bound<'_, PyAny>) -> PyResult<PyScenario> {
        PyScenario::from_text(&to_json_text(d, "scenario")?)
    }

    /// A scenario from JSON text.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<PyScenario> {
        PyScenario::from_text(text)
    }

    /// A scenario from a JSON file (at most 256 MiB, as the CLI).
    #[staticmethod]
    fn from_file(path: &Bound<'_, PyAny>) -> PyResult<PyScenario> {
        let p = path_string(path)?;
        PyScenario::from_text(&read_text(&p, "path")?)
    }

    /// The scenario as a dict (the schema `from_dict` reads).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, self.scenario())
    }

    /// The scenario as JSON text (pretty, as `scatterloc preset` prints).
    fn to_json(&self) -> String {
        self.scenario().to_json()
    }

    /// Writes the scenario as JSON to `path` (every command and the page load it), atomically
    /// as `write_recording` writes (a synced temporary renamed into place: a failed save leaves
    /// the old file whole and nothing new).
    fn save(&self, py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<()> {
        let p = std::path::PathBuf::from(path_string(path)?);
        let text = self.scenario().to_json() + "\n";
        crate::output::write_file(py, "path", &p, text.as_bytes())
    }

    /// A copy (edits of one do not change the other).
    fn copy(&self) -> PyScenario {
        self.clone()
    }

    fn __copy__(&self) -> PyScenario {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> PyScenario {
        self.clone()
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PyScenario>()
            .is_ok_and(|o| o.borrow().scenario() == self.scenario())
    }

    fn __repr__(&self) -> String {
        let s = self.scenario();
        format!(
            "Scenario(name={:?}, transmitters={}, receivers={}, links={})",
            s.name,
            s.transmitters.len(),
            s.receivers.len(),
            self.model().link_count()
        )
    }

    /// Pickling: the scenario's JSON, read back by `Scenario.from_json`.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let ctor = slf.get_type().getattr("from_json")?;
        Ok((ctor, (slf.borrow().scenario().to_json(),)))
    }

    /// The scenario's name.
    #[getter]
    fn name(&self) -> String {
        self.scenario().name.clone()
    }

    /// Transmitter positions, m, shape (T, 2).
    #[getter]
    fn transmitters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let t = &self.scenario().transmitters;
        array(
            py,
            t.iter().flat_map(|t| t.position_m).collect(),
            &[t.len(), 2],
        )
    }

    /// Receiver positions, m, shape (R, 2).
    #[getter]
    fn receivers<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let r = &self.scenario().receivers;
        array(
            py,
            r.iter().flat_map(|r| r.position_m).collect(),
            &[r.len(), 2],
        )
    }

    /// Transmitter names.
    #[getter]
    fn transmitter_names(&self) -> Vec<String> {
        self.scenario()
            .transmitters
            .iter()
            .map(|t| t.name.clone())
            .collect()
    }

    /// Receiver names.
    #[getter]
    fn receiver_names(&self) -> Vec<String> {
        self.scenario()
            .receivers
            .iter()
            .map(|r| r.name.clone())
            .collect()
    }

    /// The links as (transmitter name, receiver name), in link order.
    #[getter]
    fn links(&self) -> PyResult<Vec<(String, String)>> {
        self.scenario().link_names().py()
    }

    /// The links as (transmitter index, receiver index), shape (L, 2).
    #[getter]
    fn link_indices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let l = &self.model().network.links;
        array(
            py,
            l.iter().flat_map(|l| [l.tx as i64, l.rx as i64]).collect(),
            &[l.len(), 2],
        )
    }

    /// Number of links L.
    #[getter]
    fn link_count(&self) -> usize {
        self.model().link_count()
    }

    /// The area of interest `(x_min, x_max, y_min, y_max)`, m (matplotlib's `extent` order).
    #[getter]
    fn area(&self) -> (f64, f64, f64, f64) {
        let a = self.scenario().area_m;
        (a.x[0], a.x[1], a.y[0], a.y[1])
    }

    /// Carrier frequency, Hz.
    #[getter]
    fn carrier_hz(&self) -> f64 {
        self.scenario().radio.carrier_hz
    }

    /// Bandwidth B, Hz.
    #[getter]
    fn bandwidth_hz(&self) -> f64 {
        self.scenario().radio.bandwidth_hz
    }

    /// Target radar cross section, m².
    #[getter]
    fn rcs_m2(&self) -> f64 {
        self.scenario().target.rcs_m2
    }

    /// Noise-free bistatic delays (E1) at `points` (shape (2,) or (..., 2), m): shape (..., L), s.
    fn delays<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let net = &self.model().network;
        self.per_link(py, points, |p, r| net.delay(p, r))
    }

    /// The link budget's delay σ (E8) at `points`: shape (..., L), s.
    fn sigma_delays<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = self.model();
        self.per_link(py, points, |p, r| m.sigma_delay(p, r))
    }

    /// The echo's SNR (E8) at `points`: shape (..., L), dB.
    fn snr_db<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = self.model();
        self.per_link(py, points, |p, r| {
            10.0 * scatterloc::math::log10(m.snr(p, r))
        })
    }

    /// The delays' Jacobian ∂τ/∂(x, y) (E3) at `points`: shape (..., L, 2), s/m.
    fn delay_jacobian<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let net = &self.model().network;
        let l = net.link_count();
        let (pts, mut shape) = crate::convert::eval_points(points, "points", l)?;
        let mut out = Vec::with_capacity(pts.len() * l * 2);
        for p in &pts {
            let r = Vec2::new(p[0], p[1]);
            for k in 0..l {
                let g = net.jacobian_row(k, r);
                out.extend([g.x, g.y]);
            }
        }
        shape.extend([l, 2]);
        array(py, out, &shape)
    }

    /// Moves transmitter `i` to `position` (m).
    fn move_transmitter(&mut self, i: usize, position: &Bound<'_, PyAny>) -> PyResult<()> {
        let p = point(position, "position")?;
        self.edit(|s| s.move_transmitter(i, p))
    }

    /// Moves receiver `i` to `position` (m).
    fn move_receiver(&mut self, i: usize, position: &Bound<'_, PyAny>) -> PyResult<()> {
        let p = point(position, "position")?;
        self.edit(|s| s.move_receiver(i, p))
    }

    /// Adds a transmitter at `position` (the radio settings of the last one, a fresh name);
    /// returns its index.
    fn add_transmitter(&mut self, position: &Bound<'_, PyAny>) -> PyResult<usize> {
        let p = point(position, "position")?;
        self.session.edit(|s| s.add_transmitter(p)).py()
    }

    /// Adds a receiver at `position`; returns its index.
    fn add_receiver(&mut self, position: &Bound<'_, PyAny>) -> PyResult<usize> {
        let p = point(position, "position")?;
        self.session.edit(|s| s.add_receiver(p)).py()
    }

    /// Removes transmitter `i` (and its links).
    fn remove_transmitter(&mut self, i: usize) -> PyResult<()> {
        self.edit(|s| s.remove_transmitter(i))
    }

    /// Removes receiver `i` (and its links).
    fn remove_receiver(&mut self, i: usize) -> PyResult<()> {
        self.edit(|s| s.remove_receiver(i))
    }

    /// Sets the area of interest, m.
    fn set_area(&mut self, x_min: f64, x_max: f64, y_min: f64, y_max: f64) -> PyResult<()> {
        self.edit(|s| {
            s.set_area(Area {
                x: [x_min, x_max],
                y: [y_min, y_max],
            })
        })
    }

    /// Renames the scenario.
    fn set_name(&mut self, name: &str) -> PyResult<()> {
        limits::check_name("name", name).py()?;
        let name = name.to_string();
        self.edit(|s| {
            s.name = name;
            Ok(())
        })
    }

    /// Sets the carrier frequency, Hz.
    fn set_carrier_hz(&mut self, value: f64) -> PyResult<()> {
        self.edit(|s| s.set_carrier_hz(value))
    }

    /// Sets the bandwidth B, Hz.
    fn set_bandwidth_hz(&mut self, value: f64) -> PyResult<()> {
        self.edit(|s| s.set_bandwidth_hz(value))
    }

    /// Sets the receiver noise figure, dB (drops an explicit noise power).
    fn set_noise_figure_db(&mut self, value: f64) -> PyResult<()> {
        self.edit(|s| s.set_noise_figure_db(value))
    }

    /// Sets the target radar cross section, m².
    fn set_rcs_m2(&mut self, value: f64) -> PyResult<()> {
        self.edit(|s| s.set_rcs_m2(value))
    }

    /// Sets transmitter `i`'s power, dBm.
    fn set_tx_power_dbm(&mut self, i: usize, value: f64) -> PyResult<()> {
        self.edit(|s| s.set_tx_power_dbm(i, value))
    }

    /// Sets transmitter `i`'s peak gain, dBi.
    fn set_tx_gain_dbi(&mut self, i: usize, value: f64) -> PyResult<()> {
        self.edit(|s| s.set_tx_gain_dbi(i, value))
    }

    /// Sets receiver `i`'s gain, dBi.
    fn set_rx_gain_dbi(&mut self, i: usize, value: f64) -> PyResult<()> {
        self.edit(|s| s.set_rx_gain_dbi(i, value))
    }

    /// Sets transmitter `i`'s antenna pattern (spec §9.3): `"omni"`, or `"parabolic"` with its
    /// boresight azimuth and half-power beamwidth (degrees) and floor (dB).
    #[pyo3(signature = (i, kind, boresight_deg = 0.0, beamwidth_deg = 70.0, floor_db = 20.0))]
    fn set_tx_pattern(
        &mut self,
        i: usize,
        kind: &str,
        boresight_deg: f64,
        beamwidth_deg: f64,
        floor_db: f64,
    ) -> PyResult<()> {
        self.edit(|s| s.set_tx_pattern_kind(i, kind, boresight_deg, beamwidth_deg, floor_db))
    }
}

impl PyScenario {
    /// `f(link, point)` for every link at every point of `points`: shape (..., L).
    fn per_link<'py>(
        &self,
        py: Python<'py>,
        points_obj: &Bound<'py, PyAny>,
        f: impl Fn(usize, Vec2) -> f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let l = self.model().link_count();
        let (pts, mut shape) = crate::convert::eval_points(points_obj, "points", l)?;
        let mut out = Vec::with_capacity(pts.len() * l);
        for p in &pts {
            let r = Vec2::new(p[0], p[1]);
            out.extend((0..l).map(|k| f(k, r)));
        }
        shape.push(l);
        array(py, out, &shape)
    }
}
