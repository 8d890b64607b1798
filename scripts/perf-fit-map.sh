#!/usr/bin/env bash
# Regenerate the "Force maps (issue 78)" section of docs/performance/maps.md:
# 1. Per curve against nanite on the same curves: afmformats' JPK force map (2 × 2, curves of
#    3 226 to 24 060 rows) and QI map (4 curves of ~600 rows). nanite 4.2's `fit_model`
#    (hertz_para, E, contact point and baseline free, unweighted, after its three preprocessing
#    steps) is timed per fit inside Python (median over 3 fresh fits of each curve); `afmdyn fit-map`
#    is timed as a whole command (farm-bench, median of 5) on a map of the file's curves
#    tiled to 32 × 32 = 1 024 curves (written by afmdyn.export_map, each curve's own spring
#    constant), reading, preprocessing, fitting and writing every file included, divided by
#    1 024 (the command's fixed costs — its start, the four figures — spread over a map of a
#    thousand curves, as over a real map's; nanite's time is fit_model's alone).
# 2. A synthetic map of 128 × 128 Hertz curves of 1 000 rows (E = 5 kPa with an 800 Pa disc,
#    20 pN noise) as NetCDF (A) and as the long-format CSV (B), the whole command on this
#    machine's cores (the goal: ≤ 30 s on 2 cores).
# Usage: bash scripts/perf-fit-map.sh   (PYTHON=venv python with afmdyn, afmformats and nanite:
#        default target/venv-test/bin/python; AFMDYN_BIN=PATH: that binary, no build)
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${AFMDYN_BIN:-}" ]; then
    cargo build --release -q -p afmdyn-cli
fi
B=${AFMDYN_BIN:-$PWD/target/release/afmdyn}
PY=${PYTHON:-target/venv-test/bin/python}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# nanite's per-fit times, and each file's curves tiled into a 32 × 32 map
"$PY" - "$tmp" <<'PY' > "$tmp/nanite.json"
import json, statistics, sys, time, warnings
import afmdyn, afmformats, nanite
warnings.simplefilter("ignore")
tmp = sys.argv[1]
TILES = 32  # the map of the file's curves, TILES × TILES
files = {"force-map": "examples/fmt-jpk-fd_map2x2_extracted.jpk-force-map",
         "qi": "examples/fmt-jpk-fd_2020.02.07-16.29.05.036.jpk-qi-data"}
out = {}
for name, path in files.items():
    times, rows = [], []
    # a fresh Indentation for every fit (nanite keeps a fit's result and skips a repeated one)
    for _ in range(3):
        for idnt in nanite.IndentationGroup(path):
            idnt.apply_preprocessing(["compute_tip_position", "correct_force_offset",
                                      "correct_tip_offset"])
            p = nanite.model.model_hertz_paraboloidal.get_parameter_defaults()
            p["baseline"].vary = True
            t = time.perf_counter()
            idnt.fit_model(model_key="hertz_para", params_initial=p, range_x=(0, 0),
                           range_type="absolute", x_axis="tip position", y_axis="force",
                           segment="approach", weight_cp=False)
            times.append(time.perf_counter() - t)
            rows.append(len(idnt["force"]))
    curves = afmformats.load_data(path)
    tiled = []
    for i in range(TILES * TILES):
        c = curves[i % len(curves)]
        tiled.append({"x": (i % TILES) * 1e-6, "y": (i // TILES) * 1e-6,
                      "height": c["height (measured)"], "force": c["force"],
                      "segment": c["segment"], "spring_constant": c.metadata["spring constant"]})
    afmdyn.export_map(tiled, f"{tmp}/{name}.nc")
    out[name] = {"nanite_ms": 1e3 * statistics.median(times), "rows": rows}
json.dump(out, sys.stdout)
PY
for name in force-map qi; do
    farm-bench -n 5 --timeout 600 -- "$B" fit-map --probe examples/probe-fit-spot3.toml \
        --data "$tmp/$name.nc" --out "$tmp/out-$name" > "$tmp/bench-$name.txt"
    cat "$tmp/bench-$name.txt"
done

# the synthetic 128 × 128 map, as NetCDF and as CSV
"$PY" - "$tmp" <<'PY'
import sys
import numpy as np
import afmdyn
tmp, n, rows = sys.argv[1], 128, 1000
k, r, nu = 0.05, 10e-6, 0.5
rng = np.random.default_rng(78)
t = np.linspace(0, 1, rows)
curves = []
with open(f"{tmp}/synthetic.csv", "w") as fh:
    fh.write("x,y,height,force\n")
    for iy in range(n):
        for ix in range(n):
            e = 800.0 if (ix - n / 2) ** 2 + (iy - n / 2) ** 2 < (n / 5) ** 2 else 5e3
            cp = 50e-9 * ix / n
            x = cp + 1e-6 - 2.5e-6 * t
            f = 4 / 3 * e / (1 - nu ** 2) * np.sqrt(r) * np.clip(cp - x, 0, None) ** 1.5
            h, f = x - f / k, f + rng.normal(0, 20e-12, rows)
            curves.append({"x": ix * 1e-6, "y": iy * 1e-6, "height": h, "force": f,
                           "spring_constant": k})
            a = np.column_stack([np.full(rows, ix * 1e-6), np.full(rows, iy * 1e-6), h, f])
            np.savetxt(fh, a, fmt="%.9e", delimiter=",")
afmdyn.export_map(curves, f"{tmp}/synthetic.nc")
PY
sed 's/spring_constant = 0.043493666407368466/spring_constant = 0.05/' \
    examples/probe-fit-spot3.toml > "$tmp/probe.toml"
farm-bench -n 3 --timeout 900 \
    --vs "$B fit-map --probe $tmp/probe.toml --data $tmp/synthetic.csv --out $tmp/out-csv" \
    -- "$B" fit-map --probe "$tmp/probe.toml" --data "$tmp/synthetic.nc" --out "$tmp/out-nc" \
    > "$tmp/bench-synthetic.txt"
cat "$tmp/bench-synthetic.txt"
"$B" fit-map --probe "$tmp/probe.toml" --data "$tmp/synthetic.nc" --out "$tmp/out-doc" --json \
    > "$tmp/synthetic.json"

section=$(mktemp)
"$PY" - "$tmp" "$(cut -d' ' -f1 /proc/loadavg)" "$(nproc)" \
    "$(du -m "$tmp/synthetic.csv" | cut -f1)" "$(du -m "$tmp/synthetic.nc" | cut -f1)" \
    > "$section" <<'PY'
import json, sys
sys.path.insert(0, "scripts")
from bench_medians import medians
tmp, load, cores, csv_mb, nc_mb = sys.argv[1:6]
nanite = json.load(open(f"{tmp}/nanite.json"))
syn = medians(f"{tmp}/bench-synthetic.txt")
doc = json.load(open(f"{tmp}/synthetic.json"))
print("<!-- fit-map:begin (generated by scripts/perf-fit-map.sh; do not edit) -->")
print("| the same curves (afmformats' JPK test files) | rows per curve | nanite `fit_model` per fit | "
      "`afmdyn fit-map` per curve (whole command / 1024, wall) | ratio | per curve, cpu | ratio per core |")
print("|---|---|---|---|---|---|---|")
for name, label in (("force-map", "force map, 2 × 2"), ("qi", "QI map, 4 curves")):
    med = medians(f"{tmp}/bench-{name}.txt")
    ours = 1e3 * med[("A", "wall")] / 1024
    cpu = 1e3 * med[("A", "cpu")] / 1024
    ref = nanite[name]["nanite_ms"]
    rows = nanite[name]["rows"]
    print(f"| {label} | {min(rows)}–{max(rows)} | {ref:.2f} ms | {ours:.3f} ms | **{ref / ours:.1f}×** "
          f"| {cpu:.3f} ms | {ref / cpu:.1f}× |")
print()
print(f"| 128 × 128 synthetic map, 1 000 rows per curve | median wall | median cpu |")
print("|---|---|---|")
print(f"| NetCDF ({nc_mb} MB, `afmdyn.export_map`) | **{syn[('A', 'wall')]:.1f} s** | {syn[('A', 'cpu')]:.1f} s |")
print(f"| long-format CSV ({csv_mb} MB) | **{syn[('B', 'wall')]:.1f} s** | {syn[('B', 'cpu')]:.1f} s |")
print()
s = doc["summary"]["sample.youngs_modulus"]
print(f"The synthetic map's counts: {doc['counts']}; E's median {s['median']:.1f} Pa (16th–84th "
      f"percentile {s['p16']:.1f} to {s['p84']:.1f} Pa; truth 5 000 Pa with an 800 Pa disc). "
      "Goals (issue 78): per curve ≥ 10× faster than nanite on the same curves; a 128 × 128 map of "
      f"1 000-row curves ≤ 30 s on 2 cores. `bash scripts/perf-fit-map.sh` on this machine "
      f"({cores} cores, shared; load {load} when it ran); whole commands timed by farm-bench, "
      "every file (NetCDF, CSV, JSON, four figures) written.")
print("<!-- fit-map:end -->")
PY
python3 scripts/doc_section.py fit-map "$section" "Force maps (issue 78)"
sed -n '/fit-map:begin/,/fit-map:end/p' "$(python3 scripts/doc_section.py --where fit-map)"
