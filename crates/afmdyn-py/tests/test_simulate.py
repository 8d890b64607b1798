"""simulate(): the time series equals the command line's files sample for sample; eq. 8 and
the energy balance hold; options and errors."""

from __future__ import annotations

import csv

import numpy as np
import pytest
import xarray as xr

import afmdyn


@pytest.fixture(scope="module")
def reference(cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("simulate")
    args = "simulate --periods 20 --transient 10 --omega 2.8 --energy-balance --json --out"
    run = cli(*args.split(), out)
    assert run.returncode == 0, run.stderr
    return out, run.stdout


def test_equals_the_command_lines_output_files(reference):
    out, stdout = reference
    ds = afmdyn.simulate(periods=20, transient=10, omega=2.8, energy_balance=True)
    import json

    cli_doc = json.loads(stdout)
    assert cli_doc.pop("files") == "all"  # what the command line wrote: its own key
    assert afmdyn.summary(ds) == cli_doc
    ts = np.load(out / "timeseries.npy")
    n = ds.sizes["mode"]
    assert ts.shape == (ds.sizes["tau"], 6 + 2 * n)
    for col, name in enumerate(["tau", "v_t", "w_tip", "w_tip_dot"]):
        np.testing.assert_array_equal(ds[name].values, ts[:, col], err_msg=name)
    np.testing.assert_array_equal(ds.in_contact.values, ts[:, 4] == 1)
    np.testing.assert_array_equal(ds.contact_force.values, ts[:, 5])
    np.testing.assert_array_equal(ds.a.values, ts[:, 6 : 6 + n])
    np.testing.assert_array_equal(ds.a_dot.values, ts[:, 6 + n :])
    with open(out / "events.csv") as f:
        ev = list(csv.DictReader(f))
    assert len(ev) == ds.sizes["event"] == ds.attrs["switchings"]
    np.testing.assert_array_equal(ds.event_tau.values, [float(r["tau"]) for r in ev])
    np.testing.assert_array_equal(ds.event_v_t_dot.values, [float(r["v_t_dot"]) for r in ev])
    np.testing.assert_array_equal(ds.event_to_contact.values, [r["to"] == "contact" for r in ev])
    with open(out / "poincare.csv") as f:
        pc = list(csv.DictReader(f))
    for col in ["tau", "v_t", "w_tip", "w_tip_dot"]:
        np.testing.assert_array_equal(ds["section_" + col].values, [float(r[col]) for r in pc])
    with open(out / "energy.csv") as f:
        en = list(csv.DictReader(f))
    np.testing.assert_array_equal(ds.base_work.values, [float(r["base_work"]) for r in en])
    np.testing.assert_array_equal(ds.energy_residual.values, [float(r["residual"]) for r in en])
    # the amplitude spectrum is the same library function on the same samples
    with open(out / "spectrum.csv") as f:
        sp = list(csv.DictReader(f))
    np.testing.assert_array_equal(ds.frequency.values, [float(r["frequency"]) for r in sp])
    np.testing.assert_array_equal(ds.spectrum.values, [float(r["amplitude"]) for r in sp])
    # on whole drive periods (20): bin 20 is Ω
    assert ds.frequency.values[20] == pytest.approx(2.8, rel=1e-12)


def test_dims_dtypes_units_and_no_copies():
    ds = afmdyn.simulate(periods=3, samples_per_period=50, modes=2)
    assert isinstance(ds, xr.Dataset)
    assert ds.sizes["tau"] == 3 * 50 + 1 and ds.sizes["mode"] == 2 and ds.sizes["component"] == 4
    for name in ["v_t", "v_t_dot", "w_tip", "w_tip_dot", "contact_force"]:
        assert ds[name].dims == ("tau",) and ds[name].dtype == np.float64
    assert ds.in_contact.dtype == np.bool_
    assert ds.a.dims == ("tau", "mode") and ds.a.dtype == np.float64
    assert ds.section_state.dims == ("section", "component")
    # the units as the library names them (report::SeriesUnits, timeseries.csv's)
    assert ds.w_tip.attrs["units"] == "g0" and ds.tau.attrs["units"] == "τ (eq. 5)"
    assert ds.contact_force.attrs["units"] == "EI g0/L³"
    assert ds.attrs["modes"] == 2 and ds.attrs["omega"] == 2.6
    # the arrays are the buffers Rust filled, handed over without a copy (a 2-D array is a
    # reshaped view of the flat buffer)
    for name in ["w_tip", "a", "event_tau"]:
        values = ds[name].values
        assert not values.flags.owndata
        while isinstance(values.base, np.ndarray):
            values = values.base
        assert type(values.base).__name__ == "PySliceContainer"
    assert ds.a.values.flags.c_contiguous


def test_eq8_and_the_contact_force_hold_on_the_samples():
    p = afmdyn.Params(omega=2.8, gap=0.05)
    ds = afmdyn.simulate(p, periods=10, transient=5, energy_balance=True)
    tau = ds.tau.values
    v_t = ds.w_tip.values + p.alpha2 * np.sin(p.omega * tau) + p.alpha5
    np.testing.assert_allclose(ds.v_t.values, v_t, rtol=0, atol=1e-14)
    v_dot = ds.w_tip_dot.values + p.alpha2 * p.omega * np.cos(p.omega * tau)
    np.testing.assert_allclose(ds.v_t_dot.values, v_dot, rtol=0, atol=1e-13)
    # the paper's linear law, F_c = α4 δ + α6 δ̇ with δ = −V_T in contact, 0 off the sample:
    # repulsive positive, as the variable's sign_convention says (issue 42 §4)
    force = np.where(ds.in_contact, -(p.alpha4 * ds.v_t + p.alpha6 * ds.v_t_dot), 0.0)
    np.testing.assert_allclose(ds.contact_force.values, force, atol=1e-12)
    assert ds.contact_force.attrs["sign_convention"].startswith(
        "positive when the sample pushes the tip away"
    )
    assert ds.contact_force.values[np.argmin(ds.v_t.values)] > 0
    assert ds.in_contact.any() and not ds.in_contact.all()
    # energy balance per period (exact propagation): residual at round-off
    assert np.abs(ds.energy_residual).max() < 1e-10
    assert ds.sizes["cycle"] == 10


def test_tau_end_initial_state_and_integrators(cli, tmp_path):
    ds = afmdyn.simulate(tau_end=20.0, samples_per_period=10)
    assert ds.attrs["tau_end"] == pytest.approx(20.0, rel=1e-12)
    assert 20.0 - 2 * np.pi / 2.6 / 10 < ds.tau.values[-1] <= 20.0
    z0 = [0.1, 0.0, 0.0, 0.0, 0.0, 0.0]
    ds = afmdyn.simulate(periods=2, initial=z0, samples_per_period=10)
    assert ds.a.values[0].tolist() == [0.1, 0.0, 0.0]
    # rk4 with located switchings: the arrays of `afmdyn simulate --integrator rk4`, and
    # within its truncation error of the exact propagation
    out = tmp_path / "rk4"
    args = "simulate --periods 2 --integrator rk4 --steps-per-period 400 --samples-per-period 20"
    run = cli(*args.split(), "--out", out)
    assert run.returncode == 0, run.stderr
    a = afmdyn.simulate(periods=2, integrator="rk4", steps_per_period=400, samples_per_period=20)
    assert a.attrs["integrator"] == "rk4"
    np.testing.assert_array_equal(a.w_tip.values, np.load(out / "timeseries.npy")[:, 2])
    b = afmdyn.simulate(periods=2, samples_per_period=20)
    np.testing.assert_allclose(a.w_tip, b.w_tip, atol=1e-4)
    assert np.abs(a.w_tip - b.w_tip).max() > 0  # a different integrator, not the same code path


@pytest.mark.parametrize(
    "kwargs,exc,needle",
    [
        ({"periods": 0}, ValueError, "periods = 0"),
        ({"periods": float("nan")}, ValueError, "periods"),
        ({"periods": 2, "tau_end": 5}, ValueError, "not both"),
        ({"tau_end": 1.0, "transient": 10}, ValueError, "tau_end"),
        ({"transient": -1}, ValueError, "transient"),
        ({"samples_per_period": 0}, ValueError, "samples_per_period"),
        ({"samples_per_period": 100_001}, ValueError, "samples_per_period"),
        ({"integrator": "euler"}, ValueError, "integrator 'euler'"),
        ({"integrator": "rk4", "steps_per_period": 0}, ValueError, "steps_per_period = 0"),
        ({"integrator": "adaptive", "tolerance": 2.0}, ValueError, "tolerance"),
        ({"initial": [0.1, 0.2]}, ValueError, "initial.*expected 6 values, got 2"),
        ({"initial": [[0.1] * 6]}, ValueError, "1-D"),
        ({"initial": [float("nan")] * 6}, ValueError, "finite"),
        ({"samples_per_period": -1}, ValueError, "samples_per_period = -1: must be >= 0"),
    ],
)
def test_errors(kwargs, exc, needle):
    with pytest.raises(exc, match=needle):
        afmdyn.simulate(**kwargs)


def test_a_wrong_option_type_is_a_type_error_naming_the_option():
    with pytest.raises(TypeError, match=r"simulate\(\): periods must be a number or None, got str"):
        afmdyn.simulate(periods="3")  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"resonance\(\): mode must be an integer, got NoneType"):
        afmdyn.resonance(mode=None)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"bifurcation\(\): steps must be an integer, got str"):
        afmdyn.bifurcation(steps="10")  # type: ignore[arg-type]
    # integers beyond 64 bits name the option (not OverflowError)
    with pytest.raises(ValueError, match="points = 18446744073709551616"):
        afmdyn.approach(points=2**64)
    with pytest.raises(ValueError, match=r"modes = 10{30}: must be in 1..=20"):
        afmdyn.simulate(modes=10**30)
    # a NaN end is named as itself
    with pytest.raises(ValueError, match="from = NaN: must be a finite number"):
        afmdyn.approach(from_=float("nan"))


def test_a_failing_computation_is_a_simulation_error_with_the_command_lines_message(cli, tmp_path):
    # fixed-step RK4 at 5 steps per period is unstable (h·ω_max > 2.8): the run diverges
    args = dict(integrator="rk4", steps_per_period=5, samples_per_period=5, periods=200)
    with pytest.raises(afmdyn.SimulationError, match="diverged at tau") as e:
        afmdyn.simulate(**args)
    assert isinstance(e.value, RuntimeError) and not isinstance(e.value, ValueError)
    flags = "simulate --integrator rk4 --steps-per-period 5 --samples-per-period 5 --periods 200"
    run = cli(*flags.split(), "--out", tmp_path)
    assert run.returncode == 1 and str(e.value) in run.stderr
