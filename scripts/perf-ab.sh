#!/usr/bin/env bash
# Two builds side by side on the studies and curves a restructuring must not slow down (issue
# 43): farm-bench runs A (this tree's binary) and B (another build, e.g. the one before the
# change) in turn, A B A B, and prints the median wall time of each and the median of the
# pairwise ratios A/B. Needs farm-bench (the tool library) and a B binary.
#   bash scripts/perf-ab.sh B_BIN [A_BIN] [RUNS]
set -uo pipefail
B=$(realpath "${1:?usage: perf-ab.sh B_BIN [A_BIN] [RUNS]}")
A=$(realpath "${2:-$(dirname "$0")/../target/release/afmdyn}")
N=${3:-5}
E=$(realpath "$(dirname "$0")/../examples")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
cases=(
  "bifurcation (main job, 400 values, 2 threads)|bifurcation --threads 2 --out o"
  "chart 40 x 10, 2 threads|chart --x-steps 40 --y-steps 10 --threads 2 --out o"
  "basins 200 x 200, impact N = 1|basins --contact-law impact --restitution 0.8 --modes 1 --omega 2 --x a1 --y adot1 --x-steps 200 --y-steps 200 --threads 2 --out o"
  "approach, beam DMT probe|approach --probe $E/probe-beam-dmt.toml --out o"
  "resonance, beam DMT probe|resonance --probe $E/probe-beam-dmt.toml --out o"
  "simulate Hertz N = 3, 30 000 periods|simulate --contact-law hertz --periods 30000 --files none"
  "attractors, RTESPA-300 probe (Q = 500)|attractors --probe $E/probe-rtespa300-polystyrene.toml --samples 8"
)
printf '| case | A median (s) | B median (s) | A/B (median of pairs) |\n|---|---|---|---|\n'
for c in "${cases[@]}"; do
  name=${c%%|*}; args=${c#*|}
  # shellcheck disable=SC2086
  farm-bench -n "$N" --timeout 900 --vs "$B $args" -- $A $args >"$tmp/out.txt" 2>&1
  row=$(awk '$1 == "A" && $2 == "wall" {a = $5} $1 == "B" && $2 == "wall" {b = $5}
             $1 == "A/B" && $2 == "wall" {r = $4} END {print a " | " b " | " r}' "$tmp/out.txt")
  printf '| %s | %s |\n' "$name" "$row"
done
