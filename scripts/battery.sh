#!/usr/bin/env bash
# The reliability battery of issue 27 (crates/afmdyn-py/tests/battery.py): generated command
# lines, probe files and Python calls, each in its own process under a time and memory cap.
# Rewrites docs/reliability.md with the counts. Needs the release binary and the test venv
# (bash scripts/test.sh builds both). Options go to battery.py: --cases N --seed S --seconds T.
set -euo pipefail
cd "$(dirname "$0")/.."
PY="${PYTHON:-target/venv-test/bin/python}"
cd crates/afmdyn-py/tests
exec "../../../$PY" battery.py --binary ../../../target/release/afmdyn \
    --report ../../../docs/reliability.md "$@"
