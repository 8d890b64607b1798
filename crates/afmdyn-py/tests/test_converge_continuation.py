"""converge() and continuation(): the command line's files and --json summaries."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import afmdyn


def test_converge_equals_the_command_line(cli, cli_json, tmp_path):
    ref = cli_json("converge", "--out", tmp_path)
    ds = afmdyn.converge()
    del ref["out"]
    assert afmdyn.summary(ds) == ref
    assert ds.attrs["omega"] == 4.1  # Fig. 4's Ω is the default here, as on the command line
    csv = pd.read_csv(tmp_path / "converge.csv")
    np.testing.assert_array_equal(ds.tau_from_section.values, csv.tau_from_section.values)
    for n in range(1, 5):
        np.testing.assert_array_equal(ds.w_tip.sel(n_modes=n).values, csv[f"w_tip_n{n}"].values)
    assert ds.w_tip.dims == ("n_modes", "sample") and ds.w_tip.dtype == np.float64
    assert ds.period.values.tolist() == [1, 1, 1, 1]
    # the RMS change is the RMS of the difference of consecutive rows
    d = ds.w_tip.values
    for n in range(1, 4):
        rms = np.sqrt(np.mean((d[n] - d[n - 1]) ** 2))
        assert ds.rms_change.values[n] == pytest.approx(rms, rel=1e-12)
    assert np.isnan(ds.rms_change.values[0])
    # convergence with N (paper Fig. 4)
    assert ds.rms_change.values[3] < ds.rms_change.values[2] < ds.rms_change.values[1]


def test_converge_errors():
    with pytest.raises(ValueError, match="max_modes = 0"):
        afmdyn.converge(max_modes=0)
    with pytest.raises(ValueError, match="max_modes = 21"):
        afmdyn.converge(max_modes=21)
    with pytest.raises(ValueError, match="periods = 0: must be in 1..=10000"):
        afmdyn.converge(periods=0)


@pytest.fixture(scope="module")
def switched(cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("continue")
    run = cli("continue", "--from", 3.2, "--to", 2.6, "--switch", "--json", "--out", out)
    assert run.returncode == 0, run.stderr
    import json

    return json.loads(run.stdout), pd.read_csv(out / "continuation.csv", keep_default_na=False)


def test_continuation_with_branch_switching_equals_the_command_line(switched):
    doc, csv = switched
    ds = afmdyn.continuation(from_=3.2, to=2.6, switch=True)
    assert afmdyn.summary(ds) == doc
    assert ds.sizes["point"] == len(csv) == doc["points"]
    np.testing.assert_array_equal(ds.branch.values, csv.branch.values)
    np.testing.assert_array_equal(ds.period.values, csv.period.values)
    np.testing.assert_array_equal(ds.s.values, csv.s.values)
    np.testing.assert_array_equal(ds.value.values, csv.value.values)
    np.testing.assert_array_equal(ds.stable.values, csv.stable.values)
    np.testing.assert_array_equal(ds.max_multiplier.values, csv.max_multiplier.values)
    np.testing.assert_array_equal(ds.grazing_distance.values, csv.grazing_distance.values)
    np.testing.assert_array_equal(ds.switchings.values, csv.switchings.values)
    w = [[float(x) for x in row.split(" ")] for row in csv.w_tip_section]
    for i, row in enumerate(w):
        got = ds.w_tip_section.values[i]
        np.testing.assert_array_equal(got[: len(row)], row)
        assert np.isnan(got[len(row) :]).all()
    # event and instability names: the JSON's kebab-case in the CSV and the dataset alike
    assert ds.event.values.tolist() == csv.event.fillna("").tolist()
    assert ds.critical.values.tolist() == csv.critical.fillna("").tolist()
    # the period-doubling cascade: periods 1, 2, 4 and 8
    assert set(ds.branch.values.tolist()) == set(csv.branch.tolist())
    assert {1, 2, 4, 8} <= set(ds.period.values.tolist())
    assert ds.multipliers.dtype == np.complex128 and ds.multipliers.shape == (len(csv), 6)
    np.testing.assert_allclose(
        np.abs(ds.multipliers.values).max(axis=1), ds.max_multiplier.values, rtol=1e-12
    )


def test_continuation_closed_form_and_errors(cli_json, tmp_path):
    ds = afmdyn.continuation(from_=3.2, to=2.8)
    assert afmdyn.summary(ds) == cli_json("continue", "--from", 3.2, "--to", 2.8, "--out", tmp_path)
    # stability is |μ|max < 1 on every point
    np.testing.assert_array_equal(ds.stable.values, ds.max_multiplier.values < 1)
    events = ds.event.values[ds.event.values != ""]
    assert "period-doubling" in events.tolist()
    with pytest.raises(ValueError, match="omega"):
        afmdyn.continuation(from_=-1.0, to=2.0)
    with pytest.raises(ValueError, match="unknown parameter"):
        afmdyn.continuation(param="beta")
    with pytest.raises(ValueError, match="period = 0"):
        afmdyn.continuation(period=0)
