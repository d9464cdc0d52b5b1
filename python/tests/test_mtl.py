"""`mtl_locate` against the CLI's `scatterloc mtl locate` (bit for bit) for the icb, ppp (bound and
exact) and empirical (trained, and a given table) models and Algorithm 1's settings; the result's
arrays against the document; the targets against the closed-form bistatic ranges they were made
from; and bad input named by `ScatterlocError.field`."""

from __future__ import annotations

import math

import numpy as np
import pytest

import scatterloc as sl
from conftest import assert_bitwise

# The network of docs/cli.md "mtl locate": 3 Tx, 3 Rx around a 10 m square.
TX = [[5.0, 10.0], [0.67, 2.5], [9.33, 2.5]]
RX = [[9.33, 7.5], [0.67, 7.5], [5.0, 0.0]]
REGION = (0.0, 10.0, 0.0, 10.0)
TARGETS = np.array([[3.0, 4.0], [6.5, 7.0]])
TRPS = 9


def bistatic(p) -> list[float]:
    """The bistatic range (m) of point ``p`` on each TRP m (Tx m mod 3, Rx m div 3)."""
    tx, rx, p = np.array(TX), np.array(RX), np.asarray(p, dtype=float)
    return [float(np.linalg.norm(p - tx[m % 3]) + np.linalg.norm(p - rx[m // 3])) for m in range(TRPS)]


def make_ranges() -> list[list[float]]:
    """Both targets' exact ranges per TRP, the second target first on odd TRPs (any order is
    allowed), and two clutter ranges."""
    a, b = bistatic(TARGETS[0]), bistatic(TARGETS[1])
    ranges = [[a[m], b[m]] if m % 2 == 0 else [b[m], a[m]] for m in range(TRPS)]
    ranges[2].append(14.3)
    ranges[4].insert(0, 25.0)
    return ranges


RANGES = make_ranges()


def rng_table(seed: int = 7) -> dict:
    """An empirical table (--table) of 2 × 2 cells over the region, counts per node pattern."""
    counts = np.random.default_rng(seed).integers(0, 50, size=(4, 1 << 6))
    return {
        "min_m": [0, 0], "max_m": [10, 10], "nx": 2, "ny": 2, "n_tx": 3, "n_rx": 3,
        "pseudo_count": 0.5, "counts": counts.tolist(),
    }


@pytest.fixture
def files(cli):
    cli.write(
        "n.json",
        {"tx": TX, "rx": RX, "region": {"min_m": [0, 0], "max_m": [10, 10]}, "c_sigma_m": 0.1},
    )
    cli.write("r.json", {"ranges_m": RANGES})
    cli.write("t.json", rng_table())
    return cli


CASES = {
    "icb": ([], {}),
    "icb-p_u": (["--p-u", "0.3"], dict(p_u=0.3)),
    "icb-p_d-p_los": (["--p-d", "0.8", "--p-los", "0.95"], dict(p_d=0.8, p_los=0.95)),
    "ppp": (["--model", "ppp"], dict(model="ppp")),
    "ppp-exact": (["--model", "ppp", "--exact"], dict(model="ppp", exact=True)),
    "ppp-settings": (
        ["--model", "ppp", "--lambda", "0.05", "--diameter", "0.4", "--p-d", "0.8", "--te", "2.5",
         "--tb", "6", "--b-max", "4", "--n-min", "4"],
        dict(model="ppp", lambda_=0.05, diameter=0.4, p_d=0.8, te=2.5, tb=6.0, b_max=4, n_min=4),
    ),
    "empirical-trained": (
        ["--model", "empirical", "--cells", "4", "--scenes", "20", "--seed", "2"],
        dict(model="empirical", cells=4, scenes=20, seed=2),
    ),
    "empirical-trained-lambda": (
        ["--model", "empirical", "--cells", "3", "--scenes", "15", "--lambda", "0.05", "--diameter", "0.5"],
        dict(model="empirical", cells=3, scenes=15, lambda_=0.05, diameter=0.5),
    ),
    "empirical-table": (
        ["--model", "empirical", "--table", "t.json", "--tb", "8"],
        dict(model="empirical", table=rng_table(), tb=8.0),
    ),
    "inf-order": (
        ["--tb", "inf", "--b-max", "inf", "--order", "8,7,6,5,4,3,2,1,0"],
        dict(tb=math.inf, b_max=math.inf, order=[8, 7, 6, 5, 4, 3, 2, 1, 0]),
    ),
    "ppp-inf-order": (
        ["--model", "ppp", "--tb", "inf", "--b-max", "inf", "--order", "4,0,8,1,7,2,6,3,5"],
        dict(model="ppp", tb=float("inf"), b_max=float("inf"), order=[4, 0, 8, 1, 7, 2, 6, 3, 5]),
    ),
    "max-candidates": (["--max-candidates", "100000"], dict(max_candidates=100_000)),
}


def check_result(res: sl.MtlResult, doc: dict, ranges=RANGES, n_min: int = 3) -> None:
    """The arrays against the document, and the matchings against the ranges."""
    k = doc["count"]
    assert len(res) == k == len(doc["targets"])
    assert res.candidates == doc["candidates"]
    assert res.positions.dtype == np.float64 and res.positions.shape == (k, 2)
    assert res.scores.dtype == np.float64 and res.scores.shape == (k,)
    assert res.blocking.dtype == np.float64 and res.blocking.shape == (k,)
    assert res.direct_paths.dtype == np.int64 and res.direct_paths.shape == (k, TRPS)
    for i, t in enumerate(doc["targets"]):
        assert res.positions[i].tolist() == t["position_m"]
        assert res.scores[i] == t["j"] and res.blocking[i] == t["l_b"]
        assert res.direct_paths[i].tolist() == t["g"]
        assert res.matchings[i] == [tuple(m) for m in t["matching"]]
        # g marks the TRPs of the matching, each at most once, at least n_min of them.
        trps = [trp for trp, _ in res.matchings[i]]
        assert sorted(trps) == [m for m in range(TRPS) if t["g"][m]]
        assert len(trps) >= n_min
        assert all(0 <= j < len(ranges[trp]) for trp, j in res.matchings[i])


@pytest.mark.parametrize("case", list(CASES))
def test_mtl_locate_equals_cli(files, case):
    flags, kw = CASES[case]
    doc = files.json("mtl", "locate", "--network", "n.json", "--ranges", "r.json", *flags)
    res = sl.mtl_locate(TX, RX, RANGES, region=REGION, c_sigma=0.1, **kw)
    assert_bitwise(res.to_dict(), doc)
    check_result(res, doc, n_min=kw.get("n_min", 3))
    if kw.get("tb") == math.inf:
        assert doc["t_b"] is None
    # Both targets are found exactly, each with its own range on all 9 TRPs (the ranges are
    # exact, so every ellipse passes through the target).
    for target in (0, 1):
        d = np.linalg.norm(res.positions - TARGETS[target], axis=1)
        i = int(np.argmin(d))
        assert d[i] < 1e-6, (case, res.positions)
        want = sorted((m, RANGES[m].index(bistatic(TARGETS[target])[m])) for m in range(TRPS))
        # The matched ranges are the target's own; with a physical blocking model all 9
        # (the made-up table of "empirical-table" may prefer a partial matching).
        assert set(res.matchings[i]) <= set(want)
        if case != "empirical-table":
            assert sorted(res.matchings[i]) == want
            assert res.direct_paths[i].tolist() == [1] * TRPS


def test_mtl_locate_numpy_inputs_and_file_outputs(files):
    """numpy arrays in; `--out` writes the same document the call returns."""
    out = files.run("mtl", "locate", "--network", "n.json", "--ranges", "r.json", "--model", "ppp", "--out", "o.json")
    res = sl.mtl_locate(np.array(TX), np.array(RX), RANGES, region=REGION, model="ppp")
    assert_bitwise(res.to_dict(), files.file("o.json"))
    assert out.stdout.strip() == '{"count":%d,"out":"o.json"}' % len(res)


def test_mtl_locate_fortran_order_nodes():
    c = sl.mtl_locate(np.ascontiguousarray(TX), np.ascontiguousarray(RX), RANGES, region=REGION)
    f = sl.mtl_locate(np.asfortranarray(TX), np.asfortranarray(RX), RANGES, region=REGION)
    assert_bitwise(f.to_dict(), c.to_dict())


def test_mtl_locate_without_region_and_other_noise(cli):
    cli.write("n.json", {"tx": TX, "rx": RX, "c_sigma_m": 0.05})
    cli.write("r.json", {"ranges_m": RANGES})
    doc = cli.json("mtl", "locate", "--network", "n.json", "--ranges", "r.json", "--te", "4")
    res = sl.mtl_locate(TX, RX, RANGES, c_sigma=0.05, te=4.0)
    assert_bitwise(res.to_dict(), doc)
    check_result(res, doc)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_mtl_locate_noisy_ranges_near_targets(seed):
    """Ranges with noise of cσ = 0.1 m: both targets found within a few σ (several seeds)."""
    rng = np.random.default_rng(seed)
    noisy = [[v + 0.1 * rng.standard_normal() for v in r] for r in RANGES]
    res = sl.mtl_locate(TX, RX, noisy, region=REGION, model="ppp")
    for t in TARGETS:
        assert np.linalg.norm(res.positions - t, axis=1).min() < 0.3


@pytest.mark.parametrize(
    "kw, field",
    [
        (dict(lambda_=0.03), "lambda_"),
        (dict(diameter=0.6), "diameter"),
        (dict(exact=True), "exact"),
        (dict(table=rng_table()), "table"),
        (dict(cells=4), "cells"),
        (dict(scenes=4), "scenes"),
        (dict(seed=1), "seed"),
        (dict(model="ppp", p_u=0.2), "p_u"),
        (dict(model="ppp", p_los=0.9), "p_los"),
        (dict(model="ppp", table=rng_table()), "table"),
        (dict(model="empirical", exact=True), "exact"),
        (dict(model="empirical", table=rng_table(), cells=3), "cells"),
        (dict(model="empirical", table=rng_table(), lambda_=0.1), "lambda_"),
        (dict(p_u=0.2, p_d=0.9), "p_u"),
        (dict(model="foo"), "model"),
        (dict(b_max=1.5), "b_max"),
        (dict(b_max=0), "b_max"),
    ],
)
def test_mtl_locate_settings_errors(kw, field):
    with pytest.raises(sl.ScatterlocError) as e:
        sl.mtl_locate(TX, RX, RANGES, **kw)
    assert isinstance(e.value, ValueError)
    assert e.value.field == field, str(e.value)
    assert str(e.value).startswith(field)


def test_mtl_locate_setting_of_another_model_equals_cli_refusal(files):
    r = files.run("mtl", "locate", "--network", "n.json", "--ranges", "r.json", "--lambda", "0.03", check=False)
    assert r.returncode == 2 and r.stderr.startswith("error: --lambda:")
    with pytest.raises(sl.ScatterlocError) as e:
        sl.mtl_locate(TX, RX, RANGES, model="icb", lambda_=0.03)
    assert e.value.field == "lambda_" and e.value.kind == "InvalidArgument"


@pytest.mark.parametrize(
    "ranges, field, kind",
    [
        (RANGES[:8], "ranges_m", "LengthMismatch"),
        (RANGES + [[5.0]], "ranges_m", "LengthMismatch"),
        ([[-1.0]] + RANGES[1:], "ranges_m[0][0]", "OutOfRange"),
        (RANGES[:3] + [[10.0, -0.5]] + RANGES[4:], "ranges_m[3][1]", "OutOfRange"),
        ([[math.nan]] + RANGES[1:], "ranges_m[0][0]", "NonFinite"),
    ],
)
def test_mtl_locate_range_errors(cli, ranges, field, kind):
    with pytest.raises(sl.ScatterlocError) as e:
        sl.mtl_locate(TX, RX, ranges)
    assert e.value.field == field, str(e.value)
    assert e.value.kind == kind
    assert str(e.value).startswith(field)
    if not any(math.isnan(v) for r in ranges for v in r):
        # The CLI names the same field of the ranges file.
        cli.write("n.json", {"tx": TX, "rx": RX})
        cli.write("r.json", {"ranges_m": ranges})
        r = cli.run("mtl", "locate", "--network", "n.json", "--ranges", "r.json", check=False)
        assert r.returncode == 2
        assert r.stderr.startswith(f"error: --ranges r.json: {field}:"), r.stderr


def test_mtl_locate_ranges_not_lists():
    with pytest.raises(sl.ScatterlocError) as e:
        sl.mtl_locate(TX, RX, 5.0)
    assert e.value.field == "ranges"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.mtl_locate([[0, 0, 0]], RX, RANGES)
    assert e.value.field is not None and e.value.field.startswith("tx")
