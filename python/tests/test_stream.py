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


def test_track_stream_settings_equal_cir_track_follow_flags(cli: Cli) -> None:
    """Every setting `cir track --follow` takes is a keyword (the same `ChannelRequest`); a
    recording given without frames is streamed snapshot by snapshot. Its samples are complex64
    here, as the CLI's frame stream carries them, so both runs see the same values."""
    s = sl.Scenario.preset("sensors2019")
    s.save(str(cli.cwd / "s.json"))
    rec, _empty, _truth = sl.simulate_recording(s, dt=0.05, duration=3.0, seed=2)
    assert rec.freq_hz is not None
    rounded = sl.Recording(rec.t, rec.links, cfr=rec.samples.astype(np.complex64),
                           freq_hz=rec.freq_hz, noise_var=rec.noise_var,
                           synchronized=rec.synchronized)
    sl.write_recording(cli.cwd / "walk.npz", rounded)
    frames_bin = subprocess.run(
        [cli.exe, "cir", "stream", "walk.npz"], cwd=cli.cwd, capture_output=True, check=True
    ).stdout
    flags = ["--filter", "ukf", "--ukf-alpha", "0.5", "--ukf-kappa", "0.5",
             "--process-noise", "0.5", "--association", "spec", "--extent-sigma-m", "0.3",
             "--max-paths", "6", "--pfa", "1e-4", "--background-time", "5"]
    kw: dict[str, object] = dict(filter="ukf", ukf_alpha=0.5, ukf_kappa=0.5, process_noise=0.5,
                                 association="spec", extent_sigma=0.3, max_paths=6, pfa=1e-4,
                                 background_time=5.0)

    def follow(extra: list[str]) -> list[object]:
        r = subprocess.run(
            [cli.exe, "cir", "track", "--follow", "--scenario", "s.json", "--cir", "-", *extra],
            cwd=cli.cwd, input=frames_bin, capture_output=True, check=True, timeout=600)
        return [json.loads(l) for l in r.stdout.decode().splitlines()]

    lines = follow(flags)
    states = list(sl.track_stream(s, rounded, **kw))  # type: ignore[arg-type]
    assert len(states) == len(lines) == len(rec.t)
    assert any(st["state"] is not None for st in states), "the walk is tracked"
    for k, (st, line) in enumerate(zip(states, lines)):
        assert st == line, f"frame {k}: {st} != {line}"
    # The frames given one by one: the same run.
    frames = ((float(t), rounded.samples[k]) for k, t in enumerate(rounded.t))
    assert list(sl.track_stream(s, rounded, frames, **kw)) == states  # type: ignore[arg-type]
    # The settings matter: the defaults track otherwise.
    defaults = list(sl.track_stream(s, rounded))
    assert defaults == follow([]) and defaults != states


@pytest.mark.parametrize(
    ("kw", "field"),
    [
        ({"filter": "kalman"}, "filter"),
        ({"ukf_alpha": 0.5}, "ukf_alpha"),
        ({"seed": 3}, "seed"),
        ({"pfa": 2.0}, "pfa"),
        ({"statics": "none"}, "statics"),
        ({"delay_reference": "gps"}, "delay_reference"),
        ({"association": "nearest"}, "association"),
        ({"sigma": "guess"}, "sigma"),
        ({"extent_sigma": -1.0}, "extent_sigma_m"),
        ({"process_noise": -1.0}, "process_noise"),
        ({"background_time": 0.0}, "background_time_s"),
    ],
)
def test_track_stream_bad_settings_are_named_before_any_frame(kw: dict[str, object],
                                                               field: str) -> None:
    s = sl.Scenario.preset("sensors2019")
    rec, _e, _t = sl.simulate_recording(s, dt=0.05, duration=0.5, seed=1)
    with pytest.raises(sl.ScatterlocError) as e:
        sl.track_stream(s, rec, iter(()), **kw)  # type: ignore[arg-type]
    assert e.value.field == field, str(e.value)
