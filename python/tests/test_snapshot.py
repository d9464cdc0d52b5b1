"""`crlb`, `crlb_map` and `locate` against the CLI's `crlb`, `crlb-map` and `locate` (bit for
bit), closed forms and the arrays' dtypes and shapes."""

from __future__ import annotations

import math

import numpy as np
import pytest

import scatterloc as sl
from conftest import assert_bitwise

POINTS = [(10.0, 0.0), (4.0, 1.0), (-5.0, 12.0), (0.0, 0.0), (25.0, -8.0), (-7.5, 26.0)]


def one_link_scenario() -> sl.Scenario:
    """A scenario whose single link leaves every point unbounded (a rank-1 Fisher matrix)."""
    d = sl.Scenario.preset("sensors2019").to_dict()
    d["links"] = [["Tx", "Rx1"]]
    return sl.Scenario(d)


def test_crlb_equals_cli(cli):
    for s in (sl.Scenario.preset("sensors2019"), sl.Scenario.preset("iclgnss2019"), one_link_scenario()):
        cli.write("s.json", s.to_dict())
        c = sl.crlb(s, POINTS)
        docs = c.to_dicts()
        for k, (x, y) in enumerate(POINTS):
            doc = cli.json("crlb", "--scenario", "s.json", "--at", f"{x!r},{y!r}")
            assert_bitwise(docs[k], doc)
            if doc["bounded"]:
                assert c.sigma_x[k] == doc["sigma_x_m"]
                assert c.sigma_y[k] == doc["sigma_y_m"]
                assert c.rmse[k] == doc["rmse_bound_m"]
                assert c.covariance[k].tolist() == doc["covariance_m2"]
            else:
                assert math.isinf(c.rmse[k]) and math.isinf(c.sigma_x[k]) and math.isinf(c.sigma_y[k])
                assert np.isinf(c.covariance[k]).all()
            assert bool(c.bounded[k]) == doc["bounded"]
            assert c.fisher[k].tolist() == doc["fim_per_m2"]
            assert c.snr_db[k].tolist() == [l["snr_db"] for l in doc["links"]]
            assert c.sigma_delay[k].tolist() == [l["sigma_delay_s"] for l in doc["links"]]
            assert c.delay[k].tolist() == [l["delay_s"] for l in doc["links"]]


def test_crlb_shapes_and_closed_form():
    s = sl.Scenario.preset("sensors2019")
    grid = np.stack(np.meshgrid(np.linspace(-5, 25, 7), np.linspace(-8, 20, 5)), axis=-1)
    c = sl.crlb(s, grid)
    assert c.rmse.shape == (5, 7) and c.rmse.dtype == np.float64
    assert c.bounded.shape == (5, 7) and c.bounded.dtype == np.bool_
    assert c.fisher.shape == (5, 7, 2, 2) and c.covariance.shape == (5, 7, 2, 2)
    assert c.snr_db.shape == (5, 7, 4) and c.points.shape == (5, 7, 2)
    # S18-S24: the covariance is F^-1, rmse = sqrt(sx^2 + sy^2).
    np.testing.assert_allclose(c.covariance @ c.fisher, np.broadcast_to(np.eye(2), (5, 7, 2, 2)), atol=1e-9)
    np.testing.assert_allclose(c.rmse, np.hypot(c.sigma_x, c.sigma_y), rtol=1e-15)
    one = sl.crlb(s, [4.0, 1.0])
    assert isinstance(one.rmse, float) and isinstance(one.bounded, bool)
    e = c.ellipses()
    assert e.shape == (5, 7, 3) and not e.mask.any()
    # The ellipse's axes are the covariance's eigenvalues' square roots.
    w = np.linalg.eigvalsh(c.covariance)
    np.testing.assert_allclose(e[..., 0], np.sqrt(w[..., 1]), rtol=1e-9)
    np.testing.assert_allclose(e[..., 1], np.sqrt(w[..., 0]), rtol=1e-9)
    u = sl.crlb(one_link_scenario(), [[4.0, 1.0]])
    assert u.ellipses().mask.all() and not np.isnan(u.ellipses().data).any()


def test_crlb_map_equals_cli(cli):
    for s, (nx, ny), window in (
        (sl.Scenario.preset("sensors2019"), (64, 48), None),
        (sl.Scenario.preset("sensors2019"), (200, 150), (0.0, 10.0, -2.0, 5.0)),
        (sl.Scenario.preset("iclgnss2019"), (33, 17), None),
        (one_link_scenario(), (16, 16), None),
    ):
        cli.write("s.json", s.to_dict())
        args = ["crlb-map", "--scenario", "s.json", "--nx", str(nx), "--ny", str(ny), "--out", "m.json"]
        if window:
            args += [f"--x-min={window[0]!r}", f"--x-max={window[1]!r}", f"--y-min={window[2]!r}", f"--y-max={window[3]!r}"]
        cli.run(*args)
        doc = cli.file("m.json")
        m = sl.crlb_map(s, nx, ny, window)
        assert_bitwise(m.to_dict(), doc)
        assert m.rmse.shape == (ny, nx) and m.rmse.dtype == np.float64
        assert m.x.shape == (nx,) and m.y.shape == (ny,)
        assert not np.isnan(m.rmse).any()
        assert m.extent == (window or s.area)


def test_crlb_map_threads_and_components():
    s = sl.Scenario.preset("sensors2019")
    a = sl.crlb_map(s, 256, 256, threads=1)
    b = sl.crlb_map(s, 256, 256, threads=2)
    c = sl.crlb_map(s, 256, 256)
    assert a.rmse.tobytes() == b.rmse.tobytes() == c.rmse.tobytes()
    assert a.sigma_x is None and a.sigma_y is None
    m = sl.crlb_map(s, 40, 30, components=True)
    xx, yy = np.meshgrid(m.x, m.y)
    p = sl.crlb(s, np.stack([xx, yy], axis=-1))
    assert m.sigma_x.tobytes() == p.sigma_x.tobytes()
    assert m.sigma_y.tobytes() == p.sigma_y.tobytes()
    # The map kernel (this CPU's fastest path: FMA, estimates; within 64·ε·κ·(Γ + S + G) of the
    # core's, tests/library/map_kernel.rs) against the exact point bound.
    np.testing.assert_allclose(m.rmse, p.rmse, rtol=1e-9)


def test_crlb_map_errors():
    s = sl.Scenario.preset("sensors2019")
    with pytest.raises(sl.ScatterlocError) as e:
        sl.crlb_map(s, 5000, 10)
    assert e.value.field == "nx" and e.value.kind == "SizeLimit"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.crlb_map(s, 10, 10, (5.0, 1.0, 0.0, 1.0))
    assert e.value.kind == "InvertedArea"
    with pytest.raises(sl.ScatterlocError):
        sl.crlb_map(s, 10, 10, (float("nan"), 1.0, 0.0, 1.0))
    with pytest.raises(OverflowError):
        sl.crlb_map(s, -1, 10)


def delays_file(delays, sigma, initial=None):
    d = {"delays_s": [None if math.isnan(v) else float(v) for v in delays], "sigma_s": sigma}
    if initial is not None:
        d["initial_m"] = list(initial)
    return d


def test_locate_equals_cli(cli):
    s = sl.Scenario.preset("sensors2019")
    cli.write("s.json", s.to_dict())
    rng = np.random.default_rng(7)
    cases = 0
    for seed in range(4):
        truth = rng.uniform([-5, -8], [28, 24])
        sig = s.sigma_delays(truth)
        d = s.delays(truth) + rng.standard_normal(4) * sig
        for initial in (None, truth + [2.0, -2.0]):
            for sigma in (3.5e-11, sig.tolist()):
                for missing in (None, seed % 4):
                    dd = d.copy()
                    if missing is not None:
                        dd[missing] = np.nan
                    f = sl.locate(s, dd, sigma, initial=initial)
                    cli.write("d.json", delays_file(dd, sigma, initial))
                    doc = cli.json("locate", "--scenario", "s.json", "--delays", "d.json")
                    assert_bitwise(f.to_dict(), doc)
                    assert f.position.tolist() == doc["position_m"]
                    assert f.termination == doc["termination"] and f.converged == doc["converged"]
                    assert f.links_used == doc["links_used"] and f.iterations == doc["iterations"]
                    if doc["covariance_m2"] is not None:
                        assert f.covariance.tolist() == doc["covariance_m2"]
                    cases += 1
    assert cases == 32


def test_locate_noise_free_and_errors():
    s = sl.Scenario.preset("sensors2019")
    truth = np.array([4.0, 1.0])
    f = sl.locate(s, s.delays(truth), 3.5e-11, initial=[6.0, 3.0])
    assert f.converged and np.allclose(f.position, truth, atol=1e-9)
    assert f.position.dtype == np.float64 and f.covariance.shape == (2, 2)
    with pytest.raises(sl.ScatterlocError) as e:
        sl.locate(s, s.delays(truth)[:3], 3.5e-11)
    assert e.value.field == "delays"
    d = s.delays(truth)
    d[:2] = np.nan
    with pytest.raises(sl.ScatterlocError) as e:
        sl.locate(s, d, 3.5e-11)
    assert e.value.kind == "TooFewLinks"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.locate(s, -s.delays(truth), 3.5e-11)
    assert e.value.kind == "InvalidDelay"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.locate(s, s.delays(truth), 0.0)
    assert e.value.field == "sigma_s" and e.value.kind == "NotPositive"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.locate(s, s.delays(truth), [1e-10, 1e-10, -1.0, 1e-10])
    assert e.value.kind == "InvalidSigma"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.locate(s, s.delays(truth), [1e-10, 1e-10])
    assert e.value.kind == "LengthMismatch"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.locate(s, s.delays(truth), 1e-10, initial=[float("inf"), 0.0])
    assert e.value.field == "initial[0]"
    # Lists, ints and float32 are accepted and converted.
    g = sl.locate(s, s.delays(truth).tolist(), 3.5e-11, initial=[6, 3])
    h = sl.locate(s, s.delays(truth).astype(np.float64)[::-1][::-1], 3.5e-11, initial=(6.0, 3.0))
    assert g.to_dict() == f.to_dict() == h.to_dict()
