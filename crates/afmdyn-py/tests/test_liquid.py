"""A lever in water from Python (probe ``[medium]``, ``medium=`` as ``--medium``): the same
document as the command line, the wet modes in ``si``, the higher modes' share of the motion
on every point, and bad names refused."""

import json
import pathlib

import pytest

import afmdyn

ROOT = pathlib.Path(__file__).resolve().parents[3]
WATER = ROOT / "examples" / "probe-water-beam.toml"


def test_medium_keyword_is_the_command_lines(cli_json):
    """``medium="air"`` over the water example is ``--medium air``: the same si block, and the
    wet first mode below the one in air (Sader 1998: added mass), with a Q of a few in water."""
    water = afmdyn.probe(WATER)
    air = afmdyn.probe(WATER, medium="air")
    assert air["si"] == cli_json("units", "--probe", WATER, "--medium", "air")["si"]
    mw, ma = water["si"]["medium"], air["si"]["medium"]
    assert mw["name"] == "water" and ma["name"] == "air"
    assert mw["resonance_frequency"] < 0.5 * ma["resonance_frequency"]
    assert 1.0 < mw["quality_factor"] < 10.0 < ma["quality_factor"]
    # the lever's own values are the same in both
    assert mw["vacuum_resonance_frequency"] == pytest.approx(ma["vacuum_resonance_frequency"])
    none = afmdyn.probe(WATER, medium="none")
    assert "medium" not in none["si"]


def test_modes_report_wet_frequencies_and_quality_factors(cli_json):
    """``modes --json`` under a probe in water: one frequency and one Q per mode, the first the
    medium block's."""
    d = cli_json("modes", "--probe", WATER)
    si = d["si"]
    assert len(si["free_frequencies_hz"]) == len(si["quality_factors"]) == 3
    assert si["free_frequencies_hz"][0] == pytest.approx(si["medium"]["resonance_frequency"])
    assert si["quality_factors"][0] == pytest.approx(si["medium"]["quality_factor"])
    assert si["quality_factors"] == sorted(si["quality_factors"])


def test_approach_in_water_reports_the_higher_modes():
    """Every point of an approach in water carries ``higher_mode_fraction`` (as the command
    line's column); it grows as the tip taps harder. (Water against air at one setpoint:
    ``crates/afmdyn/tests/liquid.rs``.)"""
    ds = afmdyn.approach(probe=WATER, points=12, branches=False)
    f = ds["higher_mode_fraction"].sel(sweep="approach").values
    assert (f > 0).all()
    assert f[-1] > 1.5 * f[0]
    summary = json.loads(ds.attrs["summary"])
    assert summary["si"]["medium"]["name"] == "water"
    air = afmdyn.approach(probe=WATER, medium="air", points=12, branches=False)
    assert json.loads(air.attrs["summary"])["si"]["medium"]["name"] == "air"


def test_bad_medium_is_refused():
    with pytest.raises(ValueError, match="medium"):
        afmdyn.probe(WATER, medium="oil")
    with pytest.raises(ValueError, match="needs probe"):
        afmdyn.orbit(medium="water")
    with pytest.raises(TypeError, match="medium"):
        afmdyn.probe(WATER, medium=1)
