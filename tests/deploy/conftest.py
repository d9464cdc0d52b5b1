"""Fixtures of the scale-out tests (issue 28): the CLI under test (SCATTERLOC_CLI, default
target/debug/scatterloc), the repository's docs, and — for test_slurm.py — the local Slurm
cluster of scripts/slurm-local.sh (SLURM_CONF)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
# The JSON comparison helpers live with the package's tests (one home).
sys.path.insert(0, str(ROOT / "python" / "tests"))
from jsondoc import TIMING_KEYS, assert_bitwise, strip_timing  # noqa: E402

__all__ = ["TIMING_KEYS", "assert_bitwise", "strip_timing"]


@pytest.fixture(scope="session")
def cli() -> Path:
    p = Path(os.environ.get("SCATTERLOC_CLI", ROOT / "target" / "debug" / "scatterloc")).resolve()
    assert p.exists(), f"no scatterloc CLI at {p}: build it (cargo build) or set SCATTERLOC_CLI"
    return p


def run(args: list[str], cwd: Path, env: dict[str, str] | None = None, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return subprocess.run(args, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                          env={**os.environ, **(env or {})})


def load(p: Path) -> Any:
    return json.loads(p.read_text())
