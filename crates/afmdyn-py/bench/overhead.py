"""What calling the engine through Python costs over the Rust library alone.

    python crates/afmdyn-py/bench/overhead.py [--rounds 7] [--instructions]

Times the same work both ways, interleaved round by round (the machine may be shared), and
reports the best time of each:

* a 1000-period simulation from rest at the default parameters, 200 samples per period with
  the energy balance and the body-contact check (what ``afmdyn simulate`` records); the Python
  side also builds the xarray dataset;
* the default bifurcation run (Ω from 1 to 5, 400 values, forward and backward, all cores);
  the Python side also builds the long-format dataset.

The Rust figures come from ``cargo run --release -p afmdyn --example timing`` (built here if
missing). Target: at most 5 % overhead.

On a shared machine the run-to-run spread of wall and CPU time can exceed the overhead;
``--instructions`` counts executed instructions instead (valgrind's callgrind, a few minutes):
the Rust example against the difference of two Python runs, one importing afmdyn and doing a
trivial call, one also doing the computation.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import afmdyn

REPO = Path(__file__).resolve().parents[3]
EXAMPLE = REPO / "target" / "release" / "examples" / "timing"


def rust(*args: str) -> tuple:
    """(wall, cpu) seconds of the library alone; cpu is the child process' user + system time
    (it includes the process start, about a millisecond)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run([str(EXAMPLE), *args], capture_output=True, text=True, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return json.loads(out.stdout)["seconds"], cpu


def python(fn) -> tuple:
    """(wall, cpu) seconds of a call, cpu summed over all threads of this process."""
    t0, c0 = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - t0, time.process_time() - c0


def instructions(cmd: list) -> int:
    """Instructions executed by ``cmd`` and all its threads (callgrind)."""
    out = subprocess.run(
        ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", *cmd],
        capture_output=True,
        text=True,
        check=True,
    )
    for line in out.stderr.splitlines():
        if "Collected :" in line:
            return int(line.split(":")[-1])
    raise RuntimeError(out.stderr[-2000:])


def count_instructions(periods: int) -> None:
    py = [sys.executable, "-c"]
    setup = "import afmdyn; afmdyn.modes(); "
    base = instructions([*py, setup])
    print(f"{'case':<40} {'Rust (instr.)':>14} {'Python (instr.)':>16} {'overhead':>9}")
    for name, rust_args, call in [
        (
            f"simulate, {periods} periods",
            ["simulate", str(periods), "1"],
            f"afmdyn.simulate(periods={periods}, progress=False)",
        ),
        ("default bifurcation run (800 points)", ["bifurcation", "1"], "afmdyn.bifurcation(progress=False)"),
    ]:
        r = instructions([str(EXAMPLE), *rust_args])
        p = instructions([*py, setup + call]) - base
        print(f"{name:<40} {r:>14.4e} {p:>16.4e} {100 * (p / r - 1):>8.1f} %")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--periods", type=int, default=1000)
    ap.add_argument("--instructions", action="store_true", help="count instructions (callgrind)")
    a = ap.parse_args()
    if not EXAMPLE.exists():
        subprocess.run(
            ["cargo", "build", "--release", "-q", "-p", "afmdyn", "--example", "timing"],
            cwd=REPO,
            check=True,
        )
    if a.instructions:
        count_instructions(a.periods)
        return
    cases = {
        f"simulate, {a.periods} periods": (
            lambda: rust("simulate", str(a.periods), "1"),
            lambda: python(lambda: afmdyn.simulate(periods=a.periods, progress=False)),
        ),
        "default bifurcation run (800 points)": (
            lambda: rust("bifurcation", "1"),
            lambda: python(lambda: afmdyn.bifurcation(progress=False)),
        ),
    }
    print(
        f"best of {a.rounds} interleaved rounds; afmdyn {afmdyn.__version__}, Python {sys.version.split()[0]}"
    )
    print(
        "wall: elapsed time; cpu: user + system time of all threads (less sensitive to other load)"
    )
    print(f"{'case':<38} {'':>5} {'Rust (s)':>9} {'Python (s)':>11} {'overhead':>9}")
    worst = 0.0
    for name, (r, p) in cases.items():
        p()  # warm-up (imports, first allocation of the thread pool)
        rt, pt = [], []
        for _ in range(a.rounds):
            rt.append(r())
            pt.append(p())
        for k, label in enumerate(["wall", "cpu"]):
            best_r = min(x[k] for x in rt)
            best_p = min(x[k] for x in pt)
            over = best_p / best_r - 1
            worst = max(worst, over)
            print(
                f"{name if k == 0 else '':<38} {label:>5} {best_r:>9.4f} {best_p:>11.4f} {100 * over:>8.1f} %"
            )
    print(f"largest overhead {100 * worst:.1f} % (target <= 5 %)")


if __name__ == "__main__":
    main()
