"""peakforce(): the dataset and its channels equal the command line's ``afmdyn peakforce
--json`` for the same request (one library request and document); the cycle's force is the
one the channels summarise; bad options are refused naming them."""

from __future__ import annotations

import json

import numpy as np
import pytest

import afmdyn
from conftest import EXAMPLES

AIR = str(EXAMPLES / "probe-peakforce-air.toml")


def test_peakforce_equals_the_command_line(cli_json, tmp_path):
    doc = cli_json("peakforce", "--probe", AIR, "--z-c", "95nm", "--out", tmp_path / "pf")
    ds = afmdyn.peakforce(probe=AIR, z_c=95e-9)
    summary = json.loads(ds.attrs["summary"])
    assert summary["channels"] == doc["channels"]
    for name, value in doc["channels"].items():
        if value is not None:
            assert ds.attrs[name] == value
    # the channels are the cycle's exact extremes (located between samples): the 4096
    # samples reach within 0.5 % of them and not beyond
    force = ds["force"].values
    peak, adhesion = doc["channels"]["peak_force"], doc["channels"]["adhesion"]
    assert peak * (1 - 5e-3) <= force.max() <= peak * (1 + 1e-9)
    assert adhesion * (1 + 1e-9) <= force.min() <= adhesion * (1 - 5e-3)


def test_peakforce_temperature_equals_the_command_line(cli_json, tmp_path):
    # the thermal block's σ (the library's linear response, tested there against a simulated
    # lever and equipartition) reaches the dataset's attributes as the command line's
    # (and a thermally driven run, a function of its seed on every front end)
    doc = cli_json(
        "peakforce", "--probe", AIR, "--z-c", "97nm", "--temperature", "295",
        "--thermal-cycles", "100", "--seed", "3", "--files", "none"
    )
    ds = afmdyn.peakforce(probe=AIR, z_c=97e-9, temperature=295.0, thermal_cycles=100, seed=3)
    thermal = json.loads(ds.attrs["summary"])["thermal"]
    assert thermal == doc["thermal"]
    assert thermal["simulated"]["cycles"] == 100 and thermal["simulated"]["seed"] == 3
    assert ds.attrs["peak_force_noise"] == doc["thermal"]["peak_force_noise"] > 0
    assert ds.attrs["deformation_noise"] == doc["thermal"]["deformation_noise"] > 0
    assert "peak_force_noise" not in afmdyn.peakforce(probe=AIR, z_c=97e-9).attrs
    with pytest.raises(ValueError, match="temperature"):
        afmdyn.peakforce(probe=AIR, z_c=97e-9, temperature=-5.0)


def test_bad_peakforce_options_name_them():
    with pytest.raises(ValueError, match="setpoint"):
        afmdyn.peakforce(probe=AIR, setpoint=-1e-9)
    with pytest.raises(ValueError, match="samples"):
        afmdyn.peakforce(probe=AIR, z_c=95e-9, samples=10)


def test_peakforce_sweep_in_z_c_equals_the_command_line(cli_json, tmp_path):
    doc = cli_json(
        "peakforce",
        "--probe",
        AIR,
        "--from",
        "97nm",
        "--to",
        "95nm",
        "--step",
        "1nm",
        "--files",
        "none",
    )
    ds = afmdyn.peakforce(probe=AIR, z_c=[97e-9, 96e-9, 95e-9])
    assert ds.sizes["z_c"] == 3
    np.testing.assert_allclose(ds["z_c"].values, doc["sweep"]["values"], rtol=1e-12)
    # the command line's grid 97 nm − k × 1 nm differs from 96e-9, 95e-9 in the last bits
    for name in ("peak_force", "adhesion", "deformation"):
        np.testing.assert_allclose(
            ds[name].values, doc["sweep"]["channels"][name], rtol=1e-9
        )
    # the peak force grows as the sample reaches farther past the tip
    assert np.all(np.diff(ds["peak_force"].values) > 0)
