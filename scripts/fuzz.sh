#!/usr/bin/env bash
# Issue 12 fuzzing at full size: tests/fuzz.rs in release with 10 000 mutated cases of every
# input kind (in process and through the CLI), then one line per kind: cases, time, passes,
# named errors and known failures. `cargo test` runs the same tests with a few cases each.
#
#   scripts/fuzz.sh [--cases N] [--seed N] [--threads N] [--strict] [--collect] [KIND ...]
#
#   --cases N    cases per kind (default 10000; SCATTERLOC_FUZZ_CASES)
#   --seed N     RNG seed (default 12: the same cases as every other default run)
#   --threads N  kinds run in parallel (default 2: one per core of the build machine)
#   --strict     known failures (tests/fuzz.rs KNOWN) fail too
#   --collect    fail nothing; print every distinct failure with a short case (for triage)
#   KIND         run only these kinds: scenario page_edits mtl_scene network_ranges
#                empirical_table calibration ekf cli_delays cli_measurements cli_raw_steps
#                cli_calibration_file cli_snapshots cli_mtl noise_free_responses cir_windows
#                npz_reservations simulator_truth (test names without `fuzz_`)
#
# Budgets: an in-process case over 5 s fails (SCATTERLOC_FUZZ_BUDGET_S), one over 120 s stops
# the run (SCATTERLOC_FUZZ_HARD_S); a CLI case is killed after 15 s (SCATTERLOC_FUZZ_CLI_S) and
# runs under `prlimit --as` of 2048 MB (SCATTERLOC_FUZZ_CLI_MB); the test process itself runs
# under `prlimit --as` of FUZZ_MEM_MB (default 8192) MB.
# The Python kind is python/tests/test_fuzz.py (run by scripts/python.sh; SCATTERLOC_FUZZ_CASES scales it).
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"

cases=${SCATTERLOC_FUZZ_CASES:-10000}
threads=2
filters=()
while [ $# -gt 0 ]; do
  case "$1" in
    --cases) cases=$2; shift 2 ;;
    --seed) export SCATTERLOC_FUZZ_SEED=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --strict) export SCATTERLOC_FUZZ_STRICT=1; shift ;;
    --collect) export SCATTERLOC_FUZZ_COLLECT=1; shift ;;
    -h|--help) sed -n '2,21p' "$0"; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1" >&2; exit 2 ;;
    *) filters+=("fuzz_$1"); shift ;;
  esac
done
export SCATTERLOC_FUZZ_CASES=$cases RUST_BACKTRACE=0

echo "==== building tests/fuzz.rs and the CLI (release)"
bin=$(cargo test --release --test fuzz --no-run 2>&1 | tee /dev/stderr |
  sed -n 's/.*Executable tests\/fuzz.rs (\(.*\))/\1/p')
[ -x "$bin" ] || { echo "fuzz.sh: test binary not found" >&2; exit 1; }

log=$(mktemp); trap 'rm -f "$log"' EXIT
echo "==== $cases cases per kind, $threads kinds at a time"
start=$(date +%s)
set +e
prlimit --as=$(( ${FUZZ_MEM_MB:-8192} * 1024 * 1024 )) -- \
  "$bin" --test-threads="$threads" --nocapture "${filters[@]}" 2>&1 | tee "$log"
status=${PIPESTATUS[0]}
set -e
echo
echo "==== summary ($(( $(date +%s) - start )) s in all)"
grep -E '^fuzz [a-z_]+ ' "$log" | sort || true
grep -E '^test result:' "$log" || true
exit "$status"
