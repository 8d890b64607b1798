#!/usr/bin/env bash
# The force-curve fit's benchmark (issue 62, Performance): `afmdyn fit` on a synthetic Hertz
# approach of 10^4 rows (E = 5 kPa, R = 5 µm, k = 0.05 N/m, 20 pN of seeded Gaussian noise;
# examples/probe-fit-hertz.toml), fitting sample.youngs_modulus, contact_point and baseline with
# their profiles: the whole command (reading, preprocessing, fit, profiles, document; --json,
# no files), best of 3. Goal: ≤ 0.2 s.
# Usage: bash scripts/perf-fit.sh [ROWS]
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p afmdyn-cli
B=target/release/afmdyn
n=${1:-10000}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

source scripts/best-of.sh

python3 - "$n" "$tmp/curve.csv" <<'PY'
import math, random, sys
n, path = int(sys.argv[1]), sys.argv[2]
k, r, e, nu = 0.05, 5e-6, 5e3, 0.5
rng = random.Random(62)
with open(path, "w") as f:
    f.write("height,force\n")
    for i in range(n):
        x = 1e-6 - 2.5e-6 * i / (n - 1)
        force = 4 / 3 * e / (1 - nu * nu) * math.sqrt(r) * max(-x, 0.0) ** 1.5
        f.write(f"{x - force / k!r},{force + rng.gauss(0.0, 20e-12)!r}\n")
PY
t=$(best_of 3 "$tmp/out.json" $B fit --probe examples/probe-fit-hertz.toml --data "$tmp/curve.csv" \
    --fit sample.youngs_modulus,contact_point,baseline --json --out "$tmp/out")
python3 - "$tmp/out.json" "$t" "$n" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
e = doc["estimates"]["sample.youngs_modulus"]
print(f"| `afmdyn fit`, {sys.argv[3]} rows, E + contact point + baseline with profiles "
      f"| {float(sys.argv[2]):.3f} s | E = {e['value']:.1f} Pa ± {e['standard_error']:.1f} "
      f"| {doc['evaluations']} evaluations |")
PY
