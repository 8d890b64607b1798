"""reconstruct(): the dataset equals the command line's ``afmdyn reconstruct --json`` on the
example curve (examples/fm-vdw.csv: a van der Waals force shifted by Giessibl's relation,
scripts/fm-example.py), gives the force back within 1 % where A >= 2d, and refuses bad
curves naming the field."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import afmdyn
from conftest import EXAMPLES

FM = EXAMPLES / "fm-vdw.csv"
CONSTANTS = dict(spring_constant=40.0, resonance_frequency=3e5, amplitude=1e-8)


def _curve() -> dict:
    with open(FM, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in ("distance", "frequency_shift")}


def test_reconstruct_equals_the_command_line(cli_json, tmp_path):
    doc = cli_json("reconstruct", "--fm", FM, "--spring-constant", 40, "--resonance-frequency",
                   "300kHz", "--amplitude", "10nm", "--out", tmp_path)
    ds = afmdyn.reconstruct(**_curve(), **CONSTANTS)
    assert ds.force.values.tolist() == doc["force"]["force"]
    assert ds.potential.values.tolist() == doc["force"]["potential"]
    assert afmdyn.summary(ds) == {k: v for k, v in doc.items() if k != "csv"}
    assert ds.force.attrs["units"] == "N" and ds.distance.attrs["units"] == "m"
    d = ds.distance.values
    near = d <= 5e-9
    want = -1e-19 * 1e-8 / (6.0 * d[near] ** 2)
    np.testing.assert_allclose(ds.force.values[near], want, rtol=0.01)
    # z_c = d + A, in the approach's order (decreasing): the same reconstruction
    c = _curve()
    back = afmdyn.reconstruct(z_c=(c["distance"] + 1e-8)[::-1],
                              frequency_shift=c["frequency_shift"][::-1], **CONSTANTS)
    np.testing.assert_allclose(back.force.values, ds.force.values, rtol=1e-12)


def test_bad_curves_name_the_field():
    c = _curve()
    with pytest.raises(ValueError, match="amplitude"):
        afmdyn.reconstruct(**c, **{**CONSTANTS, "amplitude": -1.0})
    with pytest.raises(ValueError, match="frequency_shift"):
        afmdyn.reconstruct(distance=c["distance"], frequency_shift=c["frequency_shift"][:-1],
                           **CONSTANTS)
    with pytest.raises(ValueError, match="distance"):
        afmdyn.reconstruct(**c, z_c=c["distance"], **CONSTANTS)
    with pytest.raises(TypeError):
        afmdyn.reconstruct(**c, **CONSTANTS, spring=1.0)  # type: ignore[call-arg]
    # the example reaches 60 nm, where |Δf| is 5e-5 of its extreme: no truncation warning
    assert json.loads(afmdyn.reconstruct(**c, **CONSTANTS).attrs["summary"])["warnings"] == []
    # constants outside their physical range (10 m: nm given as m; 1e300), named
    for bad in (10.0, 1e300, -1e-8):
        with pytest.raises(ValueError, match="amplitude = .*: must be"):
            afmdyn.reconstruct(**c, **{**CONSTANTS, "amplitude": bad})


def test_a_likely_unit_slip_and_a_truncated_curve_warn():
    """k = 4e7 (N/m, meant mN/m) runs with an AfmdynWarning naming the slip, in the summary
    too; f0 = 300 (Hz, meant kHz) is below any lever and refused, as in a probe file; a curve
    that ends at 2 nm, where |Δf| is still a tenth of its extreme, warns of the truncation."""
    c = _curve()
    with pytest.warns(afmdyn.AfmdynWarning, match=r"spring_constant = 40000000 N/m .* mN/m"):
        ds = afmdyn.reconstruct(**c, **{**CONSTANTS, "spring_constant": 4e7})
    assert "mN/m" in json.loads(ds.attrs["summary"])["warnings"][0]
    with pytest.raises(ValueError, match="resonance_frequency = 300 Hz: below 1 kHz"):
        afmdyn.reconstruct(**c, **{**CONSTANTS, "resonance_frequency": 300.0})
    near = c["distance"] <= 2e-9
    with pytest.warns(afmdyn.AfmdynWarning, match="frequency shift at the largest distance"):
        afmdyn.reconstruct(distance=c["distance"][near],
                           frequency_shift=c["frequency_shift"][near], **CONSTANTS)


def test_a_uniform_grid_is_inverted_as_the_uneven_one_would_be():
    """The example interpolated onto an even grid of 10^5 points (inverted by FFT) gives
    −HR/(6d²) back within 2 % from 0.4 to 5 nm (A >= 2d); an uneven grid of more than 20 000
    points is refused, naming distance and the limit."""
    c = _curve()
    d = np.linspace(c["distance"][0], c["distance"][-1], 100_000)
    df = np.interp(np.log(d), np.log(c["distance"]), c["frequency_shift"])
    ds = afmdyn.reconstruct(distance=d, frequency_shift=df, **CONSTANTS)
    near = (d <= 5e-9) & (d >= 4e-10)
    want = -1e-19 * 1e-8 / (6.0 * d[near] ** 2)
    np.testing.assert_allclose(ds.force.values[near], want, rtol=0.02)
    uneven = np.geomspace(3e-10, 6e-8, 20_001)
    with pytest.raises(ValueError, match="distance = 20001 values.*at most 20000"):
        afmdyn.reconstruct(distance=uneven, frequency_shift=-1.0 / uneven, **CONSTANTS)
