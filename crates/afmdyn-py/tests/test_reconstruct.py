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
    assert json.loads(afmdyn.reconstruct(**c, **CONSTANTS).attrs["summary"])["warnings"]
