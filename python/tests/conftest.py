"""Shared fixtures of the package's tests: the ``scatterloc`` CLI the results are compared
with (``SCATTERLOC_CLI``, else ``target/release`` or ``target/debug`` of this repository), run
in a temporary directory, its JSON parsed with ``json.loads`` (as the package's ``to_dict()``
does), and helpers to compare documents."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import Any

import pytest
from jsondoc import TIMING_KEYS, assert_bitwise, strip_timing

__all__ = ["TIMING_KEYS", "assert_bitwise", "strip_timing"]

ROOT = Path(__file__).resolve().parents[2]


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
