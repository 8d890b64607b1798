#!/usr/bin/env python3
"""Peer comparison of an approach curve: dForce 2.0 (Gisbert & Garcia, Soft Matter 19 (2023) 5857)
against afmdyn, for the point-mass DMT probe of examples/probe-point-mass-dmt.toml.

This is a script, not a test. It contains no dForce code: it imports dForce's own modules from
the directory given with --dforce, drives its approach-curve routine general.runner headless (a
stand-in object answers the few GUI variables runner reads, and odeint is wrapped only to record
the time series runner computes), and reads the zcdom*.csv file runner writes.

The afmdyn side is
  * `afmdyn approach --probe P --from --to --step --json`: afmdyn's own observables, and for every
    z_c `afmdyn orbit --probe P --z-c Z_C --initial-modal ... --json`, the period-1 orbit
    (Newton shooting) started from the approach's first harmonic, so that it lies on the branch
    the sweep followed (without the approach command: from the previous z_c's orbit, and the
    afmdyn column is then the SciPy integration below);
  * an independent SciPy integration (DOP853, rtol 1e-13, the contact threshold d = a0 located
    as an event) of the point-mass model written here from the SI probe, started from afmdyn's
    orbit state: it must close after one period (checked) and gives the reference time series.

Every quantity is then computed in both conventions from the same series, so the table separates
convention differences (same orbit, two definitions) from numerical ones (same definition, two
simulators):
  afmdyn convention: first-harmonic amplitude A1 and lag phi1, E_dis = -(closed integral of
      F_ts dz), virial = (1/T) integral of F_ts z dt, peak force max F_ts (extremum located);
  dForce convention: (max - min)/2 of samples, phase from the FFT bin of the drive, E_dis and
      virial as sums over npp samples per period (dt from linspace(0, nper/f, nper*npp)), peak
      force max |F_ts| over samples.

    python3 scripts/peers/dforce_approach.py --dforce /tmp/dforce
        [--afmdyn target/release/afmdyn] [--probe examples/probe-point-mass-dmt.toml]
        [--from-nm 12 --to-nm 3 --step-nm 0.5] [--tolerance 14] [--periods 1500]
        [--retract] [--peer-json FILE (cache: reuse a saved dForce run)] [--json OUT]

The first run creates target/venv-peers (pip install of the versions dForce 2.0 pins in its
requirements.txt: numpy 1.26.3, scipy 1.12.0, matplotlib 3.8.2) and re-runs itself there.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

REPO = os.path.realpath(os.path.join(os.path.dirname(__file__), "..", ".."))
VENV = os.path.join(REPO, "target", "venv-peers")
PINS = ["numpy==1.26.3", "scipy==1.12.0", "matplotlib==3.8.2"]


def ensure_venv():
    """Re-run this script under target/venv-peers, creating it on first use."""
    py = os.path.join(VENV, "bin", "python")
    if os.path.realpath(sys.prefix) == os.path.realpath(VENV) or "--no-venv" in sys.argv:
        return
    if not os.path.exists(py):
        subprocess.check_call([sys.executable, "-m", "venv", VENV])
        subprocess.check_call([py, "-m", "pip", "install", "-q"] + PINS)
    os.execv(py, [py] + sys.argv)


ensure_venv()

import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

try:
    import tomllib  # noqa: E402
except ImportError:  # Python < 3.11
    import tomli as tomllib  # type: ignore


# ----------------------------------------------------------------------------- the probe
class Probe:
    """The SI point-mass DMT probe, read from an afmdyn probe file."""

    def __init__(self, path):
        with open(path, "rb") as fh:
            p = tomllib.load(fh)
        c, tip, s, d = p["cantilever"], p["tip"], p["sample"], p["drive"]
        if p.get("model", "point-mass") != "point-mass" or s.get("law") != "dmt":
            sys.exit("the dForce comparison needs a point-mass probe with law = \"dmt\"")
        if float(s.get("viscosity", 0.0)) != 0.0:
            sys.exit("dForce's viscous DMT term differs from afmdyn's: use viscosity = 0")
        self.k = float(c["spring_constant"])
        self.f0 = float(c["resonance_frequency"])
        self.Q = float(c["quality_factor"])
        self.R = float(tip["radius"])
        self.Et, self.nut = float(tip["youngs_modulus"]), float(tip["poisson_ratio"])
        self.Es, self.nus = float(s["youngs_modulus"]), float(s["poisson_ratio"])
        self.H = float(s["hamaker"])
        self.a0 = float(s["intermolecular_distance"])
        self.A0 = float(d["free_amplitude"])
        self.f = float(d["frequency"])
        self.Estar = 1.0 / ((1 - self.nut ** 2) / self.Et + (1 - self.nus ** 2) / self.Es)
        self.w0 = 2 * math.pi * self.f0
        self.Om = self.f / self.f0
        # drive amplitude for a free amplitude A0 at f (both codes use this definition)
        self.F0 = self.k * self.A0 * math.hypot(1 - self.Om ** 2, self.Om / self.Q)

    def force(self, d):
        """DMT tip-sample force (N) at distance d (m), repulsive positive; vectorised."""
        d = np.asarray(d, dtype=float)
        ind = np.clip(self.a0 - d, 0.0, None)
        out = -self.H * self.R / (6 * np.maximum(d, self.a0) ** 2)
        return out + 4.0 / 3.0 * self.Estar * math.sqrt(self.R) * ind ** 1.5


# ----------------------------------------------------------------------------- dForce
class _Var:
    def __init__(self, v):
        self.v = v

    def get(self):
        return self.v


class _Quiet:
    def configure(self, *a, **k):
        pass

    def update(self):
        pass

    def update_idletasks(self):
        pass


def run_dforce(dforce_dir, P, zcs, tolerance, nper, npp, nperfin, retrace=False):
    """Run dForce 2.0's general.runner (point mass, DMT only) over the z_c grid; returns the
    zcdom table it writes plus the steady-state window of every odeint call."""
    os.environ.setdefault("MPLBACKEND", "Agg")
    sys.path.insert(0, os.path.realpath(dforce_dir))
    import general  # dForce 2.0's simulation module  # noqa: E402

    gui = _Quiet()
    gui.abort = 0
    gui.progressbar1 = {}
    gui.style = _Quiet()
    gui.fcorrection_q1_var = _Var(0)          # no f0 -> f0/sqrt(1-1/2Q^2) correction
    same_f = P.f == P.f0
    gui.copy_fre1_var = _Var(1 if same_f else 0)
    gui.fd1_sp = _Var(repr(P.f / 1e3))
    gui.simulate_retrace_var = _Var(1 if retrace else 0)
    tl = _Quiet()
    for name, val in dict(saym_sp_var=P.Es / 1e6, saym2_sp_var=P.Es / 1e6, ham2_sp_var=0.0,
                          angle_sp_var=10.0, sahe_sp_var=10.0, bec_bonded_var=True,
                          musam_sp_var=P.nus, magnetic_m_tip=0.0, magnetic_m_sample=0.0,
                          magnetic_B0_sample=0.0, magnetic_k_sample=0.1, sigma_lj_var=1.0,
                          epsilon_lj_var=1.0, custom1_sp_var=0.0, custom2_sp_var=0.0,
                          custom3_sp_var=0.0, custom4_sp_var=0.0).items():
        setattr(tl, name, val)
    gui.toplevel1 = tl
    n_opts = 29
    dmt_index = 7                              # option_mask[7]: forces.dmt (vdW + DMT)
    gui.get_option_mask = lambda: [i == dmt_index for i in range(n_opts)]

    records = []
    odeint = general.odeint

    def recording_odeint(func, y0, t, args=(), **kw):
        t0 = time.time()
        y, info = odeint(func, y0, t, args=args, **kw)
        n_ss = npp * nperfin
        records.append(dict(zc=float(args[17]), wall_s=time.time() - t0, nfe=int(info["nfe"][-1]),
                            nst=int(info["nst"][-1]), t=t[-n_ss:].copy(),
                            z=y[-n_ss:, 0].copy(), v=y[-n_ss:, 1].copy(),
                            rtol=kw.get("rtol"), atol=kw.get("atol")))
        return y, info

    general.odeint = recording_odeint
    zc_max, step = zcs[0], zcs[0] - zcs[1] if len(zcs) > 1 else 1e-9
    zc_min = zcs[-1] - 0.5 * step              # runner uses np.arange(zc_max, zc_min, -step)
    b = np.array([P.f0 / 1e3, P.f / 1e3, P.k, P.Q, P.A0, P.R, P.a0, P.Estar, P.H, 0.0, 0.0, 0.0,
                  1e-9, 1.0, 0.0, 0.0, nper, npp, nperfin, zc_max, zc_min, step, zc_max,
                  tolerance])
    cwd = os.getcwd()
    work = tempfile.mkdtemp(prefix="dforce-")
    os.chdir(work)
    try:
        os.mkdir("dForceprojectpeer")
        t0 = time.time()
        devnull = open(os.devnull, "w")
        stdout, sys.stdout = sys.stdout, devnull   # runner prints one line per z_c
        try:
            general.runner(b, "peer", "1", gui)
        finally:
            sys.stdout = stdout
        wall = time.time() - t0
        zcdom = np.loadtxt("dForceprojectpeer/zcdom1.csv", delimiter=",", skiprows=1, ndmin=2)
    finally:
        os.chdir(cwd)
    general.odeint = odeint
    cols = ["zc", "Amplitude", "Phase", "Distance_min", "Force_max", "Energy_diss", "Virial1",
            "Deflection", "Contact_time", "Power_diss"]
    return dict(zcdom={c: zcdom[:, i].tolist() for i, c in enumerate(cols)}, wall_s=wall,
                tolerance=tolerance, nper=nper, npp=npp, nperfin=nperfin,
                records=[{k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in r.items()}
                         for r in records])


# ----------------------------------------------------------------------------- conventions
def dforce_grid(P, nper, npp, nperfin):
    """dForce's sample times of the steady-state window: linspace(0, nper/f, nper*npp)[-npp*nperfin:]."""
    n = int(nper * npp)
    t = np.linspace(0.0, nper / P.f, n)
    return t[n - npp * nperfin:], t[1] - t[0]


def dforce_conventions(P, zc, t, z, v, dt, npp, nperfin):
    """dForce 2.0's zc-domain definitions (general.runner + analysis.py), re-implemented, in SI."""
    f = P.force(zc + z)
    drive = P.F0 * np.cos(2 * math.pi * P.f * t)
    ft, zt = np.fft.fft(drive), np.fft.fft(z)
    i = int(np.argmax(np.abs(ft)))
    shift = -np.angle(zt[i]) + np.angle(ft[i])
    n = npp * nperfin
    return dict(amplitude=(z.max() - z.min()) / 2,
                phase_deg=math.degrees(math.acos(math.cos(shift))),
                energy_dissipated=-dt * float(np.sum(v * f)) / nperfin,
                virial=float(np.sum(z[:-1] * f[:-1])) / n,
                peak_force=float(np.max(np.abs(f))),
                mean_deflection=float(np.mean(z)),
                min_distance=float(np.min(zc + z - P.a0)))


def harmonic_fit(P, t, z, nharm=20):
    """Least-squares z = c0 + sum a_n cos(n w t) + b_n sin(n w t) on the samples; the first
    harmonic as amplitude and lag behind the drive F0 cos(w t)."""
    th = 2 * math.pi * P.f * t
    cols = [np.ones_like(t)]
    for n in range(1, nharm + 1):
        cols += [np.cos(n * th), np.sin(n * th)]
    c, *_ = np.linalg.lstsq(np.array(cols).T, z, rcond=None)
    return dict(amplitude=math.hypot(c[1], c[2]), phase_deg=math.degrees(math.atan2(c[2], c[1])),
                mean_deflection=c[0])


# ----------------------------------------------------------------------------- afmdyn
def afmdyn_json(cmd):
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(" ".join(cmd) + "\n" + out.stderr)
    return json.loads(out.stdout)


def afmdyn_orbits(afmdyn, probe, P, zcs, appr=None, sweep="approach"):
    """Period-1 orbits of afmdyn along the approach. With afmdyn's approach curve at hand, each
    orbit is started from the first harmonic that curve reports (so Newton lands on the branch
    the approach followed); otherwise from the previous orbit's state (continuation), retried
    with a long transient when that lands on an unstable orbit."""
    orbits, init = [], None
    for i, zc in enumerate(zcs):
        # z_c in m (a probe refuses the dimensionless --gap; afmdyn sets α5 = (z_c − a0)/A0)
        cmd = [afmdyn, "orbit", "--probe", probe, "--z-c", repr(zc), "--period", "1", "--json"]
        if appr is not None:
            ar = appr[sweep]
            j = int(np.argmin(np.abs(np.array(ar["z_c"]) - zc)))
            A, ph, mean = ar["amplitude"][j], math.radians(ar["phase_deg"][j]), ar["mean_deflection"][j]
            # z = mean + A cos(Om s - phi) at the section s = 0, in units of A0 (g0 of the probe)
            init = ((mean + A * math.cos(ph)) / P.A0, A * P.Om * math.sin(ph) / P.A0)
        if init is not None:
            cmd += ["--initial-modal", "%r;%r" % (init[0], init[1])]
        o = afmdyn_json(cmd)
        if not o.get("stable", False) and appr is None:
            o = afmdyn_json(cmd + ["--max-periods", "20000"])
        if not o.get("stable", False) or o.get("period") != 1:
            print("warning: z_c = %.3g nm: afmdyn orbit period %s stable %s"
                  % (zc * 1e9, o.get("period"), o.get("stable")), file=sys.stderr)
        init = o["state"]
        orbits.append(o)
    return orbits


def afmdyn_approach(afmdyn, probe, zcs):
    """afmdyn's own approach observables, when the binary has the command (else None)."""
    try:
        h = subprocess.run([afmdyn, "approach", "--help"], capture_output=True, text=True)
    except OSError:
        return None
    if h.returncode != 0:
        return None
    step = zcs[0] - zcs[1]
    return afmdyn_json([afmdyn, "approach", "--probe", probe, "--from", repr(zcs[0]),
                        "--to", repr(zcs[-1]), "--step", repr(step), "--files", "none",
                        "--out", tempfile.mkdtemp(prefix="afmdyn-approach-"), "--json"])


# ----------------------------------------------------------------------------- reference
class Reference:
    """One period of the point-mass model from an afmdyn orbit state, integrated with DOP853.

    Scaled units: x = z/A0, s = w0 t; drive F0 cos(Omega s): afmdyn's point-mass drive is
    sin(Omega s + pi/2) (Params::drive_phase) with the Poincare section at drive phase 0, and
    dForce's is F0 cos(w t), so both phase origins coincide: s = w t / Omega.
    """

    def __init__(self, P, zc, z0, v0, rtol=1e-13, atol=1e-15):
        self.P, self.zc = P, zc
        A0, k = P.A0, P.k
        S = 2 * math.pi / P.Om
        F0 = P.F0 / (k * A0)

        def fts(x):
            return float(P.force(zc + A0 * x)) / (k * A0)

        def rhs(s, q):
            x, xd = q[0], q[1]
            F = fts(x)
            acc = -xd / P.Q - x + F0 * math.cos(P.Om * s) + F
            return [xd, acc, x * math.sin(P.Om * s), x * math.cos(P.Om * s), F * x, -F * xd]

        def gap(s, q):
            return zc + A0 * q[0] - P.a0

        def vel(s, q):
            return q[1]

        q = np.array([z0 / A0, v0 / (A0 * P.w0), 0.0, 0.0, 0.0, 0.0])
        s, self.segments, self.minima, self.maxima = 0.0, [], [], []
        while s < S * (1 - 1e-15):
            g = gap(s, q)
            # at a located threshold crossing the side is decided by the velocity
            contact = g < 0 if abs(g) > 1e-9 * P.a0 else q[1] < 0
            gap.terminal, gap.direction = True, (1 if contact else -1)
            vel.terminal, vel.direction = False, 0
            sol = solve_ivp(rhs, (s, S), q, method="DOP853", rtol=rtol, atol=atol,
                            events=(gap, vel), dense_output=True)
            if not sol.success:
                raise RuntimeError(sol.message)
            self.segments.append((s, sol.t[-1], sol.sol))
            for se, ye in zip(sol.t_events[1], sol.y_events[1]):
                acc = rhs(se, ye)[1]
                (self.minima if acc > 0 else self.maxima).append((se, ye[0]))
            s, q = sol.t[-1], sol.y[:, -1].copy()
        self.S = S
        self.end = q
        self.closure = math.hypot(q[0] - z0 / A0, q[1] - v0 / (A0 * P.w0))
        a, b = 2 / S * q[2], 2 / S * q[3]
        xmin = min(x for _, x in self.minima)
        xmax = max(x for _, x in self.maxima)
        dmin = zc + A0 * xmin
        self.obs = dict(
            amplitude=A0 * math.hypot(a, b),
            phase_deg=math.degrees(math.atan2(a, b)),   # x = A1 cos(Om s - phi) + ...
            energy_dissipated=k * A0 ** 2 * q[5],
            virial=k * A0 ** 2 * q[4] / S,
            peak_force=float(P.force(dmin if dmin < P.a0 else zc + A0 * xmax)),
            min_force=float(-P.H * P.R / (6 * max(dmin, P.a0) ** 2)),
            indentation=max(0.0, P.a0 - dmin),
            half_range=A0 * (xmax - xmin) / 2,
            min_distance=dmin - P.a0)

    def state(self, s):
        """(x, x') at scaled times s (mapped into the period)."""
        s = np.mod(s, self.S)
        out = np.empty((2, len(s)))
        for lo, hi, sol in self.segments:
            m = (s >= lo) & (s <= hi)
            if m.any():
                out[:, m] = sol(s[m])[:2]
        return out

    def dforce_samples(self, t):
        """z, v (SI) at dForce sample times t (drive F0 cos(w t))."""
        P = self.P
        s = 2 * math.pi * P.f * t / P.Om
        x, xd = self.state(s)
        return P.A0 * x, P.A0 * P.w0 * xd


# ----------------------------------------------------------------------------- main
def rel(a, b):
    return (a - b) / abs(b) if b != 0 else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dforce", required=True, help="directory of dForce 2.0's sources (general.py, forces.py, analysis.py)")
    ap.add_argument("--afmdyn", default=os.path.join(REPO, "target", "release", "afmdyn"))
    ap.add_argument("--probe", default=os.path.join(REPO, "examples", "probe-point-mass-dmt.toml"))
    ap.add_argument("--from-nm", type=float, default=12.0)
    ap.add_argument("--to-nm", type=float, default=3.0)
    ap.add_argument("--step-nm", type=float, default=0.5)
    ap.add_argument("--tolerance", type=float, default=14,
                    help="dForce's tolerance x: odeint rtol = atol = 10^-x (GUI default 9; 16 fails in LSODA)")
    ap.add_argument("--periods", type=int, default=1500, help="dForce 'Number of periods' per z_c (GUI default 400)")
    ap.add_argument("--npp", type=int, default=128, help="dForce 'Number of points per period' (GUI default 128)")
    ap.add_argument("--nperfin", type=int, default=128, help="dForce steady-state window in periods (GUI default 128)")
    ap.add_argument("--retract", action="store_true",
                    help="also the retract sweep (dForce's 'Retraction' option: the z_c grid run back up)")
    ap.add_argument("--peer-json", help="cache of the dForce run: read if it exists, else written")
    ap.add_argument("--json", help="write every number of the comparison here")
    ap.add_argument("--no-venv", action="store_true", help="run in the current interpreter")
    a = ap.parse_args()

    P = Probe(a.probe)
    n = int(round((a.from_nm - a.to_nm) / a.step_nm)) + 1
    zcs = [(a.from_nm - i * a.step_nm) * 1e-9 for i in range(n)]

    # dForce
    if a.peer_json and os.path.exists(a.peer_json):
        with open(a.peer_json) as fh:
            peer = json.load(fh)
    else:
        peer = run_dforce(a.dforce, P, zcs, a.tolerance, a.periods, a.npp, a.nperfin, a.retract)
        if a.peer_json:
            with open(a.peer_json, "w") as fh:
                json.dump(peer, fh)
    print("dForce 2.0: %d z_c, tolerance 10^-%g (odeint rtol = atol), %d periods x %d points, window %d periods, %.0f s"
          % (len(peer["records"]), peer["tolerance"], peer["nper"], peer["npp"], peer["nperfin"], peer["wall_s"]))

    # afmdyn
    t0 = time.time()
    appr = afmdyn_approach(a.afmdyn, a.probe, zcs)
    sweeps = [("approach", zcs)]
    if len(peer["records"]) == 2 * len(zcs):     # dForce ran the retrace too
        sweeps.append(("retract", zcs[::-1]))
    orbits = {name: afmdyn_orbits(a.afmdyn, a.probe, P, g, appr, name) for name, g in sweeps}
    print("afmdyn: %d orbits%s, %.1f s" % (sum(len(o) for o in orbits.values()), " + approach" if appr else " (no approach command: afmdyn column = SciPy integration of afmdyn's orbit)", time.time() - t0))

    tgrid, dt = dforce_grid(P, peer["nper"], peer["npp"], peer["nperfin"])
    rows = []
    for si, (name, grid) in enumerate(sweeps):
        for ii, (zc, o) in enumerate(zip(grid, orbits[name])):
            i = si * len(zcs) + ii                  # row of dForce's zcdom file
            L, T = o["si"]["scales"]["length_m"], o["si"]["scales"]["time_s"]
            ref = Reference(P, zc, o["state"][0] * L, o["state"][1] * L / T)
            zr, vr = ref.dforce_samples(tgrid)
            ref_df = dforce_conventions(P, zc, tgrid, zr, vr, dt, peer["npp"], peer["nperfin"])
            rec = peer["records"][i]
            assert abs(rec["zc"] - zc) < 1e-15, (rec["zc"], zc)
            tp, zp, vp = (np.array(rec[k]) for k in ("t", "z", "v"))
            peer_df_check = dforce_conventions(P, zc, tp, zp, vp, dt, peer["npp"], peer["nperfin"])
            peer_fit = harmonic_fit(P, tp, zp)
            zd = {k: v[i] for k, v in peer["zcdom"].items()}
            peer_df = dict(amplitude=zd["Amplitude"] * 1e-9, phase_deg=zd["Phase"],
                           energy_dissipated=zd["Energy_diss"] * 1e-20, virial=zd["Virial1"] * 1e-20,
                           peak_force=zd["Force_max"] * 1e-12, mean_deflection=zd["Deflection"] * 1e-9)
            # the re-implementation of dForce's conventions must reproduce its own file
            for kk in peer_df:
                assert abs(rel(peer_df_check[kk], peer_df[kk])) < 1e-9 or abs(peer_df_check[kk] - peer_df[kk]) < 1e-25, (kk, peer_df_check[kk], peer_df[kk])
            afm = dict(ref.obs)
            if appr:
                ar = appr[name]
                j = int(np.argmin(np.abs(np.array(ar["z_c"]) - zc)))
                afm = dict(amplitude=ar["amplitude"][j], phase_deg=ar["phase_deg"][j],
                           energy_dissipated=ar["energy_dissipated"][j], virial=ar["virial"][j],
                           peak_force=ar["peak_force"][j], min_force=ar["min_force"][j])
            rows.append(dict(sweep=name, zc=zc, afmdyn=afm, ref=ref.obs, ref_dforce=ref_df, dforce=peer_df,
                             dforce_fit=peer_fit, closure=ref.closure, nfe=rec["nfe"], nst=rec["nst"],
                             multipliers=o.get("multipliers")))

    def table(title, key, scale, unit, peer_fit_key=None, df_peak=False):
        print("\n%s (%s)" % (title, unit))
        hdr = "%6s %12s %12s %12s %12s" % ("z_c nm", "afmdyn", "SciPy ref", "ref dF-conv", "dForce")
        if peer_fit_key:
            hdr += " %12s" % "dForce A1fit"
        hdr += " %10s %10s" % ("num rel", "conv rel")
        if peer_fit_key:
            hdr += " %10s" % "fit rel"
        print(hdr)
        for k, r in enumerate(rows):
            if k and r["sweep"] != rows[k - 1]["sweep"]:
                print("  -- %s --" % r["sweep"])
            afm, rf, rd, dfv = r["afmdyn"][key], r["ref"][key], r["ref_dforce"][key], r["dforce"][key]
            if df_peak:  # dForce reports max|F|: compare with afmdyn's max(peak, -min)
                afm = max(afm, -r["afmdyn"]["min_force"])
                rf = max(rf, -r["ref"]["min_force"])
            line = "%6.2f %12.6g %12.6g %12.6g %12.6g" % (r["zc"] * 1e9, afm * scale, rf * scale, rd * scale, dfv * scale)
            if peer_fit_key:
                line += " %12.6g" % (r["dforce_fit"][peer_fit_key] * scale)
            if key in ("phase_deg",):
                line += " %10.2e %10.2e" % (dfv - rd, rd - afm)
                if peer_fit_key:
                    line += " %10.2e" % (r["dforce_fit"][peer_fit_key] - afm)
            elif key == "energy_dissipated":
                line += " %10s %10s" % ("(abs)", "(abs)")
            else:
                line += " %10.2e %10.2e" % (rel(dfv, rd), rel(rd, afm))
                if peer_fit_key:
                    line += " %10.2e" % rel(r["dforce_fit"][peer_fit_key], afm)
            print(line)

    print("\nnum rel = dForce / (reference in dForce's convention) - 1: numerics;"
          "\nconv rel = (reference in dForce's convention) / (reference in afmdyn's) - 1: convention;"
          "\nfit rel = first harmonic fitted to dForce's own series vs afmdyn (phases: differences in degrees).")
    table("Amplitude: afmdyn A1 vs dForce (max-min)/2", "amplitude", 1e9, "nm", "amplitude")
    table("Phase lag behind the drive", "phase_deg", 1.0, "deg", "phase_deg")
    table("Virial: (1/T) int F z dt vs sum_{k<N-1} z_k F_k / N", "virial", 1e20, "1e-20 J")
    table("E_dis: -closed int F dz vs -dt sum v_k F_k / nperfin (DMT with eta = 0: zero exactly)", "energy_dissipated", 1e20, "1e-20 J")
    table("Peak force: max(F, -F_min) located vs max|F_k| over samples", "peak_force", 1e9, "nN", df_peak=True)
    print("\nclosure of the SciPy period from afmdyn's orbit state (scaled units): max %.1e;"
          " dForce odeint function evaluations per z_c: %d..%d"
          % (max(r["closure"] for r in rows), min(r["nfe"] for r in rows), max(r["nfe"] for r in rows)))
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(dict(probe=a.probe, tolerance=peer["tolerance"], nper=peer["nper"], npp=peer["npp"],
                           nperfin=peer["nperfin"], rows=rows), fh, indent=1)


if __name__ == "__main__":
    main()
