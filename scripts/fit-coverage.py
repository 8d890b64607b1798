"""The coverage of the dynamic fit's 95 % intervals (issue 62 §1, check "Coverage"): a synthetic
100-row AM approach (amplitude and phase against the piezo position z; z_c = 7.5 → 3 nm, the
repulsive branch below the approach's fold) of examples/probe-point-mass-dmt.toml made once by `afmdyn approach`,
then DRAWS draws of seeded Gaussian noise (σ = 0.02 nm and 0.1°), each fitted by `afmdyn fit`
for sample.youngs_modulus, sample.hamaker and z_offset (truth: the probe's E = 4 GPa and
H = 6.6e-20 J, z_offset = 1 nm). Prints, for each parameter, the fraction of draws whose 95 %
interval (the profile likelihood's) covers the truth; the goal is 90–99 %.

Usage: python3 scripts/fit-coverage.py [DRAWS] [PROBE]   (AFMDYN_BIN: the binary; default
target/release/afmdyn). Too long for the test suite (a fit with profiles per draw).
"""
import json
import os
import random
import subprocess
import sys
import tempfile
import time

draws = int(sys.argv[1]) if len(sys.argv) > 1 else 100
probe = sys.argv[2] if len(sys.argv) > 2 else "examples/probe-point-mass-dmt.toml"
binary = os.environ.get("AFMDYN_BIN", "target/release/afmdyn")
truth = {"sample.youngs_modulus": 4e9, "sample.hamaker": 6.6e-20, "z_offset": 1e-9}
sa, sp = 2e-11, 0.1

with tempfile.TemporaryDirectory() as tmp:
    appr = subprocess.run([binary, "approach", "--probe", probe, "--from", "7.5e-9", "--to", "3e-9",
                           "--points", "100", "--json", "--files", "none"],
                          check=True, capture_output=True, text=True)
    a = json.loads(appr.stdout)["approach"]
    covered = {k: 0 for k in truth}
    done = 0
    t0 = time.time()
    for seed in range(draws):
        rng = random.Random(seed)
        path = os.path.join(tmp, "am.csv")
        with open(path, "w") as f:
            f.write("z,amplitude,phase,sigma_amplitude,sigma_phase\n")
            for zc, amp, ph in zip(a["z_c"], a["amplitude"], a["phase_deg"]):
                f.write(f"{zc - truth['z_offset']!r},{amp + rng.gauss(0, sa)!r},"
                        f"{ph + rng.gauss(0, sp)!r},{sa},{sp}\n")
        out = subprocess.run([binary, "fit", "--probe", probe, "--data", path, "--fit",
                              ",".join(truth), "--json", "--files", "none"],
                             capture_output=True, text=True)
        if out.returncode != 0:
            print(f"draw {seed}: failed: {out.stderr.strip()[:200]}", file=sys.stderr)
            continue
        doc = json.loads(out.stdout)
        done += 1
        for k, t in truth.items():
            lo, hi = doc["estimates"][k]["interval"]
            if lo is not None and hi is not None and lo <= t <= hi:
                covered[k] += 1
        print(f"draw {seed}: " + ", ".join(
            f"{k} {doc['estimates'][k]['value']:.5g} {doc['estimates'][k]['interval']}"
            for k in truth), file=sys.stderr)
    print(f"{done} of {draws} draws fitted in {time.time() - t0:.0f} s ({probe})")
    for k in truth:
        frac = covered[k] / done if done else float("nan")
        flag = "ok" if 0.90 <= frac <= 0.99 else "OUTSIDE 90-99 %"
        print(f"{k}: the 95 % interval covers the truth in {100 * frac:.0f} % of draws ({flag})")
