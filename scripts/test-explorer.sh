#!/usr/bin/env bash
# The explorer in a real browser (issue 47, part of the README's test command): installs Debian's
# chromium and chromium-driver with apt-get when missing (no browser download), builds the site
# (scripts/explorer.sh build: the wasm engine, wasm-bindgen-cli from crates.io, the page's npm
# packages from explorer/package-lock.json), serves it on 127.0.0.1 (a free port) and drives
# headless Chromium with playwright-core (explorer/tests/browser.mjs): the default Fig. 5
# diagram, a click on a point against `afmdyn orbit --json`, the approach curve of a probe preset
# against `afmdyn approach --json`, keyboard, export, errors, the URL; saves
# ${CARGO_TARGET_DIR:-target}/explorer/screenshot.png.
# Prints "explorer: N passed, M failed" last; exit status 0 only when all passed.
set -uo pipefail
cd "$(dirname "$0")/.."
TARGET=${CARGO_TARGET_DIR:-target}
fail() { echo "explorer: 0 passed, 1 failed ($1)"; exit 1; }

chromium=$(command -v chromium || true)
if [ -z "$chromium" ]; then
    echo "== installing Debian's chromium and chromium-driver"
    if [ "$(id -u)" = 0 ]; then apt-get update -qq && apt-get install -y -qq chromium chromium-driver > /dev/null;
    else sudo apt-get update -qq && sudo apt-get install -y -qq chromium chromium-driver > /dev/null; fi
    chromium=$(command -v chromium) || fail "no chromium"
fi
bash scripts/explorer.sh build || fail "building the site"
cargo build -q --release -p afmdyn-cli || fail "native build"

port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
log=$(mktemp)
python3 -m http.server "$port" --bind 127.0.0.1 --directory "$TARGET/explorer/site" > "$log" 2>&1 &
server=$!
trap 'kill "$server" 2> /dev/null; rm -f "$log"' EXIT
for _ in $(seq 50); do
    python3 -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:$port/')" 2> /dev/null && break
    sleep 0.1
done
# each wait in the test is bounded (120 s); the whole run too
timeout 900 node explorer/tests/browser.mjs --url "http://127.0.0.1:$port/" \
    --bin "$TARGET/release/afmdyn" --chromium "$chromium" --out "$TARGET/explorer"
code=$?
[ "$code" -ne 124 ] || fail "the browser test ran past 900 s"
exit "$code"
