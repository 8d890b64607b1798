#!/usr/bin/env bash
# Prints the path of wasm-bindgen-cli at the version of the wasm-bindgen crate in Cargo.lock,
# installing it from crates.io into ${CARGO_TARGET_DIR:-target}/tools first when it is missing
# (and the wasm32-unknown-unknown target with rustup). Used by scripts/test-wasm.sh and
# scripts/explorer.sh. Messages go to stderr; exit status 1 when something cannot be had.
set -uo pipefail
cd "$(dirname "$0")/.."
TARGET=${CARGO_TARGET_DIR:-target}
rustup target list --installed 2>/dev/null | grep -q wasm32-unknown-unknown ||
    rustup target add wasm32-unknown-unknown >&2 || { echo "no wasm32 target" >&2; exit 1; }
version=$(awk '/^name = "wasm-bindgen"$/ {getline; gsub(/"/, "", $3); print $3; exit}' Cargo.lock)
[ -n "$version" ] || { echo "no wasm-bindgen in Cargo.lock" >&2; exit 1; }
tools=$TARGET/tools
bindgen=$tools/bin/wasm-bindgen
if ! { [ -x "$bindgen" ] && "$bindgen" --version | grep -q " $version"; }; then
    echo "== installing wasm-bindgen-cli $version into $tools" >&2
    # --locked first (the release's own lock file); a registry mirror that lacks one of its
    # pinned versions resolves the newest compatible ones instead
    cargo install -q wasm-bindgen-cli --version "=$version" --locked --root "$tools" >&2 2>/dev/null ||
        cargo install -q wasm-bindgen-cli --version "=$version" --root "$tools" >&2 ||
        { echo "cargo install wasm-bindgen-cli $version failed" >&2; exit 1; }
fi
echo "$bindgen"
