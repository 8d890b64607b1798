#!/usr/bin/env python3
"""Write examples/fm-vdw.csv: the frequency shift of a van der Waals force F(d) = -HR/(6 d^2)
(H = 1e-19 J, R = 10 nm) on a cantilever of k = 40 N/m, f0 = 300 kHz at A = 10 nm, against
the distance of closest approach d (0.3 nm to 60 nm, 400 log-spaced values), by Giessibl's
first-order relation (Phys. Rev. B 56, 16010 (1997)),

    df(d) = -(f0 / (pi k A)) * integral_-1^1 F(d + A (1 + u)) u / sqrt(1 - u^2) du,

with 512-node Gauss-Chebyshev quadrature (plain Python: an implementation independent of
afmdyn's). `afmdyn reconstruct --fm examples/fm-vdw.csv --spring-constant 40
--resonance-frequency 300kHz --amplitude 10nm` inverts it (Sader-Jarvis)."""

import math
from pathlib import Path

H, R, K, F0, A = 1e-19, 1e-8, 40.0, 300e3, 1e-8
NODES = 512


def force(d: float) -> float:
    return -H * R / (6.0 * d * d)


def shift(d: float) -> float:
    total = 0.0
    for i in range(1, NODES + 1):
        u = math.cos(math.pi * (2 * i - 1) / (2 * NODES))
        total += force(d + A * (1.0 + u)) * u
    return -F0 / (math.pi * K * A) * total * math.pi / NODES


def main() -> None:
    lo, hi, n = 3e-10, 6e-8, 400
    rows = ["distance,frequency_shift"]
    for i in range(n):
        d = lo * (hi / lo) ** (i / (n - 1))
        rows.append(f"{d!r},{shift(d)!r}")
    out = Path(__file__).resolve().parents[1] / "examples" / "fm-vdw.csv"
    out.write_text("\n".join(rows) + "\n", encoding="utf-8")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
