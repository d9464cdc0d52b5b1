#!/usr/bin/env bash
# The Python package (python/, issue 27): sets up the pinned virtualenv .tools/py (idempotent),
# installs the package from the clone with `pip install ./python` (a maturin build of the Rust
# extension, abi3), then runs its pytest suite against the CLI (SCATTERLOC_CLI, default
# target/debug/scatterloc, built first when missing) and mypy --strict on the code of
# docs/python.md. `bash scripts/python.sh bench` runs the benchmark (python/bench/bench.py)
# instead of the tests.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
VENV=.tools/py
PY="$VENV/bin/python"

if ! "$PY" -c 'import sys; assert sys.version_info >= (3, 9)' 2>/dev/null; then
  rm -rf "$VENV"
  if ! python3 -m venv "$VENV"; then
    # Debian's python3 has venv in its own package.
    if [ "$(id -u)" -ne 0 ]; then
      echo "python: as root, run: apt-get install -y python3-venv" >&2
      exit 1
    fi
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-venv >/dev/null
    rm -rf "$VENV"
    python3 -m venv "$VENV"
  fi
fi
want=$(sha256sum python/requirements-test.txt | awk '{print $1}')
if [ "$(cat "$VENV/.requirements.sha256" 2>/dev/null || true)" != "$want" ]; then
  "$PY" -m pip install -q --disable-pip-version-check -r python/requirements-test.txt
  echo "$want" >"$VENV/.requirements.sha256"
fi

# The package exactly as a user installs it from the clone (an isolated maturin build).
t0=$SECONDS
"$PY" -m pip install -q --disable-pip-version-check --force-reinstall --no-deps ./python
echo "pip install ./python: $((SECONDS - t0)) s"
# A development build (maturin develop) leaves its extension in the source folder; the tests
# must import the installed wheel, so they run from outside the source tree.
"$PY" - <<'PY'
import scatterloc, sys
print("scatterloc", scatterloc.__version__, "from", scatterloc.__file__, "python", sys.version.split()[0])
PY

if [ "${1:-test}" = "bench" ]; then
  shift
  exec "$PY" python/bench/bench.py "$@"
fi

export SCATTERLOC_CLI="${SCATTERLOC_CLI:-$PWD/target/debug/scatterloc}"
if [ ! -x "$SCATTERLOC_CLI" ]; then
  cargo build --bin scatterloc
fi

# The docs' tour, extracted from docs/python.md: type-checked against the package's stubs
# (mypy --strict) and run, in a temporary directory (it writes a recording and figures).
ROOT=$PWD
tour=$(mktemp -d)
trap 'rm -rf "$tour"' EXIT
"$PY" scripts/python_tour.py docs/python.md "$tour/tour.py"
(cd "$tour" && "$ROOT/$PY" -m mypy --strict --no-incremental --cache-dir=/dev/null \
  --config-file "$ROOT/python/mypy.ini" tour.py)
t0=$SECONDS
(cd "$tour" && MPLBACKEND=Agg "$ROOT/$PY" tour.py)
echo "the tour ran in $((SECONDS - t0)) s"

# The test suite, from its own folder (it imports the installed package, not python/scatterloc).
(cd python/tests && "$ROOT/$PY" -m pytest -q -p no:cacheprovider .)
