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
# The fmt and clippy stages of scripts/test.sh.
rustup component add rustfmt clippy >/dev/null 2>&1 || rustup component add rustfmt clippy

# Debian packages: chromium (the page's browser tests) and python3-numpy (/usr/bin/python3 runs
# the numpy snippet of docs/recording.md in tests/library/recording.rs). apt-get update runs
# once, and only when something is missing; installing needs root.
apt_pkgs=()
if ! command -v chromium >/dev/null || ! command -v chromedriver >/dev/null; then
  apt_pkgs+=(chromium chromium-driver)
fi
/usr/bin/python3 -c 'import numpy' 2>/dev/null || apt_pkgs+=(python3-numpy)
if [ ${#apt_pkgs[@]} -gt 0 ]; then
  if [ "$(id -u)" -ne 0 ]; then
    echo "setup: as root, run: apt-get install -y ${apt_pkgs[*]}" >&2
    exit 1
  fi
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${apt_pkgs[@]}" >/dev/null
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

# axe-core (the accessibility engine of tests/e2e/a11y.rs), pinned and checked against the npm
# registry's sha512 integrity; unpacked into the git-ignored .tools/axe-core/ (never served by the
# page, no CDN). npm pack when npm is there, else the same tarball from registry.npmjs.org.
AXE_VERSION=4.14.1
AXE_SHA512=FHfa+lmNjQZfJz1q8wKqIDwC6DExcHt/pkjNQb09a3NPjCKg2rhu5qb2S4r76ASyFNNtuFooJpZe37OgudVGtQ==
AXE_DIR=.tools/axe-core
if [ "$(cat "$AXE_DIR/VERSION" 2>/dev/null || true)" != "$AXE_VERSION" ] || [ ! -s "$AXE_DIR/axe.min.js" ]; then
  tmp=$(mktemp -d)
  tgz="$tmp/axe-core-$AXE_VERSION.tgz"
  if command -v npm >/dev/null; then
    (cd "$tmp" && npm pack --silent "axe-core@$AXE_VERSION" >/dev/null)
  else
    curl -fsSL -o "$tgz" "https://registry.npmjs.org/axe-core/-/axe-core-$AXE_VERSION.tgz"
  fi
  got=$(sha512sum "$tgz" | awk '{print $1}')
  want=$(printf '%s' "$AXE_SHA512" | base64 -d | od -An -v -tx1 | tr -d ' \n')
  if [ "$got" != "$want" ]; then
    echo "setup: axe-core $AXE_VERSION tarball sha512 mismatch (got $got)" >&2
    rm -rf "$tmp"
    exit 1
  fi
  rm -rf "$AXE_DIR" && mkdir -p "$AXE_DIR"
  tar -xzf "$tgz" -C "$AXE_DIR" --strip-components=1
  echo "$AXE_VERSION" >"$AXE_DIR/VERSION"
  rm -rf "$tmp"
fi
