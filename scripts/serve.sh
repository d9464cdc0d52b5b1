#!/usr/bin/env bash
# Sets up (idempotently), builds the wasm in release mode and serves the page on 127.0.0.1:
# www/ as the site's root, with the repository's docs/ and README.md beside it (the Help
# dialog's links; scripts/serve.py, standard library only).
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
bash scripts/setup.sh
wasm-pack build --release --target web --out-dir www/pkg --mode no-install
PORT="${PORT:-8000}"
exec python3 scripts/serve.py --port "$PORT" --bind 127.0.0.1
