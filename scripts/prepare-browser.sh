#!/usr/bin/env bash
# What the browser suites (scripts/test-wasm.sh, scripts/test-explorer.sh) need, prepared ahead
# of them: Debian's Node.js, npm, chromium and chromium-driver (apt-get, when missing), then the
# explorer's site (scripts/explorer.sh build: wasm-bindgen-cli, the wasm32 engine, the npm
# packages). scripts/test.sh runs it in the background while pytest runs; the suites check
# each step again and do what is still missing, so a failure here shows there, with its reason.
set -uo pipefail
cd "$(dirname "$0")/.."

missing=()
command -v node > /dev/null || missing+=(nodejs)
command -v npm > /dev/null || missing+=(npm)
command -v chromium > /dev/null || missing+=(chromium chromium-driver)
if [ "${#missing[@]}" -gt 0 ]; then
    echo "== installing Debian's ${missing[*]}"
    sudo=()
    [ "$(id -u)" = 0 ] || sudo=(sudo)
    "${sudo[@]}" apt-get update -qq && "${sudo[@]}" apt-get install -y -qq "${missing[@]}" > /dev/null
fi
bash scripts/explorer.sh build
