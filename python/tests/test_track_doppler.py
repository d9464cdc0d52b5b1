"""`track` with range rates (issue 42 §5; docs/doppler.md D1, D5). A walk's measurements are
made here with the package itself (delays from `Scenario.delays` plus the link budget's sigma,
range rates from `sl.range_rates` plus a CPI's sigma from `sl.sigma_range_rates`, seeded
noise). Checked: the Python track equals the CLI's `scatterloc track` on the same file bit for
bit (states, covariances, NIS, predicted range rates, the whole document) for the EKF, UKF and
PF with the rates' sigma fixed, from the file's CPI, from the caller's CPI (`cpi`, … as
`--doppler --cpi …`) and from the default CPI; the numpy form equals the dict form; the
innovations are the rates minus the predicted rates; `doppler=False` is the delay-only track
(and `--no-doppler`); the velocity RMSE with the rates is lower than without (several seeds);
every bad argument is a ValueError naming it."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import scatterloc as sl
from conftest import assert_bitwise

DT = 0.1
Q = 0.1
STEPS = 60
SIGMAS = [0.12, 0.2, 0.15, 0.3]
P0 = [[0.1, 0, 0, 0], [0, 0.1, 0, 0], [0, 0, 0.5, 0], [0, 0, 0, 0.5]]


def truth() -> np.ndarray:
    """The walk (S, 4): from (4, 2) m at (1.2, 0.4) m/s, its speed in y changing slowly."""
    t = DT * np.arange(1, STEPS + 1)
    vy = 0.4 + 0.5 * np.sin(t / 3.0)
    y = 2.0 + 0.4 * t + 1.5 * (1.0 - np.cos(t / 3.0))
    return np.stack([4.0 + 1.2 * t, y, np.full_like(t, 1.2), vy], axis=1)


def simulate(s: sl.Scenario, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Noisy delays (E8's sigma at the truth) and range rates (the default CPI's sigma at the
    truth), (S, L) each, NaN where a link misses a step."""
    rng = np.random.default_rng(seed)
    x = truth()
    pos = x[:, :2]
    d = s.delays(pos) + rng.standard_normal((STEPS, s.link_count)) * s.sigma_delays(pos)
    rates, _ = sl.range_rates(s, x)
    r = rates + rng.standard_normal(rates.shape) * sl.sigma_range_rates(s, pos)
    d[rng.random(d.shape) < 0.05] = np.nan
    r[rng.random(r.shape) < 0.1] = np.nan
    return d, r


def x0() -> list[float]:
    return [float(v) for v in truth()[0] - [0.12, 0.0, 0.0, 0.0] + [0.2, -0.15, -0.6, 0.5]]


def nulls(a: np.ndarray) -> list[list[float | None]]:
    return [[None if math.isnan(v) else float(v) for v in row] for row in a]


def steps_file(d: np.ndarray, r: np.ndarray | None = None, **extra) -> dict:
    f = {
        "dt_s": DT,
        "process_noise": Q,
        "initial_state": x0(),
        "initial_covariance": P0,
        "steps": nulls(d),
    }
    if r is not None:
        f["range_rates_mps"] = nulls(r)
    f.update(extra)
    return f


FILE_CPI = {"snapshots": 8, "spacing_s": 5e-3, "floor_mps": 0.05}
CALLER_CLI = ["--doppler", "--cpi", "32", "--cpi-spacing-s", "0.001", "--range-rate-floor", "0.2"]
CALLER_PY = {"cpi": 32, "cpi_spacing_s": 1e-3, "range_rate_floor": 0.2}

# (case, the file's sigma fields, the CLI's flags, the Python arguments)
SIGMA_CASES = [
    ("fixed", {"range_rate_sigma_mps": SIGMAS}, [], {}),
    ("file_cpi", {"cpi": FILE_CPI}, [], {}),
    ("caller_cpi", {}, CALLER_CLI, CALLER_PY),
    ("caller_over_file_cpi", {"cpi": FILE_CPI}, CALLER_CLI, CALLER_PY),
    ("default_cpi", {}, [], {}),
]
FILTERS = [
    ("ekf", [], {}),
    ("ukf", ["--ukf-alpha", "0.5"], {"ukf_alpha": 0.5}),
    ("pf", ["--particles", "300", "--seed", "4"], {"particles": 300, "seed": 4}),
]


@pytest.mark.parametrize("case, fields, flags, kwargs", SIGMA_CASES, ids=[c[0] for c in SIGMA_CASES])
@pytest.mark.parametrize("flt, flt_cli, flt_py", FILTERS, ids=[f[0] for f in FILTERS])
def test_track_with_rates_equals_cli(cli, case, fields, flags, kwargs, flt, flt_cli, flt_py):
    s = sl.Scenario.preset("sensors2019")
    cli.write("s.json", s.to_dict())
    d, r = simulate(s, 11)
    f = steps_file(d, r, **fields)
    cli.write("m.json", f)
    doc = cli.json("track", "--scenario", "s.json", "--measurements", "m.json", "--filter", flt, *flt_cli, *flags)
    assert doc["doppler"]["used"] is True
    for source in (json.loads((cli.cwd / "m.json").read_text()), cli.cwd / "m.json", str(cli.cwd / "m.json")):
        t = sl.track(s, source, filter=flt, **flt_py, **kwargs)
        assert_bitwise(t.to_dict(), doc)
    assert t.states.tolist() == doc["states"]
    assert t.covariances.tolist() == doc["covariances"]
    dop = t.doppler
    assert isinstance(dop, sl.TrackDoppler) and dop.used
    assert dop.sigma == doc["doppler"]["sigma"] == ("fixed" if case == "fixed" else "cpi")
    assert dop.cpi == doc["doppler"].get("cpi")
    assert dop.predicted_range_rates.shape == (STEPS, 4)
    assert dop.predicted_range_rates.tolist() == doc["doppler"]["predicted_range_rates_mps"]
    assert_bitwise(dop.to_dict(), doc["doppler"])
    inn = dop.range_rate_innovations
    assert isinstance(inn, np.ma.MaskedArray) and inn.shape == (STEPS, 4)
    assert (inn.mask == np.isnan(r)).all()
    # The innovation is the rate minus the predicted rate (the same IEEE subtraction).
    ok = ~np.isnan(r)
    assert (inn.data[ok] == (r - dop.predicted_range_rates)[ok]).all()
    # Which CPI: the caller's over the file's, the file's over the default.
    if case in ("caller_cpi", "caller_over_file_cpi"):
        assert (dop.cpi["snapshots"], dop.cpi["spacing_s"], dop.cpi["floor_mps"]) == (32, 1e-3, 0.2)
    elif case == "file_cpi":
        assert (dop.cpi["snapshots"], dop.cpi["spacing_s"], dop.cpi["floor_mps"]) == (8, 5e-3, 0.05)
    elif case == "default_cpi":
        assert (dop.cpi["snapshots"], dop.cpi["spacing_s"], dop.cpi["floor_mps"]) == (16, 2.048e-3, 0.1)


@pytest.mark.parametrize("flt, extra", [("ekf", {}), ("ukf", {}), ("pf", {"particles": 200, "seed": 2})])
def test_numpy_form_equals_dict_form(flt, extra):
    s = sl.Scenario.preset("sensors2019")
    d, r = simulate(s, 3)
    kw = dict(dt=DT, process_noise=Q, initial_state=x0(), initial_covariance=P0, filter=flt, **extra)
    for fields, args in (
        ({"range_rate_sigma_mps": SIGMAS}, {"range_rate_sigma": np.array(SIGMAS)}),
        ({"range_rate_sigma_mps": 0.2}, {"range_rate_sigma": 0.2}),
        # The file's CPI and the same CPI as arguments: the same sigma.
        ({"cpi": FILE_CPI}, {"cpi": 8, "cpi_spacing_s": 5e-3, "range_rate_floor": 0.05}),
        ({}, {}),
    ):
        want = sl.track(s, steps_file(d, r, **fields), filter=flt, **extra).to_dict()
        got = sl.track(s, d, range_rates=r, **args, **kw)
        assert_bitwise(got.to_dict(), want)
        # A list of lists reads as the array.
        assert_bitwise(sl.track(s, d, range_rates=r.tolist(), **args, **kw).to_dict(), want)


def test_doppler_false_is_the_delay_only_track(cli):
    s = sl.Scenario.preset("sensors2019")
    cli.write("s.json", s.to_dict())
    d, r = simulate(s, 5)
    plain = steps_file(d)
    cli.write("m.json", steps_file(d, r, range_rate_sigma_mps=SIGMAS))
    for flt, extra in (("ekf", {}), ("ukf", {}), ("pf", {"particles": 200})):
        delay_only = sl.track(s, plain, filter=flt, **extra)
        assert delay_only.doppler is None and "doppler" not in delay_only.to_dict()
        ignored = sl.track(s, cli.cwd / "m.json", doppler=False, filter=flt, **extra)
        doc = ignored.to_dict()
        dop = doc.pop("doppler")
        assert_bitwise(doc, delay_only.to_dict())
        assert dop == {"used": False, "sigma": "fixed"}
        assert not ignored.doppler.used and ignored.doppler.predicted_range_rates is None
        assert ignored.doppler.range_rate_innovations is None
        flags = ["--particles", "200"] if flt == "pf" else []
        want = cli.json("track", "--scenario", "s.json", "--measurements", "m.json", "--no-doppler", "--filter", flt, *flags)
        assert_bitwise(ignored.to_dict(), want)
        # The numpy form too.
        kw = dict(dt=DT, process_noise=Q, initial_state=x0(), initial_covariance=P0, filter=flt, **extra)
        assert_bitwise(sl.track(s, d, range_rates=r, range_rate_sigma=SIGMAS, doppler=False, **kw).to_dict(), want)
        # doppler=True is the default with rates.
        assert_bitwise(
            sl.track(s, d, range_rates=r, range_rate_sigma=SIGMAS, doppler=True, **kw).to_dict(),
            sl.track(s, d, range_rates=r, range_rate_sigma=SIGMAS, **kw).to_dict(),
        )


@pytest.mark.parametrize("flt", ["ekf", "ukf"])
def test_rates_lower_the_velocity_rmse(flt):
    s = sl.Scenario.preset("sensors2019")
    x = truth()
    kw = dict(dt=DT, process_noise=Q, initial_state=x0(), initial_covariance=P0, filter=flt)
    with_rates, without = [], []
    for seed in (1, 2, 3, 4, 5):
        d, r = simulate(s, seed)
        a = sl.track(s, d, range_rates=r, **kw).states
        b = sl.track(s, d, **kw).states
        # After the start-up (the first 10 steps), the velocity error per step.
        with_rates.append(float(np.sqrt(np.mean(np.sum((a[10:, 2:] - x[10:, 2:]) ** 2, axis=1)))))
        without.append(float(np.sqrt(np.mean(np.sum((b[10:, 2:] - x[10:, 2:]) ** 2, axis=1)))))
    print(f"{flt} velocity RMSE, m/s: with rates {with_rates}, delays only {without}")
    for w, wo in zip(with_rates, without):
        assert w < wo


def _args():
    """The base arguments of the numpy form, the delays, the rates and the scenario."""
    s = sl.Scenario.preset("sensors2019")
    d, r = simulate(s, 9)
    kw = dict(dt=DT, process_noise=Q, initial_state=x0(), initial_covariance=P0)
    return s, d, r, kw


def _bad_rates(r: np.ndarray, k: int, p: int, v: float) -> np.ndarray:
    b = r.copy()
    b[k, p] = v
    return b


BAD = [
    # (what, arguments beyond delays (None = the rates r), field)
    ("rates of too many links", lambda r: {"range_rates": r[:, [0, 1, 2, 3, 0]]}, "range_rates"),
    ("rates of too few steps", lambda r: {"range_rates": r[:-1]}, "range_rates"),
    ("rates 1-D", lambda r: {"range_rates": r[0]}, "range_rates"),
    ("an infinite rate", lambda r: {"range_rates": _bad_rates(r, 3, 1, math.inf)}, "range_rates[3][1]"),
    ("a rate out of range", lambda r: {"range_rates": _bad_rates(r, 0, 2, 1e9)}, "range_rates[0][2]"),
    ("complex rates", lambda r: {"range_rates": r.astype(complex)}, "range_rates"),
    ("a negative sigma", lambda r: {"range_rates": r, "range_rate_sigma": -0.1}, "range_rate_sigma"),
    ("a NaN sigma", lambda r: {"range_rates": r, "range_rate_sigma": math.nan}, "range_rate_sigma"),
    ("sigmas of 3 links", lambda r: {"range_rates": r, "range_rate_sigma": [0.1, 0.2, 0.3]}, "range_rate_sigma"),
    ("a bad per-link sigma", lambda r: {"range_rates": r, "range_rate_sigma": [0.1, 0.0, 0.2, 0.3]},
     "range_rate_sigma[1]"),
    ("sigma without rates", lambda r: {"range_rate_sigma": 0.1}, "range_rate_sigma"),
    ("a CPI beside a fixed sigma", lambda r: {"range_rates": r, "range_rate_sigma": 0.1, "cpi": 8}, "cpi"),
    ("no snapshot", lambda r: {"range_rates": r, "cpi": 0}, "cpi.snapshots"),
    ("negative snapshots", lambda r: {"range_rates": r, "cpi": -3}, "cpi.snapshots"),
    ("zero spacing", lambda r: {"range_rates": r, "cpi_spacing_s": 0.0}, "cpi.spacing_s"),
    ("a negative floor", lambda r: {"range_rates": r, "range_rate_floor": -0.1}, "cpi.floor_mps"),
    ("a CPI without rates", lambda r: {"cpi_spacing_s": 1e-3}, "cpi_spacing_s"),
    ("a CPI with doppler=False", lambda r: {"range_rates": r, "doppler": False, "range_rate_floor": 0.2},
     "range_rate_floor"),
    ("doppler=True without rates", lambda r: {"doppler": True}, "doppler"),
    ("doppler=False without rates", lambda r: {"doppler": False}, "doppler"),
]


@pytest.mark.parametrize("what, extra, field", BAD, ids=[b[0] for b in BAD])
def test_bad_argument_is_named(what, extra, field):
    s, d, r, kw = _args()
    with pytest.raises(ValueError, match=field.replace("[", r"\[").replace(".", r"\.")) as e:
        sl.track(s, d, **kw, **extra(r))
    assert e.value.field == field, what


def test_bad_file_and_form_are_named():
    s, d, r, kw = _args()
    f = steps_file(d, r, range_rate_sigma_mps=0.2)
    # The file holds the rates and their sigma: given twice.
    for arg in ({"range_rates": r}, {"range_rate_sigma": 0.2}):
        with pytest.raises(ValueError) as e:
            sl.track(s, f, **arg)
        assert e.value.field == next(iter(arg))
    # A CPI beside the file's fixed sigma (as `--doppler` beside range_rate_sigma_mps).
    with pytest.raises(ValueError) as e:
        sl.track(s, f, cpi=8)
    assert e.value.field == "cpi"
    # The file's own fields as the CLI names them.
    bad = steps_file(d, r)
    bad["range_rates_mps"][0] = bad["range_rates_mps"][0][:3]
    with pytest.raises(ValueError) as e:
        sl.track(s, bad)
    assert e.value.field == "range_rates_mps[0]"
    with pytest.raises(ValueError) as e:
        sl.track(s, steps_file(d, r, range_rate_sigma_mps=0.2, cpi=FILE_CPI))
    assert e.value.field == "cpi"
    with pytest.raises(ValueError) as e:
        sl.track(s, steps_file(d, r, cpi={"snapshots": 0, "spacing_s": 1e-3}))
    assert e.value.field == "cpi.snapshots"
    # Rates with raw estimates: not carried.
    raw = [[np.array([[v, 1.0]]) if not math.isnan(v) else np.zeros((0, 2)) for v in row] for row in d]
    with pytest.raises(ValueError) as e:
        sl.track(s, raw, range_rates=r, **kw)
    assert e.value.field == "range_rates"
