#!/usr/bin/env bash
# Regenerates the ray-traced test corpus tests/data/raytraced/ with NVIDIA Sionna RT on the CPU
# (see scripts/raytrace/generate.py and tests/data/raytraced/README.md). CI never runs this: the
# corpus is committed. Idempotent: installs only what is missing (Debian libLLVM 19, the venv
# .tools/sionna with sionna-rt 2.2.0, which pins mitsuba 3.9.1 and drjit 1.5.0), then traces
# (~20 minutes on two cores). Arguments go to generate.py (e.g. --scenes room, --report).
set -euo pipefail
cd "$(dirname "$0")/../.."

LLVM=/usr/lib/x86_64-linux-gnu/libLLVM-19.so
if [ ! -e "$LLVM" ]; then
    # Dr.Jit's CPU backend needs LLVM; Debian's LLVM 15 aborts on the first trace.
    sudo=""
    [ "$(id -u)" -ne 0 ] && sudo=sudo
    $sudo apt-get update
    $sudo apt-get install -y --no-install-recommends libllvm19
fi
export DRJIT_LIBLLVM_PATH="$LLVM"

VENV=.tools/sionna
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
if ! "$VENV/bin/python" -c 'import sys, importlib.metadata as m; sys.exit(m.version("sionna-rt") != "2.2.0")' 2>/dev/null; then
    "$VENV/bin/pip" install sionna-rt==2.2.0
fi

exec "$VENV/bin/python" scripts/raytrace/generate.py "$@"
