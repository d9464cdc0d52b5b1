#!/usr/bin/env bash
# Idempotent, pinned setup of everything the build and the tests need.
# Only package registries are used (crates.io, Debian). Re-running it when all is present takes < 1 s.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"

WASM_PACK_VERSION=0.15.1
# wasm-bindgen-cli must equal the wasm-bindgen version in Cargo.lock exactly.
WB_VERSION=$(awk '$0=="name = \"wasm-bindgen\""{getline; gsub(/version = |"/,""); print; exit}' Cargo.lock)

rustup target add wasm32-unknown-unknown wasm32v1-none >/dev/null 2>&1 || rustup target add wasm32-unknown-unknown wasm32v1-none

if ! command -v chromium >/dev/null || ! command -v chromedriver >/dev/null; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium chromium-driver >/dev/null
fi

ver() { command -v "$1" >/dev/null && "$1" --version 2>/dev/null | awk '{print $2; exit}'; }
if [ "$(ver wasm-pack || true)" != "$WASM_PACK_VERSION" ]; then
  cargo install wasm-pack --version "$WASM_PACK_VERSION" --locked --force
fi
if [ "$(ver wasm-bindgen || true)" != "$WB_VERSION" ]; then
  # The --locked install fails (its lock pins a crate missing from the registry); fall back to unlocked.
  cargo install wasm-bindgen-cli --version "$WB_VERSION" --locked --force \
    || cargo install wasm-bindgen-cli --version "$WB_VERSION" --force
fi
