"""Python arguments convert one way (issue 77 §6): a keyword that takes an SI value with a probe
takes a number or text with a unit ('95nm', read by the library as the command line reads
``--z-c 95nm``), never a string read as its characters; a wrong type is a ``TypeError``
naming the keyword, before any work — on every analysis the request schemas generate,
PeakForce, fit and reconstruct included."""

from __future__ import annotations

import json

import numpy as np
import pytest

import afmdyn
from conftest import EXAMPLES

AIR = str(EXAMPLES / "probe-peakforce-air.toml")
FIT_PROBE = str(EXAMPLES / "probe-fit-hertz.toml")
FIT_CURVE = str(EXAMPLES / "force-curve-hertz.csv")
FM_CURVE = dict(distance=np.linspace(1e-9, 2e-8, 40),
                frequency_shift=-50.0 * np.exp(-np.linspace(1e-9, 2e-8, 40) / 2e-9))
CONSTANTS = dict(spring_constant=40.0, resonance_frequency=3e5, amplitude=1e-8)


def test_text_with_a_unit_is_the_si_value_the_command_line_reads(cli_json, tmp_path):
    doc = cli_json("peakforce", "--probe", AIR, "--z-c", "95nm", "--out", tmp_path / "pf")
    for z_c in ("95nm", "95 nm", "0.095um", ["95nm"]):
        ds = afmdyn.peakforce(probe=AIR, z_c=z_c)
        channels = json.loads(ds.attrs["summary"])["channels"]
        assert channels == doc["channels"], z_c
    # a reconstruction's constants in SI: 300kHz is 3e5 Hz, 10 nm is 1e-8 m
    a = afmdyn.reconstruct(**FM_CURVE, **CONSTANTS)
    b = afmdyn.reconstruct(**FM_CURVE, spring_constant=40.0, resonance_frequency="300kHz",
                           amplitude="10nm")
    assert a.force.values.tolist() == b.force.values.tolist()


@pytest.mark.parametrize(
    "call, needle",
    [
        # a unit of another dimension, or a unit where the value is dimensionless
        (lambda: afmdyn.peakforce(probe=AIR, z_c="95Hz"),
         r"z_c: the unit makes it a frequency \(Hz\), but z_c takes a length \(m\)"),
        (lambda: afmdyn.peakforce(probe=AIR, setpoint="2nm"),
         r"setpoint: the unit makes it a length \(m\), but setpoint takes a force \(N\)"),
        (lambda: afmdyn.peakforce(z_c="95nm"),
         r"z_c: a value with a unit needs probe= \(without one, z_c is dimensionless"),
        (lambda: afmdyn.peakforce(probe=AIR, z_c="95 parsecs"), r"z_c = '95 parsecs': expected a number"),
    ],
)
def test_a_wrong_unit_is_a_value_error_naming_the_keyword(call, needle):
    with pytest.raises(ValueError, match=needle):
        call()


@pytest.mark.parametrize(
    "call, needle",
    [
        # the battery's cases: each was accepted, iterated or converted silently
        (lambda: afmdyn.fit(probe=FIT_PROBE, data=FIT_CURVE, approach_rows=1.5),
         r"fit\(\): approach_rows must be an integer or None, got float 1.5"),
        (lambda: afmdyn.fit(probe=FIT_PROBE, data=5),
         r"fit\(\): data must be a path, a mapping of columns .* got int 5"),
        (lambda: afmdyn.reconstruct(**FM_CURVE, **{**CONSTANTS, "spring_constant": "40"}),
         r"reconstruct\(\): spring_constant must be a number or None, got str '40'"),
        (lambda: afmdyn.reconstruct(**FM_CURVE, **CONSTANTS, inversion=None),
         r"reconstruct\(\): inversion must be a string, got NoneType None"),
        # a number as text for an SI keyword: give the number, or a unit
        (lambda: afmdyn.peakforce(probe=AIR, z_c="95"),
         r"z_c: must be a number, or text with a unit of a length \(m\) such as '95nm'"),
        # never a string read as its characters
        (lambda: afmdyn.fit(probe=FIT_PROBE, data=FIT_CURVE, fit="E"),
         r"fit\(\): fit must be a sequence of names such as \['E'\] or None, got str 'E'"),
        (lambda: afmdyn.reconstruct(distance="1nm", frequency_shift=[-1.0], **CONSTANTS),
         r"reconstruct\(\): distance must be a sequence of numbers or None, got str '1nm'"),
        (lambda: afmdyn.peakforce(probe=AIR, z_c=[95e-9, None]),
         r"peakforce\(\): z_c must be a sequence of numbers, or a number or None, got an item "
         r"NoneType None"),
        (lambda: afmdyn.peakforce(probe=AIR, z_c=95e-9, fit_band=np.array(["a", "b"])),
         r"peakforce\(\): fit_band must be a sequence of numbers or None, got an array of <U1"),
    ],
)
def test_a_wrong_type_is_a_type_error_naming_the_keyword(call, needle):
    with pytest.raises(TypeError, match=needle):
        call()
