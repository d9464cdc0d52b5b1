#!/usr/bin/env bash
# Regenerates the figures in docs/ from the papers' settings, asserts every spec check at full
# size (the library's unit tests and the #[ignore]d checks included) and prints the numbers
# docs/reproduction.md quotes. Slow: over an hour here (see README).
#
#   bash scripts/reproduce.sh           everything (checks, figures, numbers)
#   bash scripts/reproduce.sh --fast    the same without the two long filter studies (below)
#   bash scripts/reproduce.sh --checks  only the full-size spec checks (release build)
#
# The runs' JSON (and the stand-in's files) stay in $REPRODUCE_OUT (default target/reproduce),
# so every number printed at the end can be read again from them.
#
# Regenerated: docs/fig3.png, fig3_fast.png, fig3_filters.png, fig3_pf.png,
# fig3_filters_ii_fast.png, mtl_fig_va.png, mtl_fig_vb.png, mtl_fig_vc.png, walk.png, plan.png.
# Not regenerated here, and why:
# - --fast skips fig3_filters.png (EKF + UKF at paper scale: 46 min 37 s on this 2-core machine
#   under other load) and fig3_pf.png (PF, 160 runs per scenario at the paper step: 21.6 min);
# - the page screenshots (docs/screenshot*.png) need Chromium, chromedriver and the page's wasm:
#   `cargo run --example screenshot` (examples/screenshot.rs; SCATTERLOC_SCREENSHOT_HASH and
#   SCATTERLOC_SCREENSHOT_OUT choose the view and the file). docs/reproduction.md reads
#   [S] Fig. 2a's colours near the receivers from the committed docs/screenshot.png;
# - the benchmark numbers (docs/benchmarks.md): `cargo bench` and the e2e timings, machine-bound.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
mode="${1:-all}"
case "$mode" in all | --fast | --checks) ;; *) echo "reproduce.sh: unknown option $mode" >&2; exit 2 ;; esac
start=$SECONDS
step() { printf '\n==== %s (%d s so far)\n' "$*" $((SECONDS - start)); }
out="${REPRODUCE_OUT:-target/reproduce}"
mkdir -p "$out"

step "full-size spec checks (release; the library's unit tests and the #[ignore]d checks included)"
# The library's unit tests (spec check 4, the full check-9 table, ...) and every native test
# binary (tests/NAME.rs or tests/NAME/main.rs) except the browser ones (e2e needs chromium and
# www/pkg; wasm runs under wasm-pack).
tests=(--lib)
for f in tests/*.rs tests/*/main.rs; do
  [ -e "$f" ] || continue
  case "$f" in */main.rs) name=$(basename "$(dirname "$f")") ;; *) name=$(basename "$f" .rs) ;; esac
  case "$name" in e2e | wasm | common) continue ;; esac
  tests+=(--test "$name")
done
cargo test --release "${tests[@]}" -- --include-ignored 2>&1 | tee "$out/checks.log" |
  grep -E '^test result|FAILED|panicked' || true
if grep -qE 'test result: FAILED|^failures:' "$out/checks.log"; then
  echo "a full-size spec check failed: see $out/checks.log" >&2
  exit 1
fi
[ "$mode" = "--checks" ] && { echo "checks passed in $((SECONDS - start)) s"; exit 0; }

step "release CLI"
cargo build --release --bin scatterloc
bin="${CARGO_TARGET_DIR:-target}/release/scatterloc"

step "[S] Fig. 3 at paper scale (docs/fig3.png): 3 x 250 000 runs x 4883 steps"
"$bin" montecarlo --out docs/fig3.png --json "$out/fig3.json" > /dev/null
step "[S] Fig. 3, fast profile (docs/fig3_fast.png)"
"$bin" montecarlo --dt 0.1 --runs 1000 --noise-runs 10 --out docs/fig3_fast.png --json "$out/fig3_fast.json" > /dev/null

step "EKF, UKF, PF at the fast profile, scenarios II (docs/fig3_filters_ii_fast.png) and III"
for s in II III; do
  fig=()
  [ "$s" = II ] && fig=(--out docs/fig3_filters_ii_fast.png)
  "$bin" montecarlo --trajectory "$s" --filters ekf,ukf,pf --particles 1000 --runs 200 --noise-runs 5 \
    --dt 0.1 "${fig[@]}" --json "$out/filters_fast_$s.json" > /dev/null
  "$bin" montecarlo --trajectory "$s" --filters pf --particles 10000 --runs 200 --noise-runs 5 \
    --dt 0.1 --json "$out/pf10k_fast_$s.json" > /dev/null
done

if [ "$mode" = all ]; then
  step "EKF and UKF at paper scale (docs/fig3_filters.png): 46 min 37 s here under other load"
  "$bin" montecarlo --filters ekf,ukf --out docs/fig3_filters.png --json "$out/fig3_filters.json" > /dev/null
  step "EKF and PF, 160 runs per scenario at the paper step (docs/fig3_pf.png): 21.6 min here"
  "$bin" montecarlo --filters ekf,pf --particles 1000 --runs 160 --noise-runs 1 \
    --out docs/fig3_pf.png --json "$out/fig3_pf.json" > /dev/null
else
  step "skipped (--fast): docs/fig3_filters.png and docs/fig3_pf.png"
fi

step "[A] Figs. 3-5 (docs/mtl_fig_va.png, mtl_fig_vb.png, mtl_fig_vc.png) and Table II"
"$bin" mtl roc --experiment va --out docs/mtl_fig_va.png --json "$out/va.json" > /dev/null
"$bin" mtl roc --experiment vb --empirical --out docs/mtl_fig_vb.png --json "$out/vb.json" > /dev/null
"$bin" mtl roc --experiment vc --empirical --out docs/mtl_fig_vc.png --json "$out/vc.json" > /dev/null
"$bin" mtl table2 --json "$out/table2.json" > "$out/table2.txt"

step "spec 9.6 stand-in (docs/walk.png)"
"$bin" preset sensors2019 > "$out/s.json"
"$bin" simulate-walk --scenario "$out/s.json" --out-dir "$out/walk" > /dev/null
"$bin" calibrate --scenario "$out/s.json" --snapshots "$out/walk/calibration_snapshots.json" \
  --out "$out/cal.json" > /dev/null
"$bin" track --scenario "$out/s.json" --measurements "$out/walk/measurements.json" \
  --calibration "$out/cal.json" --association gated --out docs/walk.png \
  --truth "$out/walk/truth.json" > "$out/track.json"

step "planner (docs/plan.png): sensors2019, 4 Rx, p90 over the whole area, 10 000 evaluations"
"$bin" plan --move rx --objective p90 --roi=-7.5,30,-10,26 --out "$out/plan.json" \
  --figure docs/plan.png > "$out/plan_summary.json"
"$bin" plan --move all --objective p90 --roi=-7.5,30,-10,26 --out "$out/plan_all.json" \
  > "$out/plan_all_summary.json"

step "table"
python3 scripts/reproduce_table.py "$out"
echo
echo "reproduce.sh: done in $((SECONDS - start)) s; the runs' JSON are in $out"
