"""chart(): the dataset equals the command line's chart.nc; threads, the store and its resume;
errors. afmdyn.dask.chart(): equal to the local chart bit for bit on a LocalCluster of two
worker processes, with and without a Zarr store; a worker killed mid-run; a driver killed with
SIGKILL and resumed; another request or a locked store refused."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import distributed
import numpy as np
import pytest
import xarray as xr

import afmdyn
import afmdyn.dask

SMALL = dict(x_steps=4, y_steps=2, starts=2, tile=2, lyapunov_periods=50)
FLAGS = "--x-steps 4 --y-steps 2 --starts 2 --tile 2 --lyapunov-periods 50".split()


def test_chart_equals_the_command_lines_netcdf(cli, tmp_path):
    run = cli("chart", *FLAGS, "--out", tmp_path)
    assert run.returncode == 0, run.stderr
    nc = xr.open_dataset(tmp_path / "chart.nc").load()
    ds = afmdyn.chart(**SMALL)
    assert ds.sizes == {"y": 2, "x": 4, "attractor": 8}
    for k in nc.data_vars:
        np.testing.assert_array_equal(ds[k].values, nc[k].values, err_msg=k)
    np.testing.assert_array_equal(ds.x.values, nc.x.values)
    assert ds.x.attrs["long_name"] == "omega" and ds.y.attrs["long_name"] == "drive_amplitude"
    # every cell found an attractor; fractions of the random starts add up per cell
    assert (ds.attractors > 0).all()
    total = ds.fraction.fillna(0).sum("attractor")
    converged = 1 - ds.failures / 2
    np.testing.assert_allclose(total, converged, atol=1e-12)
    # λ₁ exactly where the attractor is nonperiodic
    assert (np.isfinite(ds.lyapunov) == (ds.period == -1)).all()


def test_threads_do_not_change_the_chart():
    xr.testing.assert_identical(afmdyn.chart(**SMALL, threads=1), afmdyn.chart(**SMALL, threads=2))


def test_a_stored_chart_resumes_and_refuses_another_request(tmp_path):
    ref = afmdyn.chart(**SMALL)
    ds = afmdyn.chart(**SMALL, store=tmp_path)
    xr.testing.assert_identical(ds, ref)
    stored = (tmp_path / ".chart.tiles.jsonl").read_text()
    again = afmdyn.chart(**SMALL, store=tmp_path, resume=True)
    xr.testing.assert_identical(again, ref)
    assert (tmp_path / ".chart.tiles.jsonl").read_text() == stored, "nothing computed again"
    with pytest.raises(ValueError, match="starts = 2 in the interrupted run, 3 now"):
        afmdyn.chart(**{**SMALL, "starts": 3}, store=tmp_path, resume=True)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(x="modes"), "x = modes: must be a real model parameter"),
        (dict(y="omega"), "y = omega: must differ"),
        (dict(x_steps=0), "x_steps = 0"),
        (dict(x="z_c", x_from=1e-9, x_to=2e-9), "needs a probe"),
        (dict(max_attractors=0), "max_attractors = 0"),
        (dict(tile=-1), "tile = -1"),
        (dict(integrator="nope"), "nope"),
    ],
)
def test_bad_charts_are_refused_naming_the_option(kwargs, match):
    with pytest.raises(ValueError, match=match):
        afmdyn.chart(**{**SMALL, **kwargs})


def test_unknown_keywords_are_type_errors():
    with pytest.raises(TypeError):
        afmdyn.chart(**SMALL, omegaa=2.0)
    with pytest.raises(TypeError):
        afmdyn.chart(**{**SMALL, "x_steps": "four"})


def test_a_probe_chart_runs_in_si():
    probe = Path(__file__).resolve().parents[3] / "examples" / "probe-point-mass-dmt.toml"
    f0 = afmdyn.probe(probe)["si"]["drive_frequency_hz"]
    ds = afmdyn.chart(
        x="z_c",
        x_from=6e-9,
        x_to=9e-9,
        x_steps=2,
        y="drive_frequency",
        y_from=0.999 * f0,
        y_to=1.001 * f0,
        y_steps=1,
        starts=1,
        lyapunov_periods=0,
        probe=probe,
    )
    assert ds.x.attrs["units"] == "m" and ds.y.attrs["units"] == "Hz"
    assert (ds.attractors > 0).all()
    # a value of the probe file itself: the free amplitude A₀ (the length unit) and E_s
    ds = afmdyn.chart(
        x="free_amplitude", x_from=8e-9, x_to=12e-9, x_steps=2,
        y="sample_modulus", y_from=2e9, y_to=4e9, y_steps=1,
        starts=1, lyapunov_periods=0, max_periods=6000, probe=probe,
    )
    assert ds.x.attrs["units"] == "m" and ds.y.attrs["units"] == "Pa"
    assert (ds.dominant_period == 1).all()
    with pytest.raises(ValueError, match="needs a probe file"):
        afmdyn.chart(x="free_amplitude", x_from=8e-9, x_to=12e-9)


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_dask_chart_equals_the_local_chart(client, tmp_path):
    ref = afmdyn.chart(**SMALL)
    xr.testing.assert_identical(afmdyn.dask.chart(**SMALL, client=client), ref)
    store = tmp_path / "chart.zarr"
    xr.testing.assert_identical(afmdyn.dask.chart(**SMALL, client=client, store=store), ref)
    done = Path(afmdyn.dask.ledger_dir(str(store))) / afmdyn.dask.DONE
    lines = done.read_text()
    assert sorted(int(t) for t in lines.split()) == list(range(4))
    # a finished store computes nothing; the store alone is an xarray dataset
    xr.testing.assert_identical(afmdyn.dask.chart(**SMALL, client=client, store=store), ref)
    assert done.read_text() == lines
    np.testing.assert_array_equal(xr.open_zarr(store).period.values, ref.period.values)
    with pytest.raises(ValueError, match="seed = 1 in the interrupted run, 2 now"):
        afmdyn.dask.chart(**SMALL, seed=2, client=client, store=store)
    # a second run on a store in use is refused at once
    lock = afmdyn._afmdyn.StoreLock(afmdyn.dask.ledger_dir(str(store)))
    try:
        with pytest.raises(ValueError, match="in use by another afmdyn run"):
            afmdyn.dask.chart(**SMALL, client=client, store=store)
    finally:
        lock.release()
    # never overwrites a directory that is not a store
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "keep.txt").write_text("mine")
    with pytest.raises(ValueError, match="not a Zarr store"):
        afmdyn.dask.chart(**SMALL, client=client, store=tmp_path / "notes", resume=False)
    assert (tmp_path / "notes" / "keep.txt").read_text() == "mine"


async def _die() -> None:
    """Run on a worker: end its process at once, as a crash or a killed node would."""
    os._exit(1)


WIDE = dict(x_steps=12, y_steps=2, starts=3, tile=1, lyapunov_periods=200)


def test_a_worker_killed_mid_run_loses_nothing(client):
    ref = afmdyn.chart(**WIDE)
    killed = []

    def progress(done, total):
        if done >= 1 and not killed:
            worker = sorted(client.scheduler_info()["workers"])[0]
            client.run(_die, workers=[worker], wait=False)
            killed.append((done, total))

    ds = afmdyn.dask.chart(**WIDE, client=client, progress=progress)
    assert killed and killed[0][0] < killed[0][1], "the worker died mid-run"
    xr.testing.assert_identical(ds, ref)


DRIVER = """
import sys, distributed, afmdyn.dask
if __name__ == "__main__":
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    afmdyn.dask.chart(x_steps=12, y_steps=2, starts=3, tile=1, lyapunov_periods=200,
                      client=client, store=sys.argv[1], checkpoint_seconds=0)
"""


def test_a_killed_driver_resumes_without_duplicates(client, tmp_path):
    ref = afmdyn.chart(**WIDE)
    store = tmp_path / "chart.zarr"
    script = tmp_path / "driver.py"
    script.write_text(textwrap.dedent(DRIVER))
    done = Path(afmdyn.dask.ledger_dir(str(store))) / afmdyn.dask.DONE
    p = subprocess.Popen([sys.executable, str(script), str(store)])
    try:
        t0 = time.monotonic()
        while not (done.exists() and done.read_text().strip()):
            assert p.poll() is None, "the driver ended before storing a task"
            assert time.monotonic() - t0 < 120
            time.sleep(0.02)
        p.send_signal(signal.SIGKILL)
    finally:
        p.wait()
    stored = [int(t) for t in done.read_text().split()]
    assert 0 < len(stored) < 24, stored
    ds = afmdyn.dask.chart(**WIDE, client=client, store=store)
    xr.testing.assert_identical(ds, ref)
    tasks = [int(t) for t in done.read_text().split()]
    assert sorted(tasks) == list(range(24)), "every task once: none lost, none duplicated"
    assert tasks[: len(stored)] == stored, "the stored tasks were not computed again"


def test_dask_bifurcation_equals_the_local_sweep(client):
    kw = dict(from_=2.0, to=4.0, steps=40, starts=1, seed=3)
    ref = afmdyn.bifurcation(**kw)
    xr.testing.assert_identical(afmdyn.dask.bifurcation(**kw, client=client), ref)
    # without continuation there is no coarse pass: random starts only
    kw = dict(from_=2.6, to=2.8, steps=5, starts=2, continuation=False)
    xr.testing.assert_identical(
        afmdyn.dask.bifurcation(**kw, client=client), afmdyn.bifurcation(**kw)
    )


def test_dask_bifurcation_stores_and_resumes_the_command_lines_sweep(client, cli, tmp_path):
    args = "--from 2.0 --to 4.0 --steps 40 --starts 1 --seed 3".split()
    ref = cli("bifurcation", *args, "--out", tmp_path / "ref")
    assert ref.returncode == 0, ref.stderr
    kw = dict(from_=2.0, to=4.0, steps=40, starts=1, seed=3)
    # a command-line run killed after 30 points, resumed through Dask
    cut = tmp_path / "cut"
    killed = cli("bifurcation", *args, "--out", cut, "--threads", "1", "--abort-after", "30")
    assert killed.returncode != 0
    ds = afmdyn.dask.bifurcation(**kw, client=client, store=cut)
    assert (cut / "bifurcation.csv").read_bytes() == (tmp_path / "ref" / "bifurcation.csv").read_bytes()
    xr.testing.assert_identical(ds, afmdyn.bifurcation(**kw))
    # finished: nothing computed again; another request refused
    again = afmdyn.dask.bifurcation(**kw, client=client, store=cut)
    xr.testing.assert_identical(again, ds)
    with pytest.raises(ValueError, match="steps = 40 in the interrupted run, 41 now"):
        afmdyn.dask.bifurcation(**{**kw, "steps": 41}, client=client, store=cut)


def test_netcdf_files_open_with_the_packages_own_dependencies(cli, tmp_path):
    """Issue 42 §4: after ``pip install afmdyn`` alone, ``xr.open_dataset("chart.nc")`` failed
    (xarray needs SciPy or h5netcdf/netCDF4 for NetCDF). The package now requires SciPy, the
    backend of NetCDF 3 files: its requirements outside every extra name it, and a chart.nc
    the command line wrote opens with that backend, as does one Python writes."""
    import importlib.metadata
    import re

    required = {
        re.split(r"[\s<>=!~;\[]", r, maxsplit=1)[0].lower()
        for r in importlib.metadata.requires("afmdyn") or []
        if "extra ==" not in r
    }
    assert required & {"scipy", "h5netcdf", "netcdf4"}, sorted(required)
    run = cli("chart", *FLAGS, "--out", tmp_path)
    assert run.returncode == 0, run.stderr
    nc = xr.open_dataset(tmp_path / "chart.nc", engine="scipy").load()
    assert nc.sizes["x"] == 4 and nc.sizes["y"] == 2
    ds = afmdyn.chart(**SMALL)
    ds.to_netcdf(tmp_path / "python.nc", engine="scipy")
    back = xr.open_dataset(tmp_path / "python.nc", engine="scipy").load()
    np.testing.assert_array_equal(back.period.values, ds.period.values)


def test_a_chart_without_any_attractor_fails_by_the_librarys_rule():
    # the Dask store keeps counts only: the rule of every front end on the counts
    from afmdyn import _chart

    s = _chart.study(None, {}, x_steps=2, y_steps=1)
    s.check([0, 1])
    with pytest.raises(afmdyn.SimulationError, match="every one of the 2 chart cells failed"):
        s.check([0, 0])
