#!/usr/bin/env python3
"""Write examples/force-curve-sls-dwell.csv: a synthetic approach–dwell–retract force curve on a
standard linear solid, with known truth, made independently of afmdyn.

The sample is the Zener solid with surface memory of afmdyn's ``sls`` law (López-Guerra &
Solares, Beilstein J. Nanotechnol. 5 (2014) 2149): a relaxed spring k1 in parallel with a
Maxwell arm (spring k2, dashpot η = k2 τ), its state u the dashpot's extension. The lever
(k = 0.05 N/m, examples/probe-fit-sls.toml) is in series: in contact k(x − h) = k1 δ + k2 (δ − u)
with δ = −x, so δ = (−k h + k2 u)/(k + k1 + k2); the tip touches where δ ≥ k2 u/(k1 + k2)
(the force would pull otherwise); u' = (δ − u)/τ in contact, −k1 u/(τ (k1 + k2)) free.
The piezo moves from +1 µm to −1 µm in 1 s (the surface at 0), holds 1 s, returns in 1 s;
u is integrated by classical Runge–Kutta with 50 steps per row, rows at 1 kHz, and Gaussian
noise of 50 pN (Python's ``random``, seed 62) is added to the force. The arguments set the
output file and the number of rows (the curve's 3 s sampled evenly).

Truth: k1 = 0.01 N/m, k2 = 0.02 N/m, τ = 0.1 s.

    python3 scripts/make-sls-curve.py              # rewrites examples/force-curve-sls-dwell.csv
    python3 scripts/make-sls-curve.py OUT.csv ROWS # another file (scripts/perf-fit.sh)
"""

import random
import sys
from pathlib import Path

K, K1, K2, TAU = 0.05, 0.01, 0.02, 0.1
SIGMA, SEED, SUB = 50e-12, 62, 50


def piezo(t: float) -> float:
    if t <= 1.0:
        return 1e-6 - 2e-6 * t
    if t <= 2.0:
        return -1e-6
    return -1e-6 + 2e-6 * (t - 2.0)


def indentation(h: float, u: float):
    d = (-K * h + K2 * u) / (K + K1 + K2)
    return d if d >= K2 * u / (K1 + K2) else None


def rate(t: float, u: float) -> float:
    d = indentation(piezo(t), u)
    return (d - u) / TAU if d is not None else -K1 * u / (TAU * (K1 + K2))


def main() -> None:
    root = Path(__file__).resolve().parent.parent
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else root / "examples" / "force-curve-sls-dwell.csv"
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 3001
    dt = 3.0 / (n - 1)
    rng = random.Random(SEED)
    rows = ["time,height,force"]
    u = 0.0
    for i in range(n):
        t = i * dt
        if i > 0:
            h = dt / SUB
            for j in range(SUB):
                s = t - dt + j * h
                a = rate(s, u)
                b = rate(s + h / 2, u + h / 2 * a)
                c = rate(s + h / 2, u + h / 2 * b)
                e = rate(s + h, u + h * c)
                u += h / 6 * (a + 2 * b + 2 * c + e)
        d = indentation(piezo(t), u)
        f = 0.0 if d is None else (K1 + K2) * d - K2 * u
        rows.append(f"{t:.9g},{piezo(t):.9e},{f + rng.gauss(0.0, SIGMA):.6e}")
    out.write_text("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
