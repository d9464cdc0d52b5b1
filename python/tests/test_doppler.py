"""Delay and Doppler in Python (issue 42 §1, docs/doppler.md): `crlb_doppler` against the CLI's
`crlb --doppler` (bit for bit), the CPI's delay-only bound against `crlb` over √N; `doppler_map`
against `crlb-map --doppler --quantity position|velocity` (bit for bit, two presets) and against
`crlb_doppler` per cell; `range_rates` against central differences of the path length (D1) and
of itself (D3) and the closed form; `sigma_range_rates` against D5's closed form and
`crlb_doppler`; bad arguments named."""

from __future__ import annotations

import math

import numpy as np
import pytest

import scatterloc as sl
from conftest import assert_bitwise

CASES = [
    ((10.0, 0.0), (1.0, 0.5), 16, 2.048e-3, 0.1),
    ((-3.0, 7.5), (0.0, 0.0), 4, 0.05, 0.0),
    ((20.0, 10.0), (-1.2, 0.3), 64, 1e-3, 0.3),
]


def test_crlb_doppler_equals_cli(cli):
    s = sl.Scenario.preset("sensors2019")
    cli.write("s.json", s.to_dict())
    for (x, y), (vx, vy), n, t, floor in CASES:
        got = sl.crlb_doppler(s, (x, y), np.array([vx, vy]), cpi=n, cpi_spacing_s=t, range_rate_floor=floor)
        doc = cli.json(
            "crlb", "--scenario", "s.json", "--at", f"{x!r},{y!r}", "--doppler",
            "--velocity", f"{vx!r},{vy!r}", "--cpi", str(n), "--cpi-spacing-s", repr(t),
            "--range-rate-floor", repr(floor),
        )
        assert_bitwise(got, doc["doppler"])
        one = sl.crlb(s, (x, y)).rmse
        assert math.isclose(got["delay_only_position_rmse_m"] * math.sqrt(n), one, rel_tol=1e-12)
        assert got["position_rmse_m"] <= got["delay_only_position_rmse_m"] * (1 + 1e-12)
        assert got["velocity_rmse_mps"] > 0


def test_crlb_doppler_defaults_and_unbounded():
    s = sl.Scenario.preset("sensors2019")
    d = sl.crlb_doppler(s, (10.0, 0.0))
    assert d["cpi"]["snapshots"] == 16 and d["cpi"]["spacing_s"] == 2.048e-3
    assert d["cpi"]["floor_mps"] == 0.1 and d["velocity_mps"] == [0.0, 0.0]
    one = sl.crlb_doppler(s, (10.0, 0.0), cpi=1)
    assert one["velocity_rmse_mps"] is None
    assert all(l["sigma_range_rate_mps"] is None for l in one["links"])


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"cpi": 0}, "cpi.snapshots"),
        ({"cpi_spacing_s": 0.0}, "cpi.spacing_s"),
        ({"cpi_spacing_s": float("nan")}, "cpi.spacing_s"),
        ({"range_rate_floor": -1.0}, "cpi.floor_mps"),
    ],
)
def test_bad_cpi_is_named(kwargs, field):
    with pytest.raises(ValueError, match=field.replace(".", r"\.")):
        sl.crlb_doppler(sl.Scenario.preset("sensors2019"), (10.0, 0.0), **kwargs)


def test_bad_velocity_is_named():
    with pytest.raises(ValueError, match="velocity_mps"):
        sl.crlb_doppler(sl.Scenario.preset("sensors2019"), (10.0, 0.0), (1.0, 2.0, 3.0))


# --------------------------------------------------------------------------------------------
# doppler_map: the bound with Doppler over a grid, against `crlb-map --doppler`

C = 299_792_458.0

# (preset, nx, ny, window, velocity, cpi, spacing, floor)
MAP_CASES = [
    ("sensors2019", 23, 17, None, (1.0, 0.5), 16, 2.048e-3, 0.1),
    ("sensors2019", 12, 9, (-2.0, 14.0, -3.0, 11.0), (0.0, 0.0), 4, 0.05, 0.0),
    ("iclgnss2019", 19, 11, None, (-1.2, 0.3), 64, 1e-3, 0.3),
    ("iclgnss2019", 8, 6, (-12.0, 3.0, -2.0, 12.0), (0.4, -2.0), 2, 0.01, 0.05),
]


def heights_scenario() -> sl.Scenario:
    """sensors2019 with node and target heights (3-D paths: D1's unit vectors are the
    horizontal parts of 3-D ones)."""
    d = sl.Scenario.preset("sensors2019").to_dict()
    d["transmitters"][0]["height_m"] = 2.5
    for i, r in enumerate(d["receivers"]):
        r["height_m"] = 0.8 + 0.4 * i
    d["target"]["height_m"] = 1.1
    return sl.Scenario(d)


def cli_map(cli, s, nx, ny, window, v, n, t, floor, quantity):
    cli.write("s.json", s.to_dict())
    args = ["crlb-map", "--scenario", "s.json", "--out", "map.json", "--nx", str(nx), "--ny", str(ny)]
    if window is not None:
        for flag, val in zip(("--x-min", "--x-max", "--y-min", "--y-max"), window):
            args += [flag, repr(val)]
    args += [
        "--doppler", "--velocity", f"{v[0]!r},{v[1]!r}", "--cpi", str(n),
        "--cpi-spacing-s", repr(t), "--range-rate-floor", repr(floor), "--quantity", quantity,
    ]
    cli.run(*args)
    return cli.file("map.json")


@pytest.mark.parametrize("quantity", ["position", "velocity"])
@pytest.mark.parametrize("case", MAP_CASES, ids=[f"{c[0]}-{c[1]}x{c[2]}-N{c[5]}" for c in MAP_CASES])
def test_doppler_map_equals_cli(cli, case, quantity):
    name, nx, ny, window, v, n, t, floor = case
    s = sl.Scenario.preset(name)
    got = sl.doppler_map(
        s, nx, ny, window, velocity_mps=v, cpi=n, cpi_spacing_s=t, range_rate_floor=floor,
        quantity=quantity,
    )
    assert isinstance(got, np.ndarray) and got.dtype == np.float64 and got.shape == (ny, nx)
    assert not np.isnan(got).any()
    doc = cli_map(cli, s, nx, ny, window, v, n, t, floor, quantity)
    key = "velocity_rmse_bound_mps" if quantity == "velocity" else "rmse_bound_m"
    other = "rmse_bound_m" if quantity == "velocity" else "velocity_rmse_bound_mps"
    assert key in doc and other not in doc
    # The CLI writes an unbounded cell as null; the package as inf.
    want = [[math.inf if c is None else c for c in row] for row in doc[key]]
    assert_bitwise(got.tolist(), want)
    # Each cell is `crlb_doppler`'s bound at the cell centre (the CLI's x_m, y_m), bit for bit.
    field = "velocity_rmse_mps" if quantity == "velocity" else "position_rmse_m"
    for j, i in [(0, 0), (ny - 1, nx - 1), (ny // 2, nx // 3)]:
        d = sl.crlb_doppler(
            s, (doc["x_m"][i], doc["y_m"][j]), v, cpi=n, cpi_spacing_s=t, range_rate_floor=floor
        )
        cell = math.inf if d[field] is None else d[field]
        assert cell.hex() == float(got[j, i]).hex()


def test_doppler_map_defaults_and_the_delay_only_bound():
    """Defaults are the CLI's (velocity 0, N = 16, 2.048 ms, 0.1 m/s, position, the scenario's
    area); the position bound with range rates is at most the CPI's delays alone
    (`crlb_map` over sqrt(N), D7's first term)."""
    s = sl.Scenario.preset("sensors2019")
    m = sl.doppler_map(s, 20, 16)
    explicit = sl.doppler_map(
        s, 20, 16, s.area, velocity_mps=(0.0, 0.0), cpi=16, cpi_spacing_s=2.048e-3,
        range_rate_floor=0.1, quantity="position",
    )
    np.testing.assert_array_equal(m, explicit)
    delay_only = sl.crlb_map(s, 20, 16).rmse / math.sqrt(16)
    ok = np.isfinite(delay_only)
    assert ok.sum() > 300
    assert np.isfinite(m[ok]).all()
    assert (m[ok] <= delay_only[ok] * (1 + 1e-12)).all()


def test_doppler_map_one_snapshot_is_unbounded(cli):
    """One snapshot measures no range rate: the 4x4 information is singular in every cell, so
    both maps are inf (the CLI's null), never NaN."""
    s = sl.Scenario.preset("sensors2019")
    for quantity in ("position", "velocity"):
        got = sl.doppler_map(s, 6, 5, cpi=1, quantity=quantity)
        assert np.isposinf(got).all()
        doc = cli_map(cli, s, 6, 5, None, (0.0, 0.0), 1, 2.048e-3, 0.1, quantity)
        key = "velocity_rmse_bound_mps" if quantity == "velocity" else "rmse_bound_m"
        assert all(c is None for row in doc[key] for c in row)


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"quantity": "speed"}, "quantity"),
        ({"cpi": 0}, "cpi.snapshots"),
        ({"cpi": -2}, "cpi.snapshots"),
        ({"cpi": (1 << 20) + 1}, "cpi.snapshots"),
        ({"cpi_spacing_s": 0.0}, "cpi.spacing_s"),
        ({"cpi_spacing_s": float("inf")}, "cpi.spacing_s"),
        ({"range_rate_floor": -0.1}, "cpi.floor_mps"),
        ({"range_rate_floor": float("nan")}, "cpi.floor_mps"),
        ({"velocity_mps": (float("nan"), 0.0)}, "velocity_mps[0]"),
        ({"velocity_mps": (0.0, 2e6)}, "velocity_mps[1]"),
        ({"velocity_mps": (1.0, 2.0, 3.0)}, "velocity_mps"),
        ({"nx": 1}, "nx"),
        ({"ny": -3}, "ny"),
        ({"nx": 4096, "ny": 4096}, "nx*ny"),
        ({"window": (5.0, 1.0, 0.0, 1.0)}, None),
    ],
)
def test_doppler_map_bad_arguments_are_named(kwargs, field):
    args = {"nx": 8, "ny": 8, **kwargs}
    with pytest.raises(sl.ScatterlocError) as e:
        sl.doppler_map(sl.Scenario.preset("sensors2019"), **args)
    if field is not None:
        assert e.value.field == field, (e.value.field, str(e.value))
    else:
        assert e.value.field  # the core names the area's side


# --------------------------------------------------------------------------------------------
# range_rates and sigma_range_rates (D1, D3, D5)


def ranges(s: sl.Scenario, xy: np.ndarray) -> np.ndarray:
    """Bistatic ranges c tau (m) per link at points (..., 2)."""
    return C * s.delays(xy)


@pytest.mark.parametrize("scenario", ["sensors2019", "iclgnss2019", "heights"])
def test_range_rates_are_the_range_derivative(scenario):
    """D1: the range rate is d/dt of the path length along v (central differences, 1e-7
    relative); D3: the Jacobian equals central differences of the range rates (1e-6); and with
    the nodes in the target plane, the closed form (u_T + u_R).v of 2-D unit vectors."""
    s = heights_scenario() if scenario == "heights" else sl.Scenario.preset(scenario)
    x0, x1, y0, y1 = s.area
    rng = np.random.default_rng(42)
    n = 40
    states = np.stack(
        [rng.uniform(x0, x1, n), rng.uniform(y0, y1, n), rng.normal(0, 1.5, n), rng.normal(0, 1.5, n)],
        axis=1,
    )
    rates, jac = sl.range_rates(s, states)
    L = s.link_count
    assert rates.shape == (n, L) and jac.shape == (n, L, 4)
    # A small step: some states are within a metre of a node, where the third derivatives are
    # large; rounding of c tau (30 m to 2e-16) over 2 h stays below 1e-9 m/s.
    h = 1e-6
    for k in range(n):
        r, v = states[k, :2], states[k, 2:]
        fd = (ranges(s, r + h * v) - ranges(s, r - h * v)) / (2 * h)
        np.testing.assert_allclose(rates[k], fd, rtol=1e-7, atol=1e-9)
        num = np.zeros((L, 4))
        for c in range(4):
            e = np.zeros(4)
            e[c] = h
            num[:, c] = (sl.range_rates(s, states[k] + e)[0] - sl.range_rates(s, states[k] - e)[0]) / (2 * h)
        np.testing.assert_allclose(jac[k], num, rtol=1e-6, atol=1e-9)
        # d rdot / d v = c grad tau (D3 = E3 times c).
        np.testing.assert_allclose(jac[k][:, 2:], C * s.delay_jacobian(r), rtol=1e-12, atol=1e-15)
        if scenario != "heights":
            tx, rx = s.transmitters, s.receivers
            want = []
            for i, j in s.link_indices:
                ut = (r - tx[i]) / np.linalg.norm(r - tx[i])
                ur = (r - rx[j]) / np.linalg.norm(r - rx[j])
                want.append((ut + ur) @ v)
            np.testing.assert_allclose(rates[k], want, rtol=1e-12, atol=1e-14)


def test_range_rates_shapes_and_crlb_doppler():
    """One state (4,) gives (L,) and (L, 4); any leading shape is kept; the rates are
    `crlb_doppler`'s per-link `range_rate_mps` bit for bit."""
    s = sl.Scenario.preset("sensors2019")
    x = np.array([10.0, 0.0, 1.0, 0.5])
    r, j = sl.range_rates(s, x)
    assert r.shape == (4,) and j.shape == (4, 4)
    doc = sl.crlb_doppler(s, x[:2], x[2:])
    assert_bitwise(r.tolist(), [link["range_rate_mps"] for link in doc["links"]])
    grid = np.tile(x, (2, 3, 1))
    r2, j2 = sl.range_rates(s, grid)
    assert r2.shape == (2, 3, 4) and j2.shape == (2, 3, 4, 4)
    np.testing.assert_array_equal(r2[1, 2], r)
    np.testing.assert_array_equal(j2[0, 1], j)
    # A list works; a zero velocity has zero range rates and a zero position gradient.
    r0, j0 = sl.range_rates(s, [3.0, 4.0, 0.0, 0.0])
    assert (r0 == 0).all() and (j0[:, :2] == 0).all()


@pytest.mark.parametrize(
    "states, field",
    [
        (np.zeros(3), "states"),
        (np.zeros((2, 5)), "states"),
        (np.array([np.nan, 0.0, 0.0, 0.0]), "states[0]"),
        (np.array([0.0, 0.0, 0.0, 2e6]), "states[3]"),
        (np.array([[0.0, 0.0, 0.0, 0.0], [0.0, 2e7, 0.0, 0.0]]), "states[1][1]"),
        (np.array([1.0, 2.0, 3.0, 4.0 + 1j]), "states"),
        (np.broadcast_to(np.zeros(4), (10**9, 4)), "states"),
    ],
)
def test_range_rates_bad_states_are_named(states, field):
    with pytest.raises(sl.ScatterlocError) as e:
        sl.range_rates(sl.Scenario.preset("sensors2019"), states)
    assert e.value.field == field, (e.value.field, str(e.value))


@pytest.mark.parametrize("n, t, floor", [(16, 2.048e-3, 0.1), (4, 0.05, 0.0), (64, 1e-3, 0.3), (1, 1e-3, 0.1)])
def test_sigma_range_rates_d5(n, t, floor):
    """D5 in closed form from the link's SNR (to 1e-12: the SNR passes through dB), and
    `crlb_doppler`'s per-link `sigma_range_rate_mps` bit for bit (inf where it is null)."""
    s = sl.Scenario.preset("sensors2019")
    pts = np.array([[10.0, 0.0], [-3.0, 7.5], [20.0, 10.0]])
    sig = sl.sigma_range_rates(s, pts, cpi=n, cpi_spacing_s=t, range_rate_floor=floor)
    assert sig.shape == (3, 4)
    lam = C / s.carrier_hz
    rho = 10 ** (s.snr_db(pts) / 10)
    f = (2 / 3) * math.pi**2 * rho * t**2 * n * (n * n - 1)
    if n == 1:
        assert np.isposinf(sig).all()
    else:
        np.testing.assert_allclose(sig, np.sqrt(lam**2 / f + floor**2), rtol=1e-12)
    for k, p in enumerate(pts):
        doc = sl.crlb_doppler(s, p, cpi=n, cpi_spacing_s=t, range_rate_floor=floor)
        want = [math.inf if l["sigma_range_rate_mps"] is None else l["sigma_range_rate_mps"] for l in doc["links"]]
        assert_bitwise(sig[k].tolist(), want)
    one = sl.sigma_range_rates(s, pts[0], cpi=n, cpi_spacing_s=t, range_rate_floor=floor)
    assert one.shape == (4,)
    np.testing.assert_array_equal(one, sig[0])


def test_sigma_range_rates_bad_arguments_are_named():
    s = sl.Scenario.preset("sensors2019")
    for kw, field in [({"cpi": 0}, "cpi.snapshots"), ({"cpi": -1}, "cpi.snapshots"),
                      ({"cpi_spacing_s": -1.0}, "cpi.spacing_s"), ({"range_rate_floor": -1.0}, "cpi.floor_mps")]:
        with pytest.raises(sl.ScatterlocError) as e:
            sl.sigma_range_rates(s, (1.0, 2.0), **kw)
        assert e.value.field == field
    with pytest.raises(sl.ScatterlocError) as e:
        sl.sigma_range_rates(s, (np.nan, 2.0))
    assert e.value.field == "points[0]"
