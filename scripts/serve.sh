#!/usr/bin/env bash
# Sets up (idempotently), builds the wasm in release mode and serves the page on 127.0.0.1.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
bash scripts/setup.sh
wasm-pack build --release --target web --out-dir www/pkg --mode no-install
PORT="${PORT:-8000}"
echo "scatterloc page: http://127.0.0.1:${PORT}/"
exec python3 -m http.server "$PORT" --bind 127.0.0.1 --directory www
