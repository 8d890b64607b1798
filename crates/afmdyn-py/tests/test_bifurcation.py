"""bifurcation(): the long-format dataset equals the command line's bifurcation.csv row for
row, in its order; the tidy DataFrame; progress; Ctrl-C; a store resumed across front ends;
errors."""

from __future__ import annotations

import time
import zlib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import afmdyn

ARGS = dict(from_=2.5, to=3.3, steps=9, starts=1, seed=3)


def _reference(cli, out, *extra):
    args = "bifurcation --from 2.5 --to 3.3 --steps 9 --starts 1 --seed 3"
    run = cli(*args.split(), "--out", out, *extra)
    assert run.returncode == 0, run.stderr
    return _read(out)


def _read(out: Path) -> pd.DataFrame:
    return pd.read_csv(out / "bifurcation.csv", keep_default_na=False, na_values=[""])


def _assert_rows_equal(ds, ref):
    """The dataset holds the CSV's rows in the CSV's order."""
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


def test_rows_equal_the_command_lines_csv_in_its_order(cli, tmp_path):
    ref = _reference(cli, tmp_path)
    ds = afmdyn.bifurcation(**ARGS)
    _assert_rows_equal(ds, ref)
    # one order for both front ends: by value index, then forward, backward, start k, then k
    rank = {"forward": 0, "backward": 1, "start-0": 2}
    keys = list(zip(ds["index"].values, [rank[b] for b in ds.branch.values], ds.k.values))
    assert keys == sorted(keys)
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
    ref = pd.read_csv(tmp_path / "bifurcation.csv")
    np.testing.assert_array_equal(ds.w_tip.values, ref.w_tip.values)


def test_a_failed_point_is_an_error_row_not_an_exception(cli, tmp_path):
    # Ω = 2.6 diverges (RK4 at 5 steps per period), Ω = 60 (a shorter step) is computed
    ds = afmdyn.bifurcation(values=[2.6, 60.0], integrator="rk4", steps_per_period=5)
    st = ds.status.values.tolist()
    assert "error" in st and set(st) - {"error"}, st
    bad = ds.status.values == "error"
    assert (ds.period.values[bad] == -2).all() and np.isnan(ds.w_tip.values[bad]).all()
    assert all(m.startswith("diverged at tau") for m in ds.message.values[bad])


def test_a_sweep_whose_every_point_failed_is_a_failure(cli, tmp_path):
    """The exit-code rule (docs/outputs.md): no point computed, no answer — SimulationError in
    Python, exit 1 from the command line, which still writes its readable error rows."""
    with pytest.raises(afmdyn.SimulationError, match="every one of the 4 sweep points failed"):
        afmdyn.bifurcation(values=[2.6, 2.7], integrator="rk4", steps_per_period=5)
    args = "bifurcation --from 2.6 --to 2.7 --steps 2 --integrator rk4 --steps-per-period 5"
    run = cli(*args.split(), "--out", tmp_path)
    assert run.returncode == 1, run.stderr
    assert "every one of the 4 sweep points failed; the first: diverged at tau" in run.stderr
    ref = pd.read_csv(tmp_path / "bifurcation.csv")
    assert (ref.status == "error").all()
    assert all(m.startswith("diverged at tau") for m in ref.message)


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


def _killed(cli, out, after=10):
    """The command line's sweep of ARGS in `out`, killed after `after` points."""
    args = "bifurcation --from 2.5 --to 3.3 --steps 9 --starts 1 --seed 3"
    run = cli(*args.split(), "--out", out, "--abort-after", after)
    assert run.returncode != 0, "killed"
    assert (out / ".bifurcation.partial.csv").exists() and not (out / "bifurcation.csv").exists()


def test_resume_of_a_store_killed_on_the_command_line(cli, tmp_path):
    ref = _reference(cli, tmp_path / "full")
    store = tmp_path / "cut"
    _killed(cli, store)
    ds = afmdyn.bifurcation(**ARGS, store=store, resume=True)
    _assert_rows_equal(ds, ref)
    for name in ["bifurcation.csv", ".bifurcation.run.json"]:
        assert (store / name).read_bytes() == (tmp_path / "full" / name).read_bytes(), name
    assert not (store / ".bifurcation.partial.csv").exists()
    # a finished store is read back
    _assert_rows_equal(afmdyn.bifurcation(**ARGS, store=store, resume=True), ref)
    # and the command line resumes a Python store
    run = cli(
        *"bifurcation --from 2.5 --to 3.3 --steps 9 --starts 1 --seed 3 --resume --out".split(),
        store,
    )
    assert run.returncode == 0, run.stderr
    assert _read(store).equals(ref)


def _mark(path: Path, marker: str) -> set:
    """Set `w_tip` of every row of a rows file to `marker`; the (index, branch) marked. The
    checkpoint's rows end with the CRC-32 of the row's text (`crc32`): it is written anew, as
    afmdyn would have written the marked row."""
    lines = path.read_text().split("\n")
    sealed = lines[0].endswith(",crc32")
    marked = set()
    for i, line in enumerate(lines[1:], start=1):
        cells = line.split(",")
        if len(cells) == 18 + sealed:
            cells[10] = marker
            marked.add((int(cells[2]), cells[3]))
            row = ",".join(cells[:18])
            lines[i] = f"{row},{zlib.crc32(row.encode()):08x}" if sealed else row
    path.write_text("\n".join(lines))
    return marked


def test_resume_skips_exactly_the_points_written(cli, tmp_path):
    ref = _reference(cli, tmp_path / "full")
    store = tmp_path / "cut"
    _killed(cli, store, after=12)
    # rows of the stored points read back with a mark: a point computed again loses it
    stored = _mark(store / ".bifurcation.partial.csv", "9.5")
    assert len(stored) >= 12
    ds = afmdyn.bifurcation(**ARGS, store=store, resume=True)
    keys = list(zip(ds["index"].values.tolist(), ds.branch.values.tolist()))
    marked = ds.w_tip.values == 9.5
    assert {k for k, m in zip(keys, marked) if m} == stored
    assert not any(k in stored for k, m in zip(keys, marked) if not m)
    np.testing.assert_array_equal(ds.w_tip.values[~marked], ref.w_tip.values[~marked])
    np.testing.assert_array_equal(ds.x_max.values, ref.x_max.values)
    # a finished store is read back, not computed
    _mark(store / "bifurcation.csv", "8.5")
    again = afmdyn.bifurcation(**ARGS, store=store, resume=True)
    assert (again.w_tip.values == 8.5).all()


def test_a_damaged_store_is_refused_naming_its_file_and_line(cli, tmp_path):
    """One digit changed in a stored row (its checksum left as written), or the header
    removed: resume=True raises ValueError naming the file and the line, and returns no rows
    (it returned the changed value, or lost the header; issue 42)."""
    _killed(cli, tmp_path)
    partial = tmp_path / ".bifurcation.partial.csv"
    lines = partial.read_text().split("\n")
    assert lines[0].endswith(",crc32")
    cells = lines[2].split(",")
    cells[10] = cells[10].replace(cells[10].lstrip("-")[0], "7" if cells[10].lstrip("-")[0] != "7" else "3", 1)
    damaged = "\n".join([*lines[:2], ",".join(cells), *lines[3:]])
    partial.write_text(damaged)
    with pytest.raises(ValueError) as e:
        afmdyn.bifurcation(**ARGS, store=tmp_path, resume=True)
    assert ".bifurcation.partial.csv: line 3: checksum mismatch" in str(e.value), e.value
    assert "resume=False" in str(e.value) and "--resume" not in str(e.value), e.value
    assert partial.read_text() == damaged, "left as it was"
    partial.write_text("\n".join(lines[1:]))
    with pytest.raises(ValueError, match="line 1: the header is missing or changed"):
        afmdyn.bifurcation(**ARGS, store=tmp_path, resume=True)
    assert not (tmp_path / "bifurcation.csv").exists()
    # resume=False starts over
    _assert_rows_equal(afmdyn.bifurcation(**ARGS, store=tmp_path), _read(tmp_path))


def test_resume_with_another_request_is_refused_naming_the_field(cli, tmp_path):
    _killed(cli, tmp_path)
    partial = (tmp_path / ".bifurcation.partial.csv").read_bytes()
    for kwargs, needle in [
        ({"steps": 10}, "steps = 9 in the interrupted run, 10 now"),
        ({"seed": 4}, "seed = 3 in the interrupted run, 4 now"),
        ({"alpha4": 30.0}, "alpha4 = 20.0 in the interrupted run, 30.0 now"),
        ({"values": [2.5, 2.6]}, "from = 2.5 in the interrupted run, absent now"),
    ]:
        with pytest.raises(ValueError, match=needle):
            afmdyn.bifurcation(**{**ARGS, **kwargs}, store=tmp_path, resume=True)
        assert (tmp_path / ".bifurcation.partial.csv").read_bytes() == partial, kwargs
    with pytest.raises(ValueError, match="resume=True needs store="):
        afmdyn.bifurcation(**ARGS, resume=True)
    # without resume the store starts over
    ds = afmdyn.bifurcation(**{**ARGS, "steps": 3}, store=tmp_path)
    _assert_rows_equal(ds, _read(tmp_path))


def test_a_python_sweep_stopped_early_resumes_from_its_store(tmp_path):
    kw = dict(from_=2.0, to=3.0, steps=300)

    def stop(done, total):
        if done > 0:
            raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        afmdyn.bifurcation(**kw, store=tmp_path, progress=stop)
    assert (tmp_path / ".bifurcation.partial.csv").exists(), "kept for a resume"
    assert not (tmp_path / "bifurcation.csv").exists(), "not finished"
    stored = _mark(tmp_path / ".bifurcation.partial.csv", "9.5")
    ds = afmdyn.bifurcation(**kw, store=tmp_path, resume=True)
    assert (ds.w_tip.values == 9.5).sum() >= len(stored) > 0, "not computed again"
    ds["w_tip"] = ds.w_tip.where(ds.w_tip != 9.5, afmdyn.bifurcation(**kw).w_tip)
    ref = afmdyn.bifurcation(**kw)
    for col in ["value", "index", "branch", "status", "k", "w_tip", "x_max", "a_1"]:
        np.testing.assert_array_equal(ds[col].values, ref[col].values, err_msg=col)


def test_a_probe_sweep_equals_the_command_lines(cli, tmp_path):
    """`probe=` and `z_c=` mean what `--probe` and `--z-c` mean: the point-mass DMT probe swept
    in Ω around its resonance gives the command line's rows."""
    probe = str(Path(__file__).resolve().parents[3] / "examples" / "probe-point-mass-dmt.toml")
    run = cli(
        "bifurcation", "--probe", probe, "--z-c", "8e-9", "--from", "0.99", "--to", "1.01",
        "--steps", "3", "--max-periods", "300", "--out", tmp_path,
    )
    assert run.returncode == 0, run.stderr
    ds = afmdyn.bifurcation(
        probe=probe, z_c=8e-9, from_=0.99, to=1.01, steps=3, max_periods=300
    )
    assert ds.attrs["structure"] == "point-mass"
    _assert_rows_equal(ds, _read(tmp_path))


def test_a_store_in_use_by_another_run_is_refused(tmp_path, cli):
    """One run writes a store at a time, whichever front end started it: the library locks the
    directory (``DirLock``) for the command line's ``--out`` and Python's ``store=`` alike."""
    import subprocess
    import sys

    store = tmp_path / "sweep"
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            f"import afmdyn; afmdyn.bifurcation(steps=20000, store={str(store)!r}, progress=False)",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    try:
        lock = store / ".afmdyn.lock"
        t0 = time.monotonic()
        while not (lock.exists() and lock.read_text().strip()) and time.monotonic() - t0 < 30:
            time.sleep(0.05)
        busy = rf"in use by another afmdyn run \(process {holder.pid}\)"
        with pytest.raises(ValueError, match=busy):
            afmdyn.bifurcation(from_=2.0, to=2.2, steps=3, store=store)
        run = cli("bifurcation", "--from", "2", "--to", "2.2", "--steps", "3", "--out", store)
        assert run.returncode == 2, run.stderr
        assert f"(process {holder.pid}); wait for it to finish or choose another --out" in run.stderr
    finally:
        holder.kill()
        holder.wait()
    # the kernel released the killed holder's lock: the store is usable again
    ds = afmdyn.bifurcation(from_=2.0, to=2.2, steps=3, store=store)
    assert ds.sizes["point"] >= 6
