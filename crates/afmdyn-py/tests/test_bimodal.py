"""bimodal(): the dataset equals the command line's ``afmdyn bimodal --json`` (the same library
request and document) and carries each drive component's amplitude, phase, virial and
dissipated energy over (sweep, z_c) in SI; far from the sample each component's amplitude is
its free amplitude (the probe's 10 nm and 1 nm, to 1e-4); a single-frequency probe is refused
naming ``[drive].free_amplitude``."""

from __future__ import annotations

import numpy as np
import pytest

import afmdyn
from conftest import EXAMPLES

BIM = str(EXAMPLES / "probe-bimodal.toml")
SINGLE = str(EXAMPLES / "probe-eigenmodes-dmt.toml")


def test_bimodal_equals_the_command_line_and_reports_each_component(cli_json):
    doc = cli_json("bimodal", "--probe", BIM, "--points", "8", "--no-branches", "--files",
                   "none")
    ds = afmdyn.bimodal(probe=BIM, points=8, branches=False)
    assert afmdyn.summary(ds) == doc
    for i in (1, 2):
        for name, unit in ((f"amplitude_{i}", "m"), (f"phase_{i}_deg", "degree"),
                           (f"virial_{i}", "J"), (f"energy_dissipated_{i}", "J")):
            assert ds[name].dims == ("sweep", "z_c")
            assert ds[name].attrs["units"] == unit, name
            assert ds[name].sel(sweep="approach").values.tolist() == doc["approach"][name]
    far = ds.sel(sweep="approach").isel(z_c=0)
    assert float(far.amplitude_1) == pytest.approx(10e-9, rel=1e-4)
    assert float(far.amplitude_2) == pytest.approx(1e-9, rel=1e-4)
    near = ds.sel(sweep="approach").isel(z_c=-1)
    assert float(near.amplitude_2) < 0.5e-9
    assert doc["drive_components"]["frequency"] == pytest.approx([300e3, 1.875e6], rel=1e-12)
    assert np.isfinite(ds.energy_dissipated_2.values).all()


def test_bimodal_temperature_gives_each_components_lock_in_noise(cli_json):
    """With ``temperature`` the dataset carries each component's lock-in noise over (sweep, z_c)
    in SI, equal to the command line's; far from the sample the second mode's σ_A is its own
    (k_BT/k₂ · τ₂/(τ₂ + τ_L))^½ (k₂ = 1571 N/m, τ₂ = 2Q₂/ω₂ = τ_L·4 at the default τ_L), to 1 %."""
    doc = cli_json("bimodal", "--probe", BIM, "--points", "4", "--no-branches", "--files",
                   "none", "--temperature", "295")
    ds = afmdyn.bimodal(probe=BIM, points=4, branches=False, temperature=295.0)
    assert afmdyn.summary(ds) == doc
    for name, unit in (("amplitude_noise_2", "m"), ("phase_noise_2_deg", "degree"),
                       ("amplitude_noise", "m")):
        assert ds[name].dims == ("sweep", "z_c")
        assert ds[name].attrs["units"] == unit, name
        # null in the document (a point averaged for lack of a short period), NaN here
        cli = np.array(doc["approach"][name], dtype=float)
        np.testing.assert_array_equal(ds[name].sel(sweep="approach").values, cli)
    free = (1.380649e-23 * 295.0 / 1571.0 * 0.8) ** 0.5
    far = ds.sel(sweep="approach").isel(z_c=0)
    assert float(far.amplitude_noise_2) == pytest.approx(free, rel=0.01)


def test_bimodal_refuses_a_single_frequency_drive():
    with pytest.raises(ValueError, match=r"\[drive\]\.free_amplitude"):
        afmdyn.bimodal(probe=SINGLE, points=3, branches=False)


def test_observe_reports_each_component():
    """``observe`` on a multifrequency probe: each component's amplitude, phase, virial and
    dissipation over ``component``, the first's amplitude the curve's ``amplitude``, and the
    closed forms within 1e-3 of π k A0²/Q of the direct integrals (the eigenmode model)."""
    ds = afmdyn.observe(probe=BIM, z_c=9e-9)
    assert ds.component.values.tolist() == [1, 2]
    assert float(ds.component_amplitude[0]) == pytest.approx(float(ds.amplitude), rel=1e-9)
    assert ds.component_ratio.values.tolist() == pytest.approx([1.0, 6.25])
    assert ds.component_amplitude.attrs["units"] == "m"
    for i, (k, q) in enumerate(((40.0, 400.0), (1571.0, 2500.0))):
        a0 = float(ds.component_free_amplitude[i])
        scale = np.pi * k * a0 ** 2 / q
        assert abs(float(ds.component_energy_dissipated[i] - ds.component_closed_energy_dissipated[i])) < 1e-3 * scale
        assert abs(float(ds.component_virial[i] - ds.component_closed_virial[i])) < 1e-3 * scale


def test_bimodal_average_agrees_with_the_orbits_within_its_estimates():
    """``average=True`` measures the same points by the time average: within each point's
    error estimate (or the settling tolerance 1e-5 A0) of the periodic orbits, with the
    estimates in ``to_dict()["time_average"]``."""
    curve = dict(from_=12e-9, to=8e-9, points=3, branches=False)
    orbit = afmdyn.bimodal(probe=BIM, **curve)
    avg = afmdyn.bimodal(probe=BIM, average=True, **curve)
    ta = avg.afmdyn.to_dict()["time_average"]
    assert "time_average" not in orbit.afmdyn.to_dict()
    for sweep in ("approach", "retract"):
        assert all(ta[sweep]["settled"]), ta
        err = np.asarray(ta[sweep]["amplitude_error"])
        for i, a0 in ((1, 10e-9), (2, 1e-9)):
            x = orbit[f"amplitude_{i}"].sel(sweep=sweep).values
            y = avg[f"amplitude_{i}"].sel(sweep=sweep).values
            bound = np.maximum(err[:, i - 1], 1e-5 * a0)
            assert (np.abs(x - y) <= bound).all(), (sweep, i, x, y, bound)
