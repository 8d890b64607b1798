#!/usr/bin/env python3
"""Time and accuracy of the integrators on the laws with a force (Hertz, DMT): `afmdyn simulate
--files none --json` per integrator (best of 3 wall times), and the final state's largest
difference from the adaptive oracle at tolerance 1e-14, relative to the state's largest entry.
Prints a Markdown table. Used for the decision on the exponential (Lawson) frame (issue 43;
docs/performance/laws.md).

Usage: python3 scripts/perf-integrators.py [AFMDYN_BIN] [KIND ...]
       (default: target/release/afmdyn; kinds taylor adaptive split)"""

import json
import os
import subprocess
import sys
import time

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
X = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "target/release/afmdyn")
KINDS = sys.argv[2:] or ["taylor", "adaptive", "split"]
E = os.path.join(root, "examples")
CASES = [
    ("paper beam N = 3, DMT, Ω = 2.6, 1000 periods", ["--contact-law", "dmt", "--periods", "1000"]),
    ("beam N = 8, DMT, 300 periods", ["--contact-law", "dmt", "--modes", "8", "--periods", "300"]),
    ("beam N = 3, DMT a₀ = 0.002, Ω = 2.8, 1000 periods",
     ["--contact-law", "dmt", "--intermolecular-distance", "0.002", "--omega", "2.8", "--periods", "1000"]),
    ("beam N = 3, DMT, gap 0.5 (free flight with van der Waals only), 1000 periods",
     ["--contact-law", "dmt", "--gap", "0.5", "--periods", "1000"]),
    ("examples/probe-beam-dmt.toml, 1000 periods", ["--probe", f"{E}/probe-beam-dmt.toml", "--periods", "1000"]),
    ("examples/probe-point-mass-dmt.toml, 1000 periods",
     ["--probe", f"{E}/probe-point-mass-dmt.toml", "--periods", "1000"]),
    ("RTESPA-300 on PS (Q = 500, DMT), 3000 periods",
     ["--probe", f"{E}/probe-rtespa300-polystyrene.toml", "--periods", "3000"]),
    ("paper beam N = 3, Hertz, Ω = 2.6, 1000 periods", ["--contact-law", "hertz", "--periods", "1000"]),
]


def run(args, kind, tol=None):
    cmd = [X, "simulate", *args, "--files", "none", "--json", "--integrator", kind]
    if tol:
        cmd += ["--tolerance", str(tol)]
    best, out = float("inf"), None
    for _ in range(3):
        t = time.perf_counter()
        r = subprocess.run(cmd, capture_output=True, text=True)
        best = min(best, time.perf_counter() - t)
        if r.returncode != 0:
            return None, r.stderr.strip().split(":")[-1].strip()
        out = r.stdout
    f = json.loads(out)["final"]
    return best, f["a"] + f["a_dot"]


print("| case | " + " | ".join(KINDS) + " |")
print("|---|" + "---|" * len(KINDS))
for name, args in CASES:
    _, ref = run(args, "adaptive", 1e-14)
    scale = max(abs(v) for v in ref)
    cells = []
    for k in KINDS:
        t, z = run(args, k)
        if t is None:
            cells.append("refused")
        else:
            err = max(abs(a - b) for a, b in zip(z, ref)) / scale
            cells.append(f"{t:.3f} s, {err:.0e}")
    print(f"| {name} | " + " | ".join(cells) + " |")
