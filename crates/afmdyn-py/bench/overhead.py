"""What calling the engine through Python costs over the Rust library alone.

    python crates/afmdyn-py/bench/overhead.py [--rounds 7]

Times the same work both ways, interleaved round by round (the machine may be shared), and
reports the best time of each:

* a 1000-period simulation from rest at the default parameters, 200 samples per period with
  the energy balance and the body-contact check (what ``afmdyn simulate`` records); the Python
  side also builds the xarray dataset;
* the default bifurcation run (Ω from 1 to 5, 400 values, forward and backward, all cores);
  the Python side also builds the long-format dataset.

The Rust figures come from ``cargo run --release -p afmdyn --example timing`` (built here if
missing). Target: at most 5 % overhead.
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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--periods", type=int, default=1000)
    a = ap.parse_args()
    if not EXAMPLE.exists():
        subprocess.run(
            ["cargo", "build", "--release", "-q", "-p", "afmdyn", "--example", "timing"],
            cwd=REPO,
            check=True,
        )
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
