#!/usr/bin/python3
"""Writes tests/data/recording-cir-int16.npz: a CIR recording (C2) in the int16 I/Q layout of
docs/recording.md, 3 snapshots x 4 links x 64 taps, with tap0_s/tap_spacing_s, for the sensors2019
preset (links (0, 0) ... (0, 3)). Tap m of link p in snapshot s is I + jQ with
    I = 100*s + 10*p + m - 500,   Q = 7*m - 3*p - 200 + s,
so a test can check any tap from this formula (tests/library/recording.rs, tests/wasm/recording.rs).
Deterministic (no randomness): re-running writes the same arrays.

Run: /usr/bin/python3 scripts/make-recording-fixture.py   (Debian's python3-numpy)
"""
import pathlib
import numpy as np

S, P, M = 3, 4, 64
s, p, m = np.meshgrid(np.arange(S), np.arange(P), np.arange(M), indexing="ij")
cir = np.stack([100 * s + 10 * p + m - 500, 7 * m - 3 * p - 200 + s], axis=-1).astype(np.int16)
out = pathlib.Path(__file__).resolve().parent.parent / "tests" / "data" / "recording-cir-int16.npz"
out.parent.mkdir(parents=True, exist_ok=True)
np.savez_compressed(
    out,
    t_s=np.array([0.0, 2.048e-3, 4.096e-3]),
    links=np.array([[0, 0], [0, 1], [0, 2], [0, 3]], dtype=np.int64),
    cir=cir,
    tap0_s=np.float64(-10e-9),
    tap_spacing_s=np.float64(1.0 / 240e6),
)
print(out, out.stat().st_size, "bytes")
