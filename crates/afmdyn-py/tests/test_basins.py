"""basins(): the dataset equals the command line's basins.csv and --json (labels, fractions,
measures); errors."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

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


def test_bad_basins_are_refused():
    with pytest.raises(ValueError, match="x: 'b1'"):
        afmdyn.basins(x="b1")
    with pytest.raises(ValueError, match="x = a4"):
        afmdyn.basins(x="a4", x_steps=2, y_steps=2)
    with pytest.raises(ValueError, match="near_tol = 0"):
        afmdyn.basins(near_tol=0.0)
    with pytest.raises(ValueError, match="x_steps = -1"):
        afmdyn.basins(x_steps=-1)
