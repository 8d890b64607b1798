"""Issue 60, part D, in Python: a bad value is refused with a message that names the keyword
and what it must be, and an array of the wrong kind is refused, not coerced (a complex height
map lost its imaginary part with a mere NumPy warning; a 2-D shift curve was flattened)."""

import pathlib
import numpy as np
import pytest

import afmdyn

EXAMPLES = pathlib.Path(__file__).parents[3] / "examples"


def test_a_negative_count_names_its_keyword() -> None:
    # it said "fm: invalid value: integer `-1`, expected usize"; the keyword, its value and
    # the range, as the other counts (the library's request::keywords)
    with pytest.raises(ValueError, match=r"fm: mode = -1: must be >= 0"):
        afmdyn.fm(mode=-1)


def test_a_probe_dict_holding_nan_names_the_key() -> None:
    # it said "not a probe table (expected value at line 1 column 66)": JSON has no NaN
    table = {
        "model": "point-mass",
        "cantilever": {"spring_constant": float("nan"), "resonance_frequency": 300e3,
                       "quality_factor": 400},
        "tip": {"radius": 10e-9, "youngs_modulus": 130e9, "poisson_ratio": 0.27},
        "sample": {"law": "dmt", "youngs_modulus": 4e9, "poisson_ratio": 0.33,
                   "hamaker": 6.6e-20, "intermolecular_distance": 0.165e-9, "z_c": 8e-9},
        "drive": {"free_amplitude": 10e-9, "frequency": 300e3},
    }
    with pytest.raises(ValueError, match="spring_constant") as e:
        afmdyn.orbit(probe=table)
    assert "line 1 column" not in str(e.value)
    # the same dict without the NaN is a probe: the route itself works
    table["cantilever"]["spring_constant"] = 40.0
    assert afmdyn.orbit(probe=table).to_dict()["si"]


def test_a_complex_height_map_is_refused() -> None:
    probe = str(EXAMPLES / "probe-point-mass-dmt.toml")
    sample = str(EXAMPLES / "sample-stripe.toml")
    with pytest.raises(ValueError, match="height_map: must be real numbers"):
        afmdyn.image(probe=probe, sample=sample, setpoint=0.8, height_map=np.ones((4, 4)) * (1 + 1j) * 1e-9)
    with pytest.raises(ValueError, match="height_map: must be a 2D array"):
        afmdyn.image(probe=probe, sample=sample, setpoint=0.8, height_map=np.ones(4) * 1e-9)


def test_reconstruct_refuses_arrays_that_are_not_curves() -> None:
    d = np.linspace(0.3e-9, 5e-9, 40)
    shift = -10.0 / (d / 1e-9) ** 2
    common = dict(spring_constant=40.0, resonance_frequency=300e3, amplitude=10e-9)
    with pytest.raises(ValueError, match="frequency_shift: must be a 1D array, got 2D"):
        afmdyn.reconstruct(frequency_shift=shift.reshape(2, 20), distance=d, **common)
    with pytest.raises(ValueError, match="distance: must be real numbers"):
        afmdyn.reconstruct(frequency_shift=shift, distance=d + 0j, **common)
    # the same curve as 1-D arrays is reconstructed
    ds = afmdyn.reconstruct(frequency_shift=shift, distance=d, **common)
    assert ds.sizes["distance"] > 0


def test_a_setpoint_study_is_capped_as_on_the_command_line() -> None:
    # the command line capped FROM:TO:N at 1000 ratios; Python took 1001
    probe = str(EXAMPLES / "probe-point-mass-dmt.toml")
    sample = str(EXAMPLES / "sample-stripe.toml")
    with pytest.raises(ValueError, match="at most 1000 ratios"):
        afmdyn.setpoint_study(probe, sample, np.linspace(0.2, 0.9, 1001))
