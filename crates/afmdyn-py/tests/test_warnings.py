"""A computed answer with a caveat: the command line prints ``afmdyn: warning: …`` on stderr and
lists it in the summary's ``warnings``; Python issues the same lines as ``AfmdynWarning``."""

import warnings

import pytest

import afmdyn


def test_a_caveat_is_an_afmdyn_warning_and_in_the_summary() -> None:
    # 400 RK4 steps per period do not close the energy balance to 1e-6 (the coarse run of
    # test_simulate.py; audited when asked for): the answer is returned, with a warning
    with pytest.warns(afmdyn.AfmdynWarning, match="energy balance") as caught:
        a = afmdyn.simulate(
            periods=2,
            integrator="rk4",
            steps_per_period=400,
            samples_per_period=20,
            energy_balance=True,
        )
    lines = afmdyn.summary(a)["warnings"]
    assert lines and [str(w.message) for w in caught] == lines
    assert issubclass(afmdyn.AfmdynWarning, UserWarning)


def test_no_caveat_no_warning() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error", afmdyn.AfmdynWarning)
        a = afmdyn.simulate(periods=2, samples_per_period=20)
    assert afmdyn.summary(a)["warnings"] == []


def test_an_unsettled_census_warns_and_keeps_unsettled_ends_apart() -> None:
    # a Q = 500 lever cut off after 300 drive periods: every start is still converging; the
    # ends that are provably so are listed apart, the rest carry λ₁, and a warning names the cap
    import pathlib

    probe = pathlib.Path(__file__).parents[3] / "examples" / "probe-rtespa300-polystyrene.toml"
    with pytest.warns(afmdyn.AfmdynWarning, match="300 drive periods"):
        a = afmdyn.attractors(probe=str(probe), z_c=14.3e-9, samples=6, max_periods=300)
    doc = a.to_dict()
    assert doc["transient_cap"] == 300
    assert doc["warnings"]
    # every start is accounted for: an attractor's (by fraction) or an unsettled end
    unsettled = sum(x["count"] for x in doc["unsettled"])
    assert unsettled <= 6
    for x in doc["attractors"]:
        assert x["period"] is not None or "lyapunov" in x
