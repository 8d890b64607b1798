"""Issue 42's battery defects from Python: the same refusals as the command line, through the
library's request layer — numbers beyond a double as ``ValueError`` naming the keyword, a
chart's non-finite model values, integrator tolerances, bounded probe files."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import afmdyn

CHART = dict(x="omega", x_from=2.6, x_to=3.0, x_steps=2, y="drive_amplitude", y_from=0.1,
             y_to=0.12, y_steps=2, starts=2, progress=False)


@pytest.mark.parametrize("call", [
    lambda: afmdyn.attractors(cluster_tol=10**400, samples=2, progress=False),
    lambda: afmdyn.chart(**CHART, cluster_tol=10**400),
])
def test_a_float_keyword_beyond_a_double_is_a_value_error(call) -> None:
    with pytest.raises(ValueError, match="cluster_tol"):
        call()


def test_a_model_value_beyond_a_double_is_a_value_error() -> None:
    with pytest.raises(ValueError, match="contact_stiffness"):
        afmdyn.modes(contact_stiffness=10**400)


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf")])
def test_chart_refuses_non_finite_model_values(value: float) -> None:
    with pytest.raises(ValueError, match="contact_stiffness .*must be a finite number"):
        afmdyn.chart(**CHART, contact_stiffness=value)


@pytest.mark.parametrize("tol", [float("nan"), 0.0, -1.0, 1.0])
def test_integrator_tolerance_has_a_range_for_the_linear_law(tol: float) -> None:
    with pytest.raises(ValueError, match=r"tolerance.*\[1e-16, 1e-3\]"):
        afmdyn.simulate(periods=1, tolerance=tol, progress=False)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero")
def test_probe_file_without_end_is_refused() -> None:
    with pytest.raises(ValueError, match="/dev/zero: larger than"):
        afmdyn.modes(probe="/dev/zero")


def test_binary_probe_file_is_refused(tmp_path: Path) -> None:
    p = tmp_path / "bin.toml"
    p.write_bytes(b"a = \xff\n")
    with pytest.raises(ValueError, match="not UTF-8"):
        afmdyn.modes(probe=str(p))
