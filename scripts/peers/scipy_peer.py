#!/usr/bin/env python3
"""SciPy peer of afmdyn's trajectory engine, written as a Python user would write it.

The switched model z' = A_s z + b_const + b_sin sin(Omega tau) + b_cos cos(Omega tau), s in {free,
contact}, contact when V_T = tip . a + alpha2 sin(Omega tau) + alpha5 <= 0, is integrated region by
region with scipy.integrate.solve_ivp(method="DOP853", rtol=atol=tol) and a terminal event on V_T,
restarting in the other region at each event.

Model from afmdyn (the peer benchmark, scripts/peers/run.sh): the matrices, start state on the
attractor and afmdyn's exact state 40 later are read from the JSON written by
`cargo run --release -p afmdyn --example peer_export -- N model.json`. Prints one JSON line: the
state at tau_start + 40, its agreement with afmdyn (rel_err = |z - z_ref| / |z_ref|, Euclidean
norms) and the wall time per forcing period of that run (best of --reps runs), or with --periods
of a run of that many periods from the start state. atol = tol, rtol = max(tol, 100 eps) (SciPy
raises a smaller rtol to 100 eps with a warning; atol keeps tightening the control below).

    python3 scripts/peers/scipy_peer.py model.json [--tol 1e-12] [--reps 1] [--periods 0]

Standalone (no afmdyn library): the paper's model (eqs. 8-18) assembled here with NumPy, default
parameters (paper eq. 26, alpha1 = 0.1, Omega = 2.6, N = 3) from rest, compared with
`afmdyn simulate --json` when the binary is given:

    python3 scripts/peers/scipy_peer.py --standalone [--periods 20] [--tol 1e-10] [--afmdyn target/release/afmdyn]
"""
import argparse
import json
import math
import subprocess
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq


RTOL_MIN = 100 * np.finfo(float).eps


def paper_model(n, a1, a2, a3, a4, a5, a6, om):
    """The regions (A, b_const, b_sin, b_cos) and tip vector of the paper's model, eqs. 8-18."""
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
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K[r], -Minv @ C[r]]])
        z0 = np.zeros(n)
        regions.append((A, np.concatenate([z0, Minv @ k0]), np.concatenate([z0, Minv @ s]), np.concatenate([z0, Minv @ c])))
    return regions, tip


def load(path):
    d = json.load(open(path))
    regions = [tuple(np.array(d[r][k], dtype=float) for k in ("a", "b_const", "b_sin", "b_cos")) for r in ("free", "contact")]
    return d, regions, np.array(d["tip"], dtype=float)


def integrate(regions, tip, a2, a5, om, tol, t, z, t_end):
    """Integrate from (t, z) to t_end; returns the final state, steps and switchings."""
    n = len(tip)

    def vt(tt, zz):                                               # eq. 8
        return tip @ zz[:n] + a2 * math.sin(om * tt) + a5

    def rhs(r):
        A, b0, bs, bc = regions[r]

        def f(tt, zz):
            return A @ zz + b0 + bs * math.sin(om * tt) + bc * math.cos(om * tt)
        return f

    fns = [rhs(0), rhs(1)]
    region = 1 if vt(t, z) <= 0 else 0
    switches = steps = 0
    while t < t_end:
        sign = 1.0 if region == 0 else -1.0

        def ev(tt, zz, sign=sign):
            return sign * vt(tt, zz)
        ev.terminal = True
        ev.direction = -1
        sol = solve_ivp(fns[region], (t, t_end), z, method="DOP853", rtol=max(tol, RTOL_MIN), atol=tol, events=ev)
        if sol.status < 0:
            raise RuntimeError(sol.message)
        steps += len(sol.t) - 1
        t, z = sol.t[-1], sol.y[:, -1]
        if sol.status == 1:
            region = 1 - region
            switches += 1
    return z, steps, switches


def peer(args):
    d, regions, tip = load(args.model)
    a2, a5, om = d["alpha2"], d["alpha5"], d["omega"]
    t0, z0 = d["tau_start"], np.array(d["z_start"], dtype=float)
    z_ref = np.array(d["z_ref"], dtype=float)
    period = 2.0 * math.pi / om
    best = math.inf
    for _ in range(max(1, args.reps if args.periods <= 0 else 1)):
        start = time.perf_counter()
        z, steps, switches = integrate(regions, tip, a2, a5, om, args.tol, t0, z0, t0 + d["horizon"])
        best = min(best, time.perf_counter() - start)
    err = float(np.linalg.norm(z - z_ref))
    out = {"peer": "scipy", "n": d["n"], "tol": args.tol, "abs_err": err, "rel_err": err / float(np.linalg.norm(z_ref)),
           "steps": steps, "switchings": switches, "z": z.tolist(),
           "horizon_us_per_period": best * 1e6 / (d["horizon"] / period)}
    if args.periods <= 0:
        out.update({"us_per_period": out["horizon_us_per_period"], "timed_periods": d["horizon"] / period,
                    "repetitions": max(1, args.reps)})
    else:
        best = math.inf
        for _ in range(args.reps):
            start = time.perf_counter()
            _, steps, switches = integrate(regions, tip, a2, a5, om, args.tol, t0, z0, t0 + args.periods * period)
            best = min(best, time.perf_counter() - start)
        out.update({"us_per_period": best * 1e6 / args.periods, "timed_periods": args.periods, "repetitions": args.reps,
                    "steps_per_period": steps / args.periods, "switchings_per_period": switches / args.periods})
    print(json.dumps(out))


def standalone(args):
    regions, tip = paper_model(3, 0.1, 0.1, 0.1, 20.0, 0.0, 0.2, 2.6)
    periods = args.periods if args.periods > 0 else 20.0
    t_end = periods * 2.0 * math.pi / 2.6
    start = time.perf_counter()
    z, _, switches = integrate(regions, tip, 0.1, 0.0, 2.6, args.tol, 0.0, np.zeros(6), t_end)
    wall = time.perf_counter() - start
    print(f"scipy DOP853 rtol={args.tol:g}: {periods:g} periods, {switches} switchings, "
          f"{wall / periods * 1e6:.1f} us per forcing period")
    if args.afmdyn:
        out = subprocess.run([args.afmdyn, "simulate", "--json", "--periods", str(periods), "--out", "/tmp/afmdyn-peer"],
                             check=True, capture_output=True, text=True)
        doc = json.loads(out.stdout)
        za = np.array(doc["final"]["a"] + doc["final"]["a_dot"])
        print(f"afmdyn: {doc['switchings']} switchings; max |z_scipy - z_afmdyn| at tau = {t_end:.4f}: {np.abs(z - za).max():.2e}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("model", nargs="?", help="model JSON from the peer_export example")
    ap.add_argument("--tol", "--rtol", type=float, default=None, help="rtol = atol (default 1e-12; standalone 1e-10)")
    ap.add_argument("--periods", type=float, default=0.0,
                    help="timed forcing periods (default: time the accuracy run; standalone: simulated periods, default 20)")
    ap.add_argument("--reps", type=int, default=1, help="timed repetitions, best taken")
    ap.add_argument("--standalone", action="store_true", help="assemble the paper's model here, N = 3, from rest")
    ap.add_argument("--afmdyn", default=None, help="standalone: path to the afmdyn binary for the comparison")
    args = ap.parse_args()
    if args.standalone:
        args.tol = args.tol or 1e-10
        standalone(args)
    elif args.model:
        args.tol = args.tol or 1e-12
        peer(args)
    else:
        ap.error("give a model JSON or --standalone")


if __name__ == "__main__":
    main()
