"""basins(): the dataset equals the command line's basins.csv and --json (labels, fractions,
measures); errors."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import afmdyn

IMPACT = dict(contact_law="impact", restitution=0.8, modes=1, omega=2.0)
FLAGS = "--contact-law impact --restitution 0.8 --modes 1 --omega 2.0".split()


def test_basins_equal_the_command_line(cli, tmp_path):
    run = cli("basins", *FLAGS, "--x-steps", 20, "--y-steps", 16, "--json", "--out", tmp_path)
    assert run.returncode == 0, run.stderr
    doc = json.loads(run.stdout)
    ds = afmdyn.basins(**IMPACT, x_steps=20, y_steps=16)
    assert ds.sizes["x"] == 20 and ds.sizes["y"] == 16
    np.testing.assert_array_equal(ds.label.values, np.array(doc["labels"]))
    np.testing.assert_allclose(ds.basin_fraction.values, doc["basin_fractions"], rtol=0, atol=0)
    assert ds.attrs["basin_entropy"] == doc["basin_entropy"]
    csv = pd.read_csv(tmp_path / "basins.csv")
    np.testing.assert_array_equal(csv["label"].values, ds.label.values.ravel())
    np.testing.assert_array_equal(csv["decided"].values, ds.decided.values.ravel())
    assert list(ds.period.values) == [a["period"] or -1 for a in doc["attractors"]]
    # basins.nc holds the same arrays (the library's one layout of them)
    nc = xr.open_dataset(tmp_path / "basins.nc")
    np.testing.assert_array_equal(nc.label.values, ds.label.values)
    names = nc.decided.attrs["flag_meanings"].split()
    np.testing.assert_array_equal(np.array(names)[nc.decided.values - 1], ds.decided.values)
    np.testing.assert_array_equal(nc.periods.values, ds.periods.values)
    np.testing.assert_allclose(nc.basin_fraction.values, ds.basin_fraction.values, rtol=0, atol=0)
    # the dataset's summary is the command line's document, but for the files it names
    summary = json.loads(ds.attrs["summary"])
    assert summary == {k: v for k, v in doc.items() if k not in ("csv", "netcdf")}


def test_two_passes_and_a_base_state():
    # 60 x 60 on N = 1: two passes (stride 2); most cells decided by the first pass's grid
    ds = afmdyn.basins(**IMPACT, x_steps=60, y_steps=60)
    assert json.loads(ds.attrs["summary"])["first_stride"] == 2
    assert (ds.decided.values == "grid").sum() > 1800
    one = afmdyn.basins(**IMPACT, x_steps=60, y_steps=60, stride=1)
    assert (one.decided.values == "grid").sum() == 0
    assert (one.label.values == ds.label.values).mean() >= 0.995
    # a base state: w = 0.3 set through mode 1 with the second mode's velocity from the base
    beam = afmdyn.basins(modes=2, x="w", x_from=0.0, x_to=0.3, x_steps=2, y="wdot", y_from=0.0,
                         y_to=0.0, y_steps=1, base=[0.0, 0.0, 0.0, 0.05], max_periods=300)
    assert json.loads(beam.attrs["summary"])["base"] == [0.0, 0.0, 0.0, 0.05]
    with pytest.raises(ValueError, match="base"):
        afmdyn.basins(modes=2, base=[0.0, 0.1], x_steps=2, y_steps=2)


def test_a_map_killed_on_the_command_line_resumes_in_python(cli, tmp_path):
    # one store for both front ends: the command line is killed in the first pass (26 rows of
    # the coarse grid at 50 x 50), Python resumes it to the map of an uninterrupted run
    size = ["--x-steps", 50, "--y-steps", 50]
    killed = cli("basins", *FLAGS, *size, "--threads", 1, "--abort-after", 5, "--out", tmp_path)
    assert killed.returncode != 0
    rows = (tmp_path / ".basins.rows.jsonl").read_text().splitlines()
    assert len(rows) == 5
    ds = afmdyn.basins(**IMPACT, x_steps=50, y_steps=50, store=tmp_path, resume=True)
    ref = afmdyn.basins(**IMPACT, x_steps=50, y_steps=50)
    np.testing.assert_array_equal(ds.label.values, ref.label.values)
    np.testing.assert_array_equal(ds.decided.values, ref.decided.values)
    np.testing.assert_array_equal(ds.periods.values, ref.periods.values)
    assert ds.attrs["summary"] == ref.attrs["summary"]
    stored = (tmp_path / ".basins.rows.jsonl").read_text().splitlines()
    assert stored[:5] == rows and len(stored) == 26 + 50
    # another request's store is refused naming the option; resume needs a store
    with pytest.raises(ValueError, match="near_tol"):
        afmdyn.basins(**IMPACT, x_steps=50, y_steps=50, near_tol=0.03, store=tmp_path,
                      resume=True)
    with pytest.raises(ValueError, match="resume=True needs store="):
        afmdyn.basins(**IMPACT, x_steps=4, y_steps=4, resume=True)


def test_dask_basins_equal_the_local_map():
    # two passes (50 x 50 on N = 1) on a LocalCluster of two worker processes: the recipe,
    # the starts of the passes and the rows pickle to the workers and back
    distributed = pytest.importorskip("distributed")
    import afmdyn.dask

    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    try:
        ds = afmdyn.dask.basins(**IMPACT, x_steps=50, y_steps=50, client=client)
    finally:
        client.close()
        cluster.close()
    ref = afmdyn.basins(**IMPACT, x_steps=50, y_steps=50)
    assert json.loads(ref.attrs["summary"])["first_stride"] == 2
    xr.testing.assert_identical(ds, ref)
    # a misspelt keyword is refused as afmdyn.basins refuses it, before any work
    with pytest.raises(TypeError, match="unknown model parameter 'x_step'"):
        afmdyn.dask.basins(**IMPACT, x_step=5, client=client)
    with pytest.raises(ValueError, match="near_tol"):
        afmdyn.dask.basins(**IMPACT, near_tol=0.0, client=client)


def test_bad_basins_are_refused():
    with pytest.raises(ValueError, match="x = b1"):
        afmdyn.basins(x="b1")
    with pytest.raises(ValueError, match="x = a4"):
        afmdyn.basins(x="a4", x_steps=2, y_steps=2)
    with pytest.raises(ValueError, match="near_tol = 0"):
        afmdyn.basins(near_tol=0.0)
    with pytest.raises(ValueError, match="x_steps = -1"):
        afmdyn.basins(x_steps=-1)
