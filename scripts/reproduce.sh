#!/usr/bin/env bash
# Regenerates every figure in docs/ from the papers' settings, asserts every spec check at full
# size (the #[ignore]d ones included) and prints a table of the numbers docs/reproduction.md
# quotes. Slow: see README for how long it takes here.
#
#   bash scripts/reproduce.sh           everything (figures + full-size checks)
#   bash scripts/reproduce.sh --checks  only the full-size spec checks (release build)
#
# The page screenshots (docs/screenshot*.png) come from the e2e harness: see tests/e2e/screenshot.rs.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
mode="${1:-all}"
start=$SECONDS
step() { printf '\n==== %s (%d s so far)\n' "$*" $((SECONDS - start)); }

step "full-size spec checks (release; the #[ignore]d checks 10 and 11 included)"
# Every native test binary except the browser ones (e2e needs chromium and www/pkg).
tests=()
for f in tests/*.rs; do
  name=$(basename "$f" .rs)
  case "$name" in e2e | wasm) continue ;; esac
  tests+=(--test "$name")
done
cargo test --release "${tests[@]}" -- --include-ignored 2>&1 | tee /tmp/scatterloc-reproduce-checks.log |
  grep -E '^test result|FAILED|panicked' || true
if grep -qE 'test result: FAILED|^failures:' /tmp/scatterloc-reproduce-checks.log; then
  echo "a full-size spec check failed: see /tmp/scatterloc-reproduce-checks.log" >&2
  exit 1
fi
[ "$mode" = "--checks" ] && { echo "checks passed in $((SECONDS - start)) s"; exit 0; }

step "release CLI"
cargo build --release --bin scatterloc
bin=target/release/scatterloc
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

step "[S] Fig. 3 at paper scale (docs/fig3.png): 3 x 250 000 runs x 4883 steps"
"$bin" montecarlo --out docs/fig3.png --json "$work/fig3.json"
step "[S] Fig. 3, fast profile (docs/fig3_fast.png)"
"$bin" montecarlo --dt 0.1 --runs 1000 --noise-runs 10 --out docs/fig3_fast.png --json "$work/fig3_fast.json"

step "[A] Figs. 3-5 (docs/mtl_fig_va.png, mtl_fig_vb.png, mtl_fig_vc.png) and Table II"
"$bin" mtl roc --experiment va --out docs/mtl_fig_va.png --json "$work/va.json"
"$bin" mtl roc --experiment vb --empirical --out docs/mtl_fig_vb.png --json "$work/vb.json"
"$bin" mtl roc --experiment vc --empirical --out docs/mtl_fig_vc.png --json "$work/vc.json"
"$bin" mtl table2 --json "$work/table2.json" > "$work/table2.txt"

step "spec 9.6 stand-in (docs/walk.png)"
"$bin" preset sensors2019 > "$work/s.json"
"$bin" simulate-walk --scenario "$work/s.json" --out-dir "$work/walk" > /dev/null
"$bin" calibrate --scenario "$work/s.json" --snapshots "$work/walk/calibration_snapshots.json" \
  --out "$work/cal.json" > /dev/null
"$bin" track --scenario "$work/s.json" --measurements "$work/walk/measurements.json" \
  --calibration "$work/cal.json" --association gated --out docs/walk.png \
  --truth "$work/walk/truth.json" > "$work/track.json"

step "table"
python3 - "$work" <<'PY'
import json, math, sys
w = sys.argv[1]
def at(doc, key, t):
    ts = doc["t_s"]
    i = min(range(len(ts)), key=lambda k: abs(ts[k] - t))
    v = doc[key][i]
    return v
for name, label in (("fig3.json", "[S] Fig. 3, paper scale"), ("fig3_fast.json", "[S] Fig. 3, fast profile")):
    d = json.load(open(f"{w}/{name}"))
    print(f"\n{label}: eps_EKF / eps_PCRLB (failed runs)")
    print("scenario |    1 s |    2 s |    5 s |   10 s | failed runs / runs")
    for s in d["scenarios"]:
        r = [at(s, "rmse_ekf_m", t) / at(s, "rmse_pcrlb_m", t) for t in (1, 2, 5, 10)]
        print(f"{s['trajectory']:>8} | " + " | ".join(f"{x:6.3f}" for x in r)
              + f" | {s['failed_runs']} / {s['failed_runs'] + s['runs']}")
print("\n[A] Table II (mtl table2):")
print(open(f"{w}/table2.txt").read().rstrip())
for e in ("va", "vb", "vc"):
    d = json.load(open(f"{w}/{e}.json"))
    print(f"\n[A] experiment {e}: curves " + ", ".join(c.get("label", "?") for c in d.get("curves", [])))
steps = json.load(open(f"{w}/track.json"))
print("\nspec 9.6 stand-in (q = 0.1, start at rest, sigma_v = 2 m/s): see docs/reproduction.md")
PY
echo
echo "reproduce.sh: done in $((SECONDS - start)) s"
