#!/usr/bin/env bash
# The explorer in a real browser (issue 47, part of the README's test command): installs Debian's
# chromium and chromium-driver with apt-get when missing (no browser download), builds the site
# (scripts/explorer.sh build: the wasm engine, wasm-bindgen-cli from crates.io, the page's npm
# packages from explorer/package-lock.json), serves it on 127.0.0.1 (a free port) and drives
# headless Chromium with playwright-core (explorer/tests/browser.mjs): the default Fig. 5
# diagram, a click on a point against `afmdyn orbit --json`, the approach curve of a probe preset
# against `afmdyn approach --json`, keyboard, export, errors, the URL; saves
# ${CARGO_TARGET_DIR:-target}/explorer/screenshot.png. Then the book (issue 80) in the same
# browser: ${CARGO_TARGET_DIR:-target}/book (built by scripts/test.sh, or here when absent)
# served on 127.0.0.1, its index and getting-started pages opened (explorer/tests/book.mjs).
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

# serve DIR on a free loopback port in the background, its log in LOG, until it answers: the
# port in $served, the server's pid added to $servers (killed on exit)
servers=""
serve() {
    served=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
    python3 -m http.server "$served" --bind 127.0.0.1 --directory "$1" > "$2" 2>&1 &
    servers="$servers $!"
    for _ in $(seq 50); do
        python3 -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:$served/')" 2> /dev/null && break
        sleep 0.1
    done
}
log=$(mktemp)
trap 'kill $servers 2> /dev/null; rm -f "$log" "$log".*' EXIT
serve "$TARGET/explorer/site" "$log"
port=$served
# each wait in the test is bounded (120 s); the whole run too
timeout 900 node explorer/tests/browser.mjs --url "http://127.0.0.1:$port/" \
    --bin "$TARGET/release/afmdyn" --chromium "$chromium" --out "$TARGET/explorer" | tee "$log.explorer"
code=${PIPESTATUS[0]}
[ "$code" -ne 124 ] || fail "the browser test ran past 900 s"
line=$(grep -E '^explorer: [0-9]+ passed, [0-9]+ failed' "$log.explorer" | tail -1)
passed=$(echo "$line" | awk '{print $2 + 0}')
failed=$(echo "$line" | awk '{print $4 + 0}')
[ "$code" -eq 0 ] || [ "$failed" -gt 0 ] || failed=$((failed + 1))

# the book's pages in the same browser (explorer/tests/book.mjs): the book scripts/test.sh built
# into $TARGET/book, or built here when absent (scripts/build-book.sh)
book=$TARGET/book
if [ ! -e "$book/index.html" ]; then
    echo "== the book: bash scripts/build-book.sh $book"
    bash scripts/build-book.sh "$book" || echo "the book's build failed or warned"
fi
if [ -e "$book/index.html" ]; then
    serve "$book" "$log.book"
    book_port=$served
    timeout 120 node explorer/tests/book.mjs --url "http://127.0.0.1:$book_port/" --chromium "$chromium" |
        tee "$log.pages"
    book_code=${PIPESTATUS[0]}
    line=$(grep -E '^book: [0-9]+ passed, [0-9]+ failed' "$log.pages" | tail -1)
    passed=$((passed + $(echo "$line" | awk '{print $2 + 0}')))
    book_failed=$(echo "$line" | awk '{print $4 + 0}')
    [ "$book_code" -eq 0 ] || [ "$book_failed" -gt 0 ] || book_failed=1
    failed=$((failed + book_failed))
else
    echo "FAIL the book's pages: no book in $book"
    failed=$((failed + 1))
fi
echo "explorer: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
