"""Type stubs of the native module ``scatterloc._scatterloc`` (re-exported by ``scatterloc``)."""

import os
from types import ModuleType
from typing import (
    Any,
    Callable,
    Iterable,
    Literal,
    Mapping,
    Optional,
    Sequence,
    Union,
    final,
)

import numpy as np
from numpy.typing import ArrayLike, NDArray

__version__: str
__all__ = [
    "ChannelTrack",
    "Crlb",
    "CrlbMap",
    "Curves",
    "Detections",
    "Fix",
    "MtlResult",
    "MultiTrack",
    "Paths",
    "Plan",
    "Recording",
    "ScatterlocError",
    "Scenario",
    "StaticCalibration",
    "StudyResult",
    "Track",
    "TrackDoppler",
    "TrackStream",
    "__version__",
    "_bench",
    "calibrate",
    "cir_track",
    "crlb",
    "crlb_doppler",
    "crlb_map",
    "doppler_map",
    "estimate",
    "estimate_recording",
    "gospa",
    "locate",
    "montecarlo",
    "mtl_locate",
    "pcrlb",
    "plan",
    "read_csi",
    "read_detections",
    "range_rates",
    "read_recording",
    "sigma_range_rates",
    "simulate_people",
    "simulate_recording",
    "track",
    "track_multi",
    "track_stream",
    "write_detections",
    "write_recording",
]

# The benchmark's native timings (python/bench/bench.py); not public API.
_bench: ModuleType

_F64 = NDArray[np.float64]
_I64 = NDArray[np.int64]
_Bools = NDArray[np.bool_]
_C128 = NDArray[np.complex128]
_Masked = np.ma.MaskedArray[Any, np.dtype[np.float64]]
_PathLike = Union[str, "os.PathLike[str]"]
_Progress = Optional[Callable[[int, int], object]]
_Window = tuple[float, float, float, float]
_ScenarioLike = Union["Scenario", str, Mapping[str, Any], "os.PathLike[str]"]
_FilterName = Literal["ekf", "ukf", "pf"]
_Statics = Literal["background", "clusters"]
_DelayReference = Literal["absolute", "los"]
_MultiMethod = Literal["pmb", "gnn"]

class ScatterlocError(ValueError):
    """Bad input: ``field`` names the input at fault as the core names it (or is None),
    ``kind`` is the error's kind (``OutOfRange``, ``InvalidDelay``, ...)."""

    field: Optional[str]
    kind: str

@final
class Scenario:
    """A validated scenario (schema v1, docs/cli.md) with its measurement model compiled."""

    def __new__(cls, source: Union[str, Mapping[str, Any], "os.PathLike[str]"]) -> Scenario: ...
    @staticmethod
    def preset(name: str) -> Scenario: ...
    @staticmethod
    def presets() -> list[str]: ...
    @staticmethod
    def from_dict(d: Mapping[str, Any]) -> Scenario: ...
    @staticmethod
    def from_json(text: str) -> Scenario: ...
    @staticmethod
    def from_file(path: _PathLike) -> Scenario: ...
    def to_dict(self) -> dict[str, Any]: ...
    def to_json(self) -> str: ...
    def save(self, path: _PathLike) -> None: ...
    def copy(self) -> Scenario: ...
    def __copy__(self) -> Scenario: ...
    def __deepcopy__(self, memo: Any, /) -> Scenario: ...
    def __eq__(self, other: object, /) -> bool: ...
    @property
    def name(self) -> str: ...
    @property
    def transmitters(self) -> _F64: ...
    @property
    def receivers(self) -> _F64: ...
    @property
    def transmitter_names(self) -> list[str]: ...
    @property
    def receiver_names(self) -> list[str]: ...
    @property
    def links(self) -> list[tuple[str, str]]: ...
    @property
    def link_indices(self) -> _I64: ...
    @property
    def link_count(self) -> int: ...
    @property
    def area(self) -> _Window: ...
    @property
    def carrier_hz(self) -> float: ...
    @property
    def bandwidth_hz(self) -> float: ...
    @property
    def rcs_m2(self) -> float: ...
    def delays(self, points: ArrayLike) -> _F64: ...
    def sigma_delays(self, points: ArrayLike) -> _F64: ...
    def snr_db(self, points: ArrayLike) -> _F64: ...
    def delay_jacobian(self, points: ArrayLike) -> _F64: ...
    def move_transmitter(self, i: int, position: ArrayLike) -> None: ...
    def move_receiver(self, i: int, position: ArrayLike) -> None: ...
    def add_transmitter(self, position: ArrayLike) -> int: ...
    def add_receiver(self, position: ArrayLike) -> int: ...
    def remove_transmitter(self, i: int) -> None: ...
    def remove_receiver(self, i: int) -> None: ...
    def set_area(self, x_min: float, x_max: float, y_min: float, y_max: float) -> None: ...
    def set_name(self, name: str) -> None: ...
    def set_carrier_hz(self, value: float) -> None: ...
    def set_bandwidth_hz(self, value: float) -> None: ...
    def set_noise_figure_db(self, value: float) -> None: ...
    def set_rcs_m2(self, value: float) -> None: ...
    def set_tx_power_dbm(self, i: int, value: float) -> None: ...
    def set_tx_gain_dbi(self, i: int, value: float) -> None: ...
    def set_rx_gain_dbi(self, i: int, value: float) -> None: ...
    def set_tx_pattern(
        self,
        i: int,
        kind: Literal["omni", "parabolic"],
        boresight_deg: float = 0.0,
        beamwidth_deg: float = 70.0,
        floor_db: float = 20.0,
    ) -> None: ...

@final
class Crlb:
    """The CRLB at points; arrays have the points' leading shape."""

    @property
    def points(self) -> _F64: ...
    @property
    def sigma_x(self) -> Union[float, _F64]: ...
    @property
    def sigma_y(self) -> Union[float, _F64]: ...
    @property
    def rmse(self) -> Union[float, _F64]: ...
    @property
    def bounded(self) -> Union[bool, _Bools]: ...
    @property
    def fisher(self) -> _F64: ...
    @property
    def covariance(self) -> _F64: ...
    @property
    def snr_db(self) -> _F64: ...
    @property
    def sigma_delay(self) -> _F64: ...
    @property
    def delay(self) -> _F64: ...
    def ellipses(self) -> _Masked: ...
    def to_dicts(self) -> list[dict[str, Any]]: ...

def crlb(scenario: _ScenarioLike, points: ArrayLike) -> Crlb: ...

def crlb_doppler(
    scenario: _ScenarioLike,
    point_m: ArrayLike,
    velocity_mps: Optional[ArrayLike] = None,
    *,
    cpi: int = 16,
    cpi_spacing_s: float = 2.048e-3,
    range_rate_floor: float = 0.1,
) -> dict[str, Any]:
    """The bound on position and velocity over one CPI from delays and range rates."""
    ...

def doppler_map(
    scenario: _ScenarioLike,
    nx: int = 256,
    ny: int = 256,
    window: Optional[_Window] = None,
    *,
    velocity_mps: Optional[ArrayLike] = None,
    cpi: int = 16,
    cpi_spacing_s: float = 2.048e-3,
    range_rate_floor: float = 0.1,
    quantity: Literal["position", "velocity"] = "position",
) -> _F64:
    """The position (m) or velocity (m/s) bound with Doppler over a grid, (ny, nx); inf where
    unbounded."""
    ...

def range_rates(scenario: _ScenarioLike, states: ArrayLike) -> tuple[_F64, _F64]:
    """Range rates (..., L), m/s, and their Jacobian (..., L, 4) for states [x, y, vx, vy]."""
    ...

def sigma_range_rates(
    scenario: _ScenarioLike,
    points: ArrayLike,
    *,
    cpi: int = 16,
    cpi_spacing_s: float = 2.048e-3,
    range_rate_floor: float = 0.1,
) -> _F64:
    """The CPI's range-rate sigma per link (..., L), m/s; inf for one snapshot."""
    ...

def gospa(truth: ArrayLike, estimates: ArrayLike, *, c: float, p: float = 2.0) -> dict[str, Any]:
    """GOSPA (alpha = 2) between true positions and estimates, (n, 2) in metres."""
    ...

@final
class CrlbMap:
    """The RMSE bound over a grid (rows ascending in y)."""

    @property
    def x(self) -> _F64: ...
    @property
    def y(self) -> _F64: ...
    @property
    def rmse(self) -> _F64: ...
    @property
    def sigma_x(self) -> Optional[_F64]: ...
    @property
    def sigma_y(self) -> Optional[_F64]: ...
    @property
    def extent(self) -> _Window: ...
    @property
    def compute_s(self) -> float: ...
    def to_dict(self) -> dict[str, Any]: ...

def crlb_map(
    scenario: _ScenarioLike,
    nx: int = 256,
    ny: int = 256,
    window: Optional[_Window] = None,
    *,
    threads: int = 0,
    components: bool = False,
) -> CrlbMap: ...

@final
class Fix:
    """A Levenberg-Marquardt fix."""

    @property
    def position(self) -> _F64: ...
    @property
    def covariance(self) -> Optional[_F64]: ...
    @property
    def cost(self) -> float: ...
    @property
    def iterations(self) -> int: ...
    @property
    def termination(self) -> str: ...
    @property
    def converged(self) -> bool: ...
    @property
    def links_used(self) -> int: ...
    @property
    def start(self) -> _F64: ...
    def to_dict(self) -> dict[str, Any]: ...

def locate(
    scenario: _ScenarioLike,
    delays: ArrayLike,
    sigma: Union[float, ArrayLike],
    *,
    initial: Optional[ArrayLike] = None,
) -> Fix: ...

@final
class StaticCalibration:
    """Static clusters per link (spec section 4)."""

    @property
    def clusters(self) -> list[_F64]: ...
    def to_dict(self) -> dict[str, Any]: ...

def calibrate(
    scenario: _ScenarioLike,
    snapshots: Sequence[Sequence[Sequence[float]]],
    *,
    gap: Optional[float] = None,
    min_fraction: Optional[float] = None,
    sigma_floor: Optional[float] = None,
) -> StaticCalibration: ...

@final
class Track:
    """A track: one entry per step."""

    @property
    def t(self) -> _F64: ...
    @property
    def states(self) -> _F64: ...
    @property
    def covariances(self) -> _F64: ...
    @property
    def nis(self) -> _Masked: ...
    @property
    def links_used(self) -> _I64: ...
    @property
    def delays_used(self) -> Optional[_Masked]: ...
    @property
    def choices(self) -> Optional[list[list[str]]]: ...
    @property
    def static_removed(self) -> Optional[_I64]: ...
    @property
    def start(self) -> Optional[dict[str, Any]]: ...
    @property
    def doppler(self) -> Optional[TrackDoppler]: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __len__(self) -> int: ...

@final
class TrackDoppler:
    """How a track used its range rates (issue 42 §5): whether, their σ, and per step the
    predicted range rates and their innovations (m/s)."""

    @property
    def used(self) -> bool: ...
    @property
    def sigma(self) -> Literal["fixed", "cpi", "cpi_at"]: ...
    @property
    def cpi(self) -> Optional[dict[str, Any]]: ...
    @property
    def predicted_range_rates(self) -> Optional[_F64]: ...
    @property
    def range_rate_innovations(self) -> Optional[_Masked]: ...
    def to_dict(self) -> dict[str, Any]: ...

def track(
    scenario: _ScenarioLike,
    measurements: Union[
        ArrayLike, Sequence[Sequence[ArrayLike]], Mapping[str, Any], _PathLike, Detections
    ],
    *,
    dt: Optional[float] = None,
    process_noise: Optional[float] = None,
    initial_state: Optional[ArrayLike] = None,
    initial_covariance: Optional[ArrayLike] = None,
    initial_snapshot: Optional[Sequence[ArrayLike]] = None,
    sigma: Optional[Union[float, ArrayLike]] = None,
    filter: _FilterName = "ekf",
    particles: Optional[int] = None,
    roughening: Optional[float] = None,
    bootstrap: Optional[bool] = None,
    seed: Optional[int] = None,
    ukf_alpha: Optional[float] = None,
    ukf_beta: Optional[float] = None,
    ukf_kappa: Optional[float] = None,
    calibration: Optional[Union[StaticCalibration, Mapping[str, Any], _PathLike]] = None,
    association: Optional[Literal["spec", "gated"]] = None,
    max_cpu_hours: Optional[float] = None,
    range_rates: Optional[ArrayLike] = None,
    range_rate_sigma: Optional[Union[float, ArrayLike]] = None,
    cpi: Optional[int] = None,
    cpi_spacing_s: Optional[float] = None,
    range_rate_floor: Optional[float] = None,
    doppler: Optional[bool] = None,
) -> Track: ...

@final
class MultiTrack:
    """A multi-target track: the reported targets in long format, one row per scan and target."""

    @property
    def t(self) -> _F64: ...
    @property
    def scan(self) -> _I64: ...
    @property
    def label(self) -> _I64: ...
    @property
    def states(self) -> _F64: ...
    @property
    def covariances(self) -> _F64: ...
    @property
    def existence(self) -> _F64: ...
    @property
    def count(self) -> _I64: ...
    @property
    def labels(self) -> _I64: ...
    @property
    def tracks(self) -> list[dict[str, Any]]: ...
    @property
    def static_removed(self) -> _I64: ...
    @property
    def score(self) -> Optional[dict[str, Any]]: ...
    @property
    def method(self) -> str: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __len__(self) -> int: ...

def track_multi(
    scenario: _ScenarioLike,
    measurements: Union[Mapping[str, Any], _PathLike, Detections],
    *,
    calibration: Optional[Union[StaticCalibration, Mapping[str, Any], _PathLike]] = None,
    method: _MultiMethod = "pmb",
    detection_probability: float = 0.9,
    clutter: float = 5.0,
    clutter_window_s: float = 60e-9,
    birth_rate: float = 0.01,
    truth: Optional[Union[Mapping[str, Any], _PathLike]] = None,
    gospa_c: Optional[float] = None,
    process_noise: Optional[float] = None,
) -> MultiTrack: ...

def simulate_people(
    scenario: _ScenarioLike,
    walkers: Optional[int] = None,
    *,
    paths: Optional[Union[ArrayLike, Sequence[Sequence[float]]]] = None,
    duration_s: float = 10.0,
    dt_s: float = 0.1,
    process_noise: float = 0.5,
    detection_probability: float = 0.9,
    clutter: float = 5.0,
    seed: int = 1,
) -> tuple[dict[str, Any], dict[str, Any]]: ...

@final
class Curves:
    """The curves of one trajectory of a study."""

    @property
    def trajectory(self) -> str: ...
    @property
    def t(self) -> _F64: ...
    @property
    def pcrlb(self) -> _F64: ...
    @property
    def rmse(self) -> dict[str, _F64]: ...
    @property
    def nees(self) -> dict[str, _F64]: ...
    @property
    def runs(self) -> dict[str, int]: ...
    @property
    def failed_runs(self) -> dict[str, int]: ...
    @property
    def errors(self) -> dict[str, str]: ...
    @property
    def wall_time_s(self) -> float: ...

@final
class StudyResult:
    """A study's result: one Curves per trajectory."""

    @property
    def curves(self) -> list[Curves]: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __getitem__(self, key: Union[int, str], /) -> Curves: ...
    def __len__(self) -> int: ...

def montecarlo(
    scenario: Optional[_ScenarioLike] = None,
    *,
    trajectory: Optional[Union[str, Sequence[str]]] = None,
    runs: int = 5000,
    noise_runs: int = 50,
    dt: float = 2.048e-3,
    duration: float = 10.0,
    process_noise: float = 0.01,
    seed: int = 1,
    threads: int = 0,
    oracle_noise: bool = False,
    filters: Optional[Union[str, Sequence[_FilterName]]] = None,
    particles: Optional[int] = None,
    roughening: Optional[float] = None,
    bootstrap: Optional[bool] = None,
    ukf_alpha: Optional[float] = None,
    ukf_beta: Optional[float] = None,
    ukf_kappa: Optional[float] = None,
    max_cpu_hours: Optional[float] = None,
    progress: _Progress = None,
) -> StudyResult: ...
def pcrlb(
    scenario: Optional[_ScenarioLike] = None,
    *,
    nominal: bool = False,
    trajectory: Optional[Union[str, Sequence[str]]] = None,
    runs: Optional[int] = None,
    dt: float = 2.048e-3,
    duration: float = 10.0,
    process_noise: float = 0.01,
    seed: Optional[int] = None,
    threads: Optional[int] = None,
    progress: _Progress = None,
) -> StudyResult: ...

@final
class Plan:
    """A plan: the optimised scenario and its history."""

    @property
    def scenario(self) -> Scenario: ...
    @property
    def before(self) -> float: ...
    @property
    def after(self) -> float: ...
    @property
    def history(self) -> _F64: ...
    @property
    def paths(self) -> dict[str, _F64]: ...
    @property
    def evaluations(self) -> int: ...
    @property
    def termination(self) -> str: ...
    @property
    def moved(self) -> list[str]: ...
    def to_dict(self) -> dict[str, Any]: ...

def plan(
    scenario: _ScenarioLike,
    *,
    move: str,
    objective: str,
    roi: _Window,
    bounds: Optional[_Window] = None,
    allowed: Optional[Sequence[ArrayLike]] = None,
    min_spacing: float = 0.0,
    grid: int = 64,
    budget: int = 10000,
    seed: int = 1,
    progress: _Progress = None,
) -> Plan: ...

@final
class MtlResult:
    """The targets found by multi-target localization."""

    @property
    def positions(self) -> _F64: ...
    @property
    def scores(self) -> _F64: ...
    @property
    def blocking(self) -> _F64: ...
    @property
    def direct_paths(self) -> _I64: ...
    @property
    def matchings(self) -> list[list[tuple[int, int]]]: ...
    @property
    def candidates(self) -> int: ...
    def to_dict(self) -> dict[str, Any]: ...
    def __len__(self) -> int: ...

def mtl_locate(
    tx: ArrayLike,
    rx: ArrayLike,
    ranges: Sequence[Sequence[float]],
    *,
    region: Optional[_Window] = None,
    c_sigma: float = 0.1,
    model: Literal["icb", "ppp", "empirical"] = "icb",
    p_u: Optional[float] = None,
    p_d: Optional[float] = None,
    p_los: Optional[float] = None,
    lambda_: Optional[float] = None,
    diameter: Optional[float] = None,
    exact: Optional[bool] = None,
    table: Optional[Mapping[str, Any]] = None,
    cells: Optional[int] = None,
    scenes: Optional[int] = None,
    seed: Optional[int] = None,
    te: Optional[float] = None,
    tb: Optional[float] = None,
    b_max: Optional[float] = None,
    n_min: Optional[int] = None,
    order: Optional[Sequence[int]] = None,
    max_candidates: Optional[int] = None,
) -> MtlResult: ...

@final
class Recording:
    """A channel recording (docs/recording.md)."""

    def __new__(
        cls,
        t: ArrayLike,
        links: ArrayLike,
        *,
        cfr: Optional[ArrayLike] = None,
        freq_hz: Optional[ArrayLike] = None,
        system_response: Optional[ArrayLike] = None,
        cir: Optional[ArrayLike] = None,
        tap0_s: Optional[float] = None,
        tap_spacing_s: Optional[float] = None,
        pulse: Optional[ArrayLike] = None,
        pulse_spacing_s: Optional[float] = None,
        noise_var: Optional[ArrayLike] = None,
        synchronized: Optional[bool] = None,
    ) -> Recording: ...
    @property
    def t(self) -> _F64: ...
    @property
    def links(self) -> _I64: ...
    @property
    def layout(self) -> Literal["cfr", "cir"]: ...
    @property
    def samples(self) -> _C128: ...
    @property
    def freq_hz(self) -> Optional[_F64]: ...
    @property
    def taps(self) -> Optional[tuple[float, float]]: ...
    @property
    def noise_var(self) -> Optional[_F64]: ...
    @property
    def synchronized(self) -> Optional[bool]: ...
    def between(self, t0: float, t1: float) -> Recording: ...
    def __len__(self) -> int: ...

def read_recording(
    path: _PathLike,
    *,
    format: Optional[str] = None,
    links: Optional[str] = None,
    raw_gain: bool = False,
    all_subcarriers: bool = False,
) -> Recording: ...
def read_csi(path: _PathLike, *, format: Optional[str] = None) -> dict[str, Any]: ...
@final
class TrackStream:
    """The iterator of :func:`track_stream`: one state dict per frame pulled."""
    def __iter__(self) -> TrackStream: ...
    def __next__(self) -> dict[str, Any]: ...

def track_stream(
    scenario: _ScenarioLike,
    header: Recording,
    frames: Optional[Iterable[tuple[float, ArrayLike]]] = None,
    *,
    calibration: Optional[Recording] = None,
    filter: Optional[_FilterName] = None,
    process_noise: Optional[float] = None,
    association: Optional[Literal["gated", "spec"]] = None,
    sigma: Optional[Literal["estimator", "budget"]] = None,
    extent_sigma: Optional[float] = None,
    seed: Optional[int] = None,
    particles: Optional[int] = None,
    roughening: Optional[float] = None,
    bootstrap: Optional[bool] = None,
    ukf_alpha: Optional[float] = None,
    ukf_beta: Optional[float] = None,
    ukf_kappa: Optional[float] = None,
    max_paths: Optional[int] = None,
    pfa: Optional[float] = None,
    statics: Optional[_Statics] = None,
    delay_reference: Optional[_DelayReference] = None,
    background_time: Optional[float] = None,
) -> TrackStream:
    """``scatterloc cir track --follow`` in Python: one dict per frame (``t_s``, ``state``,
    ``covariance``, ``segment``, ``links_used``, ``delays_s``, ``snapshot``, ``event``, ``end``,
    ``dropped_hypotheses``), computed as each ``(t, samples (links, bins))`` of ``frames`` is
    pulled; ``header`` gives the links, bins, system response and clock flag, and without
    ``frames`` its own snapshots are the frames. The keywords are ``cir_track``'s that
    ``--follow`` accepts, checked before the first frame."""
@final
class Detections:
    """Detections, JSON lines (docs/detections.md), in long format: one row per detection."""
    def __new__(cls, lines: Iterable[Mapping[str, Any]]) -> Detections: ...
    @property
    def t(self) -> _F64: ...
    @property
    def frame(self) -> _I64: ...
    @property
    def links(self) -> _I64: ...
    @property
    def delay(self) -> _F64: ...
    @property
    def snr_db(self) -> _Masked: ...
    @property
    def sigma(self) -> _Masked: ...
    @property
    def doppler(self) -> _Masked: ...
    def to_text(self) -> str: ...
    def lines(self) -> list[dict[str, Any]]: ...
    def __len__(self) -> int: ...
    def __eq__(self, other: object, /) -> bool: ...

def read_detections(source: _PathLike) -> Detections:
    """A detections file (a path), or its text (a str holding a newline or starting with
    ``{`` or ``#``); errors name the line and the field."""
def write_detections(path: _PathLike, detections: Detections) -> None: ...
def write_recording(path: _PathLike, recording: Recording) -> None: ...
def simulate_recording(
    scenario: _ScenarioLike,
    *,
    scene: Optional[Mapping[str, Any]] = None,
    walk: Optional[ArrayLike] = None,
    speed: Optional[float] = None,
    duration: Optional[float] = None,
    dt: Optional[float] = None,
    calibration_duration: Optional[float] = None,
    seed: Optional[int] = None,
) -> tuple[Recording, Recording, dict[str, Any]]:
    """``scatterloc cir simulate``: the walk's recording, the empty area's and the truth dict.
    None takes the library's default (``channel::SimulationRequest``): ``scene`` the hangar,
    ``walk``/``speed``/``duration``/``dt`` the scene's, ``calibration_duration`` 1 s,
    ``seed`` 1."""

@final
class Paths:
    """Estimated paths in long format (one row per path)."""

    @property
    def snapshot(self) -> _I64: ...
    @property
    def link(self) -> Optional[_I64]: ...
    @property
    def delay(self) -> _F64: ...
    @property
    def amplitude(self) -> _C128: ...
    @property
    def sigma(self) -> _F64: ...
    @property
    def snr_db(self) -> _Masked: ...
    @property
    def track(self) -> _I64: ...
    @property
    def confirmed(self) -> _Bools: ...
    @property
    def noise_var(self) -> _F64: ...
    @property
    def t(self) -> _F64: ...
    def to_dict(self) -> Optional[dict[str, Any]]: ...
    def to_detections(self) -> Detections:
        """``cir estimate --detections-out`` of these paths (``estimate_recording``'s only)."""
    def __len__(self) -> int: ...

def estimate(
    response: ArrayLike,
    *,
    freq_hz: Optional[ArrayLike] = None,
    system_response: Optional[ArrayLike] = None,
    tap0_s: Optional[float] = None,
    tap_spacing_s: Optional[float] = None,
    pulse: Optional[ArrayLike] = None,
    pulse_spacing_s: Optional[float] = None,
    bandwidth_hz: Optional[float] = None,
    t: Optional[ArrayLike] = None,
    noise_var: Optional[float] = None,
    max_paths: Optional[int] = None,
    pfa: Optional[float] = None,
    progress: _Progress = None,
) -> Paths: ...
def estimate_recording(
    scenario: _ScenarioLike,
    recording: Recording,
    *,
    calibration: Optional[Recording] = None,
    max_paths: Optional[int] = None,
    pfa: Optional[float] = None,
    statics: Optional[_Statics] = None,
    delay_reference: Optional[_DelayReference] = None,
    background_time: Optional[float] = None,
    calibration_range: Optional[tuple[float, float]] = None,
    threads: int = 0,
    progress: _Progress = None,
) -> Paths:
    """``scatterloc cir estimate``; ``to_dict()`` is its EST.json. None takes the library's
    default (``study::ChannelRequest``): ``calibration`` the empty area's recording (None: a
    recursive background), ``max_paths`` 12, ``pfa`` 1e-3, ``statics`` "background",
    ``delay_reference`` from ``recording.synchronized`` (absolute unless False),
    ``background_time`` 10 s, ``calibration_range`` (t0, t1) s of the recording as the empty
    area instead of ``calibration``."""

@final
class ChannelTrack:
    """A recording's track."""

    @property
    def t(self) -> _F64: ...
    @property
    def states(self) -> _Masked: ...
    @property
    def covariances(self) -> _Masked: ...
    @property
    def links_used(self) -> _I64: ...
    @property
    def delays_used(self) -> _Masked: ...
    @property
    def error(self) -> Optional[_Masked]: ...
    @property
    def segments(self) -> list[dict[str, Any]]: ...
    def to_dict(self) -> dict[str, Any]: ...

def cir_track(
    scenario: _ScenarioLike,
    recording: Recording,
    calibration: Optional[Recording] = None,
    *,
    truth: Optional[Union[Mapping[str, Any], _PathLike]] = None,
    filter: Optional[_FilterName] = None,
    process_noise: Optional[float] = None,
    association: Optional[Literal["gated", "spec"]] = None,
    sigma: Optional[Literal["estimator", "budget"]] = None,
    extent_sigma: Optional[float] = None,
    seed: Optional[int] = None,
    particles: Optional[int] = None,
    roughening: Optional[float] = None,
    bootstrap: Optional[bool] = None,
    ukf_alpha: Optional[float] = None,
    ukf_beta: Optional[float] = None,
    ukf_kappa: Optional[float] = None,
    max_paths: Optional[int] = None,
    pfa: Optional[float] = None,
    statics: Optional[_Statics] = None,
    delay_reference: Optional[_DelayReference] = None,
    background_time: Optional[float] = None,
    calibration_range: Optional[tuple[float, float]] = None,
    threads: int = 0,
    progress: _Progress = None,
) -> ChannelTrack:
    """``scatterloc cir track``; ``to_dict()`` is its TRACK.json. The front-end keywords are
    ``estimate_recording``'s; None takes the library's default (``study::ChannelRequest``):
    ``filter`` "ekf", ``process_noise`` 1 m^2/s^3, ``association`` "gated", ``sigma``
    "estimator", ``extent_sigma`` 0.2 m, ``seed`` 1 and ``particles`` 1000 (pf only),
    ``ukf_alpha``/``ukf_beta``/``ukf_kappa`` (ukf only), ``roughening``/``bootstrap`` (pf
    only)."""
