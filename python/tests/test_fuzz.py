"""The Python fuzz kind (issue 37): tests/fuzz.rs's noise-free, CIR-window, `.npz` reservation and
simulator-truth kinds, and hostile arrays, through the package's public API.

Every case must end in a normal return whose numbers are all finite (the documented fields of a
`Recording`, `Paths` or the simulator's truth; delays inside the searched window), or in the
package's named error, `scatterloc.ScatterlocError` (docs/python.md: "Errors"); never a
`pyo3_runtime.PanicException` (a `BaseException`), another exception, a non-finite number, a
case over its time budget, or a crash of the interpreter.

Sub-kinds (each a seeded `numpy.random.Generator` per case, the same cases every run):

- npz: archives written by `write_recording` / `numpy.savez_compressed`, with tests/fuzz.rs's
  zip edits (declared sizes, same-length renames into duplicate members, header and byte
  flips, truncation) and `.npy` descrs holding multi-byte characters, through `read_recording`;
  the peak address space may not grow by more than the archive only declares.
- arrays: `Recording(...)`, `estimate(...)` (and `estimate_recording` on what is accepted) with
  odd dtypes, shapes (0-size, mismatched, `numpy.broadcast_to` views of 10^10 values), strides
  and values (NaN, inf, 1e300, 1e-300).
- noise_free: noise-free CFRs of 1-8 paths through `estimate` with `noise_var` None, 1e-40,
  1e-60 ... 1e250 and edge values; delays in [0, 1/df].
- cir_windows: band-limited CIRs (the closed form of tests/fuzz.rs) with tap0 in +-10 us through
  `estimate`; delays in [tap0, tap0 + M dt] up to rounding, and within 0.05/B of the truth when
  well posed (true delays > 0: `estimate`'s absolute delays drop those <= 0).
- simulator: small random scenes through `simulate_recording`, and scenes over its caps (many
  scatterers x long durations, too many samples or too much work, invalid fields), which must be
  named errors within a second.

Each sub-kind runs in a child interpreter (this file run as a script), so a hard crash or a hang
fails its test instead of ending the suite. SCATTERLOC_FUZZ_CASES (as for tests/fuzz.rs) sets
the cases per sub-kind (default: DEFAULT_CASES, 1650 in all, about 10 s on a 2-core machine).
SCATTERLOC_FUZZ_SEED changes the seed (default 12, as tests/fuzz.rs). One summary line per
sub-kind: cases, ok, named errors, failures, known failures, time. Known failures (KNOWN, as
tests/fuzz.rs's) are printed once and fail only with SCATTERLOC_FUZZ_STRICT=1.
"""

from __future__ import annotations

import io
import math
import os
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

import scatterloc as sl
from test_hardening import npy_v1, replace_member, small_cfr

HERE = Path(__file__).resolve().parent

# Cases per sub-kind by default (about 10 s for the module on the 2-core machine of issue 37).
DEFAULT_CASES = {"npz": 500, "arrays": 400, "noise_free": 300, "cir_windows": 300, "simulator": 150}
# A case slower than this fails (tests/fuzz.rs's SCATTERLOC_FUZZ_BUDGET_S); over-cap simulator
# cases must be refused faster still.
BUDGET_S = float(os.environ.get("SCATTERLOC_FUZZ_BUDGET_S", "5"))
REFUSE_S = 1.0
SEED = int(os.environ.get("SCATTERLOC_FUZZ_SEED", "12"))
NPZ_RESERVE_LIMIT = 512 << 20

B = 120e6  # tests/common/multipath.rs: the preset's band and bins
N_BINS = 241


def cases_of(kind: str) -> int:
    env = os.environ.get("SCATTERLOC_FUZZ_CASES")
    return int(env) if env else DEFAULT_CASES[kind]


# Known failures (as tests/fuzz.rs's KNOWN): counted and printed, not failed, unless
# SCATTERLOC_FUZZ_STRICT=1. Each is a reported bug, matched on the failure's text.
KNOWN = {
    # A negative int for an unsigned keyword (`max_paths=-1`, `threads=-1`) is PyO3's
    # `OverflowError: can't convert negative int to unsigned`, not a `ScatterlocError` naming it.
    "OverflowError: can't convert negative int to unsigned": "negative int for an unsigned keyword",
}
STRICT = os.environ.get("SCATTERLOC_FUZZ_STRICT") == "1"


class Bad(Exception):
    """A broken invariant in a returned value."""


# --------------------------------------------------------------------------------------------
# Checks of what comes back


def finite(name: str, a: Any) -> np.ndarray:
    if a is None:
        return np.zeros(0)
    if isinstance(a, np.ma.MaskedArray):
        a = a.compressed()
    a = np.asarray(a)
    if a.dtype.kind in "fc" and not np.isfinite(a).all():
        k = int(np.flatnonzero(~np.isfinite(a.ravel()))[0])
        raise Bad(f"{name}[{k}] = {a.ravel()[k]!r} (not finite)")
    if a.dtype.kind not in "fcuib":
        raise Bad(f"{name}: dtype {a.dtype}")
    return a


def finite_tree(name: str, x: Any) -> int:
    """Every float in a dict/list document is finite; returns how many numbers it holds."""
    if isinstance(x, dict):
        return sum(finite_tree(f"{name}.{k}", v) for k, v in x.items())
    if isinstance(x, (list, tuple)):
        return sum(finite_tree(f"{name}[{i}]", v) for i, v in enumerate(x))
    if isinstance(x, float) and not math.isfinite(x):
        raise Bad(f"{name} = {x!r}")
    return 1 if isinstance(x, (int, float)) else 0


def check_recording(r: sl.Recording) -> None:
    t = finite("t", r.t)
    if t.ndim != 1 or len(t) != len(r) or (len(t) > 1 and not (np.diff(t) > 0).all()):
        raise Bad(f"t: not strictly increasing times of len(recording) {len(r)}: {t[:8]}")
    links = finite("links", r.links)
    h = finite("samples", r.samples)
    if h.dtype != np.complex128 or h.ndim != 3 or h.shape[:2] != (len(t), len(links)):
        raise Bad(f"samples {h.dtype} {h.shape} for {len(t)} snapshots, {len(links)} links")
    if r.layout == "cfr":
        f = finite("freq_hz", r.freq_hz)
        if f.shape != (h.shape[2],):
            raise Bad(f"freq_hz {f.shape} for {h.shape[2]} bins")
    else:
        taps = r.taps
        if taps is None:
            raise Bad("a cir recording without taps")
        finite("taps", np.array(taps, dtype=float))
    nv = finite("noise_var", r.noise_var)
    if (nv < 0).any():
        raise Bad(f"noise_var < 0: {nv}")


def check_paths(p: sl.Paths, window: tuple[float, float] | None = None) -> None:
    n = len(p)
    fields = {
        "snapshot": p.snapshot, "delay": p.delay, "amplitude": p.amplitude, "sigma": p.sigma,
        "snr_db": p.snr_db, "track": p.track, "confirmed": p.confirmed,
    }
    if p.link is not None:
        fields["link"] = p.link
    for name, a in fields.items():
        a = finite(name, a)
        if name != "snr_db" and a.shape != (n,):
            raise Bad(f"{name}: shape {a.shape} for {n} paths")
    nv = finite("noise_var", p.noise_var)
    finite("t", p.t)
    if (np.asarray(p.sigma) < 0).any() or (nv < 0).any():
        raise Bad(f"a negative sigma or noise_var: {p.sigma}, {nv}")
    if window is not None and n:
        lo, hi = window
        slack = 4 * np.finfo(float).eps * max(abs(lo), abs(hi))
        d = np.asarray(p.delay)
        out = (d < lo - slack) | (d > hi + slack)
        if out.any():
            raise Bad(f"delay {d[out][0]!r} outside the window [{lo!r}, {hi!r}]")


# --------------------------------------------------------------------------------------------
# Running cases


class Kind:
    """Counts cases of one sub-kind and keeps the failures with a reproducer each."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.cases = self.ok = self.named = 0
        self.failures: list[str] = []
        self.known: dict[str, int] = {}
        self.t0 = time.perf_counter()
        self.last = Path(os.environ["SCATTERLOC_FUZZ_LAST"]) if "SCATTERLOC_FUZZ_LAST" in os.environ else None

    def run(self, what: str, case: Callable[[], Any], budget: float = BUDGET_S) -> Any:
        """Runs one case; returns its value, or None after a named error (or a failure)."""
        self.cases += 1
        if self.last is not None:
            self.last.write_text(what)
        t0 = time.perf_counter()
        out = None
        fail = None
        try:
            out = case()
        except sl.ScatterlocError as e:
            self.named += 1
            msg = str(e)
            if "\n" in msg or len(msg) > 1000 or e.kind == "Panic":
                fail = f"a named error that is a panic or not one short line ({len(msg)} bytes): {msg[:300]!r}"
        except Bad as e:
            fail = f"bad output: {e}"
        except BaseException as e:  # PanicException, KeyboardInterrupt, anything else
            if isinstance(e, (KeyboardInterrupt, SystemExit)):
                raise
            fail = f"{type(e).__module__}.{type(e).__name__}: {str(e)[:300]}"
            if not isinstance(e, Exception):
                fail += " (a BaseException)"
        else:
            self.ok += 1
        took = time.perf_counter() - t0
        if fail is None and took > budget:
            fail = f"took {took:.2f} s (budget {budget} s)"
        if fail is not None:
            known = next((k for k in KNOWN if k in fail), None)
            if known is not None and not STRICT:
                if known not in self.known:
                    print(f"KNOWN {fail}\n    case: {what}")
                self.known[known] = self.known.get(known, 0) + 1
            else:
                self.failures.append(f"{fail}\n    case: {what}")
        return out

    def summary(self) -> str:
        return (
            f"fuzz {self.name}: {self.cases} cases, {self.ok} ok, {self.named} named errors, "
            f"{len(self.failures)} failures, {sum(self.known.values())} known, "
            f"{time.perf_counter() - self.t0:.1f} s (seed {SEED})"
        )


def rng_of(kind: str, i: int) -> np.random.Generator:
    return np.random.default_rng([SEED, sum(kind.encode()), i])


def log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(10 ** rng.uniform(lo, hi))


# --------------------------------------------------------------------------------------------
# npz: hostile archives through read_recording (tests/fuzz.rs fuzz_npz_reservations)


def npz_bases(tmp: Path) -> list[bytes]:
    """A CFR (system response, noise variances, the synchronized flag) and a CIR with its pulse
    as `write_recording` writes them (stored members), and a CFR of 8192 zero bins written by
    `numpy.savez_compressed` (deflated: its `cfr.npy` inflates about 500-fold)."""
    cfr = sl.Recording(
        [0.0, 2.048e-3], [[0, 0], [0, 1]],
        cfr=(1e-6 - 3e-7j) * np.arange(64.0).reshape(2, 2, 16),
        freq_hz=-60e6 + 8e6 * np.arange(16.0), system_response=1 + 0.01j * np.arange(16.0),
        noise_var=[1e-13, 2e-13], synchronized=True,
    )
    cir = sl.Recording(
        [0.5], [[0, 3]], cir=(0.5 - 0.03 * np.arange(32.0) + 0.01j).reshape(1, 1, 32),
        tap0_s=-1e-8, tap_spacing_s=1e-9, pulse=[0.25 + 0.1j, 1.0 + 0j, 0.25 - 0.1j],
        pulse_spacing_s=0.5e-9,
    )
    out = []
    for i, r in enumerate((cfr, cir)):
        p = tmp / f"base{i}.npz"
        sl.write_recording(p, r)
        out.append(p.read_bytes())
    b = io.BytesIO()
    np.savez_compressed(
        b, t_s=np.zeros(1), links=np.zeros((1, 2), np.int64), cfr=np.zeros((1, 1, 8192), complex),
        freq_hz=-60e6 + 15e3 * np.arange(8192.0), synchronized=np.bool_(False),
    )
    out.append(b.getvalue())
    # An int16 (I, Q) CIR as numpy.savez writes it.
    t, links, cir_h, _ = small_cfr(S=3, P=2, N=16)
    iq = np.stack([np.round(cir_h.real * 100), np.round(cir_h.imag * 100)], -1).astype(np.int16)
    b = io.BytesIO()
    np.savez(b, t_s=t, links=links, cir=iq, tap0_s=np.float64(1e-6), tap_spacing_s=np.float64(4e-9))
    out.append(b.getvalue())
    return out


def zip_members(z: bytes) -> list[tuple[int, int, bytes]]:
    """(local header, central record, name) of each member of a valid archive."""
    eocd = z.rindex(b"PK\x05\x06")
    count, = struct.unpack_from("<H", z, eocd + 10)
    p, = struct.unpack_from("<I", z, eocd + 16)
    out = []
    for _ in range(count):
        assert z[p:p + 4] == b"PK\x01\x02"
        n, m, k = struct.unpack_from("<HHH", z, p + 28)
        local, = struct.unpack_from("<I", z, p + 42)
        out.append((local, p, z[p + 46:p + 46 + n]))
        p += 46 + n + m + k
    return out


SIZES = [0, 1, 2, 1 << 20, 1 << 30, (1 << 30) + (64 << 20) + 1, 2**32 - 2, 2**32 - 1]
DESCRS = ["<é", "<é8", "é<f8", "<f8é", "<\U0001F600", "<c16\u00e9", "\u20ac", "<f\u0308"]


def edit_zip(rng: np.random.Generator, base: bytes, members: list, edits: list) -> bytes:
    z = bytearray(base)

    def put(at: int, b: bytes) -> None:
        if at + len(b) <= len(z):
            z[at:at + len(b)] = b

    for e in edits:
        op = e[0]
        if op == "size":
            _, i, local, central, v = e
            loc, cen, _ = members[i % len(members)]
            if isinstance(v, tuple):  # relative to the true size
                now, = struct.unpack_from("<I", base, cen + 24)
                v = min(max(now + v[1], 0), 2**32 - 1)
            if local:
                put(loc + 22, struct.pack("<I", v))
            if central:
                put(cen + 24, struct.pack("<I", v))
        elif op == "rename":
            _, i, to, local, central = e
            loc, cen, name = members[i % len(members)]
            same = [o[2] for j, o in enumerate(members) if j != i % len(members) and len(o[2]) == len(name)]
            new = same[to % len(same)] if same else b"x" + name[1:]
            if local:
                put(loc + 30, new)
            if central:
                put(cen + 46, new)
        elif op == "header":
            _, i, central, at, x = e
            loc, cen, _ = members[i % len(members)]
            p = (cen if central else loc) + (at if central else at % 30)
            if p < len(z):
                z[p] ^= x
        elif op == "end":
            p = len(base) - 22 + e[1]
            if p < len(z):
                z[p] ^= e[2]
        elif op == "flip":
            p = int(e[1] * len(z))
            if p < len(z):
                z[p] ^= e[2]
        elif op == "truncate":
            del z[int(e[1] * len(z)):]
    return bytes(z)


def zip_edit(rng: np.random.Generator) -> tuple:
    which = [(True, False), (False, True), (True, True)][rng.integers(3)]
    r = rng.integers(21)
    mem = int(rng.integers(1 << 30))
    if r < 8:
        k = rng.integers(8)
        v: Any = SIZES[rng.integers(len(SIZES))] if k < 3 else int(rng.integers(2**32)) if k < 5 else (
            "rel", int(rng.integers(-16, 17)))
        return ("size", mem, *which, v)
    if r < 12:
        return ("rename", mem, int(rng.integers(1 << 30)), *which)
    if r < 16:
        return ("header", mem, bool(rng.integers(2)), int(rng.integers(46)), int(rng.integers(1, 256)))
    if r < 17:
        return ("end", int(rng.integers(22)), int(rng.integers(1, 256)))
    if r < 20:
        return ("flip", float(rng.random()), int(rng.integers(1, 256)))
    return ("truncate", float(rng.random()))


def vm_peak() -> int | None:
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmPeak:"):
                return int(line.split()[1]) << 10
    except OSError:
        pass
    return None


def read_checked(path: Path, size: int) -> sl.Recording:
    before = vm_peak()
    r = sl.read_recording(path)
    after = vm_peak()
    if before is not None and after is not None and after > before + NPZ_RESERVE_LIMIT:
        raise Bad(f"the peak address space grew by {(after - before) >> 20} MiB reading {size} bytes")
    check_recording(r)
    return r


def fuzz_npz(kind: Kind, n: int, tmp: Path) -> None:
    bases = npz_bases(tmp)
    members = [zip_members(b) for b in bases]
    p = tmp / "case.npz"
    for i in range(n):
        rng = rng_of("npz", i)
        b = int(rng.integers(len(bases)))
        base = bases[b]
        if rng.random() < 0.15:
            # A member's descr with a multi-byte character (item 2), then maybe zip edits.
            names = [m[2].decode() for m in members[b]]
            name = names[rng.integers(len(names))]
            descr = DESCRS[rng.integers(len(DESCRS))]
            shape = tuple(int(x) for x in rng.integers(0, 5, size=rng.integers(0, 3)))
            z = replace_member(base, name, npy_v1(descr, shape, bytes(int(rng.integers(0, 64)))))
            edits = [zip_edit(rng) for _ in range(rng.integers(0, 2))]
            what = f"base {b}, {name} with descr {descr!r} shape {shape}, edits {edits}"
            if edits:
                z = edit_zip(rng, z, zip_members(z), edits)
        else:
            edits = [zip_edit(rng) for _ in range(rng.integers(1, 5))]
            z = edit_zip(rng, base, members[b], edits)
            what = f"base {b} ({[m[2].decode() for m in members[b]]}), edits {edits}"
        p.write_bytes(z)
        r = kind.run(f"npz case {i}: {what}", lambda: read_checked(p, len(z)))
        if r is not None and i % 4 == 0:
            # What was read is written and read back the same.
            q = tmp / "back.npz"
            back = kind.run(f"npz case {i} written back: {what}",
                            lambda: (sl.write_recording(q, r), read_checked(q, 0))[1])
            if back is not None and back.samples.tobytes() != r.samples.tobytes():
                kind.failures.append(f"bad output: read back different samples\n    case: {what}")


# --------------------------------------------------------------------------------------------
# arrays: hostile arrays to Recording(...) / estimate(...)

HOSTILE_VALUES = [np.nan, np.inf, -np.inf, 1e300, -1e300, 1e-300, 5e-324, 0.0, -0.0, 1e101]
ODD_DTYPES: list[Any] = [np.int8, np.int16, np.int32, np.int64, np.uint8, np.float16, np.float32,
                         np.float64, np.bool_, np.clongdouble, object, ">c16", ">c8", np.complex64,
                         np.complex128]
HUGE = [10**10, (64 << 20) + 1, 2**24 + 1, 65_537, 4097]


def big(x: Any) -> bool:
    """Whether `x` is (or may be) a broadcast view too large to copy."""
    return bool(np.size(x) > 1 << 20)


def cast(rng: np.random.Generator, a: np.ndarray, dtype: Any) -> Any:
    if a.size > 1 << 20:  # a broadcast view of a huge size stays as it is
        return a
    if dtype is object:
        return a.astype(object)
    dt = np.dtype(dtype)
    if dt.kind == "c":
        return a.astype(dt)
    if dt.kind == "b":
        return np.abs(a) > 0.5
    if dt.kind in "iu":
        return np.clip(np.round(a.real * 50), -100, 100).astype(dt)
    with np.errstate(all="ignore"):
        return a.real.astype(dt)


def arrays_case(rng: np.random.Generator, s: sl.Scenario) -> tuple[str, Callable[[], Any]]:
    S = int(rng.choice([1, 2, 3, 5]))
    P = int(rng.integers(1, 5))
    N = int(rng.choice([2, 3, 8, 16, 33]))
    layout = "cfr" if rng.random() < 0.6 else "cir"
    target = "Recording" if rng.random() < 0.6 else "estimate"
    t = 0.1 * np.arange(S)
    links = np.array([[0, j] for j in range(P)], dtype=np.int64)
    h = (rng.normal(size=(S, P, N)) + 1j * rng.normal(size=(S, P, N))) * 1e-6
    df = B / N
    kw: dict[str, Any] = {}
    if layout == "cfr":
        kw["freq_hz"] = (np.arange(N) - (N - 1) / 2) * df
        if rng.random() < 0.2:
            kw["system_response"] = np.ones(N, complex)
    else:
        kw["tap0_s"] = float(rng.uniform(-1e-6, 1e-6))
        kw["tap_spacing_s"] = 1 / (2 * B)
        if rng.random() < 0.3:
            kw["pulse"] = np.array([0.25 + 0.1j, 1.0, 0.25 - 0.1j])
            kw["pulse_spacing_s"] = 0.5 / B
    if rng.random() < 0.3:
        kw["noise_var"] = np.full(P, 1e-14) if target == "Recording" else 1e-14
    samples: Any = h
    mutations = []
    for _ in range(rng.integers(1, 4)):
        m = rng.integers(7)
        if m == 0:  # an odd dtype of the samples (or of another array)
            dt = ODD_DTYPES[rng.integers(len(ODD_DTYPES))]
            if layout == "cir" and rng.random() < 0.3:
                dt = [np.int16, np.int32][rng.integers(2)]
                samples = np.stack([np.round(h.real * 1e8), np.round(h.imag * 1e8)], -1).astype(dt)
                mutations.append(f"cir as {np.dtype(dt).name} (I, Q)")
                continue
            which = rng.choice(["samples", "t", "links", "freq_hz", "system_response", "pulse", "noise_var"])
            if which == "samples":
                samples = cast(rng, np.asarray(samples), dt)
            elif which == "t":
                t = cast(rng, np.asarray(t) + 0j if np.size(t) <= 1 << 20 else np.asarray(t), dt)
            elif which == "links":
                links = cast(rng, np.asarray(links) + 0j if np.size(links) <= 1 << 20 else np.asarray(links), dt)
            elif which in kw and kw[which] is not None and not np.isscalar(kw[which]):
                kw[which] = cast(rng, np.asarray(kw[which]) + 0j if np.size(kw[which]) <= 1 << 20 else np.asarray(kw[which]), dt)
            mutations.append(f"{which} as {getattr(dt, '__name__', dt)}")
        elif m == 1:  # a 0-size or mismatched shape
            which = rng.choice(["S0", "P0", "N0", "N1", "t", "links", "freq", "extra", "flat", "noise"])
            a = np.asarray(samples)
            if a.ndim != 3 and which in ("S0", "P0", "N0", "N1"):
                which = "extra"
            if which == "S0":
                samples, t = a[:0], np.asarray(t)[:0]
            elif which == "P0":
                samples, links = a[:, :0], np.asarray(links)[:0]
            elif which == "N0":
                samples = a[:, :, :0]
            elif which == "N1":
                samples = a[:, :, :1]
            elif which == "t":
                t = np.asarray(t)[: max(0, len(t) - 1)] if rng.random() < 0.5 else np.append(t, 9.9)
            elif which == "links":
                links = np.asarray(links)[:, :1] if rng.random() < 0.5 else np.concatenate([links, links[:1]])
            elif which == "freq" and "freq_hz" in kw:
                kw["freq_hz"] = np.asarray(kw["freq_hz"])[:-1]
            elif which == "extra":
                samples = a[None]
            elif which == "flat" and not big(a):
                samples = a.ravel()
            elif which == "noise" and "noise_var" in kw:
                kw["noise_var"] = np.ones(P + 1) if target == "Recording" else np.ones(2)
            mutations.append(f"shape {which}")
        elif m == 2:  # a broadcast view of a huge logical size (a few bytes)
            n = HUGE[rng.integers(len(HUGE))]
            which = rng.choice(["samples", "t", "links", "freq_hz", "noise_var", "system_response", "pulse"])
            if which == "samples":
                samples = np.broadcast_to(np.complex128(1e-6), (2, 1, n) if target == "Recording" else (n, 2))
            elif which == "t":
                t = np.broadcast_to(0.0, (n,))
            elif which == "links":
                links = np.broadcast_to(np.int64(0), (n, 2))
            elif which == "freq_hz" and layout == "cfr":
                kw["freq_hz"] = np.broadcast_to(1.0, (n,))
            elif which == "noise_var" and target == "Recording":
                kw["noise_var"] = np.broadcast_to(1e-14, (n,))
            elif which == "system_response" and layout == "cfr":
                kw["system_response"] = np.broadcast_to(1 + 0j, (n,))
            elif which == "pulse" and layout == "cir":
                kw["pulse"] = np.broadcast_to(1 + 0j, (n,))
                kw["pulse_spacing_s"] = 1e-9
            mutations.append(f"{which} broadcast to {n}")
        elif m == 3:  # a hostile value somewhere
            v = HOSTILE_VALUES[rng.integers(len(HOSTILE_VALUES))]
            which = rng.choice(["samples", "t", "freq_hz", "noise_var", "tap0_s", "tap_spacing_s",
                                "system_response", "pulse_spacing_s", "scale"])
            if which == "samples" and not big(samples):
                a = np.array(samples)
                if a.size and a.dtype.kind in "fc":
                    a.flat[rng.integers(a.size)] = v * (1j if rng.random() < 0.5 and a.dtype.kind == "c" else 1)
                samples = a
            elif which == "scale" and not big(samples):
                a = np.asarray(samples)
                if a.dtype.kind == "c":
                    with np.errstate(all="ignore"):
                        samples = a * v if v != 0 else a * 0
            elif which == "t" and not big(t) and np.asarray(t).dtype != object:
                tt = np.array(t, dtype=float)
                if tt.size:
                    tt[rng.integers(tt.size)] = v
                t = tt
            elif which in kw and kw[which] is not None:
                x = kw[which]
                if np.isscalar(x):
                    kw[which] = v
                elif not big(x):
                    x = np.array(x)
                    if x.size and x.dtype.kind in "fc":
                        x.flat[rng.integers(x.size)] = v
                    kw[which] = x
            mutations.append(f"{which} = {v!r}")
        elif m == 4 and not big(samples):  # strides, order, byte order
            a = np.asarray(samples)
            which = rng.choice(["fortran", "strided", "swapped", "readonly", "list"])
            if which == "fortran":
                samples = np.asfortranarray(a)
            elif which == "strided":
                samples = np.repeat(a, 2, axis=-1)[..., ::2]
            elif which == "swapped" and a.dtype.kind == "c":
                samples = a.astype(a.dtype.newbyteorder())
            elif which == "readonly":
                a = a.copy()
                a.setflags(write=False)
                samples = a
            elif which == "list" and a.size < 2000:
                samples = a.tolist()
            mutations.append(which)
        elif m == 5:  # settings
            which = rng.choice(["max_paths", "pfa", "bandwidth_hz", "synchronized", "layout"])
            if which == "max_paths":
                kw["max_paths"] = int(rng.choice([-1, 0, 1, 64, 65, 2**40]))
            elif which == "pfa":
                kw["pfa"] = float(rng.choice([0.0, 1.0, 1e-300, np.nan, -0.5, 0.5]))
            elif which == "bandwidth_hz":
                kw["bandwidth_hz"] = float(rng.choice([B, -B, 0.0, np.inf, 1e20, 1.0]))
            elif which == "synchronized":
                kw["synchronized"] = bool(rng.integers(2))
            else:  # both layouts' settings at once
                kw.update(freq_hz=np.arange(N) * df, tap0_s=0.0, tap_spacing_s=1e-9)
            mutations.append(which)
        else:
            mutations.append("none")
    if target == "Recording":
        for k in ("max_paths", "pfa", "bandwidth_hz"):
            kw.pop(k, None)
        kw[layout] = samples
        what = f"Recording(S={S}, P={P}, N={N}, {layout}) with {mutations}"
        run_rec = rng.random() < 0.5

        def case() -> Any:
            r = sl.Recording(t, links, **kw)
            check_recording(r)
            if run_rec:
                check_paths(sl.estimate_recording(s, r, threads=1, max_paths=4))
            return r

        return what, case
    kw.pop("synchronized", None)
    a = np.asarray(samples) if not isinstance(samples, list) else samples
    resp = a[:, 0] if isinstance(a, np.ndarray) and a.ndim == 3 and a.shape[1] else a
    if layout == "cir" and "pulse" not in kw and "bandwidth_hz" not in kw:
        kw["bandwidth_hz"] = B
    if isinstance(kw.get("noise_var"), np.ndarray):
        kw["noise_var"] = 1e-14
    if len(np.shape(t)) == 1 and np.shape(t)[0] in (S, 0) and rng.random() < 0.5:
        kw["t"] = t
    what = f"estimate(S={S}, N={N}, {layout}) with {mutations}"
    return what, lambda: check_paths(sl.estimate(resp, **kw))


def fuzz_arrays(kind: Kind, n: int, tmp: Path) -> None:
    s = sl.Scenario.preset("sensors2019")
    for i in range(n):
        rng = rng_of("arrays", i)
        what, case = arrays_case(rng, s)
        kind.run(f"arrays case {i}: {what}", case)


# --------------------------------------------------------------------------------------------
# noise_free: noise-free responses (tests/fuzz.rs fuzz_noise_free_responses)

NOISE_EDGES = [0.0, 5e-324, 1e-300, 1e200, 1.0000001e200, float(np.finfo(float).max)]


def fuzz_noise_free(kind: Kind, n: int, tmp: Path) -> None:
    for i in range(n):
        rng = rng_of("noise_free", i)
        r = rng.integers(5)
        bins = N_BINS if r < 3 else int(rng.integers(2, 65)) if r < 4 else int(rng.integers(65, 2049))
        df = B / bins
        span = 1 / df
        k = int(rng.integers(1, 9))
        u = rng.uniform(0, 1, k)
        u[rng.random(k) < 1 / 8] = 0.0
        edge = rng.random(k) < 1 / 8
        u[edge] = rng.uniform(0.999, 1.0, int(edge.sum()))
        lg = rng.uniform(-9, 3, k)
        scale = None if rng.random() < 0.5 else int(rng.integers(-100, 121))
        amp = 10.0 ** (lg + (scale or 0)) * np.exp(1j * rng.uniform(0, 2 * np.pi, k))
        f = (np.arange(bins) - (bins - 1) / 2) * df
        with np.errstate(all="ignore"):
            h = np.exp(-2j * np.pi * np.outer(f, u * span)) @ amp
        x = rng.integers(8)
        nv = None if x < 3 else 1e-40 if x < 5 else log_uniform(rng, -60, 250) if x < 7 else NOISE_EDGES[rng.integers(6)]
        max_paths = 12 if rng.random() < 0.75 else int(rng.integers(1, 65))
        snaps = 1 if rng.random() < 0.8 else int(rng.integers(2, 4))
        resp = np.tile(h, (snaps, 1)) if snaps > 1 else h
        what = (f"noise_free case {i}: {bins} bins, paths (delay/span, log10|a|) "
                f"{list(zip(u.round(6).tolist(), lg.round(3).tolist()))}, scale 1e{scale}, noise_var {nv!r}, "
                f"max_paths {max_paths}, {snaps} snapshots")
        kind.run(what, lambda: check_paths(
            sl.estimate(resp, freq_hz=f, noise_var=nv, max_paths=max_paths), (0.0, span)))


# --------------------------------------------------------------------------------------------
# cir_windows: CIR tap windows (tests/fuzz.rs fuzz_cir_windows)


def band_kernel(k_max: int, half_edge: bool, theta: np.ndarray) -> np.ndarray:
    """sum_k w_k e^{jk theta} over the bins a band-limited CIR holds (|k| <= k_max; weight 1/2
    at +-k_max when that bin lies at B/2), by the Dirichlet kernel's closed form."""

    def dirichlet(k: int, t: np.ndarray) -> np.ndarray:
        s = np.sin(0.5 * t)
        with np.errstate(all="ignore"):
            d = np.sin((k + 0.5) * t) / s
        return np.where(s == 0.0, 2 * k + 1.0, d)

    if half_edge:
        return dirichlet(k_max - 1, theta) + np.cos(k_max * theta)
    return dirichlet(k_max, theta)


def cir_taps(m: int, dt: float, t0: float, b: float, paths: list[tuple[float, complex]]) -> tuple[np.ndarray, int]:
    big_t = m * dt
    x = b * big_t / 2
    if abs(x - round(x)) <= 1e-9 * x:
        k_max, half = int(round(x)), True
    else:
        k_max, half = int(math.floor(x)), False
    t = t0 + np.arange(m) * dt
    acc = np.zeros(m, complex)
    for tau, a in paths:
        u = (t - tau) / big_t
        u -= np.round(u)
        acc += a * (band_kernel(k_max, half, 2 * np.pi * u) / (b * big_t))
    return acc, (2 * k_max - 1 if half else 2 * k_max + 1)


def fuzz_cir_windows(kind: Kind, n: int, tmp: Path) -> None:
    posed_count = 0
    for i in range(n):
        posed_count += cir_window_case(kind, i)
    print(f"fuzz cir_windows: {posed_count} of {n} cases well posed (delays checked to 0.05/B)")


def cir_window_case(kind: Kind, i: int) -> int:
    """Runs case `i`; returns 1 when it was well posed (its delays checked to 0.05/B)."""
    posed_count = 0
    rng = rng_of("cir_windows", i)
    b = 120e6 if rng.random() < 0.6 else log_uniform(rng, 7.0, 9.3)
    r = rng.integers(8)
    taps = (int(rng.integers(2, 17)) if r < 1 else int(rng.integers(17, 257)) if r < 4
            else int(rng.integers(257, 1025)) if r < 6 else 1 << int(rng.integers(1, 11)))
    r = rng.integers(6)
    ratio = 1.0 if r < 2 else 2.0 if r < 3 else float(rng.uniform(1, 4))
    r = rng.integers(7)
    tap0 = (0.0 if r < 2 else float(rng.uniform(-10e-6, 10e-6)) if r < 6
            else float(rng.choice([-10e-6, 10e-6, 100e-9, 1e-6])))
    k = int(rng.integers(1, 4))
    frac = rng.uniform(0, 1, k)
    z = rng.random(k)
    frac[z < 0.1] = 0.0
    hi = z > 0.9
    frac[hi] = rng.uniform(0.99, 1.0, int(hi.sum()))
    dbs = rng.uniform(0, 40, k)
    level = float(rng.uniform(-6, 3))
    snr_db = float(rng.uniform(20, 40) if rng.random() < 1 / 3 else rng.uniform(40, 60))
    dt = 1 / (b * ratio)
    window = taps * dt
    truth = [(tap0 + u * window, 10 ** (level - d / 20) * np.exp(1j * rng.uniform(0, 2 * np.pi)))
             for u, d in zip(frac, dbs)]
    h, bins = cir_taps(taps, dt, tap0, b, truth)
    weakest = min(abs(a) ** 2 for _, a in truth)
    var = max(bins, 1) * weakest * 10 ** (-snr_db / 10)
    res = 1 / b
    posed = (
        bins >= 32 and dbs.max() - dbs.min() <= 20 and snr_db >= 40
        and tap0 >= 0  # the front end drops delays <= 0 (`in_reference`)
        and all(tau - tap0 >= 2 * res and tap0 + window - tau >= 2 * res for tau, _ in truth)
        and all(abs(p[0] - q[0]) >= 3 * res for j, p in enumerate(truth) for q in truth[j + 1:])
    )
    what = (f"cir_windows case {i}: B {b!r} Hz, {taps} taps at {dt!r} s from tap0 {tap0!r} s, "
            f"paths (delay s, dB) {[(tau, round(float(d), 2)) for (tau, _), d in zip(truth, dbs)]}, "
            f"level {level:.3f}, noise_var {var!r}")

    def case() -> None:
        # `noise_var` is per tap, the estimator's (and `var`) per bin: the factor between them
        # is the per-bin variance reported for a stated 1 W per tap.
        probe = sl.estimate(h, tap0_s=tap0, tap_spacing_s=dt, bandwidth_hz=b, noise_var=1.0)
        check_paths(probe, (tap0, tap0 + window))
        per_tap = var / float(probe.noise_var[0])
        p = sl.estimate(h, tap0_s=tap0, tap_spacing_s=dt, bandwidth_hz=b, noise_var=per_tap)
        check_paths(p, (tap0, tap0 + window))
        used = float(p.noise_var[0])
        if posed and bins * weakest >= 1e4 * used * (1 - 1e-9):
            nonlocal posed_count
            posed_count += 1
            for tau, _ in truth:
                best = np.min(np.abs(p.delay - tau)) if len(p) else np.inf
                if not best <= 0.05 / b:
                    raise Bad(f"well posed, {bins} bins: the path at {tau!r} s estimated "
                              f"{best * b:.3f}/B off (> 0.05/B); estimates {p.delay.tolist()}")

    kind.run(what, case)
    return posed_count


# --------------------------------------------------------------------------------------------
# simulator: small scenes and scenes over the caps through simulate_recording
# (tests/fuzz.rs fuzz_simulator_truth)

MAX_TRUTH_PATHS = 1 << 20
WALK = {"waypoints_m": [[2.0, 4.0], [16.0, 4.0], [16.0, 16.0], [4.0, 16.0], [4.0, 8.0]],
        "speed_mps": 1.4, "turn_radius_m": 2.5}
NODES = [[0.0, 0.0], [-5.0, 12.0], [10.0, 10.0], [-6.0, -8.0], [12.0, -6.0]]


def sim_point(rng: np.random.Generator) -> list[float]:
    r = rng.random()
    if r < 0.02:
        return list(NODES[rng.integers(len(NODES))])
    if r < 0.03:
        return rng.uniform(-1e6, 1e6, 2).tolist()
    return rng.uniform(-60, 60, 2).tolist()


def sim_scene(rng: np.random.Generator, scatterers: int, walls: int) -> dict[str, Any]:
    ws = [{"a_m": [-8.0, 24.0], "b_m": [30.0, 24.0], "gamma": -0.6}][:walls]
    while len(ws) < walls:
        a = sim_point(rng)
        ln, d = rng.uniform(0.01, 80), rng.uniform(0, 2 * np.pi)
        ws.append({"a_m": a, "b_m": [a[0] + ln * math.cos(d), a[1] + ln * math.sin(d)],
                   "gamma": float(rng.uniform(-1, 1))})
    return {
        "walls": ws,
        "scatterers": [{"position_m": sim_point(rng), "rcs_m2": float(10 ** rng.uniform(-2, 2))}
                       for _ in range(scatterers)],
        "walk": dict(WALK),
    }


INVALID = [
    ("walls", 65), ("scatterers", 4097), ("subcarriers", 0), ("subcarriers", 1), ("subcarriers", 65_537),
    ("subcarriers", 2**64 - 1), ("dt_s", 0.0), ("dt_s", -1.0), ("dt_s", math.nan), ("dt_s", math.inf),
    ("dt_s", 1e-10), ("dt_s", 1e4), ("duration_s", -1.0), ("duration_s", math.nan),
    ("duration_s", math.inf), ("duration_s", 2e6), ("centres", 0), ("centres", 65), ("rcs", 0.0),
    ("rcs", -1.0), ("rcs", math.nan), ("rcs", 1e-9), ("rcs", 1e9), ("gamma", 1.5), ("gamma", -1.01),
    ("gamma", math.nan), ("degenerate_wall", None), ("coordinate", 1e300), ("coordinate", math.nan),
    ("coordinate", -1e8), ("calibration_duration", -1.0), ("calibration_duration", 1e9),
    ("speed", 0.0), ("speed", math.inf),
]


def sim_case(rng: np.random.Generator) -> tuple[str, str, dict[str, Any], dict[str, Any]]:
    """(class, description, scene, keywords of simulate_recording)."""
    dt = 2.048e-3
    r = rng.integers(10)
    if r < 6:  # small: a few snapshots of a few rays
        cls = "small"
        sc = int(rng.choice([0, 1, 2, 4, 8, 64, 256]))
        wl = int(rng.choice([0, 1, 2, 3, 8]))
        scene = sim_scene(rng, sc, wl)
        scene["subcarriers"] = int(rng.choice([2, 16, 64, 241]))
        if rng.random() < 0.3:
            dt = log_uniform(rng, -6, 1)
        scene["second_order"] = bool(rng.integers(2))
        scene["double_reflections"] = bool(rng.integers(2))
        if rng.random() < 0.25:
            scene["body"] = {"centres": int(rng.integers(1, 65))}
        if rng.random() < 0.3:
            scene["dynamic_range_db"] = float(rng.uniform(0, 300))
        if rng.random() < 0.3:
            scene["clock"] = {"timing_offset_s": 1e-7, "carrier_phase": True, "agc_step_db": 3.0,
                              "agc_every": 4, "phase_noise_rad": 0.05}
        k = int(rng.integers(1, 6))
        kw = dict(duration=(k - 1 + 0.9 * rng.random()) * dt, dt=dt,
                  calibration_duration=float(rng.choice([0.0, dt, 3 * dt])))
    elif r < 7:  # samples over the cap (64 Mi): long and fine
        cls = "samples"
        scene = sim_scene(rng, int(rng.integers(0, 9)), 1)
        scene["subcarriers"] = int(2 ** rng.uniform(10, 16))
        dt = log_uniform(rng, -9, -6)
        kw = dict(dt=dt, duration=(64 << 20) / (4 * scene["subcarriers"]) * dt * rng.uniform(1.1, 100))
    elif r < 8:  # static paths x snapshots over the truth's cap
        cls = "truth"
        sc = int(rng.integers(2048, 4097))
        scene = sim_scene(rng, sc, int(rng.integers(0, 5)))
        scene["subcarriers"] = int(rng.integers(2, 65))
        k = rng.uniform(1.0, 4.0) * 2 * MAX_TRUTH_PATHS / (4 * (1 + sc))
        kw = dict(dt=dt, duration=(k - 1 + 0.5) * dt)
    elif r < 9:  # static paths x snapshots x subcarriers over the work cap
        cls = "work"
        scene = sim_scene(rng, int(rng.integers(3584, 4097)), 0)
        scene["subcarriers"] = int(rng.integers(50_000, 65_537))
        kw = dict(dt=dt, duration=(int(rng.integers(48, 64)) - 0.5) * dt)
    else:  # an invalid field on a small scene
        cls = "invalid"
        scene = sim_scene(rng, 2, 1)
        scene["subcarriers"] = 16
        kw = dict(dt=dt, duration=2 * dt, calibration_duration=0.0)
        field, v = INVALID[rng.integers(len(INVALID))]
        if field == "walls":
            scene["walls"] = [scene["walls"][0]] * 65
        elif field == "scatterers":
            scene["scatterers"] = [{"position_m": [i * 0.01, 20.0], "rcs_m2": 1.0} for i in range(4097)]
        elif field == "subcarriers":
            scene["subcarriers"] = v
        elif field == "dt_s":
            kw["dt"] = v
        elif field == "duration_s":
            kw["duration"] = v
        elif field == "centres":
            scene["body"] = {"centres": v}
        elif field == "rcs":
            scene["scatterers"].append({"position_m": [3.0, 3.0], "rcs_m2": v})
        elif field == "gamma":
            scene["walls"].append({"a_m": [-8.0, -9.0], "b_m": [30.0, -9.0], "gamma": v})
        elif field == "degenerate_wall":
            scene["walls"].append({"a_m": [1.0, 1.0], "b_m": [1.0, 1.0 + 1e-4], "gamma": 0.5})
        elif field == "coordinate":
            scene["scatterers"].append({"position_m": [v, 0.0], "rcs_m2": 1.0})
        elif field == "calibration_duration":
            kw["calibration_duration"] = v
        elif field == "speed":
            kw["speed"] = v
        cls = f"invalid {field}={v!r}"
    kw["seed"] = int(rng.integers(2**63))
    kw.setdefault("calibration_duration", 0.0)
    what = (f"{cls}: {len(scene['scatterers'])} scatterers, {len(scene['walls'])} walls, "
            f"{scene.get('subcarriers')} subcarriers, {kw}")
    return cls, what, scene, kw


def check_simulation(out: Any, small: bool) -> None:
    rec, cal, truth = out
    if not small:
        raise Bad("accepted, though over a cap")
    for r in (rec, cal):
        check_recording(r)
        if r.noise_var is not None and not (r.noise_var > 0).all():
            raise Bad(f"noise_var {r.noise_var}")
    finite_tree("truth", truth)
    entries = sum(len(paths) for links in truth.get("paths", []) for paths in links)
    if entries > MAX_TRUTH_PATHS:
        raise Bad(f"{entries} true paths > {MAX_TRUTH_PATHS}")
    if len(truth.get("paths", [])) != len(rec):
        raise Bad(f"{len(rec)} snapshots, a truth of {len(truth.get('paths', []))} path lists")


def fuzz_simulator(kind: Kind, n: int, tmp: Path) -> None:
    s = sl.Scenario.preset("sensors2019")
    for i in range(n):
        rng = rng_of("simulator", i)
        cls, what, scene, kw = sim_case(rng)
        small = cls == "small"
        kind.run(f"simulator case {i}: {what}",
                 lambda: check_simulation(sl.simulate_recording(s, scene=scene, **kw), small),
                 budget=BUDGET_S if small else REFUSE_S)


# --------------------------------------------------------------------------------------------
# The tests: each sub-kind in a child interpreter

KINDS: dict[str, Callable[[Kind, int, Path], None]] = {
    "npz": fuzz_npz,
    "arrays": fuzz_arrays,
    "noise_free": fuzz_noise_free,
    "cir_windows": fuzz_cir_windows,
    "simulator": fuzz_simulator,
}


def child(name: str) -> int:
    kind = Kind(name)
    with tempfile.TemporaryDirectory() as tmp:
        KINDS[name](kind, cases_of(name), Path(tmp))
    for f in kind.failures[:20]:
        print("FAIL", f)
    if len(kind.failures) > 20:
        print(f"... and {len(kind.failures) - 20} more failures")
    print(kind.summary())
    return 1 if kind.failures else 0


def run_child(name: str, capsys: Any, tmp_path: Path) -> None:
    last = tmp_path / "last_case"
    env = dict(os.environ, SCATTERLOC_FUZZ_LAST=str(last))
    # Generous for a loaded machine: every case has its own budget inside the child.
    limit = 120 + 2 * BUDGET_S * cases_of(name) / 10
    try:
        r = subprocess.run([sys.executable, str(Path(__file__).resolve()), name], cwd=HERE, env=env,
                           capture_output=True, text=True, timeout=limit)
    except subprocess.TimeoutExpired:
        case = last.read_text() if last.exists() else "?"
        raise AssertionError(f"fuzz {name}: no end after {limit:.0f} s; the case running: {case}")
    summary = [ln for ln in r.stdout.splitlines() if ln.startswith("fuzz ")]
    with capsys.disabled():
        for ln in summary:
            print("\n" + ln, end="")
    case = last.read_text() if last.exists() else "?"
    assert r.returncode == 0, (
        f"fuzz {name}: the child exited {r.returncode}"
        + (f" (signal {-r.returncode}; the case running: {case})" if r.returncode < 0 else "")
        + f"\n{r.stdout[-20000:]}\n{r.stderr[-5000:]}"
    )


def test_fuzz_npz(capsys, tmp_path):
    run_child("npz", capsys, tmp_path)


def test_fuzz_arrays(capsys, tmp_path):
    run_child("arrays", capsys, tmp_path)


def test_fuzz_noise_free(capsys, tmp_path):
    run_child("noise_free", capsys, tmp_path)


def test_fuzz_cir_windows(capsys, tmp_path):
    run_child("cir_windows", capsys, tmp_path)


def test_fuzz_simulator(capsys, tmp_path):
    run_child("simulator", capsys, tmp_path)


if __name__ == "__main__":
    sys.exit(child(sys.argv[1]))
