#!/usr/bin/env bash
# Latency and memory of `cir track --follow` (issue 40 §3; docs/benchmarks.md "Live tracking").
# A simulated walk of 4 links × 241 subcarriers (the sensors2019 preset and the hangar scene,
# 2.048 ms snapshots) is streamed `--repeat` times through a pipe into `cir track --follow`,
# whose summary line (stderr) gives the frames, the latency from a frame's last byte read to
# its line written (median, p99, max) and the peak resident memory (VmHWM).
# Usage: scripts/follow-bench.sh FRAMES...   (e.g. 10000 100000); needs `cargo build --release`.
set -euo pipefail
BIN=${BIN:-target/release/scatterloc}
DIR=$(mktemp -d)
trap 'rm -rf "$DIR"' EXIT
"$BIN" preset sensors2019 > "$DIR/s.json"
SNAPS=$("$BIN" cir simulate --scenario "$DIR/s.json" --out-dir "$DIR/sim" --duration 2 \
    --calibration-duration 0.1 | sed -E 's/.*"snapshots":([0-9]+).*/\1/')
for FRAMES in "$@"; do
    REPEAT=$(( (FRAMES + SNAPS - 1) / SNAPS ))
    START=$(date +%s.%N)
    "$BIN" cir stream "$DIR/sim/recording.npz" --repeat "$REPEAT" \
        | "$BIN" cir track --follow --scenario "$DIR/s.json" 2> "$DIR/summary" | wc -l > "$DIR/lines"
    END=$(date +%s.%N)
    echo "{\"asked\":$FRAMES,\"repeat\":$REPEAT,\"wall_s\":$(echo "$END - $START" | bc),\"lines\":$(cat "$DIR/lines"),\"summary\":$(cat "$DIR/summary")}"
done
