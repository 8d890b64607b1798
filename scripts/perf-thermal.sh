#!/usr/bin/env bash
# Regenerate the "Thermal noise" section of docs/performance/propagator.md (issue 79's two
# performance aims), from `cargo bench -p afmdyn --bench thermal` (criterion's estimates):
#   1. the PSD of an N = 10 beam over 0–5 f₀ at 10⁵ frequencies (aim ≤ 0.1 s);
#   2. a thermally driven free lever (the paper's default lever, sample out of reach) by the exact
#      stochastic step against the deterministic exact propagator, 100 periods on the same grid,
#      N = 3 and 10 (aim ≤ 2× per period).
# Usage: bash scripts/perf-thermal.sh
set -euo pipefail
cd "$(dirname "$0")/.."
log=$(mktemp)
trap 'rm -f "$log" "${section:-}"' EXIT
cargo bench -p afmdyn --bench thermal 2>&1 | tee "$log" | grep -E "time:|grid steps" || true
section=$(mktemp)
python3 - "$log" > "$section" <<'PY'
import json, re, sys
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
for n in ("3", "10"):
    d, _, _ = est(g, f"deterministic N={n}")
    t, _, _ = est(g, f"thermal N={n}")
    print(f"| free lever, N = {n}, per period: deterministic exact propagator / exact stochastic "
          f"step ({steps.get(n, '?')} grid steps per period) | {d * 1e4:.2f} µs / "
          f"{t * 1e4:.1f} µs: **{t / d:.0f}×** | ≤ 2× |")
print()
print("The deterministic propagator crosses a free stretch in spans of the modal solution; the "
      "stochastic step draws 2N normals and two 2N × 2N products per grid step, the grid "
      "resolving the fastest mode (its cost per step is near that floor).")
print("<!-- thermal:end -->")
PY
python3 scripts/doc_section.py thermal "$section" "Thermal noise (issue 79)"
sed -n '/thermal:begin/,/thermal:end/p' "$(python3 scripts/doc_section.py --where thermal)"
