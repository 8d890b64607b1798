#!/usr/bin/env bash
# Regenerate every figure of the paper that afmdyn covers (Figs. 3, 4, 5, 6-17, eq. 25) into
# docs/figures/ (or $FIGURES), plus the coarse-step RK4 reruns used in docs/paper-reproduction.md,
# and print the summaries that the docs quote.
# Usage: bash scripts/reproduce.sh   (about a minute on 2 cores)
# The outputs are deterministic: two runs write identical files (the sweep's rows are in a fixed
# order whatever the thread count), so rerunning leaves a clean `git status`.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q
A=target/release/afmdyn
F=${FIGURES:-docs/figures}
mkdir -p "$F"/approach "$F"/continuation "$F"/lyapunov "$F"/fig4 "$F"/fig5 "$F"/fig6-7 "$F"/fig8-14 "$F"/fig15-17 "$F"/fig15-17-text
S=${SAMPLES:-64}

$A modes --config examples/eq25.toml --json > "$F/eq25.json"
$A modes --sweep fig3 --out "$F/fig3" > /dev/null
$A converge --config examples/fig4.toml --json --out "$F/fig4" > "$F/fig4/summary.json"
$A bifurcation --config examples/fig5.toml --starts 2 --json --out "$F/fig5" > "$F/fig5/summary.json"
for fig in fig6-7 fig8-14 fig15-17 fig15-17-text; do
  $A attractors --config "examples/$fig.toml" --samples "$S" --json --out "$F/$fig" > "$F/$fig/summary.json"
done
# the paper's integrator: fixed-step RK4 choosing the region per stage, at coarse steps
# (RK4 is unstable for h·ω_max > 2.8: at Ω = 2.6 that needs more than ~50 steps per period)
for run in "fig8-14 8" "fig8-14 32" "fig8-14 100" "fig6-7 64" "fig6-7 128" "fig6-7 512"; do
  set -- $run
  out="$F/rk4-naive-$2-$1"
  $A attractors --config "examples/$1.toml" --samples "$S" --integrator rk4-naive --steps-per-period "$2" \
    --json --out "$out" > "$out.json"
  rm -rf "$out"
done
# beyond the paper: the period-1 branch by continuation over the Fig. 5 diagram, and the
# Lyapunov classification of the paper's nonperiodic motions
$A continue --config examples/fig5.toml --from 5 --to 1 --switch --overlay "$F/fig5/bifurcation.csv" \
  --json --out "$F/continuation" > "$F/continuation/summary.json"
for om in 2.0 2.05 2.1 2.15 2.6 20; do
  $A lyapunov --config examples/fig5.toml --omega "$om" --json > "$F/lyapunov/omega-$om.json"
  $A orbit --config examples/fig5.toml --omega "$om" --json > "$F/lyapunov/orbit-omega-$om.json"
done
# beyond the paper: the approach curve of the example probe (point mass, DMT on polystyrene,
# A0 = 10 nm) at the command's default settings, plots in AFM units
$A approach --probe examples/probe-point-mass-dmt.toml --json --out "$F/approach" > "$F/approach/summary.json"
rm -f "$F"/approach/approach.csv
# keep the pictures and summaries; drop the bulky vector and table copies and the run
# bookkeeping (lock files hold a process id, the sweep's ledger the arguments)
find "$F" \( -name '*.svg' -o -name '*.npy' -o -name '*.npy.json' -o -name 'attractor-*.csv' \
  -o -name '.afmdyn.lock' -o -name '.bifurcation.run.json' \) -delete
rm -f "$F/fig5/bifurcation.csv"
# what the docs quote
for f in "$F"/eq25.json "$F"/*/summary.json "$F"/rk4-naive-*.json "$F"/lyapunov/*.json; do
  echo "== ${f#"$F"/}"
  cat "$f"
  echo
done
echo "figures in $F"
