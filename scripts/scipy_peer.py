#!/usr/bin/env python3
"""SciPy peer of afmdyn's trajectory engine, written as a Python user would write it.

The paper's model (eqs. 8-18) is assembled with NumPy and integrated region by region with
scipy.integrate.solve_ivp(method="DOP853") and a terminal event on V_T, switching the region at
each event. It runs the default parameters (paper eq. 26, alpha1 = 0.1, Omega = 2.6, N = 3) from
rest, prints the wall time per forcing period, and compares the final state with
`afmdyn simulate --json` when the binary is given.

    pip install numpy scipy
    python3 scripts/scipy_peer.py [--periods 20] [--rtol 1e-10] [--afmdyn target/release/afmdyn]
"""
import argparse
import json
import math
import subprocess
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq


def model(n, a1, a2, a3, a4, a5, a6, om):
    beta = np.array([brentq(lambda b: math.cos(b) + 1.0 / math.cosh(b), (i - 0.5) * math.pi - 1.0, (i - 0.5) * math.pi + 1.0)
                     for i in range(1, n + 1)])
    sigma = (np.cosh(beta) + np.cos(beta)) / (np.sinh(beta) + np.sin(beta))
    tip = np.array([2.0 * (-1) ** i for i in range(n)])          # phi_i(1) = +-2
    integ = 2.0 * sigma / beta                                    # int phi_i
    M = np.eye(n) + a1 * np.outer(tip, tip)                       # eq. 11
    K = [np.diag(beta ** 4), np.diag(beta ** 4) + a4 * np.outer(tip, tip)]     # eqs. 13, 17
    C = [a3 * np.eye(n), a3 * np.eye(n) + a6 * np.outer(tip, tip)]             # eqs. 12, 16
    fs = a2 * om ** 2 * (a1 * tip + integ)                        # eq. 14
    fc = -a2 * a3 * integ
    Minv = np.linalg.inv(M)
    regions = []
    for r in range(2):
        s = fs - (a2 * a4 * tip if r else 0.0)                    # eq. 18
        c = fc - (a2 * a6 * om * tip if r else 0.0)
        k0 = -a4 * a5 * tip if r else np.zeros(n)
        regions.append((Minv @ K[r], Minv @ C[r], Minv @ s, Minv @ c, Minv @ k0))

    def rhs(r):
        MK, MC, s, c, k0 = regions[r]

        def f(t, z):
            a, ad = z[:n], z[n:]
            return np.concatenate([ad, s * math.sin(om * t) + c * math.cos(om * t) + k0 - MK @ a - MC @ ad])
        return f

    def vt(t, z):                                                 # eq. 8
        return tip @ z[:n] + a2 * math.sin(om * t) + a5
    return rhs, vt


def run(periods, rtol, n=3, a1=0.1, a2=0.1, a3=0.1, a4=20.0, a5=0.0, a6=0.2, om=2.6):
    rhs, vt = model(n, a1, a2, a3, a4, a5, a6, om)
    t, t_end = 0.0, periods * 2.0 * math.pi / om
    z = np.zeros(2 * n)
    region = 0  # V_T(0) = 0 moving up: free
    switches = 0
    fns = [rhs(0), rhs(1)]
    while t < t_end:
        sign = 1.0 if region == 0 else -1.0

        def ev(tt, zz, sign=sign):
            return sign * vt(tt, zz)
        ev.terminal = True
        ev.direction = -1
        sol = solve_ivp(fns[region], (t, t_end), z, method="DOP853", rtol=rtol, atol=rtol, events=ev)
        t, z = sol.t[-1], sol.y[:, -1]
        if sol.status == 1:
            region = 1 - region
            switches += 1
    return z, switches, t_end


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--periods", type=float, default=20.0)
    ap.add_argument("--rtol", type=float, default=1e-10)
    ap.add_argument("--afmdyn", default=None, help="path to the afmdyn binary for the comparison")
    args = ap.parse_args()
    start = time.perf_counter()
    z, switches, t_end = run(args.periods, args.rtol)
    wall = time.perf_counter() - start
    print(f"scipy DOP853 rtol={args.rtol:g}: {args.periods:g} periods, {switches} switchings, "
          f"{wall / args.periods * 1e6:.1f} us per forcing period")
    if args.afmdyn:
        out = subprocess.run([args.afmdyn, "simulate", "--json", "--periods", str(args.periods), "--out", "/tmp/afmdyn-peer"],
                             check=True, capture_output=True, text=True)
        doc = json.loads(out.stdout)
        za = np.array(doc["final"]["a"] + doc["final"]["a_dot"])
        print(f"afmdyn: {doc['switchings']} switchings; max |z_scipy - z_afmdyn| at tau = {t_end:.4f}: {np.abs(z - za).max():.2e}")


if __name__ == "__main__":
    main()
