#!/usr/bin/env bash
# Two builds side by side on the studies and curves a restructuring must not slow down (issue
# 43): farm-bench runs A (this tree's binary) and B (another build, e.g. the one before the
# change) in turn, A B A B, and prints the median wall time of each and the median of the
# pairwise ratios A/B. Needs farm-bench (the tool library) and a B binary. The cases cover
# the commands of scripts/perf-curves.sh and scripts/perf-study.sh; with B_EXAMPLES (the
# release examples directory of the B build: target/release/examples of that tree, with
# period_cost and basin_cost built) also the engine cases of scripts/perf-stability.sh
# (`period_cost`) and scripts/perf-basins.sh (`basin_cost`), A's from this tree.
#   [B_EXAMPLES=DIR] [ONLY_ENGINE=1] bash scripts/perf-ab.sh B_BIN [A_BIN] [RUNS]
set -uo pipefail
ROOT=$(realpath "$(dirname "$0")/..")
B=$(realpath "${1:?usage: perf-ab.sh B_BIN [A_BIN] [RUNS]}")
A=$(realpath "${2:-$ROOT/target/release/afmdyn}")
N=${3:-5}
E=$ROOT/examples
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
cases=(
  "bifurcation (main job, 400 values, 2 threads)|bifurcation --threads 2 --out o"
  "bifurcation (main job), 1 thread|bifurcation --threads 1 --out o"
  "chart 40 x 10, 2 threads|chart --x-steps 40 --y-steps 10 --threads 2 --out o"
  "chart 100 x 50 (perf-study), 2 threads|chart --x omega --x-from 2.6 --x-to 3.0 --x-steps 100 --y drive-amplitude --y-from 0.08 --y-to 0.12 --y-steps 50 --threads 2 --out o"
  "resonance (default)|resonance --out o"
  "approach, point-mass DMT probe|approach --probe $E/probe-point-mass-dmt.toml --out o"
  "basins 200 x 200, impact N = 1|basins --contact-law impact --restitution 0.8 --modes 1 --omega 2 --x a1 --y adot1 --x-steps 200 --y-steps 200 --threads 2 --out o"
  "approach, beam DMT probe|approach --probe $E/probe-beam-dmt.toml --out o"
  "resonance, beam DMT probe|resonance --probe $E/probe-beam-dmt.toml --out o"
  "simulate Hertz N = 3, 30 000 periods|simulate --contact-law hertz --periods 30000 --files none"
  "attractors, RTESPA-300 probe (Q = 500)|attractors --probe $E/probe-rtespa300-polystyrene.toml --samples 8"
)
printf '| case | A median (s) | B median (s) | A/B (median of pairs) |\n|---|---|---|---|\n'
for c in "${cases[@]}"; do
  [ -n "${ONLY_ENGINE:-}" ] && break
  name=${c%%|*}; args=${c#*|}
  # shellcheck disable=SC2086
  farm-bench -n "$N" --timeout 900 --vs "$B $args" -- $A $args >"$tmp/out.txt" 2>&1
  row=$(awk '$1 == "A" && $2 == "wall" {a = $5} $1 == "B" && $2 == "wall" {b = $5}
             $1 == "A/B" && $2 == "wall" {r = $4} END {print a " | " b " | " r}' "$tmp/out.txt")
  printf '| %s | %s |\n' "$name" "$row"
done
if [ -n "${B_EXAMPLES:-}" ]; then
  BX=$(realpath "$B_EXAMPLES")
  (cd "$ROOT" && cargo build --release -q -p afmdyn --example period_cost --example basin_cost)
  AX=$ROOT/target/release/examples
  engine=(
    "period_cost shoot 3 200 (Newton shooting, N = 3)|period_cost shoot 3 200"
    "period_cost continuation 3 3 (period-1 branch, Ω 5 → 1)|period_cost continuation 3 3"
    "basin_cost impact 100|basin_cost impact 100"
    "basin_cost beam 60|basin_cost beam 60"
    "basin_cost beam2 100 (Figs. 15-17)|basin_cost beam2 100"
  )
  for c in "${engine[@]}"; do
    name=${c%%|*}; args=${c#*|}; bin=${args%% *}; rest=${args#* }
    # shellcheck disable=SC2086
    farm-bench -n "$N" --timeout 1800 --vs "$BX/$bin $rest" -- "$AX/$bin" $rest >"$tmp/out.txt" 2>&1
    row=$(awk '$1 == "A" && $2 == "wall" {a = $5} $1 == "B" && $2 == "wall" {b = $5}
               $1 == "A/B" && $2 == "wall" {r = $4} END {print a " | " b " | " r}' "$tmp/out.txt")
    printf '| %s | %s |\n' "$name" "$row"
  done
fi
