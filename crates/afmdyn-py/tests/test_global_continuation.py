"""global_continuation(): the dataset equals the command line's ``attractors --sweep`` (JSON and
attractors-sweep.csv); fractions add up per value; ids follow the impact oscillator's two
period-1 orbits; errors name the option."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

import afmdyn

IMPACT = dict(contact_law="impact", restitution=0.8, modes=1)
FLAGS = "--contact-law impact --restitution 0.8 --modes 1".split()
SWEEP = dict(from_=1.98, to=2.06, steps=5, samples=16)


def test_global_continuation_equals_the_command_line(cli, tmp_path):
    run = cli("attractors", *FLAGS, "--sweep", "omega", "--from", 1.98, "--to", 2.06,
              "--steps", 5, "--samples", 16, "--json", "--out", tmp_path)
    assert run.returncode == 0, run.stderr
    doc = json.loads(run.stdout)
    ds = afmdyn.global_continuation(**IMPACT, **SWEEP)
    assert afmdyn.summary(ds) == doc
    np.testing.assert_array_equal(ds.basin_fraction.values, np.array(doc["fractions"]))
    np.testing.assert_allclose(ds.value.values, doc["values"], rtol=0, atol=0)
    csv = pd.read_csv(tmp_path / "attractors-sweep.csv")
    assert len(csv) == sum(len(s["attractors"]) for s in doc["steps"])
    for row in csv.itertuples():
        i = int(np.argmin(abs(ds.value.values - row.omega)))
        assert ds.basin_fraction.values[i, row.id] == row.basin_fraction
        assert ds.x_max.values[i, row.id] == row.x_max
    assert (tmp_path / "attractors-sweep.png").stat().st_size > 0


def test_fractions_add_up_and_ids_follow_the_orbits():
    ds = afmdyn.global_continuation(**IMPACT, **SWEEP)
    # no run failed, so every value's random starts are shared among its attractors
    assert (ds.failures.values == 0).all()
    np.testing.assert_allclose(ds.basin_fraction.sum("id").values, 1.0, rtol=0, atol=1e-12)
    # two period-1 orbits (the impact oscillator at Ω ≈ 2): two ids, each of period 1 where
    # present, and X_max moving by less than 0.01 per step of 0.02 along an id
    assert ds.sizes["id"] == 2
    assert set(np.unique(ds.period.values)) <= {0, 1}
    for k in range(2):
        x = ds.x_max.sel(id=k).values
        steps = np.abs(np.diff(x))
        assert np.all(steps[np.isfinite(steps)] < 0.01)


def test_a_continuation_killed_on_the_command_line_resumes_in_python(cli, tmp_path):
    # one store for both front ends: killed after 2 of 5 values, resumed from the second
    # value's attractors (seeds and ids) to the continuation of an uninterrupted run
    killed = cli("attractors", *FLAGS, "--sweep", "omega", "--from", 1.98, "--to", 2.06,
                 "--steps", 5, "--samples", 16, "--abort-after", 2, "--out", tmp_path)
    assert killed.returncode != 0
    values = tmp_path / ".continuation.values.jsonl"
    assert len(values.read_text().splitlines()) == 2
    ds = afmdyn.global_continuation(**IMPACT, **SWEEP, store=tmp_path, resume=True)
    ref = afmdyn.global_continuation(**IMPACT, **SWEEP)
    assert afmdyn.summary(ds) == afmdyn.summary(ref)
    np.testing.assert_array_equal(ds.basin_fraction.values, ref.basin_fraction.values)
    assert len(values.read_text().splitlines()) == 5
    with pytest.raises(ValueError, match="samples"):
        afmdyn.global_continuation(**IMPACT, **{**SWEEP, "samples": 8}, store=tmp_path,
                                   resume=True)


def test_bad_global_continuations_are_refused():
    with pytest.raises(ValueError, match="unknown"):
        afmdyn.global_continuation(param="beta", **IMPACT)
    with pytest.raises(ValueError, match="match_tol"):
        afmdyn.global_continuation(match_tol=-1.0, **IMPACT)
    with pytest.raises(ValueError, match="steps = 0"):
        afmdyn.global_continuation(steps=0, **IMPACT)
    with pytest.raises(ValueError, match="samples = -1"):
        afmdyn.global_continuation(samples=-1, **IMPACT)
    with pytest.raises(ValueError, match="omega"):
        afmdyn.global_continuation(from_=-1.0, to=2.0, steps=3, **IMPACT)
