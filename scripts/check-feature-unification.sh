#!/usr/bin/env bash
# Checks that maturin's build of the Python extension (crates/afmdyn-py alone) and the build of
# the command line alone (crates/afmdyn-cli, by scripts/test-wasm.sh and test-explorer.sh)
# compile the library's dependencies with the same features as the Rust tests' build (cargo
# test --workspace, dev-dependencies included), so that they reuse the library the Rust tests
# compiled instead of compiling it again (issue 60 E21). The features come from `cargo tree` on Cargo.lock: no build runs.
# On a difference it prints both feature lists of each package and exits 1: add the missing
# features to the "feature unification" block of crates/afmdyn-py/Cargo.toml.
set -euo pipefail
cd "$(dirname "$0")/.."

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# the packages the library is built from (its normal and build dependencies, itself included)
cargo tree -p afmdyn -e normal,build -f '{p}' --prefix none |
    sed 's/ (\*)$//; s/ (proc-macro)$//; s/ (\/.*)$//' | sort -u >"$tmp/closure"
# "name vX.Y.Z [features]" of each package in a build, restricted to that closure
features() {
    sed 's/ (\*)$//; s/ (proc-macro)//; s/ (\/[^)]*)//' |
        awk -v closure="$tmp/closure" 'BEGIN { while ((getline l < closure) > 0) keep[l] = 1 }
            { key = $1 " " $2; if (key in keep) print }' | sort -u
}
cargo tree --workspace -e normal,build,dev -f '{p} [{f}]' --prefix none | features >"$tmp/tests"

status=0
# the Python extension (maturin builds it alone) and the command line (built alone by the
# wasm and explorer checks)
for crate in afmdyn-py afmdyn-cli; do
    cargo tree -p "$crate" -e normal,build -f '{p} [{f}]' --prefix none | features >"$tmp/$crate"
    if diff "$tmp/$crate" "$tmp/tests" >"$tmp/diff"; then
        echo "feature unification: $crate builds the library with the Rust tests' features ($(wc -l <"$tmp/tests") packages)"
    else
        echo "feature unification: $crate's build alone (<) and the Rust tests' build (>) differ:"
        cat "$tmp/diff"
        echo "add the features the tests' build has to the feature unification block of crates/$crate/Cargo.toml"
        status=1
    fi
done
exit "$status"
