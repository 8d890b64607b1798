#!/usr/bin/env bash
# The fixed command set of the refactoring rule (issue 43): every subcommand, every law, probe
# runs and the Python datasets, run with one afmdyn binary into one directory, and a manifest of
# SHA-256 sums of every file they write (stdout of --json runs included). Two builds agree when
# their manifests are equal:
#   bash scripts/golden-outputs.sh OUT_A [BIN_A] [PYTHON_A]; bash scripts/golden-outputs.sh OUT_B ...
#   diff OUT_A/manifest.txt OUT_B/manifest.txt
# BIN defaults to target/release/afmdyn, PYTHON to target/venv-test/bin/python (the test
# command's environment, with the extension of the same tree); PYTHON=none skips the Python part.
# Short runs only (a few minutes on 2 cores): reduced grids, few starts, threads 2.
set -uo pipefail
cd "$(dirname "$0")/.."
OUT=${1:?usage: golden-outputs.sh OUT [BIN] [PYTHON]}
BIN=$(realpath "${2:-target/release/afmdyn}")
PY=${3:-target/venv-test/bin/python}
[ "$PY" = none ] || PY=$(cd "$(dirname "$PY")" && pwd)/$(basename "$PY")
rm -rf "$OUT" && mkdir -p "$OUT"
OUT=$(realpath "$OUT")
EX=$(realpath examples)
fails=0
run() { # name, args...
    local name=$1; shift
    mkdir -p "$OUT/$name"
    (cd "$OUT/$name" && "$BIN" "$@" >stdout.txt 2>stderr.txt; echo $? >exit.txt)
}
P="$EX/probe-point-mass-dmt.toml"; B="$EX/probe-beam-dmt.toml"; H="$EX/probe-rtespa300-polystyrene.toml"
run modes modes --json
run modes-eq25 modes --modes 5 --alpha3 0 --alpha6 0 --json
run modes-fig3 modes --sweep fig3 --out o
run modes-probe modes --probe "$B" --json
run units units --config "$EX/probe.toml" --json
run cantilevers cantilevers --json
for law in linear hertz dmt impact; do
    extra=(); [ $law = dmt ] && extra=(--hamaker 1e-5 --intermolecular-distance 0.01)
    [ $law = impact ] && extra=(--restitution 0.8 --modes 1)
    run simulate-$law simulate --contact-law $law "${extra[@]}" --periods 20 --transient 50 --out o --json
    run orbit-$law orbit --contact-law $law "${extra[@]}" --omega 2.8 --json
    run bif-$law bifurcation --contact-law $law "${extra[@]}" --from 2.4 --to 3.0 --steps 7 --threads 2 --out o --json
    run attr-$law attractors --contact-law $law "${extra[@]}" --omega 2.6 --samples 6 --json
done
run simulate-csv simulate --periods 10 --transient 10 --csv --out o
run converge converge --json
run continue continue --from 3 --to 2.5 --json --out o
run lyapunov lyapunov --omega 2.6 --periods 200 --transient 200 --json
run attr-sweep attractors --modes 1 --contact-law impact --restitution 0.8 --sweep omega --from 1.9 --to 2.1 --steps 3 --samples 4 --json
run chart chart --x-steps 4 --y-steps 2 --starts 2 --threads 2 --out o --json
run chart-probe chart --probe "$P" --x z-c --x-from 2nm --x-to 6nm --x-steps 3 --y free-amplitude --y-from 8nm --y-to 10nm --y-steps 2 --starts 2 --threads 2 --out o --json
run basins basins --contact-law impact --restitution 0.8 --modes 1 --omega 2 --x a1 --y adot1 --x-steps 12 --y-steps 12 --threads 2 --out o --json
run approach-pm approach --probe "$P" --out o --json
run approach-beam approach --probe "$B" --out o --json
run resonance resonance --probe "$B" --out o --json
run orbit-probe orbit --probe "$B" --z-c 6e-9 --json
run attr-highq attractors --probe "$H" --samples 4 --json
run bad-input orbit --omega -1
run fm-probe fm --probe "$P" --points 12 --out o --json
run fm-model fm --contact-law dmt --hamaker 1e-5 --intermolecular-distance 0.01 --points 12 --out o --json
run bimodal bimodal --probe "$EX/probe-bimodal.toml" --points 10 --setpoint 0.7 --out o --json
run reconstruct reconstruct --fm "$EX/fm-vdw.csv" --spring-constant 40 --resonance-frequency 300kHz --amplitude 10nm --out o --json
run image image --probe "$P" --sample "$EX/sample-stripe.toml" --setpoint 0.8 --pixels 8 --curve-points 30 --out o --json
# PeakForce (steady taps, sweep, point mass, water) and stepped sweeps of hysteretic laws
run pf-air peakforce --probe "$EX/probe-peakforce-air.toml" --z-c 97nm --json --out o
run pf-sweep peakforce --probe "$EX/probe-peakforce-air.toml" --from 98nm --to 94nm --step 1nm --json --out o
run pf-pm peakforce --probe "$EX/probe-peakforce-air.toml" --modes 1 --json --out o
run pf-water peakforce --probe "$EX/probe-peakforce-water.toml" --json --out o
run approach-jkr approach --probe "$EX/probe-jkr-polymer.toml" --out o --json
run approach-cap approach --probe "$EX/probe-capillary-humid.toml" --out o --json
# the Python datasets: every variable's dims, attrs and bytes
if [ "$PY" != none ] && [ -x "$PY" ]; then
    mkdir -p "$OUT/python"
    (cd "$OUT/python" && "$PY" - "$EX" >stdout.txt 2>stderr.txt <<'PYEOF'
import hashlib, json, sys, warnings
import numpy as np
import afmdyn
warnings.simplefilter("ignore")
ex = sys.argv[1]
def dump(name, ds):
    out = {"attrs": {k: str(v) for k, v in ds.attrs.items()}}
    for k in sorted(list(ds.variables)):
        v = ds[k]
        a = np.ascontiguousarray(v.values)
        h = hashlib.sha256(a.tobytes() if a.dtype != object else repr(a.tolist()).encode()).hexdigest()[:16]
        out[k] = [list(v.dims), str(a.dtype), {kk: str(vv) for kk, vv in v.attrs.items()}, h]
    print(name, json.dumps(out, sort_keys=True))
dump("simulate", afmdyn.simulate(periods=10, transient=10))
dump("bifurcation", afmdyn.bifurcation(from_=2.4, to=3.0, steps=7, threads=2))
dump("chart", afmdyn.chart(x_steps=4, y_steps=2, starts=2, threads=2))
dump("basins", afmdyn.basins(contact_law="impact", restitution=0.8, modes=1, omega=2, x="a1", y="adot1", x_steps=12, y_steps=12, threads=2))
dump("approach", afmdyn.approach(probe=ex + "/probe-point-mass-dmt.toml"))
dump("resonance", afmdyn.resonance(probe=ex + "/probe-beam-dmt.toml"))
PYEOF
    echo $? >exit.txt)
fi
# the manifest: every file's sum (absolute paths of this run are replaced before summing)
# (a store's records, .jsonl, are summed in sorted order: threads append them as they finish)
(cd "$OUT" && find . -type f ! -name manifest.txt ! -name "*.lock" ! -name ".chart.tiles.jsonl" ! -path ./python/stderr.txt | LC_ALL=C sort | while read -r f; do
    case "$f" in
        *.jsonl) sum=$(sed "s#$OUT#OUT#g; s#$EX#EX#g" "$f" | LC_ALL=C sort | sha256sum | cut -c1-16) ;;
        *) sum=$(sed "s#$OUT#OUT#g; s#$EX#EX#g" "$f" | sha256sum | cut -c1-16) ;;
    esac
    printf '%s  %s\n' "$sum" "$f"
done) >"$OUT/manifest.txt"
echo "$(wc -l <"$OUT/manifest.txt") files in $OUT/manifest.txt"
