"""`afmdyn approach` against an independent integrator: the point-mass DMT model of García &
San Paulo (*Phys. Rev. B* 60 (1999) 4961; DMT: Derjaguin, Muller & Toporov, *J. Colloid
Interface Sci.* 53 (1975) 314), written here from the equations alone and integrated with
SciPy's DOP853 (rtol 1e-11) with terminal events at the contact threshold d = a0.

In the units of the probe (tau = omega0 t, lengths of g0, forces of k g0):
    z'' + alpha3 z' + z = alpha2 cos(Omega tau) + F(d, d'),   d = z + alpha5 + a0,
    F = -H/d^2 for d > a0,   F = -H/a0^2 + alpha4 delta^1.5 + alpha6 sqrt(delta) delta'
    for delta = a0 - d >= 0.
Each steady state is a fixed point of the stroboscopic map found by Newton's method with a
finite-difference Jacobian, started from the orbit afmdyn reports (z(0) = <z> + A cos phi,
z'(0) = A Omega sin phi); A and phi are the first Fourier coefficients of z over one period,
z ~ <z> + A cos(Omega tau - phi), integrated with the motion. Agreement to 1e-6 in A/A0 and
in phi (rad) at every z_c, on both the attractive and the repulsive branch, is required.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import scipy.integrate as scipy_integrate  # the [test] extra of pyproject.toml installs SciPy

RTOL = 1e-11
REPO = Path(__file__).resolve().parents[3]


def _model(p):
    law = p["contact_law"]
    assert law["law"] == "dmt" and p["structure"] == "point-mass"
    h, a0 = law["hamaker"], law["intermolecular_distance"]
    a2, a3, a4, a5, a6, om = (p[k] for k in ("alpha2", "alpha3", "alpha4", "alpha5", "alpha6", "omega"))

    def rhs(contact):
        def f(t, y):
            z, v = y[0], y[1]
            vt = z + a5  # V_T: contact while V_T <= 0 (d <= a0)
            if contact:
                delta = max(-vt, 0.0)
                force = -h / a0**2 + a4 * delta**1.5 + a6 * math.sqrt(delta) * (-v)
            else:
                force = -h / (a0 + vt) ** 2
            acc = a2 * math.cos(om * t) - a3 * v - z + force
            # running Fourier integrals of z: cos, sin, and the mean
            return [v, acc, z * math.cos(om * t), z * math.sin(om * t), z]

        return f

    def vt_event(t, y):
        return y[0] + a5

    vt_event.terminal = True

    def period_map(z0, record=False):
        """z(T) from z(0) = z0 over one drive period, and (A, phi, <z>) when `record`."""
        t, t_end = 0.0, 2.0 * math.pi / om
        y = [z0[0], z0[1], 0.0, 0.0, 0.0]
        contact = z0[0] + a5 <= 0.0
        for _ in range(10000):
            sol = scipy_integrate.solve_ivp(
                rhs(contact), (t, t_end), y, method="DOP853", rtol=RTOL, atol=RTOL * 1e-2,
                events=vt_event,
            )
            t, y = sol.t[-1], list(sol.y[:, -1])
            if sol.status != 1:
                break
            contact = not contact
            # step off the event so that it is not found again at the start
            y_ev = sol.y_events[0][0]
            t, y = sol.t_events[0][0], list(y_ev)
            nudge = 1e-13 * t_end
            s2 = scipy_integrate.solve_ivp(
                rhs(contact), (t, t + nudge), y, method="DOP853", rtol=RTOL, atol=RTOL * 1e-2
            )
            t, y = s2.t[-1], list(s2.y[:, -1])
        assert abs(t - t_end) < 1e-12 * t_end
        z1 = np.array(y[:2])
        if not record:
            return z1
        period = 2.0 * math.pi / om
        a = 2.0 / period * y[2]
        b = 2.0 / period * y[3]
        amp = math.hypot(a, b)
        phi = math.atan2(b, a)
        if phi <= -math.pi / 2:
            phi += 2.0 * math.pi
        return z1, amp, phi, y[4] / period

    def free_amplitude():
        return a2 / math.hypot(1.0 - om * om, a3 * om)

    return period_map, free_amplitude


def _fixed_point(period_map, z):
    z = np.array(z, dtype=float)
    for _ in range(30):
        f0 = period_map(z) - z
        if np.linalg.norm(f0) < 1e-12 * (1.0 + np.linalg.norm(z)):
            return z
        jac = np.empty((2, 2))
        for k in range(2):
            dz = np.zeros(2)
            dz[k] = 1e-7 * (1.0 + abs(z[k]))
            jac[:, k] = ((period_map(z + dz) - z - dz) - (period_map(z - dz) - z + dz)) / (2 * dz[k])
        z = z - np.linalg.solve(jac, f0)
    raise AssertionError(f"SciPy Newton did not converge from {z}")


def test_approach_matches_scipy_dop853(cli_json):
    doc = cli_json(
        "approach", "--probe", "examples/probe-point-mass-dmt.toml", "--from", "11e-9",
        "--to", "3e-9", "--points", "5", "--no-branches", "--files", "none",
        cwd=str(REPO),
    )
    p = doc["params"]
    length = doc["scales"]["length"]
    law = p["contact_law"]
    ap = doc["approach"]
    # the 5 points span the attractive branch (11, 9 nm) and the repulsive one (7, 5, 3 nm)
    assert min(ap["phase_deg"]) < 90.0 < max(ap["phase_deg"])
    worst_a = worst_phi = 0.0
    for zc_m, ratio, phase_deg, mean in zip(ap["z_c"], ap["amplitude_ratio"], ap["phase_deg"],
                                            ap["mean_deflection"]):
        zc = zc_m / length
        q = dict(p, alpha5=zc - law["intermolecular_distance"])
        period_map, free_amplitude = _model(q)
        a0 = free_amplitude()
        amp, phi, om = ratio * a0, math.radians(phase_deg), q["omega"]
        guess = [mean / length + amp * math.cos(phi), amp * om * math.sin(phi)]
        z = _fixed_point(period_map, guess)
        _, amp_s, phi_s, _ = period_map(z, record=True)
        worst_a = max(worst_a, abs(amp_s / a0 - ratio))
        worst_phi = max(worst_phi, abs(phi_s - phi))
    print(f"SciPy DOP853 vs afmdyn: max |ΔA|/A0 = {worst_a:.2e}, max |Δφ| = {worst_phi:.2e} rad")
    assert worst_a <= 1e-6, worst_a
    assert worst_phi <= 1e-6, worst_phi
