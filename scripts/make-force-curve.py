#!/usr/bin/env python3
"""The synthetic force curve of docs/tutorials/fitting-force-curves.md:
examples/force-curve-hertz.csv, an approach and retract on a Hertz sample with known truth.

A 10 µm bead (R = 5 µm) on a lever of k = 0.05 N/m indents a sample of E = 5 kPa, ν = 0.5
(a rigid paraboloid, F = (4/3) E/(1 − ν²) √R δ^{3/2}, Sneddon 1965 eq. 6.9) with its contact
at the piezo height 0; the force has a 0.1 nN offset and 20 pN of Gaussian noise (seed 62).
The tip position x runs from +1 µm to −1.5 µm and back; the piezo height is h = x − F/k.

Also examples/force-map-hertz.csv, the smallest force map (`afmdyn fit-map --data`, long format
x, y, height, force, segment): the approach of that curve at two positions 1 µm apart, the
second on a sample twice as stiff (its own noise, the same seed's stream).
"""

import numpy as np

K, R, E, NU = 0.05, 5e-6, 5e3, 0.5
ROWS, SIGMA, OFFSET = 500, 20e-12, 1e-10


def main() -> None:
    rng = np.random.default_rng(62)
    down = np.linspace(1e-6, -1.5e-6, ROWS)
    x = np.concatenate([down, down[::-1]])
    f = 4 / 3 * E / (1 - NU**2) * np.sqrt(R) * np.clip(-x, 0, None) ** 1.5
    h = x - f / K
    measured = f + OFFSET + rng.normal(0.0, SIGMA, x.size)
    with open("examples/force-curve-hertz.csv", "w") as out:
        out.write("height,force\n")
        for hi, fi in zip(h, measured):
            out.write(f"{hi:.9e},{fi:.9e}\n")
    with open("examples/force-map-hertz.csv", "w") as out:
        out.write("x,y,height,force,segment\n")
        for k, stiffer in enumerate([1.0, 2.0]):
            fk = stiffer * f[:ROWS]
            hk = x[:ROWS] - fk / K
            mk = fk + OFFSET + rng.normal(0.0, SIGMA, ROWS)
            for hi, fi in zip(hk, mk):
                out.write(f"{k * 1e-6:.1e},0,{hi:.9e},{fi:.9e},0\n")


if __name__ == "__main__":
    main()
