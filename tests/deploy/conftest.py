"""Fixtures of the scale-out tests (issue 28): the CLI under test (SCATTERLOC_CLI, default
target/debug/scatterloc), the repository's docs, and — for test_slurm.py — the local Slurm
cluster of scripts/slurm-local.sh (SLURM_CONF)."""

from __future__ import annotations

import json
import math
import os
import subprocess
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
TIMING_KEYS = {"wall_time_s", "ns_per_ekf_step", "wall_ns_per_ekf_step", "threads"}


@pytest.fixture(scope="session")
def cli() -> Path:
    p = Path(os.environ.get("SCATTERLOC_CLI", ROOT / "target" / "debug" / "scatterloc")).resolve()
    assert p.exists(), f"no scatterloc CLI at {p}: build it (cargo build) or set SCATTERLOC_CLI"
    return p


def run(args: list[str], cwd: Path, env: dict[str, str] | None = None, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return subprocess.run(args, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                          env={**os.environ, **(env or {})})


def strip_timing(doc: Any) -> Any:
    if isinstance(doc, dict):
        return {k: strip_timing(v) for k, v in doc.items() if k not in TIMING_KEYS}
    if isinstance(doc, list):
        return [strip_timing(v) for v in doc]
    return doc


def assert_bitwise(a: Any, b: Any, path: str = "$") -> None:
    """``a == b`` with floats compared bit for bit."""
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


def load(p: Path) -> Any:
    return json.loads(p.read_text())
