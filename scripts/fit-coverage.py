"""The coverage of the dynamic fit's 95 % intervals (issue 62, check "Coverage"): a synthetic
100-row AM approach (amplitude and phase against the piezo position z; z_c = 7.5 → 3 nm, the
repulsive branch below the approach's fold) of examples/probe-point-mass-dmt.toml made once by
`afmdyn approach`, then DRAWS draws of seeded Gaussian noise (σ = 0.02 nm and 0.1°), each fitted
by `afmdyn fit` for sample.youngs_modulus, sample.hamaker and z_offset (truth: the probe's
E = 4 GPa and H = 6.6e-20 J, z_offset = 1 nm). For each parameter: the fraction of draws whose
95 % interval (the document's `interval`: Wald, ±1.96 standard errors, unless EXTRA asks for
profiles) covers the truth (goal 90–99 %), the mean reported standard error beside the standard
deviation of the estimates over the draws (equal when the Wald intervals are honest), and the
mean χ²/dof. Writes the "fit-coverage" section of docs/performance/commands.md (scripts/doc_section.py)
when DRAWS is the default 100 and no PROBE is given.

Usage: python3 scripts/fit-coverage.py [DRAWS] [PROBE] [EXTRA FIT ARGUMENTS…]   (AFMDYN_BIN: the
binary; default target/release/afmdyn). Too long for the test suite (~100 fits of 3 s CPU).
"""
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time

draws = int(sys.argv[1]) if len(sys.argv) > 1 else 100
probe = sys.argv[2] if len(sys.argv) > 2 else "examples/probe-point-mass-dmt.toml"
extra = sys.argv[3:]
binary = os.environ.get("AFMDYN_BIN", "target/release/afmdyn")
truth = {"sample.youngs_modulus": 4e9, "sample.hamaker": 6.6e-20, "z_offset": 1e-9}
units = {"sample.youngs_modulus": (1e9, "GPa"), "sample.hamaker": (1e-20, "× 10⁻²⁰ J"),
         "z_offset": (1e-9, "nm")}
sa, sp = 2e-11, 0.1

with tempfile.TemporaryDirectory() as tmp:
    appr = subprocess.run([binary, "approach", "--probe", probe, "--from", "7.5e-9", "--to", "3e-9",
                           "--points", "100", "--json", "--files", "none"],
                          check=True, capture_output=True, text=True)
    a = json.loads(appr.stdout)["approach"]
    covered = {k: 0 for k in truth}
    values = {k: [] for k in truth}
    errors = {k: [] for k in truth}
    chi2 = []
    method = ""
    done = 0
    t0 = time.time()
    cpu0 = os.times()
    for seed in range(draws):
        rng = random.Random(seed)
        path = os.path.join(tmp, "am.csv")
        with open(path, "w") as f:
            f.write("z,amplitude,phase,sigma_amplitude,sigma_phase\n")
            for zc, amp, ph in zip(a["z_c"], a["amplitude"], a["phase_deg"]):
                f.write(f"{zc - truth['z_offset']!r},{amp + rng.gauss(0, sa)!r},"
                        f"{ph + rng.gauss(0, sp)!r},{sa},{sp}\n")
        out = subprocess.run([binary, "fit", "--probe", probe, "--data", path, "--fit",
                              ",".join(truth), "--json", "--files", "none", *extra],
                             capture_output=True, text=True)
        if out.returncode != 0:
            print(f"draw {seed}: failed: {out.stderr.strip()[:200]}", file=sys.stderr)
            continue
        doc = json.loads(out.stdout)
        method = doc["method"].split(";")[0]
        method += ")" * (method.count("(") - method.count(")"))
        done += 1
        chi2.append(doc["chi2_dof"])
        for k, t in truth.items():
            e = doc["estimates"][k]
            lo, hi = e["interval"]
            values[k].append(e["value"])
            errors[k].append(e["standard_error"])
            if lo is not None and hi is not None and lo <= t <= hi:
                covered[k] += 1
        print(f"draw {seed}: χ²/dof {doc['chi2_dof']:.3f}; " + ", ".join(
            f"{k} {doc['estimates'][k]['value']:.5g} {doc['estimates'][k]['interval']}"
            for k in truth), file=sys.stderr, flush=True)
    wall = time.time() - t0
    cpu1 = os.times()
    cpu = (cpu1.children_user + cpu1.children_system) - (cpu0.children_user + cpu0.children_system)
    lines = [f"{done} of {draws} draws fitted in {wall:.0f} s wall, {cpu:.0f} s CPU ({probe}); "
             f"mean χ²/dof {statistics.fmean(chi2) if chi2 else float('nan'):.3f}"]
    rows = []
    for k in truth:
        frac = covered[k] / done if done else float("nan")
        flag = "met" if 0.90 <= frac <= 0.99 else "NOT met (outside 90–99 %)"
        s, u = units[k]
        sd = statistics.stdev(values[k]) if done > 1 else float("nan")
        mean_se = statistics.fmean(errors[k]) if done else float("nan")
        bias = statistics.fmean(values[k]) - truth[k] if done else float("nan")
        lines.append(f"{k}: the 95 % interval covers the truth in {100 * frac:.0f} % of draws ({flag})")
        rows.append(f"| {k} | {truth[k] / s:g} {u} | {covered[k]} of {done} ({100 * frac:.0f} %) — {flag} "
                    f"| {mean_se / s:.3g} {u} | {sd / s:.3g} {u} | {bias / s:+.2g} {u} |")
    print("\n".join(lines))
    if len(sys.argv) <= 2:
        section = os.path.join(tmp, "section.md")
        with open(section, "w") as f:
            f.write("<!-- fit-coverage:begin (generated by scripts/fit-coverage.py; do not edit) -->\n")
            f.write(f"| `afmdyn fit`, {done} draws, 100-row AM approach, E + H + z_offset ({method}) "
                    "| truth | draws whose 95 % interval covers the truth (goal 90–99 %) "
                    "| mean standard error | standard deviation of the estimates | mean bias |\n")
            f.write("|---|---|---|---|---|---|\n")
            f.write("\n".join(rows) + "\n\n")
            f.write(f"{lines[0]}. Synthetic approach of the point mass (examples/probe-point-mass-dmt.toml, "
                    "z_c = 7.5 → 3 nm) by `afmdyn approach`, seeded Gaussian noise σ = 0.02 nm and 0.1° "
                    f"(seeds 0 … {draws - 1}), each draw fitted from the probe's starts; "
                    "`python3 scripts/fit-coverage.py` on this machine (2 cores, shared; load "
                    f"{open('/proc/loadavg').read().split()[0]} when it ended).\n")
            f.write("<!-- fit-coverage:end -->\n")
        subprocess.run([sys.executable, "scripts/doc_section.py", "fit-coverage", section,
                        "Coverage of the dynamic fit's intervals (issue 62)"], check=True)
