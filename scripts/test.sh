#!/usr/bin/env bash
# The test command (README "Tests"; .ci/run calls it):
#   1. the Rust tests: cargo test --workspace --release --no-fail-fast (every test binary runs,
#      so one failure does not hide the others), and the toy contact law's test (feature toy-law,
#      run in the background beside pytest, with the toy-law wheel and the browser suites'
#      builds, scripts/prepare-browser.sh: pytest leaves a core mostly idle)
#   2. the Python package: a virtual environment in target/venv-test (created once, reused;
#      $AFMDYN_TEST_VENV chooses another),
#      `pip install ./crates/afmdyn-py[test]` (maturin builds the extension into it, reusing the
#      library the Rust tests compiled: scripts/check-feature-unification.sh), then
#      pytest crates/afmdyn-py/tests, which also executes the example notebook and script and
#      runs every page of the book (tests/test_docs.py); then tests/test_toy_law.py against a
#      second wheel built with the toy law (feature toy-law). Before pytest, the book:
#      docs/requirements.txt into the venv and bash scripts/build-book.sh into $TARGET/book
#      (Sphinx -W: one test, failed by any warning).
#   3. the WebAssembly engine: bash scripts/test-wasm.sh (crates/afmdyn-wasm built for wasm32,
#      its JavaScript glue by wasm-bindgen-cli, checked under Node.js against the command line).
#   4. the explorer in a real browser: bash scripts/test-explorer.sh (the static page built with
#      its npm packages, served on 127.0.0.1, driven in Debian's headless Chromium, installed with
#      apt-get when missing, by playwright-core, against the command line), and the book's pages
#      opened in the same browser (explorer/tests/book.mjs).
#   3 and 4 run in the background too, beside pytest, after the toy law; their output is printed
#   after pytest's.
# Needs a Rust toolchain and Python >= 3.9 with network access to crates.io and PyPI.
# The last line is "N passed, N failed", Rust, Python, the book, wasm and the explorer together;
# the exit status is 0 only when everything ran and passed.
set -uo pipefail
cd "$(dirname "$0")/.."

PYTHON=${PYTHON:-python3}
TARGET=${CARGO_TARGET_DIR:-target}
VENV=${AFMDYN_TEST_VENV:-$TARGET/venv-test}
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
status=0
extra_failed=0

echo "== Rust: cargo test --workspace --release --no-fail-fast"
cargo test --workspace --release --no-fail-fast 2>&1 | tee "$logs/rust.log"
rust_code=${PIPESTATUS[0]}

# wasm-bindgen-cli for the browser suites (scripts/wasm-bindgen.sh: in its own build directory,
# so it never waits for the workspace's) while the Python packages download and install
bash scripts/wasm-bindgen.sh > "$logs/bindgen.log" 2>&1 &
bindgen_job=$!

echo "== Python: virtual environment $VENV"
if [ ! -x "$VENV/bin/python" ]; then
    mkdir -p "$(dirname "$VENV")"
    # plain venv; where the venv module has no pip (Debian without python3-venv), virtualenv
    "$PYTHON" -m venv "$VENV" 2>"$logs/venv.log" ||
        { rm -rf "$VENV" && "$PYTHON" -m pip install -q --user virtualenv && "$PYTHON" -m virtualenv -q "$VENV"; } ||
        { cat "$logs/venv.log"; echo "cannot create a virtual environment with $PYTHON"; status=1; }
fi
py="$VENV/bin/python"
py_passed=0
py_failed=0
book_passed=0
book_failed=0
toy="$logs/toy"
# Beside pytest, which leaves a core mostly idle, in the background: the toy contact law
# (feature toy-law, not shipped: a law is one file plus one registry line) — its Rust test
# (--workspace: the dependencies' features as the wheel's, which then reuses the library) and
# its wheel, installed beside the venv's packages, not into them — then the browser suites'
# tools and builds (scripts/prepare-browser.sh) and the browser suites. Its output is printed
# after pytest.
background() {
    echo "== Rust: cargo test --release --workspace --features afmdyn/toy-law --test toy_law"
    cargo test --release --workspace --features afmdyn/toy-law --test toy_law > "$logs/toy-rust.log" 2>&1
    echo $? > "$logs/toy-rust.code"
    cat "$logs/toy-rust.log"
    if [ -x "$py" ]; then
        echo "== Python: the toy-law wheel (feature toy-law)"
        MATURIN_PEP517_ARGS="--features toy-law" "$py" -m pip wheel -q --no-deps -w "$toy/wheel" ./crates/afmdyn-py &&
            "$py" -m pip install -q --no-deps --target "$toy/site" "$toy"/wheel/*.whl &&
            touch "$toy/built"
    fi
    echo "== the browser suites' tools and builds: bash scripts/prepare-browser.sh"
    bash scripts/prepare-browser.sh
    # then the browser suites themselves, still beside pytest (their logs are printed after it)
    run_suite wasm scripts/test-wasm.sh
    run_suite explorer scripts/test-explorer.sh
}
# a suite whose script prints "NAME: N passed, M failed" last: its output and exit status into
# $logs (count_suite reads them)
run_suite() {
    bash "$2" > "$logs/$1.log" 2>&1
    echo $? > "$logs/$1.code"
}
if [ -x "$py" ]; then
    "$py" -m pip install -q --upgrade pip 2>&1 | tail -1
    echo "== Python: pip install ./crates/afmdyn-py[test] (maturin builds the extension)"
    if "$py" -m pip install -q "./crates/afmdyn-py[test]"; then
        # the book (issue 80): its builder (docs/requirements.txt, also the docs test's Markdown
        # parser) into the venv, then Sphinx with -W over docs/ into $TARGET/book, where the
        # explorer's browser suite opens it; one test, failed by any warning
        echo "== the book: pip install -r docs/requirements.txt; bash scripts/build-book.sh $TARGET/book"
        if "$py" -m pip install -q -r docs/requirements.txt &&
            PYTHON_BOOK="$py" bash scripts/build-book.sh "$TARGET/book"; then
            book_passed=1
            echo "the book: built without warnings into $TARGET/book"
        else
            book_failed=1
            status=1
            echo "the book: the build failed or warned"
        fi
        background > "$logs/background.log" 2>&1 &
        bg=$!
        echo "== Python: pytest crates/afmdyn-py/tests"
        AFMDYN_BIN="$TARGET/release/afmdyn" "$py" -m pytest crates/afmdyn-py/tests -p no:cacheprovider -rs 2>&1 |
            tee "$logs/py.log"
        code=${PIPESTATUS[0]}
        # exit code 5: no tests were collected, which is a failure here
        [ "$code" -eq 0 ] || status=1
        summary=$(grep -E '^=+ .*(passed|failed|error|no tests ran).* in [0-9.]+s' "$logs/py.log" | tail -1)
        py_passed=$(echo "$summary" | grep -Eo '[0-9]+ passed' | awk '{print $1}')
        py_failed=$(echo "$summary" | grep -Eo '[0-9]+ (failed|errors?)' | awk '{s += $1} END {print s + 0}')
        py_passed=${py_passed:-0}
        if [ "$code" -ne 0 ] && [ "$py_failed" -eq 0 ]; then
            echo "pytest exited with status $code"
            extra_failed=$((extra_failed + 1))
        fi
        wait "$bg"
        cat "$logs/background.log"
        # the toy contact law from Python: tests/test_toy_law.py against the toy-law wheel
        echo "== Python: the toy law (tests/test_toy_law.py against the toy-law wheel)"
        if [ -e "$toy/built" ]; then
            AFMDYN_TOY_LAW=1 PYTHONPATH="$toy/site" AFMDYN_BIN="$TARGET/release/afmdyn" \
                "$py" -m pytest crates/afmdyn-py/tests/test_toy_law.py -p no:cacheprovider 2>&1 | tee "$logs/toy.log"
            code=${PIPESTATUS[0]}
            summary=$(grep -E '^=+ .*(passed|failed|error|no tests ran).* in [0-9.]+s' "$logs/toy.log" | tail -1)
            n=$(echo "$summary" | grep -Eo '[0-9]+ passed' | awk '{print $1}')
            f=$(echo "$summary" | grep -Eo '[0-9]+ (failed|errors?)' | awk '{s += $1} END {print s + 0}')
            py_passed=$((py_passed + ${n:-0}))
            py_failed=$((py_failed + f))
            if [ "$code" -ne 0 ]; then
                status=1
                [ "$f" -gt 0 ] || extra_failed=$((extra_failed + 1))
            fi
        else
            echo "building the toy-law wheel failed"
            status=1
            extra_failed=$((extra_failed + 1))
        fi
    else
        echo "building or installing the Python package failed"
        status=1
        extra_failed=$((extra_failed + 1))
    fi
else
    status=1
    extra_failed=$((extra_failed + 1))
fi
# the background's work when pytest did not run
if [ -z "${bg:-}" ]; then
    background > "$logs/background.log" 2>&1
    cat "$logs/background.log"
fi
[ "$(cat "$logs/toy-rust.code" 2>/dev/null)" = 0 ] || rust_code=1
cat "$logs/toy-rust.log" >> "$logs/rust.log" 2>/dev/null
rust_passed=$(grep -Eo '^test result: [a-zA-Z]+\. [0-9]+ passed' "$logs/rust.log" | awk '{s += $4} END {print s + 0}')
rust_failed=$(grep -Eo '[0-9]+ failed;' "$logs/rust.log" | awk '{s += $1} END {print s + 0}')
if [ "$rust_code" -ne 0 ]; then
    status=1
    # a build failure runs no test: count it as one failure
    [ "$rust_failed" -gt 0 ] || extra_failed=$((extra_failed + 1))
fi

wait "$bindgen_job"
cat "$logs/bindgen.log"

# a browser suite's output, and its counts into NAME_passed and NAME_failed; a non-zero exit
# (or none recorded) without a counted failure counts as one
count_suite() {
    local name=$1 title=$2 code line
    echo "== $title"
    cat "$logs/$name.log" 2>/dev/null
    code=$(cat "$logs/$name.code" 2>/dev/null || echo 1)
    line=$(grep -E "^$name: [0-9]+ passed, [0-9]+ failed" "$logs/$name.log" 2>/dev/null | tail -1)
    printf -v "${name}_passed" '%s' "$(echo "$line" | awk '{print $2 + 0}')"
    printf -v "${name}_failed" '%s' "$(echo "$line" | awk '{print $4 + 0}')"
    if [ "$code" -ne 0 ]; then
        status=1
        local f="${name}_failed"
        [ "${!f:-0}" -gt 0 ] || extra_failed=$((extra_failed + 1))
    fi
}
count_suite wasm "WebAssembly: bash scripts/test-wasm.sh (the browser engine under Node.js)"
count_suite explorer "Explorer: bash scripts/test-explorer.sh (the page in headless Chromium)"

echo "Rust: ${rust_passed} passed, ${rust_failed} failed; Python: ${py_passed} passed, ${py_failed} failed; book: ${book_passed} passed, ${book_failed} failed; wasm: ${wasm_passed:-0} passed, ${wasm_failed:-0} failed; explorer: ${explorer_passed:-0} passed, ${explorer_failed:-0} failed"
echo "$((rust_passed + py_passed + book_passed + ${wasm_passed:-0} + ${explorer_passed:-0})) passed, $((rust_failed + py_failed + book_failed + ${wasm_failed:-0} + ${explorer_failed:-0} + extra_failed)) failed"
exit "$status"
