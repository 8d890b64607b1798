#!/usr/bin/env bash
# The front ends' sizes (issue 59 §6): lines of the CLI's Rust, the Python binding's Rust and
# the binding's hand-written Python. A file whose first 5 lines say it is "generated" (by a
# script, from the schemas) is not counted; .pyi stubs are never counted.
#
#     scripts/frontend-sizes.sh          # prints the three sizes and the aims
set -euo pipefail
cd "$(dirname "$0")/.."

# the lines of the files given, those with a "generated" header left out
count() {
    local total=0 f n
    for f in "$@"; do
        [ -f "$f" ] || continue
        if head -n 5 "$f" | grep -qi 'generated'; then
            continue
        fi
        n=$(wc -l <"$f")
        total=$((total + n))
    done
    echo "$total"
}

cli=$(count $(find crates/afmdyn-cli/src -name '*.rs' | sort))
rust=$(count $(find crates/afmdyn-py/src -name '*.rs' | sort))
py=$(count $(find crates/afmdyn-py/python/afmdyn -name '*.py' | sort))
printf '%-28s %6s  (aim %s)\n' "CLI Rust" "$cli" 4000 \
    "binding Rust" "$rust" 1500 "hand-written Python" "$py" 2000
