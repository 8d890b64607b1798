#!/usr/bin/env bash
# The compiled DOP853 peer of the nonlinear path (issue 26, item 5): afmdyn's default integrator
# for DMT (the Taylor series integrator since issue 26; `--integrator adaptive` is its DOP853) on
# the point-mass DMT model against an independent C++ DOP853 (dmt_peer.cpp: dop853.f's method and
# step control, switchings located on the dense output and polished by Newton, restart at each).
#
#   bash scripts/peers/dmt.sh        # prints the table, regenerates docs/performance/laws.md's section
#
# 1. Builds afmdyn (cargo build --release) and the peer (g++ -O3 -march=native, standard library
#    only).
# 2. Takes the model's dimensionless groups from afmdyn itself (`afmdyn units --probe … --json`).
# 3. Agreement first: the peer integrates from rest through a transient of DMT_TRANSIENT periods
#    (default 6000; the orbit's Floquet multipliers have modulus 0.992), then records
#    DMT_RECORD periods (default 100) and forms the first harmonic of the tip deflection as
#    afmdyn's `observe` does (16-point Gauss–Legendre on the dense output of every step piece).
#    afmdyn's reference is its `observe` on the shooting orbit, as `afmdyn approach` reports it
#    for its first point (z_c of the probe; the CLI has no `observe` command); its period-1 orbit
#    state comes from `afmdyn orbit`. Amplitude (relative), phase (absolute, rad) and the state
#    at the period end (relative to 1 + |z|) must agree to ≤ 1e-8, and the orbit must be a
#    stable period-1 orbit; otherwise the script stops with status 1 and leaves the docs alone.
# 4. Timing in the same run: afmdyn simulate --periods DMT_PERIODS (default 3000)
#    --samples-per-period 1 --files none, best of DMT_REPS (default 3) wall times / periods,
#    against the peer over the same periods (best of DMT_REPS runs interleaved with afmdyn's,
#    in-process clock): from rest, from rest with a quadrature on every step (as simulate's
#    energy balance), and on the orbit. The peer's accepted and rejected steps, events,
#    event-polish steps and vector-field evaluations per period; afmdyn's switchings per period
#    from its --json summary (it does not print step counts).
# 5. Prints the table and rewrites the part of docs/performance/laws.md between
#    <!-- dmt-peer:begin … --> and <!-- dmt-peer:end --> (scripts/doc_section.py); DMT_NO_DOCS=1
#    leaves the docs alone. DMT_PROBE selects another point-mass DMT probe file.
#
# A benchmark, not a test: not run by scripts/test.sh. About 10 s on 2 shared cores.
set -euo pipefail
cd "$(dirname "$0")/../.."
PROBE=${DMT_PROBE:-examples/probe-point-mass-dmt.toml}
OUT=target/peers
mkdir -p "$OUT"

cargo build --release -q
g++ -O3 -march=native -std=c++17 -o "$OUT/dmt_peer" scripts/peers/dmt_peer.cpp

python3 - "${CARGO_TARGET_DIR:-target}/release/afmdyn" "$OUT/dmt_peer" "$PROBE" \
  "${DMT_TRANSIENT:-6000}" "${DMT_RECORD:-100}" "${DMT_PERIODS:-3000}" "${DMT_REPS:-3}" \
  "${DMT_NO_DOCS:-0}" <<'PY'
import atexit, datetime, json, math, os, shutil, subprocess, sys, tempfile, time

afmdyn, peer, probe = sys.argv[1:4]
transient, record, periods, reps = (int(x) for x in sys.argv[4:8])
write_docs = sys.argv[8] != "1"
LIMIT = 1e-8
tmp = tempfile.mkdtemp(prefix="dmt-peer-")
atexit.register(shutil.rmtree, tmp, True)


def run(cmd):
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({res.returncode}):\n{res.stderr}")
    return json.loads(res.stdout)


def fail(msg):
    sys.exit(f"dmt peer: {msg}")


# 2. the model's groups, from afmdyn
units = run([afmdyn, "units", "--probe", probe, "--json"])
p = units["params"]
law = p["contact_law"]
if p["structure"] != "point-mass" or law["law"] != "dmt" or p["modes"] != 1:
    fail(f"{probe} is not a point-mass DMT probe ({p['structure']}, {law['law']})")
z_c = units["si"]["z_c_m"]
args = [f"{k}={v!r}" for k, v in [
    ("alpha2", p["alpha2"]), ("alpha3", p["alpha3"]), ("alpha4", p["alpha4"]), ("alpha5", p["alpha5"]),
    ("alpha6", p["alpha6"]), ("omega", p["omega"]), ("hamaker", law["hamaker"]),
    ("a0", law["intermolecular_distance"])]]

# 3. afmdyn's periodic orbit and its observables at the probe's z_c
orbit = run([afmdyn, "orbit", "--probe", probe, "--json"])
if orbit["period"] != 1 or not orbit["stable"]:
    fail(f"the orbit at z_c = {z_c:g} m is not a stable period-1 orbit (period {orbit['period']}, "
         f"stable {orbit['stable']}): choose another z_c")
mu = max(math.hypot(*m) for m in orbit["multipliers"])
appr = run([afmdyn, "approach", "--probe", probe, "--from", repr(z_c), "--to", repr(0.99 * z_c),
            "--points", "2", "--no-branches", "--files", "none", "--out", f"{tmp}/approach", "--json"])
first = {k: v[0] for k, v in appr["approach"].items()}
if first["period"] != 1 or not first["stable"] or first["z_c"] != z_c:
    fail(f"afmdyn approach's first point is not the stable period-1 orbit at z_c: {first}")
ref_amp = first["amplitude"] / appr["scales"]["length"]
ref_phase = math.radians(first["phase_deg"])

peer_cmd = [peer, *args, "tol=1e-12", f"transient={transient}", f"record={record}", f"periods={periods}", "reps=1"]
peer_out = run(peer_cmd)
d_amp = abs(peer_out["amplitude"] - ref_amp) / abs(ref_amp)
d_phase = abs(peer_out["phase"] - ref_phase)
z_ref = orbit["state"]
d_state = math.dist(peer_out["state"], z_ref) / (1 + math.hypot(*z_ref))
checks = [("amplitude", d_amp), ("phase", min(d_phase, d_phase / abs(ref_phase))), ("state", d_state)]
failed = [f"{name} {err:.2e}" for name, err in checks if not err <= LIMIT]

# 4. time per period, best of reps; afmdyn's runs and the peer's interleaved (the machine is shared:
# both see the same load)
best = math.inf
for rep in range(reps):
    t0 = time.perf_counter()
    sim = run([afmdyn, "simulate", "--probe", probe, "--periods", str(periods), "--samples-per-period", "1",
               "--files", "none", "--out", f"{tmp}/simulate", "--json"])
    best = min(best, time.perf_counter() - t0)
    again = peer_out if rep == 0 else run(peer_cmd)
    for key in ("from_rest", "steady", "recording"):
        if again[key]["us_per_period"] < peer_out[key]["us_per_period"]:
            peer_out[key] = again[key]
afm_us = best / periods * 1e6
afm_events = sim["switchings"] / periods
# the two runs from rest end on the same state (both integrate the same transient)
d_end = math.dist(peer_out["from_rest_end"], [sim["final"]["w_tip"], sim["final"]["w_tip_dot"]])

cpu = "unknown CPU"
try:
    cpu = next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name"))
except (OSError, StopIteration):
    pass
gxx = subprocess.run(["g++", "-dumpfullversion"], capture_output=True, text=True).stdout.strip()
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
fr, st, rc = peer_out["from_rest"], peer_out["steady"], peer_out["recording"]


def row(name, t, what):
    return (f"| {name} | {t['us_per_period']:.1f} µs | {t['accepted_per_period']:.1f} | {t['rejected_per_period']:.1f} | "
            f"{t['events_per_period']:.2f} | {t['polish_steps_per_period']:.2f} | {t['rhs_per_period']:.0f} | {what} |")


lines = [
    "<!-- dmt-peer:begin (generated by scripts/peers/dmt.sh; do not edit) -->",
    f"Agreement at z_c = {z_c * 1e9:g} nm (stable period-1 orbit, largest Floquet multiplier |μ| = {mu:.4f}); "
    f"afmdyn: `observe` on its shooting orbit (via `afmdyn approach`), orbit state from `afmdyn orbit`; peer: "
    f"{transient} periods from rest, then {record} periods recorded, rtol = atol = 1e-12:",
    "",
    "| quantity | afmdyn | peer | difference |",
    "|---|---|---|---|",
    f"| A₁ / A₀ | {ref_amp:.12f} | {peer_out['amplitude']:.12f} | {d_amp:.1e} relative |",
    f"| φ (rad) | {ref_phase:.12f} | {peer_out['phase']:.12f} | {d_phase:.1e} |",
    f"| (z, z′) at τ = kT | ({z_ref[0]:.12f}, {z_ref[1]:.12f}) | ({peer_out['state'][0]:.12f}, {peer_out['state'][1]:.12f}) "
    f"| {d_state:.1e} relative to 1 + ‖z‖ |",
    "",
    f"Time per drive period, best of {reps}:",
    "",
    "| run | time / period | accepted steps | rejected steps | events | event-polish steps | f evaluations | what |",
    "|---|---|---|---|---|---|---|---|",
    f"| afmdyn simulate | {afm_us:.1f} µs | — | — | {afm_events:.2f} | — | — | `simulate --periods {periods} "
    f"--samples-per-period 1 --files none`, from rest, wall time of the process |",
    row("peer", fr, f"the same {periods} periods from rest (end states {d_end:.0e} apart)"),
    row("peer", st, f"{periods} periods on the orbit"),
    row("peer, recording", rc, f"the same {periods} periods from rest with a 16-point Gauss–Legendre quadrature on "
        "every step (simulate evaluates its energy balance on every step too: 8 Gauss–Legendre nodes of "
        "the Taylor series)"),
    "",
    f"Peer / afmdyn (how many times faster afmdyn is): **{fr['us_per_period'] / afm_us:.1f}×** from rest, "
    f"{rc['us_per_period'] / afm_us:.1f}× against the peer's recording run (the goal of issue 26: ≥ 5×). Measured "
    f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d} at commit {commit} on {cpu} ({os.cpu_count()} cores), "
    f"g++ {gxx} -O3 -march=native; load average {os.getloadavg()[0]:.1f} (1 min).",
    "<!-- dmt-peer:end -->",
]
table = "\n".join(lines)
print(table)
if failed:
    fail(f"agreement above {LIMIT:g}: {', '.join(failed)} (docs/performance/laws.md left alone)")
if write_docs:
    path = f"{tmp}/section.md"
    open(path, "w").write(table + "\n")
    subprocess.run([sys.executable, "scripts/doc_section.py", "dmt-peer", path,
                    "Peer for the nonlinear path: compiled DOP853, point-mass DMT"], check=True)
PY
