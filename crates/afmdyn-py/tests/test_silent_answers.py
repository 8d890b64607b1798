"""Issue 60, part A, in Python: the same refusals, reductions and warnings as the command line
(crates/afmdyn-cli/tests/silent_answers.rs), through the one library route."""

import pathlib

import pytest

import afmdyn

EXAMPLES = pathlib.Path(__file__).parents[3] / "examples"


def test_modes_on_a_lumped_probe_are_the_probes() -> None:
    probe = str(EXAMPLES / "probe-eigenmodes-dmt.toml")
    with pytest.raises(ValueError, match="eigenmodes model has 2 mode"):
        afmdyn.modes(probe=probe, modes=3)
    with pytest.raises(ValueError, match="point-mass model has 1 mode"):
        afmdyn.modes(probe=str(EXAMPLES / "probe-point-mass-dmt.toml"), modes=2)
    # the probe's own two modes (its file: 300 kHz and 1.88 MHz), with or without modes=2
    same = afmdyn.modes(probe=probe, modes=2).to_dict()
    assert same == afmdyn.modes(probe=probe).to_dict()
    f = same["si"]["free_frequencies_hz"]
    assert f == pytest.approx([300e3, 1.88e6], rel=1e-9)


def test_a_typical_range_slip_warns_and_a_physical_one_is_refused(tmp_path: pathlib.Path) -> None:
    text = (EXAMPLES / "probe-capillary-humid.toml").read_text()
    assert "surface_tension = 0.072" in text
    slip = tmp_path / "slip.toml"
    slip.write_text(text.replace("surface_tension = 0.072", "surface_tension = 72.0"))
    with pytest.raises(ValueError, match="mN/m"):
        afmdyn.orbit(probe=str(slip))
    odd = tmp_path / "odd.toml"
    odd.write_text(text.replace("surface_tension = 0.072", "surface_tension = 0.8"))
    with pytest.warns(afmdyn.AfmdynWarning, match=r"surface_tension = 0\.8 \(N/m\) is outside"):
        afmdyn.approach(probe=str(odd), points=6)


def test_an_image_beyond_its_memory_budget_is_refused_before_any_work() -> None:
    # issue 60 item 6: 2048 x 2048 pixels aborted with a PanicException on allocation
    with pytest.raises(ValueError, match=r"2048 × 2048 pixels.*GiB"):
        afmdyn.image(
            probe=str(EXAMPLES / "probe-point-mass-dmt.toml"),
            sample=str(EXAMPLES / "sample-blend.toml"),
            setpoint=0.7,
            pixels=2048,
        )
