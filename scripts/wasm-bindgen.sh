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
installed() { [ -x "$bindgen" ] && "$bindgen" --version | grep -q " $version"; }
mkdir -p "$tools"
# one install at a time (scripts/test.sh starts one early, in the background, and the suites'
# scripts ask again): the others wait for it here, then find it installed
exec 9> "$tools/.install.lock"
flock 9
if ! installed; then
    echo "== installing wasm-bindgen-cli $version into $tools" >&2
    # --debug: a test tool, built in half the time of a release build (it runs in under a
    # second either way); in its own build directory, so that it never waits for the
    # workspace's. --locked first (the release's own lock file); a registry mirror that lacks
    # one of its pinned versions resolves the newest compatible ones instead
    cargo_install() { CARGO_TARGET_DIR="$tools/build" cargo install -q --debug wasm-bindgen-cli --version "=$version" --root "$tools" "$@"; }
    cargo_install --locked >&2 2>/dev/null || cargo_install >&2 ||
        { echo "cargo install wasm-bindgen-cli $version failed" >&2; exit 1; }
fi
echo "$bindgen"
