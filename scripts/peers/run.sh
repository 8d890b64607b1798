#!/usr/bin/env bash
# The peer benchmark: afmdyn's exact propagator against a compiled adaptive integrator
# (Boost.Odeint runge_kutta_dopri5, dense output, TOMS748 switchings: odeint_peer.cpp) and SciPy
# (solve_ivp DOP853 with terminal events: scipy_peer.py) on the same model, at matched accuracy.
#
#   bash scripts/peers/run.sh            # N = 1 3 10 20, regenerates docs/performance/propagator.md
#   PEER_NS="1 3" bash scripts/peers/run.sh   # other mode counts (docs/performance/propagator.md untouched)
#
# 1. Installs what is missing: libboost-dev and nlohmann-json3-dev (apt-get; root or sudo), NumPy
#    and SciPy in the venv target/venv-peers (pip).
# 2. Builds the C++ peer (g++ -O3 -march=native) and the afmdyn example peer_export.
# 3. For each N: exports the model (both regions' matrices, tip vector, start state on the
#    attractor, afmdyn's exact state at τ = 40 and afmdyn's time per period); checks accuracy
#    first: each peer's tolerance (atol = rtol) is tightened along a ladder until its state at
#    τ = 40 agrees with afmdyn's to ≤ 1e-9 relative to the state norm, or until the peer stops
#    improving (its round-off floor: then its best agreement and its own spread are reported);
#    then times each peer at that tolerance.
# 4. Prints the table and, for the default N list, rewrites the part of docs/performance/propagator.md
#    between <!-- peers:begin ... --> and <!-- peers:end -->.
#
# Exit status 1 when afmdyn disagrees with a peer (above 1e-9 and outside twice the peer's own
# spread): the table is printed, the docs are left alone unless PEERS_ALLOW_UNMATCHED=1. Takes
# about 9 minutes on 2 shared cores, most of it SciPy at N = 10 and 20. Details: docs/performance/propagator.md.
set -euo pipefail
cd "$(dirname "$0")/../.."
NS=${PEER_NS:-"1 3 10 20"}
OUT=target/peers
VENV=target/venv-peers
mkdir -p "$OUT"

# 1. dependencies
missing=()
[ -f /usr/include/boost/numeric/odeint.hpp ] || missing+=(libboost-dev)
[ -f /usr/include/nlohmann/json.hpp ] || missing+=(nlohmann-json3-dev)
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo -n"
  echo "installing ${missing[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}" > /dev/null
fi
if ! "$VENV/bin/python" -c "import numpy, scipy" 2> /dev/null; then
  echo "creating $VENV with numpy and scipy" >&2
  # plain venv; where the venv module has no pip (Debian without python3-venv), virtualenv
  python3 -m venv "$VENV" ||
    { rm -rf "$VENV" && python3 -m pip install -q --user virtualenv && python3 -m virtualenv -q "$VENV"; }
  "$VENV/bin/pip" install -q numpy scipy
fi

# 2. builds
g++ -O3 -march=native -std=c++17 -o "$OUT/odeint_peer" scripts/peers/odeint_peer.cpp
cargo build --release -q -p afmdyn --example peer_export

# 3., 4. accuracy, timing, table
WRITE_DOCS=0
[ -z "${PEER_NS:-}" ] && WRITE_DOCS=1
"$VENV/bin/python" - "$OUT" "$WRITE_DOCS" $NS <<'PY'
import datetime, json, math, os, platform, re, subprocess, sys, time

out, write_docs, ns = sys.argv[1], sys.argv[2] == "1", [int(n) for n in sys.argv[3:]]
TARGET = 1e-9
# the tolerance ladder (atol = rtol; SciPy: rtol = max(tol, 100 eps)), loosest first
LADDER = [1e-10, 1e-11, 1e-12, 3e-13, 1e-13, 3e-14, 1e-14, 3e-15, 1e-15]


def run(cmd):
    res = subprocess.run(cmd, check=True, capture_output=True, text=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def dist(a, b):
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)))


def ladder(name, cmd, start, z_ref):
    """Tighten the tolerance from LADDER[start] until |z - z_ref| <= TARGET |z_ref|. The next rung
    is the loosest one at or below max(tol TARGET / err, tol / 10) (the error is about linear in
    the tolerance; at most a decade per step). Stops at a match, or at the peer's floor (an error
    not below 0.7 of the best so far with its own spread as large, at 1e-13 or tighter: round-off),
    or when it converges away from afmdyn (no improvement, own spread below a quarter of the
    error), or at the end of the ladder. Returns a dict: index, the accepted or best run,
    verdict (matched / floor / converged / exhausted) and the spread
    |z(last rung) - z(previous rung)| / |z_ref| (the peer's own resolution at the end)."""
    scale = math.sqrt(sum(x * x for x in z_ref))
    i, best, prev, runs = start, None, None, []
    while True:
        t0 = time.perf_counter()
        r = cmd(LADDER[i])
        r["wall_s"] = time.perf_counter() - t0
        runs.append({k: r[k] for k in ("tol", "rel_err", "steps", "switchings", "wall_s", "z")})
        spread = dist(r["z"], prev["z"]) / scale if prev else math.nan
        print(f"  {name:6} tol {LADDER[i]:.0e}: |z - z_afmdyn| / |z_afmdyn| = {r['rel_err']:.2e}"
              f"{'' if prev is None else f', spread from the previous rung {spread:.1e}'} "
              f"({r['steps']} steps, {r['switchings']} switchings, {r['wall_s']:.1f} s)", flush=True)
        verdict = None
        if r["rel_err"] <= TARGET:
            verdict = "matched"
        elif best is not None and r["rel_err"] > 0.7 * best[1]["rel_err"]:
            # not improving: converged away from afmdyn (the peer's own spread small: afmdyn is
            # off), or the peer's round-off floor (its spread as large as its error, at a tight
            # tolerance); at loose tolerances a chaotic fluctuation, so go on
            if spread < 0.25 * r["rel_err"]:
                verdict = "converged"
            elif LADDER[i] <= 1e-13:
                verdict = "floor"
        if verdict is None and i + 1 == len(LADDER):
            verdict = "exhausted"
        if best is None or r["rel_err"] < best[1]["rel_err"]:
            best = (i, r)
        if verdict:
            j, b = (i, r) if verdict == "matched" else best
            return {"index": j, "run": b, "verdict": verdict, "spread": spread, "runs": runs}
        want = max(LADDER[i] * TARGET / r["rel_err"], LADDER[i] / 10)
        prev, i = r, next((k for k in range(i + 1, len(LADDER)) if LADDER[k] <= want * (1 + 1e-9)), len(LADDER) - 1)


def judged(lad):
    """ok: afmdyn agrees with the peer to TARGET, or within the peer's own resolution (twice the
    spread of its last two rungs) when the peer cannot get tighter."""
    err = lad["run"]["rel_err"]
    return err <= TARGET or (lad["verdict"] != "matched" and err <= 2 * lad["spread"])


rows, failed = [], []
start = {"odeint": 0, "scipy": 0}
t_total = time.perf_counter()
load0 = os.getloadavg()
for n in ns:
    model = f"{out}/model-n{n}.json"
    print(subprocess.run(["target/release/examples/peer_export", str(n), model], check=True,
                         capture_output=True, text=True).stdout.strip(), flush=True)
    m = json.load(open(model))
    afm = m["afmdyn"]["us_per_period"]
    cmds = {
        "odeint": lambda t: run([f"{out}/odeint_peer", model, repr(t)]),
        "scipy": lambda t: run([sys.executable, "scripts/peers/scipy_peer.py", model, "--tol", repr(t)]),
    }
    peers = {}
    for name in ("odeint", "scipy"):
        # odeint's ladder starts a decade looser than the tolerance it needed at the previous N
        # (cheap, and N = 3 needs a looser one than N = 1); SciPy's at the tolerance it needed
        # at the previous N (a larger N has never needed a looser one; this keeps N = 20 at
        # two rungs of 3-4 minutes each)
        first = start[name]
        if name == "odeint":
            first = next(k for k in range(len(LADDER)) if LADDER[k] <= LADDER[first] * 10 * (1 + 1e-9))
        lad = ladder(name, cmds[name], first, m["z_ref"])
        json.dump(lad["runs"], open(f"{out}/ladder-{name}-n{n}.json", "w"))
        if lad["verdict"] == "matched":
            start[name] = lad["index"]
        tol = LADDER[lad["index"]]
        if name == "odeint":
            # timed: as many periods as take about 0.3 s, best of 5
            t = run([f"{out}/odeint_peer", model, repr(tol), "auto", "5"])
        else:
            # timed: the accuracy run itself (τ = 0 → 40, 16.6 periods), best of 3 when short
            t = lad["run"]
            if t["us_per_period"] * t["timed_periods"] < 3e6:
                t = run([sys.executable, "scripts/peers/scipy_peer.py", model, "--tol", repr(tol), "--reps", "3"])
        t.update(tol=tol, rel_err=lad["run"]["rel_err"], verdict=lad["verdict"], spread=lad["spread"], ok=judged(lad))
        peers[name] = t
        if not t["ok"]:
            failed.append(f"{name} at N = {n}: agreement {t['rel_err']:.2e} > {TARGET:.0e} and beyond the peer's "
                          f"own resolution (spread {t['spread']:.1e}, {lad['verdict']})")
    o, s = peers["odeint"], peers["scipy"]
    rows.append((n, afm, m["afmdyn"]["switchings_per_period"], o, s, m["afmdyn"]["timed_periods"]))
    print(f"  N = {n}: afmdyn {afm:.1f} µs, odeint {o['us_per_period']:.1f} µs ({o['us_per_period'] / afm:.0f}×), "
          f"scipy {s['us_per_period'] / 1e3:.1f} ms ({s['us_per_period'] / afm:.0f}×)", flush=True)


def ratio(x):
    return f"{x:,.0f}×".replace(",", " ")


def agree(p):
    if p["verdict"] == "matched":
        return f"{p['rel_err']:.1e}"
    why = {"floor": "the peer's round-off floor", "converged": "the peer converged elsewhere",
           "exhausted": "end of the tolerance ladder"}[p["verdict"]]
    return f"{p['rel_err']:.1e} (not ≤ 1e-9: {why}; its own spread {p['spread']:.1e})"


def each(f):
    return ", ".join(f(r) for r in rows)


cpu = "unknown CPU"
try:
    cpu = next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name"))
except (OSError, StopIteration):
    pass
boost = re.search(r'BOOST_LIB_VERSION "([^"]+)"', open("/usr/include/boost/version.hpp").read())[1].replace("_", ".")
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
lines = [
    "<!-- peers:begin (generated by scripts/peers/run.sh; do not edit) -->",
    "| N | afmdyn (exact) µs / period | Boost.Odeint dopri5 µs / period | ratio | tol | agreement | SciPy DOP853 ms / period | ratio | tol | agreement |",
    "|---|---|---|---|---|---|---|---|---|---|",
]
for n, afm, _, o, s, _ in rows:
    lines.append(f"| {n} | {afm:.1f} | {o['us_per_period']:.0f} | **{ratio(o['us_per_period'] / afm)}** | {o['tol']:.0e} | {agree(o)} "
                 f"| {s['us_per_period'] / 1e3:.1f} | {ratio(s['us_per_period'] / afm)} | {s['tol']:.0e} | {agree(s)} |")
lines += [
    "",
    f"N = {each(lambda r: str(r[0]))}. Agreement: |z_peer − z_afmdyn| / |z_afmdyn| at τ = 40. Timed runs from the "
    f"start state: afmdyn best of 5 runs of {each(lambda r: format(r[5], 'g'))} periods; odeint best of 5 runs of "
    f"{each(lambda r: format(r[3]['timed_periods'], 'g'))} periods; SciPy the accuracy run, τ = 0 → 40 (16.6 periods), "
    f"best of {each(lambda r: str(r[4]['repetitions']))} runs. Steps per period: odeint "
    f"{each(lambda r: format(r[3]['steps_per_period'], '.0f'))}; SciPy "
    f"{each(lambda r: format(r[4]['steps'] / r[4]['timed_periods'], '.0f'))}; switchings per period "
    f"{each(lambda r: format(r[2], '.2f'))}.",
    "",
    f"Measured {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d} at commit {commit} on {cpu} "
    f"({os.cpu_count()} cores), g++ -O3 -march=native, Boost {boost}, "
    f"Python {platform.python_version()}, SciPy {__import__('scipy').__version__}; whole run {time.perf_counter() - t_total:.0f} s, "
    f"load average at the start {load0[2]:.1f} and at the end {os.getloadavg()[2]:.1f} (15 min).",
    "<!-- peers:end -->",
]
table = "\n".join(lines)
print()
print(table)
if failed:
    print("\naccuracy agreement FAILED: " + "; ".join(failed), file=sys.stderr)
if write_docs and (not failed or os.environ.get("PEERS_ALLOW_UNMATCHED") == "1"):
    page = subprocess.run([sys.executable, "scripts/doc_section.py", "--where", "peers"],
                          capture_output=True, text=True, check=True).stdout.strip()
    doc = open(page).read()
    pat = re.compile(r"<!-- peers:begin.*?<!-- peers:end -->", re.S)
    if not pat.search(doc):
        sys.exit(f"{page} has no <!-- peers:begin --> ... <!-- peers:end --> markers")
    open(page, "w").write(pat.sub(lambda _: table, doc))
    print(f"\n{page}: peers section regenerated")
sys.exit(1 if failed else 0)
PY
