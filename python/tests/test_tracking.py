"""`track` and `calibrate` against the CLI's `track` and `calibrate` (bit for bit) for every
filter and both measurement forms, the arrays' dtypes and shapes, and bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

import scatterloc as sl
from conftest import assert_bitwise

P0 = [[0.1, 0, 0, 0], [0, 0.1, 0, 0], [0, 0, 0.01, 0], [0, 0, 0, 0.01]]


def walk_delays(s: sl.Scenario, seed: int, steps: int = 60, dt: float = 0.1) -> np.ndarray:
    """Noisy delays (E2 with the link budget's sigma) of a straight walk, NaN for a few lost links."""
    rng = np.random.default_rng(seed)
    t = dt * np.arange(1, steps + 1)
    pos = np.stack([4.0 + 1.39 * t, 1.0 + 0.25 * t], axis=1)
    d = s.delays(pos) + rng.standard_normal((steps, s.link_count)) * s.sigma_delays(pos)
    d[rng.random(d.shape) < 0.05] = np.nan
    return d


def steps_file(d: np.ndarray, dt: float, q: float, sigma=None) -> dict:
    f = {
        "dt_s": dt,
        "process_noise": q,
        "initial_state": [4.0, 1.0, 1.39, 0.25],
        "initial_covariance": P0,
        "steps": [[None if np.isnan(v) else float(v) for v in row] for row in d],
    }
    if sigma is not None:
        f["sigma_s"] = sigma
    return f


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_track_steps_equals_cli(cli, seed):
    s = sl.Scenario.preset("sensors2019")
    cli.write("s.json", s.to_dict())
    d = walk_delays(s, seed)
    for sigma in (None, 3.5e-11):
        cli.write("m.json", steps_file(d, 0.1, 0.01, sigma))
        for flt, extra_cli, extra_py in (
            ("ekf", [], {}),
            ("ukf", ["--ukf-alpha", "0.5"], {"ukf_alpha": 0.5}),
            ("pf", ["--particles", "300", "--seed", str(seed)], {"particles": 300, "seed": seed}),
        ):
            doc = cli.json("track", "--scenario", "s.json", "--measurements", "m.json", "--filter", flt, *extra_cli)
            kw = dict(dt=0.1, process_noise=0.01, initial_state=[4.0, 1.0, 1.39, 0.25], initial_covariance=P0, sigma=sigma)
            t = sl.track(s, d, filter=flt, **kw, **extra_py)
            assert_bitwise(t.to_dict(), doc)
            # The same from the file's dict and from its path.
            assert_bitwise(sl.track(s, json.loads((cli.cwd / "m.json").read_text()), filter=flt, **extra_py).to_dict(), doc)
            assert_bitwise(sl.track(s, cli.cwd / "m.json", filter=flt, **extra_py).to_dict(), doc)
            assert t.states.tolist() == doc["states"]
            assert t.covariances.tolist() == doc["covariances"]
            assert t.links_used.tolist() == doc["links_used"]
            assert [None if m else v for v, m in zip(t.nis.data.tolist(), t.nis.mask.tolist())] == doc["nis"]


def test_track_arrays():
    s = sl.Scenario.preset("sensors2019")
    d = walk_delays(s, 5, steps=40)
    d[7] = np.nan  # a step with no link: predict only
    t = sl.track(s, d, dt=0.1, process_noise=0.01, initial_state=[4.0, 1.0, 1.39, 0.25], initial_covariance=P0)
    assert len(t) == 40
    assert t.t.shape == (40,) and t.t.dtype == np.float64
    np.testing.assert_allclose(t.t, 0.1 * np.arange(1, 41))
    assert t.states.shape == (40, 4) and t.covariances.shape == (40, 4, 4)
    assert t.links_used.dtype == np.int64 and t.links_used[7] == 0
    assert isinstance(t.nis, np.ma.MaskedArray) and t.nis.mask[7] and not np.isnan(t.nis.data).any()
    assert t.delays_used is None and t.choices is None and t.static_removed is None and t.start is None
    # Symmetric positive definite covariances.
    np.testing.assert_allclose(t.covariances, np.swapaxes(t.covariances, 1, 2), atol=1e-15)
    assert (np.linalg.eigvalsh(t.covariances) > 0).all()


@pytest.mark.parametrize("seed", [1, 4])
def test_raw_chain_equals_cli(cli, seed):
    s = sl.Scenario.preset("sensors2019")
    cli.write("s.json", s.to_dict())
    cli.run("simulate-walk", "--scenario", "s.json", "--out-dir", "walk", "--duration", "6", "--seed", str(seed))
    cli.run("calibrate", "--scenario", "s.json", "--snapshots", "walk/calibration_snapshots.json", "--out", "cal.json")
    snaps = cli.file("walk/calibration_snapshots.json")["snapshots"]
    cal = sl.calibrate(s, snaps)
    assert_bitwise(cal.to_dict(), cli.file("cal.json"))
    assert len(cal.clusters) == 4 and all(c.shape[1] == 2 for c in cal.clusters)
    cal2 = sl.calibrate(s, snaps, gap=2e-9, min_fraction=0.4, sigma_floor=1e-11)
    cli.run("calibrate", "--scenario", "s.json", "--snapshots", "walk/calibration_snapshots.json",
            "--gap-s", "2e-9", "--min-fraction", "0.4", "--sigma-floor-s", "1e-11", "--out", "cal2.json")
    assert_bitwise(cal2.to_dict(), cli.file("cal2.json"))

    m = cli.file("walk/measurements.json")
    raw = [[np.array(l, dtype=float).reshape(-1, 2) for l in step] for step in m["raw_steps"]]
    init = [np.array(l, dtype=float).reshape(-1, 2) for l in m["initial_snapshot"]]
    for flt, extra_cli, extra_py in (("ekf", [], {}), ("ukf", [], {}), ("pf", ["--particles", "500"], {"particles": 500})):
        for assoc in ("spec", "gated"):
            doc = cli.json("track", "--scenario", "s.json", "--measurements", "walk/measurements.json",
                           "--calibration", "cal.json", "--association", assoc, "--filter", flt, *extra_cli)
            for c in (cal, cal.to_dict(), cli.cwd / "cal.json"):
                t = sl.track(s, raw, dt=m["dt_s"], process_noise=m["process_noise"], initial_snapshot=init,
                             calibration=c, association=assoc, filter=flt, **extra_py)
                assert_bitwise(t.to_dict(), doc)
            assert t.choices == doc["choices"]
            assert t.static_removed.tolist() == doc["static_removed"]
            assert t.delays_used.shape == (len(raw), 4)
            assert [[None if mk else v for v, mk in zip(r, k)] for r, k in
                    zip(t.delays_used.data.tolist(), t.delays_used.mask.tolist())] == doc["delays_used_s"]
            assert t.start == doc["start"]


def test_track_bad_input():
    s = sl.Scenario.preset("sensors2019")
    d = walk_delays(s, 1, steps=5)
    kw = dict(dt=0.1, process_noise=0.01, initial_state=[4.0, 1.0, 1.39, 0.25], initial_covariance=P0)
    for bad, field in (
        (dict(particles=100), "particles"),
        (dict(ukf_alpha=0.5), "ukf_alpha"),
        (dict(seed=3), "seed"),
        (dict(association="gated"), "association"),
    ):
        with pytest.raises(sl.ScatterlocError) as e:
            sl.track(s, d, **kw, **bad)
        assert e.value.field == field
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track(s, d, **kw, filter="kalman")  # type: ignore[arg-type]
    assert e.value.kind == "UnknownFilter"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track(s, d[:, :3], **kw)
    assert e.value.field == "measurements"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track(s, d, dt=0.1, process_noise=0.01, initial_state=[4.0, 1.0, 1.39], initial_covariance=P0)
    assert e.value.field == "initial_state"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track(s, d, dt=-1.0, process_noise=0.01, initial_state=[4.0, 1.0, 1.39, 0.25], initial_covariance=P0)
    assert e.value.field is not None and "dt" in e.value.field
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track(s, d, **kw, filter="pf", particles=0)
    assert e.value.field == "particles"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track(s, {"dt_s": 0.1}, dt=0.1)
    assert e.value.field == "dt"
    bad_p = np.array(P0)
    bad_p[0, 0] = -1
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track(s, d, dt=0.1, process_noise=0.01, initial_state=[4.0, 1.0, 1.39, 0.25], initial_covariance=bad_p)
    assert e.value.kind == "NotPositiveDefinite"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track(s, d, **kw, filter="pf", particles=1000, max_cpu_hours=1e-12)
    assert e.value.kind == "TooLong"
