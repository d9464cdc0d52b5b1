"""`crlb_doppler` (issue 42 §1) against the CLI's `crlb --doppler` (bit for bit), the CPI's
delay-only bound against `crlb` over √N, and bad CPI settings named."""

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
