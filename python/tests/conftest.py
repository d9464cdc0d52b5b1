"""Shared fixtures of the package's tests: the ``scatterloc`` CLI the results are compared
with (``SCATTERLOC_CLI``, else ``target/release`` or ``target/debug`` of this repository), run
in a temporary directory, its JSON parsed with ``json.loads`` (as the package's ``to_dict()``
does), and helpers to compare documents."""

from __future__ import annotations

import json
import math
import os
import subprocess
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]

# Keys whose values are timings or machine facts, not results: left out of comparisons.
TIMING_KEYS = {"wall_time_s", "ns_per_ekf_step", "wall_ns_per_ekf_step", "threads", "compute_ms", "write_ms"}


def cli_path() -> Path:
    env = os.environ.get("SCATTERLOC_CLI")
    if env:
        return Path(env).resolve()
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "scatterloc"
        if p.exists():
            return p
    raise RuntimeError("no scatterloc CLI: build it (cargo build) or set SCATTERLOC_CLI")


class Cli:
    """Runs the CLI in ``cwd``."""

    def __init__(self, cwd: Path) -> None:
        self.exe = str(cli_path())
        self.cwd = cwd

    def run(self, *args: str, check: bool = True) -> subprocess.CompletedProcess[str]:
        r = subprocess.run(
            [self.exe, *args], cwd=self.cwd, capture_output=True, text=True, timeout=600
        )
        if check and r.returncode != 0:
            raise AssertionError(f"scatterloc {' '.join(args)} failed ({r.returncode}): {r.stderr}")
        return r

    def json(self, *args: str) -> Any:
        """The JSON the command prints on stdout."""
        return json.loads(self.run(*args).stdout)

    def file(self, name: str) -> Any:
        """A JSON file the CLI wrote."""
        return json.loads((self.cwd / name).read_text())

    def write(self, name: str, doc: Any) -> str:
        """Writes ``doc`` as JSON to ``name`` in the working directory; returns the name."""
        (self.cwd / name).write_text(json.dumps(doc))
        return name


@pytest.fixture
def cli(tmp_path: Path) -> Cli:
    return Cli(tmp_path)


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
