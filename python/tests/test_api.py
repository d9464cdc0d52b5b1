"""The package's surface: documented (help), typed (the stubs match the compiled module,
mypy's stubtest), nothing public undocumented."""

from __future__ import annotations

import inspect
import pydoc
import subprocess
import sys
from pathlib import Path

import scatterloc as sl

STUBS = Path(sl.__file__).with_name("_scatterloc.pyi")
ALLOWLIST = Path(__file__).resolve().parents[1] / "stubtest-allowlist.txt"


def public_names() -> list[str]:
    return [n for n in sl.__all__ if not n.startswith("_")]


def test_help_documents_every_public_name():
    text = pydoc.render_doc(sl, renderer=pydoc.plaintext)
    assert "ScatterlocError" in text
    for name in public_names():
        obj = getattr(sl, name)
        doc = inspect.getdoc(obj)
        assert doc and len(doc) > 20, f"{name} has no documentation"
        assert name in text, f"help(scatterloc) does not show {name}"


def test_every_method_and_property_is_documented():
    missing = []
    for name in public_names():
        cls = getattr(sl, name)
        if not isinstance(cls, type):
            continue
        for attr, value in vars(cls).items():
            if attr.startswith("_"):
                continue
            if not (inspect.getdoc(value) or "").strip():
                missing.append(f"{name}.{attr}")
    assert not missing, f"undocumented: {missing}"


def test_functions_have_signatures():
    for name in public_names():
        obj = getattr(sl, name)
        if callable(obj) and not isinstance(obj, type):
            sig = inspect.signature(obj)  # pyo3's text signatures
            assert sig.parameters, name


def test_stubs_match_the_compiled_module():
    """mypy's stubtest: every name, parameter, default and kind of the stub against runtime."""
    r = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "scatterloc._scatterloc", "--ignore-disjoint-bases",
         "--allowlist", str(ALLOWLIST)],
        capture_output=True, text=True, timeout=300,
    )
    assert r.returncode == 0, r.stdout + r.stderr


def test_all_is_the_stubs_public_api():
    stub = STUBS.read_text()
    for name in public_names():
        if name == "__version__":
            continue
        assert f"class {name}" in stub or f"def {name}(" in stub, f"{name} missing from the stub"
    assert (Path(sl.__file__).with_name("py.typed")).exists()
