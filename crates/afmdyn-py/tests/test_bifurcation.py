"""bifurcation(): the long-format dataset equals the command line's bifurcation.csv row for
row; the tidy DataFrame; progress; Ctrl-C; errors."""

from __future__ import annotations

import time

import numpy as np
import pandas as pd
import pytest

import afmdyn

ARGS = dict(from_=2.5, to=3.3, steps=9, starts=1, seed=3)


def _reference(cli, out, *extra):
    args = "bifurcation --from 2.5 --to 3.3 --steps 9 --starts 1 --seed 3"
    run = cli(*args.split(), "--out", out, *extra)
    assert run.returncode == 0, run.stderr
    ref = pd.read_csv(out / "bifurcation.csv", keep_default_na=False, na_values=[""])
    # the CLI writes points as they finish; the Python result is sorted by branch, then index
    order = ref.branch.map(
        lambda b: {"forward": 0, "backward": 1}.get(
            b, 2 + int(b.split("-")[-1]) if b.startswith("start-") else 9
        )
    )
    return (
        ref.assign(_o=order)
        .sort_values(["_o", "index", "point"], kind="stable")
        .reset_index(drop=True)
    )


def test_rows_equal_the_command_lines_csv(cli, tmp_path):
    ref = _reference(cli, tmp_path)
    ds = afmdyn.bifurcation(**ARGS)
    assert ds.sizes["point"] == len(ref)
    np.testing.assert_array_equal(ds.value.values, ref.value.values)
    np.testing.assert_array_equal(ds["index"].values, ref["index"].values)
    assert ds.branch.values.tolist() == ref.branch.tolist()
    assert ds.status.values.tolist() == ref.status.tolist()
    np.testing.assert_array_equal(ds.k.values, ref.point.values)
    np.testing.assert_array_equal(ds.n_points.values, ref.points.values)
    for col in [
        "tau",
        "v_t",
        "w_tip",
        "x_max",
        "v_t_min",
        "contact_fraction",
        "contacts_per_period",
    ]:
        np.testing.assert_array_equal(ds[col].values, ref[col].values, err_msg=col)
    periodic = ref.status == "periodic"
    np.testing.assert_array_equal(ds.period.values[periodic], ref.period[periodic].astype(int))
    assert (ds.period.values[~periodic] < 0).all()
    state = np.array([[float(v) for v in s.split(" ")] for s in ref.state])
    n = ds.attrs["modes"]
    for j in range(n):
        np.testing.assert_array_equal(ds[f"a_{j + 1}"].values, state[:, j])
        np.testing.assert_array_equal(ds[f"a_dot_{j + 1}"].values, state[:, n + j])
    # 9 values × (forward, backward, one random start), every one reached
    keys = set(zip(ds["index"].values.tolist(), ds.branch.values.tolist()))
    assert len(keys) == 27


def test_long_format_and_tidy_dataframe():
    ds = afmdyn.bifurcation(from_=2.7, to=2.9, steps=3)
    assert list(ds.dims) == ["point"]
    assert ds.w_tip.dtype == np.float64 and ds.period.dtype == np.int64
    assert ds.attrs["param"] == "omega" and ds.value.attrs["long_name"] == "Ω (omega)"
    np.testing.assert_array_equal(ds.attrs["values"], [2.7, 2.8, 2.9])
    df = ds.to_dataframe()
    assert len(df) == ds.sizes["point"]
    assert {"value", "branch", "status", "period", "w_tip", "x_max", "a_1", "a_dot_3"} <= set(
        df.columns
    )
    # at drive phase 0, V_T = W(1,τ) + α5 (eq. 8 with sin 0 = 0)
    np.testing.assert_allclose(df.v_t, df.w_tip + ds.attrs["alpha5"], atol=1e-12)
    # the period-2 window near Ω = 2.8 (docs/paper-reproduction.md): two section points there
    at = df[(df.branch == "forward") & np.isclose(df.value, 2.8)]
    assert at.period.tolist() == [2, 2] and at.k.tolist() == [0, 1]


def test_other_parameters_and_explicit_values(cli, tmp_path):
    ds = afmdyn.bifurcation(
        param="contact-stiffness", values=[10.0, 20.0], omega=2.8, continuation=False, starts=1
    )
    assert ds.attrs["param"] == "alpha4"
    assert sorted(set(ds.value.values.tolist())) == [10.0, 20.0]
    assert set(ds.branch.values.tolist()) == {"start-0"}
    run = cli(
        *"bifurcation --param alpha4 --from 10 --to 20 --steps 2 --omega 2.8".split(),
        *"--no-continuation --starts 1 --out".split(),
        tmp_path,
    )
    assert run.returncode == 0, run.stderr
    ref = pd.read_csv(tmp_path / "bifurcation.csv").sort_values(["index", "point"])
    np.testing.assert_array_equal(ds.w_tip.values, ref.w_tip.values)


def test_a_failed_point_is_an_error_row_not_an_exception(cli, tmp_path):
    ds = afmdyn.bifurcation(values=[2.6, 2.7], integrator="rk4", steps_per_period=5)
    assert ds.status.values.tolist() == ["error"] * 4
    assert (ds.period.values == -2).all() and np.isnan(ds.w_tip.values).all()
    assert all(m.startswith("diverged at tau") for m in ds.message.values)
    args = "bifurcation --from 2.6 --to 2.7 --steps 2 --integrator rk4 --steps-per-period 5"
    run = cli(*args.split(), "--out", tmp_path)
    assert run.returncode == 0, run.stderr  # the command line's error rows are readable too
    ref = pd.read_csv(tmp_path / "bifurcation.csv")
    assert sorted(ref.message) == sorted(ds.message.values.tolist())


def test_progress_callback_sees_every_point():
    calls = []
    ds = afmdyn.bifurcation(
        from_=2.0, to=3.0, steps=5, starts=1, progress=lambda d, t: calls.append((d, t))
    )
    assert calls[-1] == (15, 15)  # 5 values × (forward + backward + 1 start)
    assert all(t == 15 for _, t in calls)
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)
    assert ds.sizes["point"] >= 15


def test_an_exception_in_the_progress_callback_stops_the_sweep():
    seen = []

    def stop(done, total):
        seen.append(done)
        if done > 0:
            raise RuntimeError("enough")

    t0 = time.monotonic()
    with pytest.raises(RuntimeError, match="enough"):
        afmdyn.bifurcation(steps=4000, progress=stop)
    assert time.monotonic() - t0 < 20
    assert 0 < seen[-1] < 8000


def test_progress_bar_on_request(capfd):
    afmdyn.bifurcation(from_=2.0, to=2.2, steps=3, progress=True)
    err = capfd.readouterr().err
    assert "bifurcation" in err and "6/6" in err


def test_threads_option():
    one = afmdyn.bifurcation(from_=2.0, to=2.4, steps=3, threads=1)
    two = afmdyn.bifurcation(from_=2.0, to=2.4, steps=3, threads=2)
    np.testing.assert_array_equal(one.w_tip.values, two.w_tip.values)


@pytest.mark.parametrize(
    "kwargs,exc,needle",
    [
        ({"param": "stiffness"}, ValueError, "unknown parameter 'stiffness'"),
        ({"steps": 0}, ValueError, "steps = 0"),
        ({"from_": float("nan")}, ValueError, "from"),
        ({"from_": -1.0, "to": 1.0}, ValueError, "omega"),
        ({"param": "alpha4", "from_": -5.0, "to": 5.0}, ValueError, "alpha4"),
        ({"continuation": False, "starts": 0}, ValueError, "starts"),
        ({"threads": 0}, ValueError, "threads = 0"),
        ({"tol": 0.0}, ValueError, "tol = 0"),
        ({"max_period": 65}, ValueError, "max_period = 65"),
        ({"max_periods": 0}, ValueError, "max_periods = 0"),
        ({"starts": -1}, ValueError, "starts = -1"),
        ({"values": []}, ValueError, "values"),
        ({"integrator": "rk5"}, ValueError, "rk5"),
    ],
)
def test_errors(kwargs, exc, needle):
    with pytest.raises(exc, match=needle):
        afmdyn.bifurcation(**kwargs)
