#!/usr/bin/env bash
# Regenerate the "Bimodal AM curves" section of docs/performance/commands.md (issue 44): `afmdyn bimodal`
# over 100 z_c values (the default range) on examples/probe-bimodal.toml (the eigenmode model,
# f2/f1 = 25/4: a common period of 4 drive periods), with and without the branches; the same
# lever with f2/f1 = 94/15 (mode 2 at 1.88 MHz, the beam's 6.27: 15 periods); and, for the
# cost of the second component, the single-frequency approach curve of the same lever (its
# auto integrator, Taylor); then the time-domain way, the library's time average, against the
# exact orbits (cargo run --release -p afmdyn --example bimodal_timing); and at f2/f1 =
# 1761/281 (mode 2 at 1.88007 MHz: a common period of 281 drive periods) the orbits against
# --average over 10 values (one run each: the orbits take minutes); at the true 6.27 = 627/100
# (mode 2 and its drive at 1.881 MHz: 100 periods) on invariant circles (the default there,
# issue 63) and on the exact orbits (--exact). Whole command
# (outputs and plots included), best of 3. Goal: ≤ 2 s on the eigenmode model.
# Usage: bash scripts/perf-bimodal.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p afmdyn-cli
cargo build --release -q -p afmdyn --example bimodal_timing
B=target/release/afmdyn
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
P=examples/probe-bimodal.toml
sed 's/1.875e6/1.88e6/g' $P > "$tmp/ratio-94-15.toml"
sed 's/1.875e6/1.881e6/g' $P > "$tmp/ratio-627-100.toml"
sed 's/^frequency = .*/frequency = [300e3, 1.88007e6]/' $P > "$tmp/ratio-1761-281.toml"
sed -e 's/^free_amplitude = .*/free_amplitude = 10e-9/' -e 's/^frequency = .*/frequency = 300e3/' \
    $P > "$tmp/single.toml"

source scripts/best-of.sh

rows=""
for case in "eigenmodes, f2/f1 = 25/4, branches|bimodal|$P|" \
            "eigenmodes, f2/f1 = 25/4, --no-branches|bimodal|$P|--no-branches" \
            "eigenmodes, f2/f1 = 94/15, --no-branches|bimodal|$tmp/ratio-94-15.toml|--no-branches" \
            "eigenmodes, f2/f1 = 627/100 (the true 6.27), branches asked (invariant circles)|bimodal|$tmp/ratio-627-100.toml|" \
            "eigenmodes, f2/f1 = 627/100, --exact --no-branches (100-period orbits)|bimodal|$tmp/ratio-627-100.toml|--exact --no-branches" \
            "one component (approach, Taylor integrator), --no-branches|approach|$tmp/single.toml|--no-branches"; do
    IFS='|' read -r name cmd probe extra <<< "$case"
    # shellcheck disable=SC2086
    t=$(best_of 3 "$tmp/doc.json" $B $cmd --probe "$probe" --points 100 $extra --json --out "$tmp/out")
    stats=$(python3 - "$tmp/doc.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
a = d["approach"]
comp = d.get("drive_components")
line = f"{len(a['z_c'])} values each way, {len(d['branches'])} branch(es), {len(d['folds'])} fold(s)"
if comp:
    line += (f", A1 {a['amplitude_1'][0] * 1e9:.3f} → {a['amplitude_1'][-1] * 1e9:.3f} nm, "
             f"A2 {a['amplitude_2'][0] * 1e9:.4f} → {a['amplitude_2'][-1] * 1e9:.4f} nm")
c = d.get("invariant_circle")
if c:
    n = [m for s in ("approach", "retract") for m in c[s]["nodes"]]
    line += f", {sum(1 for m in n if m)} of {len(n)} points on circles of {max(n)} nodes"
print(line + f", warnings {len(d['warnings'])}")
PY
)
    rows="$rows| $name | $(python3 -c "print(f'{$t:.2f}')") s | $stats |
"
done

td_line=$(target/release/examples/bimodal_timing)
td_row=$(python3 - "$td_line" <<'PY'
import json, sys
d = json.loads(sys.argv[1])
print(f"| the time domain (`--average`: the motion integrated on at each z_c, demodulated over "
      f"Hann² windows of {d['window_periods']} drive periods until two agree to "
      f"{d['tolerance']:g} of each free amplitude) against the exact orbits (both sweeps), "
      f"library calls | {d['time_domain_s']:.1f} s against {d['exact_s']:.2f} s: "
      f"**{d['ratio']:.0f}×** | {d['values']} values, {d['periods']} drive periods, "
      f"{d['unsettled']} unsettled, {d['outside_estimate']} outside their error estimates; the "
      f"amplitudes agree to {d['amplitude_difference']:.1e} of the free ones |")
PY
)

# f2/f1 = 1761/281: orbits of 281 drive periods against the time average, 10 values
q281=""
for mode in "--no-branches" "--average"; do
    t=$(best_of 1 "$tmp/q281$mode.json" $B bimodal --probe "$tmp/ratio-1761-281.toml" --points 10 $mode \
        --json --files none)
    q281="$q281 $t"
done
q281_row=$(python3 - "$tmp/q281--no-branches.json" "$tmp/q281--average.json" $q281 <<'PY'
import json, sys
o, a = (json.load(open(f)) for f in sys.argv[1:3])
t_o, t_a = (float(x) for x in sys.argv[3:5])
ta = a["time_average"]
both = [(s, i) for s in ("approach", "retract") for i in range(len(o[s]["z_c"]))
        if ta[s]["settled"][i]]
settled = len(both)
diffs = [max(abs(o[s][f"amplitude_{c}"][i] - a[s][f"amplitude_{c}"][i]) / a0
             for c, a0 in ((1, 10e-9), (2, 1e-9))) for s, i in both]
same = [d for d in diffs if d < 1e-3]
diff = max(same, default=float("nan"))
print(f"| f2/f1 = 1761/281 (1.88007 MHz), 10 values each way: orbits (`--no-branches`) against "
      f"`--average` (window {ta['window_periods']} periods), whole command | {t_o:.1f} s against "
      f"{t_a:.1f} s: **{t_o / t_a:.1f}×** | {settled} of {2 * len(o['approach']['z_c'])} averaged "
      f"points settled; of those, {len(same)} agree with the orbits to {diff:.1e} of the free "
      f"amplitudes, {len(diffs) - len(same)} differ by more than 1e-3 (another attractor: the "
      f"sweeps' histories differ in the bistable range) |")
PY
)
section=$(mktemp)
{
    echo "<!-- bimodal:begin (generated by scripts/perf-bimodal.sh; do not edit) -->"
    echo "| \`afmdyn bimodal --probe P --points 100\` | best of 3 (whole command) | curve |"
    echo "|---|---|---|"
    printf "%s" "$rows"
    echo "$td_row"
    echo "$q281_row"
    echo
    echo "Goal (issue 44): ≤ 2 s for 100 z_c values on the eigenmode model. The steady state is a"
    echo "periodic orbit of the common period q/f1, so a point costs about q times a single-frequency"
    echo "point; the Taylor integrator carries every drive component in its series (auto's choice for"
    echo "Hertz and DMT; it replaced the adaptive DOP853 for such drives, the curves equal to 1e-7)."
    echo "The time average does not depend on q but on the decay time and the combination tones'"
    echo "slowest beat (docs/tutorials/bimodal.md): slower than the orbits at small q, faster at large q,"
    echo "and the way for a quasi-periodic (incommensurate) drive. At 627/100 the points are invariant"
    echo "circles of the stroboscopic map on 37 nodes (docs/tutorials/bimodal.md, curves on invariant circles),"
    echo "the exact orbit where a circle is not smooth (inside such a stretch the circle is tried again"
    echo "only every 4th point); circles have no branches (goal, issue 63: ≤ 2× the 25/4 curve with"
    echo "branches)."
    echo "\`bash scripts/perf-bimodal.sh\` on this machine"
    echo "(2 cores; one curve is one chain, so one core)."
    echo "<!-- bimodal:end -->"
} > "$section"
python3 scripts/doc_section.py bimodal "$section" "Bimodal AM curves (issue 44)"
sed -n '/bimodal:begin/,/bimodal:end/p' "$(python3 scripts/doc_section.py --where bimodal)"
