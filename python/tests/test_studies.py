"""`montecarlo` and `pcrlb` against the CLI's `--json` documents (bit for bit, timings left
out), independence from the thread count, progress, Ctrl-C and bad input."""

from __future__ import annotations

import math
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import scatterloc as sl
from conftest import assert_bitwise, strip_timing

FAST = ["--runs", "24", "--noise-runs", "2", "--dt", "0.1", "--duration", "4"]
FAST_PY = dict(runs=24, noise_runs=2, dt=0.1, duration=4.0)


@pytest.mark.parametrize("seed", [1, 7])
def test_montecarlo_ekf_equals_cli(cli, seed):
    cli.run("montecarlo", *FAST, "--seed", str(seed), "--json", "mc.json")
    r = sl.montecarlo(**FAST_PY, seed=seed)
    doc = cli.file("mc.json")
    assert_bitwise(strip_timing(r.to_dict()), strip_timing(doc))
    assert len(r) == 3 and [c.trajectory for c in r.curves] == ["I", "II", "III"]
    for c, d in zip(r.curves, doc["scenarios"]):
        assert c.t.tolist() == d["t_s"]
        assert c.rmse["ekf"].tolist() == d["rmse_ekf_m"]
        assert c.nees["ekf"].tolist() == d["nees"]
        assert [math.inf if v is None else v for v in d["rmse_pcrlb_m"]] == c.pcrlb.tolist()
        assert c.runs == {"ekf": d["runs"]} and c.failed_runs == {"ekf": d["failed_runs"]}
    assert r["II"].trajectory == "II" and r[-1].trajectory == "III"


def test_montecarlo_three_filters_equals_cli(cli):
    args = ["--trajectory", "II", "--filters", "ekf,ukf,pf", "--particles", "150", "--ukf-kappa", "1"]
    cli.run("montecarlo", *FAST, *args, "--json", "mc.json")
    r = sl.montecarlo(**FAST_PY, trajectory="II", filters=["ekf", "ukf", "pf"], particles=150, ukf_kappa=1.0)
    doc = cli.file("mc.json")
    assert_bitwise(strip_timing(r.to_dict()), strip_timing(doc))
    c = r["II"]
    assert list(c.rmse) == ["ekf", "ukf", "pf"]
    for name, f in doc["filters"].items():
        assert c.rmse[name].tolist() == f["rmse_m"]
        assert c.nees[name].tolist() == f["nees"]
        assert c.runs[name] == f["runs"] and c.failed_runs[name] == f["failed_runs"]
    # The filters as a comma-separated string, as the CLI's flag.
    r2 = sl.montecarlo(**FAST_PY, trajectory="II", filters="ekf,ukf,pf", particles=150, ukf_kappa=1.0)
    assert_bitwise(strip_timing(r2.to_dict()), strip_timing(doc))


def test_montecarlo_threads_and_progress():
    seen: list[tuple[int, int]] = []
    a = sl.montecarlo(**FAST_PY, trajectory="I", threads=1)
    b = sl.montecarlo(**FAST_PY, trajectory="I", threads=2, progress=lambda d, t: seen.append((d, t)))
    assert_bitwise(strip_timing(a.to_dict()), strip_timing(b.to_dict()))
    assert seen and seen[-1] == (48, 48)
    assert all(d <= t for d, t in seen) and [d for d, _ in seen] == sorted(d for d, _ in seen)


def test_all_runs_failed_warns():
    with pytest.warns(UserWarning, match="every run of the PF failed"):
        r = sl.montecarlo(**FAST_PY, trajectory="I", filters=["ekf", "pf"], particles=1)
    c = r["I"]
    assert "pf" in c.errors and "pf" not in c.rmse and "ekf" in c.rmse
    assert c.runs["pf"] == 0 and c.failed_runs["pf"] == 48


@pytest.mark.parametrize("traj", ["I", "III"])
def test_pcrlb_equals_cli(cli, traj):
    cli.run("pcrlb", "--nominal", "--trajectory", traj, "--dt", "0.05", "--duration", "5", "--json", "n.json")
    n = sl.pcrlb(nominal=True, trajectory=traj, dt=0.05, duration=5.0)
    assert_bitwise(strip_timing(n.to_dict()), strip_timing(cli.file("n.json")))
    cli.run("pcrlb", "--trajectory", traj, "--runs", "60", "--seed", "3", "--dt", "0.05", "--duration", "5", "--json", "m.json")
    m = sl.pcrlb(trajectory=traj, runs=60, seed=3, dt=0.05, duration=5.0)
    assert_bitwise(strip_timing(m.to_dict()), strip_timing(cli.file("m.json")))
    assert m[0].pcrlb.shape == (101,) and not np.isnan(m[0].pcrlb).any()
    assert m[0].rmse == {}


def test_study_bad_input():
    for kw, field in (
        (dict(trajectory="IV"), "trajectory"),
        (dict(filters=["ekf", "kf"]), "filters[1]"),
        (dict(particles=10), "particles"),
        (dict(threads=1000), "threads"),
        (dict(duration=-1.0), "duration"),
        (dict(runs=0), None),
    ):
        with pytest.raises(sl.ScatterlocError) as e:
            sl.montecarlo(**{**FAST_PY, **kw})
        if field is not None:
            assert e.value.field == field
    with pytest.raises(sl.ScatterlocError) as e:
        sl.montecarlo(runs=5000, noise_runs=50, filters=["pf"], particles=100000)
    assert e.value.kind == "TooLong"
    with pytest.raises(sl.ScatterlocError) as e:
        sl.pcrlb(nominal=True, runs=10)
    assert e.value.field == "runs"


def test_ctrl_c_stops_a_study():
    """A paper-scale study (minutes) interrupted by SIGINT raises KeyboardInterrupt: it ends with
    the interrupt's status long before the study could finish (the 30 s guard below is a hang
    guard; the time it took is printed, not asserted: tests do not time the wall clock)."""
    # The child restores Python's own SIGINT handler: a shell that starts this suite in the
    # background (`cmd &` without job control) leaves SIGINT ignored, and children inherit that.
    code = (
        "import signal\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "import scatterloc as sl, sys, time\n"
        "print('ready', flush=True)\n"
        "t0 = time.perf_counter()\n"
        "try:\n"
        "    sl.montecarlo()\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted %.3f' % (time.perf_counter() - t0), flush=True)\n"
        "    sys.exit(3)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert p.stdout is not None
    assert p.stdout.readline().strip() == "ready"
    time.sleep(1.0)
    t0 = time.perf_counter()
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=30)
    stopped = time.perf_counter() - t0
    assert p.returncode == 3, out
    assert out.startswith("interrupted")
    print(f"stopped {stopped:.3f} s after SIGINT")
