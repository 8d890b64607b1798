"""afmdyn.dask.fit_map() (issue 78, "Scale"): a synthetic 16 × 16 map of Hertz curves (200 rows
each, written by ``afmdyn.export_map``) fitted on a LocalCluster of two worker processes, a line
of the map per task, equals ``afmdyn.fit_map`` bit for bit, with and without a store; a store
of ``afmdyn.fit_map`` is resumed (finished: nothing computed) and another request refused; a
driver killed with SIGKILL mid-map and resumed fits only the lines it had not stored — every
line once, the stored ones kept as they were."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import textwrap
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import afmdyn

distributed = pytest.importorskip("distributed")
import afmdyn.dask  # noqa: E402  (needs distributed)

N, ROWS = 16, 200
PROBE = {"model": "point-mass",
         "cantilever": {"spring_constant": 0.05, "resonance_frequency": 10e3,
                        "quality_factor": 50}, "tip": {"radius": 10e-6},
         "sample": {"law": "hertz", "youngs_modulus": 3e3, "poisson_ratio": 0.5},
         "drive": {"free_amplitude": 10e-9}}
#: the store's file of finished lines (one JSON line per task: ``{"task": t, ...}``)
LINES = ".fit_map.lines.jsonl"


def _synthetic(n=N, rows=ROWS, k=0.05, r=10e-6, e=5e3, nu=0.5):
    """An n × n map of Hertz approaches (Sneddon 1965: F = (4/3) E/(1 − ν²) √R δ^1.5), E rising
    along x and y, with a little deterministic noise, as a list of mappings."""
    rng = np.random.default_rng(78)
    curves = []
    t = np.linspace(0, 1, rows)
    for iy in range(n):
        for ix in range(n):
            modulus = e * (1 + ix + 0.5 * iy)
            x = 1e-6 - 2.5e-6 * t
            f = 4 / 3 * modulus / (1 - nu ** 2) * np.sqrt(r) * np.clip(-x, 0, None) ** 1.5
            f = f + 1e-12 * rng.standard_normal(rows)
            curves.append({"x": ix * 1e-6, "y": iy * 1e-6, "height": x - f / k, "force": f,
                           "spring_constant": k})
    return curves


@pytest.fixture(scope="module")
def nc(tmp_path_factory):
    return afmdyn.export_map(_synthetic(), tmp_path_factory.mktemp("map") / "map.nc")


@pytest.fixture(scope="module")
def local(nc):
    return _quiet(afmdyn.fit_map, data=nc)


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def _quiet(f, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        return f(probe=PROBE, **kw)


def _tasks(store: Path):
    """The tasks of the store's lines, in the order stored."""
    return [json.loads(l)["task"] for l in (store / LINES).read_text().splitlines()]


def test_the_dask_map_equals_the_local_map(client, nc, local, tmp_path):
    assert local["youngs_modulus"].shape == (N, N)
    assert (local["flag"] == "fitted").all()
    xr.testing.assert_identical(_quiet(afmdyn.dask.fit_map, data=nc, client=client), local)
    # into a store: every line once; a finished store computes nothing
    store = tmp_path / "run"
    xr.testing.assert_identical(
        _quiet(afmdyn.dask.fit_map, data=nc, client=client, store=store), local)
    assert sorted(_tasks(store)) == list(range(N))
    text = (store / LINES).read_text()
    xr.testing.assert_identical(
        _quiet(afmdyn.dask.fit_map, data=nc, client=client, store=store), local)
    assert (store / LINES).read_text() == text
    with pytest.raises(ValueError, match="in the interrupted run"):
        _quiet(afmdyn.dask.fit_map, data=nc, client=client, store=store,
               fit_range=(-1e-6, 0.0))
    # curves given as data: exported into the store, as afmdyn.fit_map does
    curves = _synthetic(n=3)
    xr.testing.assert_identical(
        _quiet(afmdyn.dask.fit_map, data=curves, client=client, store=tmp_path / "curves"),
        _quiet(afmdyn.fit_map, data=curves))
    assert (tmp_path / "curves" / "map.nc").exists()


def test_a_store_of_the_local_map_resumes_through_dask(client, nc, local, tmp_path):
    store = tmp_path / "run"
    xr.testing.assert_identical(_quiet(afmdyn.fit_map, data=nc, store=store), local)
    text = (store / LINES).read_text()
    # finished by afmdyn.fit_map: nothing computed again, the same dataset
    xr.testing.assert_identical(
        _quiet(afmdyn.dask.fit_map, data=nc, client=client, store=store), local)
    assert (store / LINES).read_text() == text
    # started over without resume: every line again
    xr.testing.assert_identical(
        _quiet(afmdyn.dask.fit_map, data=nc, client=client, store=store, resume=False), local)
    assert sorted(_tasks(store)) == list(range(N))


DRIVER = """
import sys, time, warnings, distributed, afmdyn, afmdyn.dask
if __name__ == "__main__":
    warnings.simplefilter("ignore")
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    # each stored line held a while by the progress callback: the kill lands mid-map
    afmdyn.dask.fit_map(data=sys.argv[1], store=sys.argv[2], probe=%r, client=client,
                        progress=lambda done, total: time.sleep(0.3))
"""


def test_a_killed_driver_resumes_fitting_only_the_lines_not_stored(client, nc, local, tmp_path):
    store = tmp_path / "run"
    script = tmp_path / "driver.py"
    script.write_text(textwrap.dedent(DRIVER % (PROBE,)))
    lines = store / LINES
    p = subprocess.Popen([sys.executable, str(script), str(nc), str(store)])
    try:
        t0 = time.monotonic()
        while not (lines.exists() and lines.read_text().count("\n") >= 2):
            assert p.poll() is None, "the driver ended before storing two lines"
            assert time.monotonic() - t0 < 120
            time.sleep(0.02)
        p.send_signal(signal.SIGKILL)
    finally:
        p.wait()
    stored = _tasks(store)
    assert 2 <= len(stored) < N, stored
    before = lines.read_text()
    done = []
    ds = _quiet(afmdyn.dask.fit_map, data=nc, client=client, store=store,
                progress=lambda d, total: done.append((d, total)))
    xr.testing.assert_identical(ds, local)
    tasks = _tasks(store)
    assert sorted(tasks) == list(range(N)), "every line once: none lost, none duplicated"
    assert lines.read_text().startswith(before), "the stored lines were kept as they were"
    assert tasks[: len(stored)] == stored
    # only the lines not stored were computed (counted from what was stored)
    assert len(done) == N - len(stored), (done, stored)
