"""Detections, JSON lines (issue 40 §3, docs/detections.md) in Python: ``Paths.to_detections()``
is the file ``scatterloc cir estimate --detections-out`` writes (byte for byte),
``read_detections`` reads it back, ``write_detections`` writes what ``scatterloc track
--detections`` reads, and ``sl.track(s, detections)`` is that command's track (bit for bit).
The format is the library's (``formats::Detections``): errors name the line and the field, as
the CLI's do."""

from __future__ import annotations

import numpy as np
import pytest

import scatterloc as sl
from conftest import Cli, assert_bitwise

C = 299_792_458.0


def walk(cli: Cli) -> tuple[sl.Scenario, sl.Recording, sl.Recording]:
    """The sensors2019 layout, a 2 s walk (41 snapshots) and its empty area, saved for the CLI."""
    s = sl.Scenario.preset("sensors2019")
    s.save(str(cli.cwd / "s.json"))
    rec, empty, _truth = sl.simulate_recording(s, dt=0.05, duration=2.0, seed=3)
    sl.write_recording(cli.cwd / "walk.npz", rec)
    sl.write_recording(cli.cwd / "empty.npz", empty)
    return s, rec, empty


def test_to_detections_is_cir_estimate_detections_out(cli: Cli) -> None:
    s, rec, empty = walk(cli)
    cli.run("cir", "estimate", "--scenario", "s.json", "--cir", "walk.npz",
            "--calibration", "empty.npz", "--out", "est.json", "--detections-out", "d.jsonl")
    paths = sl.estimate_recording(s, rec, calibration=empty)
    det = paths.to_detections()
    written = (cli.cwd / "d.jsonl").read_text()
    assert det.to_text() == written
    # One line per snapshot and link (1 transmitter, 4 receivers).
    assert len(written.splitlines()) == 41 * 4
    back = sl.read_detections(cli.cwd / "d.jsonl")
    assert back == det
    assert sl.read_detections(written) == det  # the text itself
    # The long format follows EST.json's estimates, path for path, to the bit.
    est = cli.file("est.json")
    rows = [(s_, p, path) for s_, snap in enumerate(est["estimates"])
            for p, link in enumerate(snap) for path in link]
    assert len(back) == len(rows) == len(paths) > 0
    np.testing.assert_array_equal(back.t, rec.t)
    np.testing.assert_array_equal(back.frame, [r[0] for r in rows])
    np.testing.assert_array_equal(back.links, [[0, r[1]] for r in rows])
    np.testing.assert_array_equal(back.delay, [r[2]["delay_s"] for r in rows])
    np.testing.assert_array_equal(back.sigma.filled(np.nan),
                                  [np.nan if r[2]["sigma_s"] is None else r[2]["sigma_s"]
                                   for r in rows])
    np.testing.assert_array_equal(back.snr_db.filled(np.nan),
                                  [np.nan if r[2]["snr_db"] is None else r[2]["snr_db"]
                                   for r in rows])
    assert back.doppler.mask.all()  # the front end gives no Doppler
    first = back.lines()[0]
    assert list(first) == ["timestamp", "tx", "rx", "unit", "delay", "snr", "sigma"]


def test_python_detections_track_as_the_cli_does(cli: Cli) -> None:
    s, rec, empty = walk(cli)
    det = sl.estimate_recording(s, rec, calibration=empty).to_detections()
    sl.write_detections(cli.cwd / "py.jsonl", det)
    assert (cli.cwd / "py.jsonl").read_text() == det.to_text()
    for q in (None, 0.5):
        flags = [] if q is None else ["--process-noise", str(q)]
        by_cli = cli.json("track", "--scenario", "s.json", "--detections", "py.jsonl", *flags)
        t = sl.track(s, det, process_noise=q)
        assert_bitwise(t.to_dict(), by_cli)
        # The first frame starts the track; the other 40 are its steps, 0.05 s apart.
        assert len(t) == 40
        np.testing.assert_allclose(np.diff(t.t), 0.05, rtol=1e-9)
        assert t.start is not None
    with pytest.raises(sl.ScatterlocError, match="dt: not with detections") as e:
        sl.track(s, det, dt=0.05)
    assert e.value.field == "dt"


def test_detections_from_lines_text_and_metres() -> None:
    lines = [
        {"timestamp": 0.0, "tx": 0, "rx": 1, "delay": [5e-8, 9e-8], "snr": [20.0, None],
         "sigma": [1e-10, None], "doppler": [3.5, -1.0]},
        {"timestamp": 0.0, "link": [0, 2], "unit": "m", "delay": [15.0], "sigma": [0.03]},
        {"timestamp": 0.1, "tx": 0, "rx": 1, "delay": []},
    ]
    det = sl.Detections(lines)
    assert repr(det) == "Detections(frames=2, lines=3, detections=3)"
    np.testing.assert_array_equal(det.t, [0.0, 0.1])
    np.testing.assert_array_equal(det.frame, [0, 0, 0])
    np.testing.assert_array_equal(det.links, [[0, 1], [0, 1], [0, 2]])
    # Metres become seconds: range / c (E1).
    np.testing.assert_array_equal(det.delay, [5e-8, 9e-8, 15.0 / C])
    assert det.sigma.tolist() == [1e-10, None, 0.03 / C]
    assert det.snr_db.tolist() == [20.0, None, None]
    assert det.doppler.tolist() == [3.5, -1.0, None]
    # The text (the library's writer: tx/rx, the unit kept) reads back to the same detections.
    text = det.to_text()
    assert text.splitlines()[1] == (
        '{"timestamp":0.0,"tx":0,"rx":2,"unit":"m","delay":[15.0],"sigma":[0.03]}')
    assert sl.read_detections(text) == det
    commented = "# a comment\n\n" + text
    assert sl.read_detections(commented) == det
    assert det.lines()[2] == {"timestamp": 0.1, "tx": 0, "rx": 1, "unit": "s", "delay": []}
    assert sl.read_detections("") == sl.Detections([])


def test_detection_errors_name_the_line_and_field(cli: Cli) -> None:
    bad = ('{"timestamp": 0, "tx": 0, "rx": 1, "delay": [5e-8]}\n'
           '{"timestamp": 0.1, "tx": 0, "rx": 1, "delay": [5e-8, 6e-8], "snr": [10]}\n')
    (cli.cwd / "bad.jsonl").write_text(bad)
    with pytest.raises(sl.ScatterlocError) as e:
        sl.read_detections(cli.cwd / "bad.jsonl")
    assert str(e.value) == "line 2: snr: 1 values, expected 2 (one per delay)"
    sl.Scenario.preset("sensors2019").save(str(cli.cwd / "s.json"))
    r = cli.run("track", "--scenario", "s.json", "--detections", "bad.jsonl", check=False)
    assert r.returncode == 2 and str(e.value) in r.stderr
    with pytest.raises(sl.ScatterlocError, match=r"line 1: .*unknown field `bogus`"):
        sl.Detections([{"timestamp": 0, "tx": 0, "rx": 1, "delay": [], "bogus": 1}])
    with pytest.raises(ValueError, match=r"lines\[0\]: expected a dict"):
        sl.Detections(["{}"])
    with pytest.raises(ValueError, match=r"lines\[0\]: not a JSON document"):
        sl.Detections([{"timestamp": float("nan"), "tx": 0, "rx": 1, "delay": []}])
    with pytest.raises(FileNotFoundError):
        sl.read_detections(cli.cwd / "missing.jsonl")
    # A link the scenario does not have is named when tracking, with its line.
    s = sl.Scenario.preset("sensors2019")
    far = sl.Detections([{"timestamp": 0.0, "tx": 0, "rx": 1, "delay": [5e-8]},
                         {"timestamp": 0.1, "tx": 3, "rx": 0, "delay": [5e-8]}])
    with pytest.raises(sl.ScatterlocError, match=r"line 2: link: \[3, 0\] \(tx, rx\) is not"):
        sl.track(s, far)
    one = sl.Detections([{"timestamp": 0.0, "tx": 0, "rx": 1, "delay": [5e-8]}])
    with pytest.raises(sl.ScatterlocError, match="at least 2 are needed"):
        sl.track(s, one)
    # `estimate`'s paths have no scenario links: no detections.
    freq = np.linspace(-60e6, 60e6, 64)
    h = np.exp(-2j * np.pi * freq * 40e-9)
    with pytest.raises(ValueError, match="paths: detections need the scenario's links"):
        sl.estimate(h, freq_hz=freq).to_detections()
