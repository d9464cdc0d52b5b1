"""Comparing JSON documents (the CLI's output, the package's ``to_dict()``): the one home of
these helpers for the package's tests (python/tests) and the scale-out tests (tests/deploy)."""

from __future__ import annotations

import math
from typing import Any

# Keys whose values are timings or machine facts, not results: left out of comparisons.
TIMING_KEYS = {
    "wall_time_s",
    "ns_per_ekf_step",
    "wall_ns_per_ekf_step",
    "threads",
    "compute_ms",
    "write_ms",
    "kernel",
}


def strip_timing(doc: Any) -> Any:
    """``doc`` without the timing keys (at any depth)."""
    if isinstance(doc, dict):
        return {k: strip_timing(v) for k, v in doc.items() if k not in TIMING_KEYS}
    if isinstance(doc, list):
        return [strip_timing(v) for v in doc]
    return doc


def assert_bitwise(a: Any, b: Any, path: str = "$") -> None:
    """``a == b`` with floats compared bit for bit (and a path to the first difference)."""
    if isinstance(a, dict) and isinstance(b, dict):
        assert list(a) == list(b), f"{path}: keys {list(a)} != {list(b)}"
        for k in a:
            assert_bitwise(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list) and isinstance(b, list):
        assert len(a) == len(b), f"{path}: length {len(a)} != {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            assert_bitwise(x, y, f"{path}[{i}]")
    elif isinstance(a, float) and isinstance(b, float):
        assert a.hex() == b.hex() or (math.isnan(a) and math.isnan(b)), f"{path}: {a!r} != {b!r}"
    else:
        assert a == b and type(a) is type(b), f"{path}: {a!r} != {b!r}"
