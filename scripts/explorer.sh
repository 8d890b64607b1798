#!/usr/bin/env bash
# The explorer (issue 47): afmdyn in a static web page over the WebAssembly engine.
#   bash scripts/explorer.sh build         builds the site into ${CARGO_TARGET_DIR:-target}/explorer/site
#   bash scripts/explorer.sh serve [PORT]  builds it and serves it on http://127.0.0.1:PORT/ (8047)
# Build: crates/afmdyn-wasm for wasm32-unknown-unknown (release), its JavaScript glue by
# wasm-bindgen-cli (--target web; scripts/wasm-bindgen.sh installs it), the page's npm packages
# (explorer/package-lock.json: Plotly's basic bundle, smol-toml, esbuild, playwright-core for the
# tests) and esbuild's bundle (explorer/build.mjs). The site is plain files: any static host
# serves it.
set -euo pipefail
cd "$(dirname "$0")/.."
TARGET=${CARGO_TARGET_DIR:-target}
what=${1:-serve}
port=${2:-8047}

command -v npm > /dev/null || {
    echo "== installing Node.js and npm (Debian nodejs, npm)"
    if [ "$(id -u)" = 0 ]; then apt-get update -qq && apt-get install -y -qq nodejs npm > /dev/null;
    else sudo apt-get update -qq && sudo apt-get install -y -qq nodejs npm > /dev/null; fi
}
bindgen=$(bash scripts/wasm-bindgen.sh)
echo "== afmdyn-wasm for wasm32-unknown-unknown"
cargo build -q --release -p afmdyn-wasm --target wasm32-unknown-unknown
pkg=$TARGET/explorer/pkg
"$bindgen" --target web --out-dir "$pkg" "$TARGET/wasm32-unknown-unknown/release/afmdyn_wasm.wasm"
if [ ! -d explorer/node_modules ] || [ explorer/package-lock.json -nt explorer/node_modules/.package-lock.json ]; then
    echo "== npm ci (explorer/package-lock.json)"
    (cd explorer && npm ci --no-audit --no-fund --loglevel=error)
fi
node explorer/build.mjs --pkg "$pkg" --out "$TARGET/explorer/site"
case "$what" in
    build) ;;
    serve)
        echo "== serving $TARGET/explorer/site on http://127.0.0.1:$port/ (Ctrl-C stops)"
        exec python3 -m http.server "$port" --bind 127.0.0.1 --directory "$TARGET/explorer/site" ;;
    *) echo "usage: bash scripts/explorer.sh [build|serve [PORT]]" >&2; exit 2 ;;
esac
