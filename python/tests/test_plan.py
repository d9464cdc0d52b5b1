"""`plan` against the CLI's `scatterloc plan --out plan.json` (bit for bit) for several objectives,
moved-node sets and constraints; the `Plan` attributes against plan.json and against the CRLB
objective recomputed from `crlb` at the ROI's cell centres; the progress callback; and bad input
named by `ScatterlocError.field`."""

from __future__ import annotations

import numpy as np
import pytest

import scatterloc as sl
from conftest import assert_bitwise

AREA = (-7.5, 30.0, -10.0, 26.0)  # sensors2019's area_m
ROOMS = [
    [[-7.5, -10.0], [10.0, -10.0], [10.0, 26.0], [-7.5, 26.0]],
    [[20.0, 0.0], [30.0, 0.0], [25.0, 20.0]],
]


def flag(v) -> str:
    return ",".join(repr(float(x)) for x in v)


# (CLI flags, Python keyword arguments) of each case; budgets ≤ 1000.
CASES = {
    "p90-rx": (
        ["--move", "rx", "--objective", "p90", f"--roi={flag(AREA)}", "--budget", "300", "--grid", "16"],
        dict(move="rx", objective="p90", roi=AREA, budget=300, grid=16),
    ),
    "mean-tx-boresight": (
        ["--move", "tx-boresight", "--objective", "mean", "--roi=0,20,0,20", "--budget", "300", "--grid", "24"],
        dict(move="tx-boresight", objective="mean", roi=(0, 20, 0, 20), budget=300, grid=24),
    ),
    "coverage-names-allowed-spacing": (
        [
            "--move", "Tx,Rx2", "--objective", "coverage:0.1", f"--roi={flag(AREA)}",
            "--bounds=-7.5,30,-10,26", "--allowed", "rooms.json", "--min-spacing", "2",
            "--budget", "400", "--grid", "20", "--seed", "3",
        ],
        dict(
            move="Tx,Rx2", objective="coverage:0.1", roi=AREA, bounds=(-7.5, 30, -10, 26),
            allowed=[np.array(r) for r in ROOMS], min_spacing=2.0, budget=400, grid=20, seed=3,
        ),
    ),
    "max-all-bounds": (
        [
            "--move", "all", "--objective", "max", "--roi=0,20,-5,15", "--bounds=-5,25,-8,20",
            "--min-spacing", "1.5", "--budget", "500", "--grid", "12", "--seed", "7",
        ],
        dict(
            move="all", objective="max", roi=(0, 20, -5, 15), bounds=(-5, 25, -8, 20),
            min_spacing=1.5, budget=500, grid=12, seed=7,
        ),
    ),
}


def cell_centres(roi, n: int) -> np.ndarray:
    x0, x1, y0, y1 = roi
    xs = x0 + (np.arange(n) + 0.5) * (x1 - x0) / n
    ys = y0 + (np.arange(n) + 0.5) * (y1 - y0) / n
    x, y = np.meshgrid(xs, ys)
    return np.stack([x, y], axis=-1)


def objective_of(s: sl.Scenario, objective: str, roi, n: int) -> float:
    """The plan objective recomputed from the CRLB at the N × N cell centres of the ROI."""
    r = np.asarray(sl.crlb(s, cell_centres(roi, n)).rmse).ravel()
    if objective == "mean":
        return float(np.mean(r))
    if objective == "p90":
        return float(np.percentile(r, 90))
    if objective == "max":
        return float(np.max(r))
    t = float(objective.split(":")[1])
    return float(np.mean(r <= t))


def in_polygon(p, poly, tol: float = 1e-9) -> bool:
    """Whether ``p`` lies inside ``poly`` or on its boundary (within ``tol`` m): ray casting,
    and the distance to each edge for points on it."""
    q = np.asarray(p, dtype=float)
    v = np.asarray(poly, dtype=float)
    inside = False
    for a, b in zip(v, np.roll(v, -1, axis=0)):
        ab = b - a
        u = np.clip(np.dot(q - a, ab) / np.dot(ab, ab), 0.0, 1.0)
        if np.linalg.norm(a + u * ab - q) <= tol:
            return True
        if (a[1] > q[1]) != (b[1] > q[1]):
            if q[0] < a[0] + (q[1] - a[1]) * ab[0] / ab[1]:
                inside = not inside
    return inside


@pytest.mark.parametrize("case", list(CASES))
def test_plan_equals_cli(cli, case):
    flags, kw = CASES[case]
    base = sl.Scenario.preset("sensors2019")
    cli.write("s.json", base.to_dict())
    cli.write("rooms.json", ROOMS)
    cli.run("plan", "--scenario", "s.json", *flags, "--out", "plan.json")
    doc = cli.file("plan.json")
    p = sl.plan(base, **kw)
    assert_bitwise(p.to_dict(), doc)
    # The scenario may be given as a dict or a path too.
    assert_bitwise(sl.plan(base.to_dict(), **kw).to_dict(), doc)
    assert_bitwise(sl.plan(cli.cwd / "s.json", **kw).to_dict(), doc)

    # Attributes against plan.json.
    obj = doc["objective"]
    assert p.before == obj["before"] and p.after == obj["after"]
    assert p.evaluations == doc["evaluations"] <= kw["budget"]
    assert p.termination == doc["termination"] in ("budget", "converged")
    assert p.moved == doc["moved"]
    h = p.history
    assert isinstance(h, np.ndarray) and h.dtype == np.float64
    assert h.shape == (len(doc["history"]), 2) and h.shape[0] >= 1
    assert h[:, 0].tolist() == [float(e["evaluations"]) for e in doc["history"]]
    assert h[:, 1].tolist() == [e["best"] for e in doc["history"]]
    assert (np.diff(h[:, 0]) > 0).all()
    improving = np.diff(h[:, 1])
    assert (improving > 0).all() if obj["maximised"] else (improving < 0).all()
    assert isinstance(p.paths, dict) and list(p.paths) == [q["name"] for q in doc["paths"]] == p.moved
    for q in doc["paths"]:
        a = p.paths[q["name"]]
        assert a.dtype == np.float64 and a.shape == (len(q["points"]), 2)
        assert a.tolist() == q["points"]
    assert isinstance(p.scenario, sl.Scenario)
    assert p.scenario == sl.Scenario.from_dict(doc["scenario"])
    assert_bitwise(p.scenario.to_dict(), doc["scenario"])

    # Each path starts at the base layout and ends at the planned one; fixed nodes stay.
    names = base.transmitter_names + base.receiver_names
    before = np.vstack([base.transmitters, base.receivers])
    after = np.vstack([p.scenario.transmitters, p.scenario.receivers])
    for i, name in enumerate(names):
        if name in p.paths:
            assert p.paths[name][0].tolist() == before[i].tolist()
            assert p.paths[name][-1].tolist() == after[i].tolist()
        else:
            assert after[i].tolist() == before[i].tolist()

    # Constraints: bounds, rooms and spacing.
    bx0, bx1, by0, by1 = kw.get("bounds") or AREA
    assert not any(in_polygon((15.0, 10.0), r) for r in ROOMS)  # between the rooms
    for i, name in enumerate(names):
        if name in p.paths:
            x, y = after[i]
            assert bx0 <= x <= bx1 and by0 <= y <= by1
            if "allowed" in kw:
                assert any(in_polygon((x, y), r) for r in ROOMS)
    d = np.linalg.norm(after[:, None] - after[None, :], axis=-1)
    assert d[np.triu_indices(len(after), 1)].min() >= kw.get("min_spacing", 0.0) - 1e-9

    # `before` and `after` are the objective of the CRLB on the N grid (closed form).
    roi, n = kw["roi"], kw["grid"]
    assert p.before == pytest.approx(objective_of(base, kw["objective"], roi, n), rel=1e-12)
    assert p.after == pytest.approx(objective_of(p.scenario, kw["objective"], roi, n), rel=1e-12)
    assert (p.after >= p.before) if obj["maximised"] else (p.after <= p.before)


def test_plan_preset_and_seed(cli):
    """`--preset` and the seed: another seed, another (deterministic) search."""
    flags = ["--preset", "iclgnss2019", "--move", "rx", "--objective", "p90"]
    s = sl.Scenario.preset("iclgnss2019")
    x0, x1, y0, y1 = s.area
    roi = (x0 + 0.25 * (x1 - x0), x1 - 0.25 * (x1 - x0), y0 + 0.25 * (y1 - y0), y1 - 0.25 * (y1 - y0))
    docs = []
    for seed in (1, 2, 3):
        cli.run("plan", *flags, f"--roi={flag(roi)}", "--budget", "200", "--grid", "16", "--seed", str(seed), "--out", f"p{seed}.json")
        doc = cli.file(f"p{seed}.json")
        p = sl.plan(s, move="rx", objective="p90", roi=roi, budget=200, grid=16, seed=seed)
        assert_bitwise(p.to_dict(), doc)
        assert doc["seed"] == seed and p.after <= p.before
        docs.append(doc)
    assert docs[0]["paths"] != docs[1]["paths"]


def test_plan_fortran_order_polygon():
    s = sl.Scenario.preset("sensors2019")
    kw = dict(move="rx", objective="p90", roi=(0, 20, 0, 20), budget=50, grid=16)
    room = np.array(ROOMS[0])
    c = sl.plan(s, allowed=[np.ascontiguousarray(room)], **kw)
    f = sl.plan(s, allowed=[np.asfortranarray(room)], **kw)
    assert_bitwise(f.to_dict(), c.to_dict())


def test_plan_progress_callback():
    calls: list[tuple[int, int]] = []
    budget = 1000
    p = sl.plan(
        sl.Scenario.preset("sensors2019"), move="rx", objective="p90", roi=AREA, grid=32,
        budget=budget, progress=lambda done, total: calls.append((done, total)),
    )
    assert calls, "progress was never called"
    assert calls[-1] == (budget, budget)
    assert all(total == budget for _, total in calls)
    done = [d for d, _ in calls]
    assert done == sorted(done) and all(0 <= d <= budget for d in done)
    assert p.evaluations <= budget


def test_plan_progress_exception_stops_the_plan():
    class Stop(Exception):
        pass

    def cb(done, total):
        raise Stop

    # A callback that raises cancels the run and its exception propagates (also from the last
    # report, (budget, budget), of a plan that ends before the first poll).
    with pytest.raises(Stop):
        sl.plan(sl.Scenario.preset("sensors2019"), move="rx", objective="p90", roi=AREA, grid=16, budget=50, progress=cb)


@pytest.mark.parametrize(
    "kw, field, cli_flag",
    [
        (dict(objective="p95"), "objective", ("--objective", "p95")),
        (dict(objective="coverage:x"), "objective", ("--objective", "coverage:x")),
        (dict(roi=(0, 200, 0, 20)), "roi", ("--roi", "0,200,0,20")),
        (dict(roi=(-20, 10, 0, 10)), "roi", ("--roi", "-20,10,0,10")),
        (dict(grid=1), "grid", ("--grid", "1")),
        (dict(grid=513), "grid", ("--grid", "513")),
        (dict(move="Rx9"), "move", ("--move", "Rx9")),
        (dict(budget=0), "budget", ("--budget", "0")),
    ],
)
def test_plan_errors_name_the_input(cli, kw, field, cli_flag):
    args = dict(move="rx", objective="p90", roi=(0, 20, 0, 20), budget=50, grid=16)
    args.update(kw)
    with pytest.raises(sl.ScatterlocError) as e:
        sl.plan(sl.Scenario.preset("sensors2019"), **args)
    assert isinstance(e.value, ValueError)
    assert e.value.field == field, str(e.value)
    assert str(e.value).startswith(field)
    # The CLI names the same input (its flag) for the same value, with exit status 2.
    flags = {"--move": "rx", "--objective": "p90", "--roi": "0,20,0,20", "--budget": "50", "--grid": "16"}
    flags[cli_flag[0]] = cli_flag[1]
    r = cli.run("plan", *(f"{k}={v}" for k, v in flags.items()), "--out", "x.json", check=False)
    assert r.returncode == 2
    assert r.stderr.startswith(f"error: --{field}:"), r.stderr
    assert not (cli.cwd / "x.json").exists()


def test_plan_bad_objective_message_names_the_value():
    with pytest.raises(sl.ScatterlocError) as e:
        sl.plan(sl.Scenario.preset("sensors2019"), move="rx", objective="p95", roi=(0, 20, 0, 20), budget=50)
    assert "'p95'" in str(e.value) and "NaN" not in str(e.value)


@pytest.mark.parametrize(
    "kw, field",
    [
        (dict(objective="coverage:0"), "objective.threshold_m"),
        (dict(roi=(20, 0, 0, 20)), "roi.x"),
        (dict(min_spacing=-1.0), "min_spacing"),
        (dict(allowed=[[[0, 0], [1, 1]]]), "allowed[0]"),
        (dict(allowed=[[[0, 0], [1, 1], [2, 2]]]), "allowed[0]"),
        (dict(allowed=5), "allowed"),
    ],
)
def test_plan_more_errors(kw, field):
    args = dict(move="rx", objective="p90", roi=(0, 20, 0, 20), budget=50, grid=16)
    args.update(kw)
    with pytest.raises(sl.ScatterlocError) as e:
        sl.plan(sl.Scenario.preset("sensors2019"), **args)
    assert e.value.field == field, str(e.value)
    assert str(e.value).startswith(field)
