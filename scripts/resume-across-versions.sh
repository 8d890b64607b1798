#!/usr/bin/env bash
# A store written by one build resumes in another (issue 43: "resume of a store written before
# the change either works or is refused naming the plan"): OLD writes a chart store and a
# sweep store and is killed mid-run (--abort-after), NEW resumes each, and the resumed files
# must equal NEW's uninterrupted run byte for byte.
#   bash scripts/resume-across-versions.sh OLD_BIN [NEW_BIN]
set -uo pipefail
OLD=$(realpath "${1:?usage: resume-across-versions.sh OLD_BIN [NEW_BIN]}")
NEW=$(realpath "${2:-$(dirname "$0")/../target/release/afmdyn}")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
fail=0
check() { # name, files..., -- args...
    local name=$1; shift
    local files=()
    while [ "$1" != -- ]; do files+=("$1"); shift; done
    shift
    "$OLD" "$@" --threads 1 --abort-after 3 --out "$name-cut" >/dev/null 2>&1
    "$NEW" "$@" --threads 1 --resume --out "$name-cut" >/dev/null 2>"$name.err" || { echo "$name: resume refused: $(cat "$name.err")"; fail=1; return; }
    "$NEW" "$@" --threads 1 --out "$name-full" >/dev/null 2>&1
    for f in "${files[@]}"; do
        cmp -s "$name-cut/$f" "$name-full/$f" || { echo "$name: $f differs"; fail=1; }
    done
    echo "$name: resumed from the old build's store, ${files[*]} identical"
}
check chart chart.csv chart.nc -- chart --x-steps 12 --y-steps 4 --starts 2
check bifurcation bifurcation.csv bifurcation.npy -- bifurcation --from 2.4 --to 3 --steps 20
exit $fail
