"""attractors(), orbit(), lyapunov(): to_dict() equals the command line's --json for the same
arguments; closed forms (Floquet multipliers = eigenvalues of the monodromy matrix, Liouville,
a linear system's exponents); handoffs between them; errors."""

from __future__ import annotations

import numpy as np
import pytest

import afmdyn


@pytest.fixture(scope="module")
def att28():
    return afmdyn.attractors(omega=2.8, samples=6)


def test_attractors_to_dict_is_the_command_lines_document(att28, cli_json, tmp_path):
    assert att28.to_dict() == cli_json(
        "attractors", "--omega", 2.8, "--samples", 6, "--out", tmp_path
    )
    a = afmdyn.attractors(omega=3.2, samples=5, seed=7, cluster_tol=1e-4)
    assert a.to_dict() == cli_json(
        "attractors",
        "--omega",
        3.2,
        "--samples",
        5,
        "--seed",
        7,
        "--cluster-tol",
        1e-4,
        "--out",
        tmp_path,
    )


def test_attractor_objects(att28):
    assert len(att28) == 1 and att28.samples == 6 and att28.failures == []
    a = att28[0]
    assert a.period == 2 and a.periodic and a.count == 6 and a.basin_fraction == 1.0
    assert a.section_state.shape == (2, 6) and a.section_state.dtype == np.float64
    assert a.initial.shape == (6,) and a.state.shape == (6,)
    assert a.section_w_tip.shape == a.section_v_t.shape == a.section_tau.shape == (2,)
    # section points at drive phase 0: τ = 2πk/Ω and V_T = W(1,τ) + α5
    np.testing.assert_allclose(
        a.section_tau * 2.8 / (2 * np.pi), np.round(a.section_tau * 2.8 / (2 * np.pi)), atol=1e-9
    )
    np.testing.assert_allclose(a.section_v_t, a.section_w_tip, atol=1e-12)
    assert a.x_max >= a.section_w_tip.max() and a.x_min <= a.section_w_tip.min()
    assert a.to_dict() == att28.to_dict()["attractors"][0]
    df = att28.to_dataframe()
    assert df.loc[1, "period"] == 2 and df.loc[1, "basin_fraction"] == 1.0
    assert "period-2" in repr(att28)
    assert sum(x.basin_fraction for x in att28) == pytest.approx(1.0)


def test_attractor_handoff_to_orbit_matches_the_command_line(att28, cli_json):
    a = att28[0]
    o = a.orbit()
    # what the command line does with the attractor's initial_modal string
    ref = cli_json(
        "orbit", "--omega", 2.8, "--period", 2, "--initial-modal", a.to_dict()["initial_modal"]
    )
    assert o.to_dict() == ref
    assert o.stable and o.period == 2
    # the orbit found by shooting is the attractor: same section points (in some order)
    for w in o.poincare_w_tip:
        assert np.min(np.abs(a.section_w_tip - w)) < 1e-6
    ts = a.simulate(samples_per_period=50)
    assert ts.sizes["tau"] == 2 * 50 + 1
    np.testing.assert_allclose(ts.w_tip.values[0], a.section_w_tip[0], atol=1e-15)


def test_orbit_default_start_and_closed_forms(cli_json):
    o = afmdyn.orbit(omega=2.8)
    assert o.to_dict() == cli_json("orbit", "--omega", 2.8)
    assert o.monodromy.shape == (6, 6) and o.monodromy.dtype == np.float64
    assert o.multipliers.dtype == np.complex128 and o.multipliers.shape == (6,)
    # Floquet multipliers are the eigenvalues of the monodromy matrix (a C-ordered copy of it)
    ev = np.linalg.eigvals(o.monodromy)
    for mu in o.multipliers:
        assert np.min(np.abs(ev - mu)) < 1e-10
    assert np.all(np.diff(np.abs(o.multipliers)) <= 1e-12)
    np.testing.assert_array_equal(o.section[0], o.state)
    assert o.section.shape == (2, 6)
    assert o.newton_residuals[-1] < 1e-9
    assert o.critical in {"fold", "period-doubling", "neimark-sacker"}
    assert "period-2" in repr(o)


def test_an_unstable_orbit_in_the_chaotic_regime(cli_json):
    # Ω = 2.6 is chaotic; the period-1 orbit there is unstable by a flip (docs/paper-reproduction.md)
    o = afmdyn.orbit(omega=2.6, period=1)
    assert o.to_dict() == cli_json("orbit", "--omega", 2.6, "--period", 1)
    assert not o.stable and o.critical == "period-doubling"
    assert o.multipliers[0].real == pytest.approx(-1.392, abs=1e-3)


def test_orbit_errors():
    with pytest.raises(ValueError, match="period = 0"):
        afmdyn.orbit(period=0)
    with pytest.raises(ValueError, match="period = 65"):
        afmdyn.orbit(period=65)
    with pytest.raises(ValueError, match="initial.*expected 6 values, got 4"):
        afmdyn.orbit(initial=[0.0] * 4)
    with pytest.raises(ValueError, match="tol"):
        afmdyn.orbit(tol=-1.0)


def test_attractor_errors():
    with pytest.raises(ValueError, match="samples = 0"):
        afmdyn.attractors(samples=0)
    with pytest.raises(ValueError, match="cluster_tol = 0"):
        afmdyn.attractors(samples=2, cluster_tol=0.0)
    with pytest.raises(ValueError, match="max_period = 0"):
        afmdyn.attractors(samples=2, max_period=0)
    with pytest.raises(ValueError, match="seed = -1"):
        afmdyn.attractors(samples=2, seed=-1)


def test_lyapunov_to_dict_and_liouville(cli_json):
    args = dict(omega=3.5, transient=100, periods=300, blocks=3)
    ly = afmdyn.lyapunov(**args)
    assert ly.to_dict() == cli_json(
        "lyapunov", "--omega", 3.5, "--transient", 100, "--periods", 300, "--blocks", 3
    )
    assert ly.exponents.dtype == np.float64 and ly.exponents.shape == (6,)
    assert ly.uncertainty.shape == (6,)
    assert ly.verdict == "periodic" and ly.periods == 300
    assert ly.exponents.sum() == pytest.approx(ly.volume_rate, abs=1e-9)  # Liouville


def test_lyapunov_of_a_linear_system():
    # α1 = 0 and a gap the tip never closes: M = I, C = α3 I, every exponent is −α3/2 and the
    # phase volume contracts at −N α3
    ly = afmdyn.lyapunov(
        modes=2, alpha1=0, beam_damping=0.1, gap=100, transient=10, periods=200, blocks=4
    )
    assert ly.volume_rate == pytest.approx(-0.2, abs=1e-12)
    np.testing.assert_allclose(ly.exponents, -0.05, atol=0.01)
    assert ly.exponents.mean() == pytest.approx(-0.05, abs=1e-12)
    assert ly.verdict == "periodic"


def test_lyapunov_from_an_attractor_and_errors(att28):
    ly = afmdyn.lyapunov(att28[0].params, initial=att28[0], transient=0, periods=100, blocks=2)
    assert ly.exponents[0] < 0
    with pytest.raises(ValueError, match="blocks = 10 with periods = 1: need periods >= blocks >= 2"):
        afmdyn.lyapunov(periods=1, blocks=10)
    with pytest.raises(ValueError, match="blocks = -2"):
        afmdyn.lyapunov(blocks=-2)


def test_counted_analyses_report_their_progress():
    """The library counts the units of work of a run (random starts, curve points, periods,
    mode counts) and the callback sees the count and its total."""
    calls = []
    afmdyn.attractors(samples=4, progress=lambda d, t: calls.append((d, t)))
    assert calls[-1] == (4, 4)
    calls.clear()
    afmdyn.lyapunov(transient=10, periods=40, blocks=4, progress=lambda d, t: calls.append((d, t)))
    assert calls[-1] == (50, 50)
    calls.clear()
    afmdyn.approach(points=5, branches=False, progress=lambda d, t: calls.append((d, t)))
    assert calls[-1] == (10, 10)  # approach and retract
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)
