"""fm(): the dataset equals the command line's ``afmdyn fm --json`` (the same library request
and document); ``reconstruct(fm=ds)`` equals ``afmdyn reconstruct --fm fm.json`` and gives the
probe's van der Waals force −HR/(6d²) back within 2 % between 3a₀ and A/2 (the Sader–Jarvis
round trip); bad options are refused naming them."""

from __future__ import annotations

import json

import numpy as np
import pytest

import afmdyn
from conftest import EXAMPLES

P1 = str(EXAMPLES / "probe-point-mass-dmt.toml")
GRID = dict(from_=40e-9, to=10.5e-9, step=0.02e-9)


def test_fm_equals_the_command_line_and_inverts_to_the_force(cli_json, tmp_path):
    doc = cli_json("fm", "--probe", P1, "--from", "40nm", "--to", "10.5nm", "--step", "0.02nm",
                   "--out", tmp_path / "fm")
    ds = afmdyn.fm(probe=P1, **GRID)
    assert afmdyn.summary(ds) == {k: v for k, v in doc.items() if k != "csv"}
    assert ds.frequency_shift.values.tolist() == doc["curve"]["frequency_shift"]
    assert ds.z_c.attrs["units"] == "m" and ds.frequency_shift.attrs["units"] == "Hz"
    assert ds.attrs["spring_constant"] == 40.0 and ds.attrs["mode"] == 1
    assert bool(ds.stable.all())
    # attractive van der Waals: Δf < 0, growing in magnitude towards the sample
    assert (np.diff(ds.frequency_shift.values) < 0).all()

    back = afmdyn.reconstruct(fm=ds)
    rec = cli_json("reconstruct", "--fm", tmp_path / "fm" / "fm.json", "--out", tmp_path / "r")
    assert back.force.values.tolist() == rec["force"]["force"]
    d = back.distance.values
    inside = (d >= 3 * 0.165e-9) & (d <= 5e-9)
    want = -6.6e-20 * 10e-9 / (6.0 * d[inside] ** 2)
    np.testing.assert_allclose(back.force.values[inside], want, rtol=0.02)
    # a constant given replaces the document's
    k2 = afmdyn.reconstruct(fm=ds, spring_constant=80.0)
    np.testing.assert_allclose(k2.force.values, 2 * back.force.values, rtol=1e-12)


def test_fm_temperature_equals_the_command_line(cli_json):
    # the loops' thermal noise (the library's linear response, tested there against a
    # simulated loop and Albrecht's formula) reaches the dataset as the command line's
    doc = cli_json("fm", "--probe", P1, "--points", "3", "--temperature", "295",
                   "--bandwidth", "50Hz", "--files", "none")
    ds = afmdyn.fm(probe=P1, points=3, temperature=295.0, bandwidth=50.0)
    assert afmdyn.summary(ds) == doc
    assert ds.frequency_shift_noise.values.tolist() == doc["curve"]["frequency_shift_noise"]
    assert ds.frequency_shift_noise.attrs["units"] == "Hz"
    assert doc["thermal"]["bandwidth"] == pytest.approx(50.0, rel=1e-12)
    assert "frequency_shift_noise" not in afmdyn.fm(probe=P1, points=3)
    with pytest.raises(ValueError, match="bandwidth"):
        afmdyn.fm(probe=P1, points=3, bandwidth=50.0)


def test_bad_fm_options_name_them():
    with pytest.raises(ValueError, match="amplitude"):
        afmdyn.fm(probe=P1, amplitude=-1e-9, points=3)
    with pytest.raises(ValueError, match="mode"):
        afmdyn.fm(probe=P1, mode=3, points=3)
    with pytest.raises(ValueError, match="tolerance"):
        afmdyn.fm(probe=P1, tolerance=0.0, points=3)
    with pytest.raises(TypeError, match="mode"):
        afmdyn.fm(probe=P1, mode=1.5, points=3)  # type: ignore[arg-type]
    plain = afmdyn.fm(points=3)
    assert plain.z_c.attrs["units"] == "g0"
    with pytest.raises(ValueError, match="SI"):
        afmdyn.reconstruct(fm=plain)
    with pytest.raises(ValueError, match="not both"):
        afmdyn.reconstruct(fm=plain, frequency_shift=[1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="spring_constant"):
        afmdyn.reconstruct(frequency_shift=[1.0, 2.0, 3.0], distance=[1.0, 2.0, 3.0])
    assert json.loads(plain.attrs["summary"])["mode"] == 1


def test_reconstruct_of_fm_carries_the_model_force_law():
    ds = afmdyn.fm(probe=P1, from_=30e-9, to=10.5e-9, step=0.1e-9)
    back = afmdyn.reconstruct(fm=ds)
    assert back.law.attrs["units"] == "N"
    d = back.distance.values
    outside = d > 0.165e-9
    # the law's force outside contact is the probe's van der Waals force, exactly
    np.testing.assert_allclose(back.law.values[outside], -6.6e-20 * 10e-9 / (6.0 * d[outside] ** 2),
                               rtol=1e-12)
    # and it is the fm dataset's law_force at its lower turning points, in increasing distance
    np.testing.assert_allclose(np.sort(ds.law_force.values), np.sort(back.law.values), rtol=0)


def test_reconstruct_of_an_am_approach_gives_the_force():
    ds = afmdyn.approach(probe=P1, from_=60e-9, to=3e-9, step=0.02e-9, branches=False)
    back = afmdyn.reconstruct(am=ds)
    doc = json.loads(back.attrs["summary"])
    assert doc["points"] > 2000 and "matrix method" in doc["method"]
    d = back.distance.values
    inside = (d >= 0.5e-9) & (d <= 5e-9)
    assert inside.sum() > 200
    want = -6.6e-20 * 10e-9 / (6.0 * d[inside] ** 2)
    np.testing.assert_allclose(back.force.values[inside], want, rtol=0.01)
    with pytest.raises(ValueError, match="constants"):
        afmdyn.reconstruct(am=ds, spring_constant=40.0)
