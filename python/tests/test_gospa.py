"""GOSPA (alpha = 2, issue 41): ``scatterloc.gospa`` equals Stone Soup's ``GOSPAMetric`` (an
independent implementation: its own cost matrix and assignment) to 1e-9 on random truth and
estimate sets of several seeds, sizes (empty sides included), cut-offs and orders."""

from __future__ import annotations

import datetime

import numpy as np
import pytest
import scatterloc as sl
from stonesoup.metricgenerator.ospametric import GOSPAMetric
from stonesoup.types.state import State

T0 = datetime.datetime(2026, 12, 7)


def stonesoup_gospa(truth: np.ndarray, est: np.ndarray, c: float, p: float) -> dict:
    metric = GOSPAMetric(c=c, p=p)
    states = lambda pts: [State(np.asarray(q, float).reshape(2, 1), timestamp=T0) for q in pts]
    value, _ = metric.compute_gospa_metric(states(est), states(truth))
    return value.value


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_gospa_equals_stone_soup(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for case in range(60):
        n, m = rng.integers(0, 7, size=2)
        c = [0.5, 1.0, 2.0, 5.0][case % 4]
        p = [1.0, 2.0, 3.0][case % 3]
        truth = rng.uniform(0, 4, size=(n, 2))
        est = rng.uniform(0, 4, size=(m, 2))
        got = sl.gospa(truth, est, c=c, p=p)
        if n == m == 0:
            # Stone Soup needs a state to read the time from; two empty sets are at distance 0.
            assert got["distance"] == 0.0 and got["pairs"] == []
            continue
        want = stonesoup_gospa(truth, est, c, p)
        for key in ("distance", "localisation", "missed", "false"):
            assert got[key] == pytest.approx(want[key], rel=1e-9, abs=1e-12), (seed, case, key)
        assert got["missed_count"] + len(got["pairs"]) == n
        assert got["false_count"] + len(got["pairs"]) == m


def test_gospa_errors_are_named() -> None:
    with pytest.raises(sl.ScatterlocError) as e:
        sl.gospa(np.zeros((1, 2)), np.zeros((1, 2)), c=0.0)
    assert e.value.field == "gospa.c"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.gospa(np.array([[np.nan, 0.0]]), np.zeros((1, 2)), c=1.0)
    assert "truth" in e.value.field
