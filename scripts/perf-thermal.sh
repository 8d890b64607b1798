#!/usr/bin/env bash
# Regenerate the "Thermal noise" section of docs/performance/propagator.md (issue 79's two
# performance aims), from `cargo bench -p afmdyn --bench thermal` (criterion's estimates):
#   1. the PSD of an N = 10 beam over 0–5 f₀ at 10⁵ frequencies (aim ≤ 0.1 s);
#   2. a thermally driven free lever (the paper's default lever, sample out of reach) by the exact
#      stochastic step, one point held per period (free flight between them), against the
#      deterministic exact propagator, 100 periods, N = 3 and 10 (aim ≤ 2× per period);
#   3. the whole command: `afmdyn simulate --periods 10000` of a free lever with
#      `--temperature 295` against without (farm-bench, paired A/B medians), the water beam
#      (examples/probe-water-beam.toml, three modes, Q₁ ≈ 2.3) and the RTESPA-300 in air
#      (examples/probe-rtespa300-polystyrene.toml, point mass, Q = 500), each over a linear
#      sample at z_c = 500 nm (out of reach).
# Usage: bash scripts/perf-thermal.sh
set -euo pipefail
cd "$(dirname "$0")/.."
log=$(mktemp)
trap 'rm -f "$log"' EXIT
cargo bench -p afmdyn --bench thermal 2>&1 | tee "$log" | grep -E "time:|grid steps" || true
cargo build --release -q -p afmdyn-cli
tmp=$(mktemp -d)
trap 'rm -rf "$log" "${section:-}" "$tmp"' EXIT
for lever in water-beam rtespa300-polystyrene; do
    # the probe over a linear sample out of reach (the thermal step needs the linear law)
    python3 - "examples/probe-$lever.toml" "$tmp/$lever.toml" <<'PY'
import sys
head, rest = open(sys.argv[1]).read().split("[sample]", 1)
i = rest.find("\n[")
tail = rest[i + 1:] if i >= 0 else ""
open(sys.argv[2], "w").write(head + '[sample]\nlaw = "linear"\nstiffness = 1.0\nz_c = 500e-9\n' + tail)
PY
    run="target/release/afmdyn simulate --probe $tmp/$lever.toml --periods 10000"
    farm-bench -n 5 --timeout 600 --vs "$run --out $tmp/b" -- $run --temperature 295 \
        --out "$tmp/a" > "$tmp/$lever.bench"
done
section=$(mktemp)
python3 - "$log" "$tmp" > "$section" <<'PY'
import json, re, sys
sys.path.insert(0, "scripts")
from bench_medians import medians
from pathlib import Path

def est(group, name):
    """criterion's point estimate (s) and its 95 % interval of group/name."""
    e = json.loads((Path("target/criterion") / group / name / "new" / "estimates.json").read_text())
    m = e["mean"]
    return m["point_estimate"] * 1e-9, m["confidence_interval"]["lower_bound"] * 1e-9, \
        m["confidence_interval"]["upper_bound"] * 1e-9

steps = dict(re.findall(r"N = (\d+): (\d+) grid steps per period", open(sys.argv[1]).read()))
psd, lo, hi = est("thermal", "psd_n10_1e5_frequencies")
print("<!-- thermal:begin (scripts/perf-thermal.sh; do not edit by hand) -->")
print("| what | figure | aim |")
print("|---|---|---|")
print(f"| PSD of an N = 10 beam, 0–5 f₀ at 10⁵ frequencies (`thermal_spectrum`) | "
      f"{psd * 1e3:.1f} ms [{lo * 1e3:.1f}, {hi * 1e3:.1f}] | ≤ 100 ms |")
g = "thermal free lever, 100 periods"
ratios = []
for n in ("3", "10"):
    d, _, _ = est(g, f"deterministic N={n}")
    t, _, _ = est(g, f"thermal N={n}")
    ratios.append(t / d)
    print(f"| free lever, N = {n}, per period: deterministic exact propagator / exact stochastic "
          f"step held once per period (free flight; grid of {steps.get(n, '?')} steps per period) | "
          f"{d * 1e4:.2f} µs / {t * 1e4:.2f} µs: **{t / d:.2f}×** | ≤ 2× |")
whole = []
for lever, what in (("water-beam", "water beam, N = 3, Q₁ ≈ 2.3"),
                    ("rtespa300-polystyrene", "RTESPA-300 in air, point mass, Q = 500")):
    med = medians(f"{sys.argv[2]}/{lever}.bench")
    whole.append(med[("A/B", "cpu")])
    print(f"| `afmdyn simulate --periods 10000 --temperature 295` / without, free lever: {what} "
          f"(whole command, recording included; farm-bench medians) | cpu **{med[('A/B', 'cpu')]:.2f}×**, "
          f"wall {med[('A/B', 'wall')]:.2f}× | ≤ 2× |")
print()
print("The bare propagation " + ("meets the aim" if max(ratios) <= 2.0 else "misses the aim") +
      ": where the surface is far the stochastic step takes one step from held point to held "
      "point (free flight, certified by the drift's Lyapunov bound and the noise's Rice estimate; "
      "`crate::integrate::exact::noise`), 2N normals and two 2N × 2N products per period, while "
      "the deterministic propagator crosses the period in spans of the modal solution. Near the "
      "surface both keep the grid. " + ("The whole command meets it too" if max(whole) <= 2.0 else
      f"The whole command is near it ({min(whole):.2f}–{max(whole):.2f}×)") + ": with 200 samples "
      "per period held, recording the series costs more than either propagation.")
import os, subprocess, time
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
print()
print(f"Measured {time.strftime('%Y-%m-%d', time.gmtime())} at commit {commit} ({os.cpu_count()} cores); "
      f"load average at the end {os.getloadavg()[0]:.1f}.")
print("<!-- thermal:end -->")
PY
python3 scripts/doc_section.py thermal "$section" "Thermal noise (issue 79)"
sed -n '/thermal:begin/,/thermal:end/p' "$(python3 scripts/doc_section.py --where thermal)"
