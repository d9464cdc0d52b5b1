"""scatterloc: locate and track non-cooperative scatterers (people, cars) from bistatic radio
delays, with numpy in and out.

The functions run the same Rust library as the ``scatterloc`` command line and the web page
(PyO3 bindings that only convert types and call its use cases), so a notebook gets the CLI's
numbers bit for bit; ``to_dict()`` on a result gives the document the CLI prints for the same
input. Units are SI: positions in metres, delays in seconds, frequencies in hertz, dB where a
name says so. Bad input raises :class:`ScatterlocError` (a ``ValueError``) whose ``field``
names the input at fault; no output holds NaN (an unbounded CRLB is ``inf``, a missing value is
masked). Long work releases the GIL, runs on all cores, reports ``progress(done, total)`` and
stops on Ctrl-C (``KeyboardInterrupt``).

Scenario and snapshot
    :class:`Scenario`, :func:`crlb`, :func:`crlb_doppler`, :func:`crlb_map`, :func:`locate`
Delay and Doppler (docs/doppler.md)
    :func:`crlb_doppler`, :func:`doppler_map` (the bound over a grid), :func:`range_rates`
    (and their Jacobian), :func:`sigma_range_rates` (a CPI's sigma)
Tracking
    :func:`track` (with range rates: ``Track.doppler``, a :class:`TrackDoppler`),
    :func:`calibrate`, :func:`montecarlo`, :func:`pcrlb`
Planning and multi-target
    :func:`plan`, :func:`mtl_locate`, :func:`gospa` (the GOSPA metric), :func:`track_multi`
    (several people, PMB or GNN), :func:`simulate_people`
Channel recordings (CFR/CIR to delays)
    :class:`Recording`, :func:`read_recording` (``.npz`` or a Wi-Fi CSI file), :func:`read_csi`,
    :func:`write_recording`, :func:`track_stream` (live, frame by frame),
    :func:`simulate_recording`, :func:`estimate`, :func:`estimate_recording`, :func:`cir_track`
Detections (JSON lines, docs/detections.md)
    :class:`Detections`, :func:`read_detections`, :func:`write_detections`,
    ``Paths.to_detections()``; :func:`track` takes them
Stone Soup
    :mod:`scatterloc.stonesoup` (``BistaticDelayModel``, ``BistaticDelayDopplerModel``; needs
    ``pip install scatterloc[stonesoup]``)

Docs: ``docs/python.md`` in the repository.
"""

from ._scatterloc import (
    ChannelTrack,
    Crlb,
    CrlbMap,
    Curves,
    Detections,
    Fix,
    MtlResult,
    MultiTrack,
    Paths,
    Plan,
    Recording,
    Scenario,
    ScatterlocError,
    StaticCalibration,
    StudyResult,
    Track,
    TrackDoppler,
    TrackStream,
    __version__,
    calibrate,
    cir_track,
    crlb,
    crlb_doppler,
    crlb_map,
    doppler_map,
    estimate,
    estimate_recording,
    gospa,
    locate,
    montecarlo,
    mtl_locate,
    pcrlb,
    plan,
    read_csi,
    read_detections,
    range_rates,
    read_recording,
    sigma_range_rates,
    simulate_people,
    simulate_recording,
    track,
    track_multi,
    track_stream,
    write_detections,
    write_recording,
)

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
    "Scenario",
    "ScatterlocError",
    "StaticCalibration",
    "StudyResult",
    "Track",
    "TrackDoppler",
    "TrackStream",
    "__version__",
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
