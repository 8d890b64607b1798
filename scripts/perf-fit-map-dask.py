#!/usr/bin/env python3
"""Issue 78, "Scale": a Dask run of a 256 × 256 synthetic map equals the local run; killed and
resumed, it recomputes nothing it finished. A benchmark, not part of the test command.

Makes an N × N synthetic force map (noise-free Hertz approaches plus a little seeded noise, E
rising across the map, ``--rows`` rows a curve) written by ``afmdyn.export_map``; fits it with
``afmdyn.fit_map`` (threads, all cores) and with ``afmdyn.dask.fit_map`` on a LocalCluster of
``--workers`` single-threaded worker processes, and checks the two Datasets identical; then runs
a driver (its own in-process LocalCluster of ``--workers`` threads) into a store, kills it with
SIGKILL once ``--kill-at`` of the lines are stored, resumes through Dask and checks that the
resumed run computed exactly the lines not stored, that every line is stored once and that the
result is again the local one. Prints the timings.

    python3 scripts/perf-fit-map-dask.py                 # 256 × 256, 200 rows a curve
    python3 scripts/perf-fit-map-dask.py --n 64 --rows 500
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

PROBE = {"model": "point-mass",
         "cantilever": {"spring_constant": 0.05, "resonance_frequency": 10e3,
                        "quality_factor": 50}, "tip": {"radius": 10e-6},
         "sample": {"law": "hertz", "youngs_modulus": 3e3, "poisson_ratio": 0.5},
         "drive": {"free_amplitude": 10e-9}}
LINES = ".fit_map.lines.jsonl"

DRIVER = """
import sys, warnings, distributed, afmdyn, afmdyn.dask
if __name__ == "__main__":
    warnings.simplefilter("ignore")
    cluster = distributed.LocalCluster(n_workers=int(sys.argv[3]), threads_per_worker=1,
                                       processes=False, dashboard_address=None)
    client = distributed.Client(cluster)
    afmdyn.dask.fit_map(data=sys.argv[1], store=sys.argv[2], probe=%r, client=client,
                        progress=False)
"""


def curves(n: int, rows: int, k: float = 0.05, r: float = 10e-6, e: float = 5e3,
           nu: float = 0.5):
    """The n × n map's curves, one at a time (mappings as ``export_map`` takes them)."""
    rng = np.random.default_rng(78)
    t = np.linspace(0, 1, rows)
    x = 1e-6 - 2.5e-6 * t
    shape = np.sqrt(r) * np.clip(-x, 0, None) ** 1.5 * 4 / 3 / (1 - nu ** 2)
    for iy in range(n):
        for ix in range(n):
            f = e * (1 + 4 * ix / n + 2 * iy / n) * shape + 1e-12 * rng.standard_normal(rows)
            yield {"x": ix * 1e-6, "y": iy * 1e-6, "ix": ix, "iy": iy, "height": x - f / k,
                   "force": f, "spring_constant": k}


def tasks(store: Path):
    return [json.loads(l)["task"] for l in (store / LINES).read_text().splitlines()]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=256, help="curves along x and y (default 256)")
    ap.add_argument("--rows", type=int, default=200, help="rows a curve (default 200)")
    ap.add_argument("--workers", type=int, default=2, help="Dask workers (default 2)")
    ap.add_argument("--kill-at", type=float, default=0.5,
                    help="the fraction of lines stored when the driver is killed (default 0.5)")
    ap.add_argument("--dir", default=None, help="working directory (default: a temporary one)")
    a = ap.parse_args()

    import distributed

    import afmdyn
    import afmdyn.dask

    warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
    tmp = tempfile.TemporaryDirectory(prefix="perf-fit-map-dask-")
    where = Path(a.dir or tmp.name)
    where.mkdir(parents=True, exist_ok=True)
    n = a.n
    print(f"map: {n} x {n} curves of {a.rows} rows; {os.cpu_count()} cores; "
          f"{a.workers} Dask workers", flush=True)

    t0 = time.perf_counter()
    nc = afmdyn.export_map(list(curves(n, a.rows)), where / "map.nc")
    print(f"export_map:            {time.perf_counter() - t0:8.1f} s "
          f"({os.path.getsize(nc) / 2**20:.0f} MiB)", flush=True)

    t0 = time.perf_counter()
    local = afmdyn.fit_map(data=nc, probe=PROBE, progress=False)
    t_local = time.perf_counter() - t0
    fitted = int((local["flag"] == "fitted").sum())
    print(f"local fit_map:         {t_local:8.1f} s ({1e3 * t_local / n**2:.3f} ms a curve; "
          f"{fitted} of {n * n} fitted)", flush=True)

    cluster = distributed.LocalCluster(n_workers=a.workers, threads_per_worker=1,
                                       processes=True, dashboard_address=None)
    client = distributed.Client(cluster)
    ok = True
    try:
        t0 = time.perf_counter()
        ds = afmdyn.dask.fit_map(data=nc, probe=PROBE, client=client, progress=False)
        t_dask = time.perf_counter() - t0
        same = ds.identical(local)
        ok &= same
        print(f"dask fit_map:          {t_dask:8.1f} s (identical to local: {same})", flush=True)

        store = where / "run"
        script = where / "driver.py"
        script.write_text(textwrap.dedent(DRIVER % (PROBE,)))
        lines = store / LINES
        t0 = time.perf_counter()
        p = subprocess.Popen([sys.executable, str(script), str(nc), str(store),
                              str(a.workers)])
        try:
            while not (lines.exists() and lines.read_text().count("\n") >= a.kill_at * n):
                if p.poll() is not None:
                    print("the driver ended before it was killed", file=sys.stderr)
                    return 1
                time.sleep(0.05)
            p.send_signal(signal.SIGKILL)
        finally:
            p.wait()
        t_killed = time.perf_counter() - t0
        stored = tasks(store)
        before = lines.read_text()
        print(f"driver killed after:   {t_killed:8.1f} s ({len(stored)} of {n} lines stored)",
              flush=True)

        computed = []
        t0 = time.perf_counter()
        resumed = afmdyn.dask.fit_map(data=nc, probe=PROBE, client=client, store=store,
                                      progress=lambda d, total: computed.append(d))
        t_resume = time.perf_counter() - t0
        after = tasks(store)
        checks = {
            "identical to local": resumed.identical(local),
            "every line stored once": sorted(after) == list(range(n)),
            "stored lines kept": lines.read_text().startswith(before)
            and after[: len(stored)] == stored,
            "only the lines not stored computed": len(computed) == n - len(stored),
        }
        ok &= all(checks.values())
        print(f"resumed (dask):        {t_resume:8.1f} s ({len(computed)} lines computed)",
              flush=True)
        for k, v in checks.items():
            print(f"  {k}: {v}")

        t0 = time.perf_counter()
        computed.clear()
        again = afmdyn.dask.fit_map(data=nc, probe=PROBE, client=client, store=store,
                                    progress=lambda d, total: computed.append(d))
        t_again = time.perf_counter() - t0
        finished = again.identical(local) and not computed
        ok &= finished
        print(f"finished store again:  {t_again:8.1f} s ({len(computed)} lines computed; "
              f"identical: {again.identical(local)})")
    finally:
        client.close()
        cluster.close()
    print("OK" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
