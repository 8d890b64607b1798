#!/usr/bin/env bash
# The browser front end's engine under a real WebAssembly runtime (issue 47, part of the README's
# test command): builds crates/afmdyn-wasm for wasm32-unknown-unknown (no threads, no files),
# generates its JavaScript glue with wasm-bindgen-cli at the version of the wasm-bindgen crate in
# Cargo.lock (installed from crates.io into target/tools if missing), and runs
# scripts/wasm-check.mjs under Node.js (Debian's nodejs, installed with apt-get if missing): the
# wasm documents of `orbit` (the paper's Ω = 2.8) and of an approach curve from a probe file
# must equal the native command line's `--json` ones, and a bad value must give its message.
# Prints "wasm: N passed, M failed" last; exit status 0 only when all passed.
set -uo pipefail
cd "$(dirname "$0")/.."
TARGET=${CARGO_TARGET_DIR:-target}
fail() { echo "wasm: 0 passed, 1 failed ($1)"; exit 1; }

command -v node > /dev/null || {
    echo "== installing Node.js (Debian nodejs)"
    if [ "$(id -u)" = 0 ]; then apt-get update -qq && apt-get install -y -qq nodejs > /dev/null;
    else sudo apt-get update -qq && sudo apt-get install -y -qq nodejs > /dev/null; fi
} || fail "no Node.js"
bindgen=$(bash scripts/wasm-bindgen.sh) || fail "wasm-bindgen-cli"
echo "== afmdyn-wasm for wasm32-unknown-unknown"
cargo build -q --release -p afmdyn-wasm --target wasm32-unknown-unknown || fail "wasm build"
cargo build -q --release -p afmdyn-cli || fail "native build"
out=$TARGET/wasm-node
"$bindgen" --target nodejs --out-dir "$out" \
    "$TARGET/wasm32-unknown-unknown/release/afmdyn_wasm.wasm" || fail "wasm-bindgen"
node scripts/wasm-check.mjs "$out/afmdyn_wasm.js" "$TARGET/release/afmdyn"
