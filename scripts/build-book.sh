#!/usr/bin/env bash
# The book (issue 80): Sphinx with MyST Markdown over docs/ (docs/conf.py), as HTML in OUT
# (default ${CARGO_TARGET_DIR:-target}/book; open OUT/index.html).
#   bash scripts/build-book.sh [OUT]
# The Python is $PYTHON_BOOK, else the test venv's (${AFMDYN_TEST_VENV:-$TARGET/venv-test}, as
# scripts/test.sh makes it; never the system's); docs/requirements.txt (sphinx, myst-parser) is
# installed into it when sphinx is missing. The Python reference is autodoc of the installed
# afmdyn package, so that Python needs afmdyn installed (pip install ./crates/afmdyn-py).
# -W --keep-going: every warning is printed and the exit status is non-zero if there was one.
set -uo pipefail
cd "$(dirname "$0")/.."
TARGET=${CARGO_TARGET_DIR:-target}
VENV=${AFMDYN_TEST_VENV:-$TARGET/venv-test}
OUT=${1:-$TARGET/book}

if [ -n "${PYTHON_BOOK:-}" ]; then
    py=$PYTHON_BOOK
elif [ -x "$VENV/bin/python" ]; then
    py=$VENV/bin/python
else
    echo "no Python for the book: set PYTHON_BOOK, or run scripts/test.sh once (it makes $VENV)"
    exit 1
fi
if ! "$py" -c 'import sphinx, myst_parser' 2> /dev/null; then
    echo "== installing docs/requirements.txt into $py"
    "$py" -m pip install -q -r docs/requirements.txt || { echo "cannot install docs/requirements.txt"; exit 1; }
fi
# a fresh build (-E: no saved environment), so that a warning of an unchanged page is not hidden
# by the incremental build
"$py" -m sphinx -E -q -W --keep-going -b html docs "$OUT"
