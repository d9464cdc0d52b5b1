"""`sl.track_stream` (issue 40 §3): the live chain of `scatterloc cir track --follow` as a Python
iterator over the same core run — one state per frame, equal to the CLI's JSON lines for the
same frames (the CLI's stream carries float32 samples, so the frames given to Python are rounded
to float32 as well) — and its errors named by frame."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

import scatterloc as sl
from conftest import Cli


def test_track_stream_equals_cir_track_follow(cli: Cli) -> None:
    s = sl.Scenario.preset("sensors2019")
    s.save(str(cli.cwd / "s.json"))
    rec, _empty, _truth = sl.simulate_recording(s, dt=0.05, duration=3.0, seed=2)
    sl.write_recording(cli.cwd / "walk.npz", rec)
    frames_bin = subprocess.run(
        [cli.exe, "cir", "stream", "walk.npz"], cwd=cli.cwd, capture_output=True, check=True
    ).stdout
    follow = subprocess.run(
        [cli.exe, "cir", "track", "--follow", "--scenario", "s.json", "--cir", "-"],
        cwd=cli.cwd,
        input=frames_bin,
        capture_output=True,
        check=True,
        timeout=600,
    )
    lines = [json.loads(l) for l in follow.stdout.decode().splitlines()]
    rounded = rec.samples.astype(np.complex64).astype(np.complex128)
    frames = ((float(t), rounded[k]) for k, t in enumerate(rec.t))
    states = list(sl.track_stream(s, rec, frames))
    assert len(states) == len(lines) == len(rec.t)
    assert any(st["state"] is not None for st in states), "the walk is tracked"
    for k, (st, line) in enumerate(zip(states, lines)):
        assert st == line, f"frame {k}: {st} != {line}"


def test_track_stream_names_bad_frames() -> None:
    s = sl.Scenario.preset("sensors2019")
    rec, _e, _t = sl.simulate_recording(s, dt=0.05, duration=1.0, seed=1)
    good = [(float(t), rec.samples[k]) for k, t in enumerate(rec.t[:3])]
    with pytest.raises(ValueError, match=r"frames\[1\]"):
        list(sl.track_stream(s, rec, [good[0], (0.5, rec.samples[0][:, :10])]))
    with pytest.raises(sl.ScatterlocError, match=r"frames\[2\]"):
        list(sl.track_stream(s, rec, [good[0], good[1], (good[1][0], good[2][1])]))
    with pytest.raises(ValueError, match="frames"):
        sl.track_stream(s, rec, 42)
