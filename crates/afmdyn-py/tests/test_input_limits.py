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


# Issue 59 (Deliver 2): every file-taking keyword reads through the library's bounded reader —
# /dev/zero (no end, no line end) and a 2 GiB sparse file are refused at once with a ValueError
# naming the file, never read on or held whole.
REPO = Path(__file__).resolve().parents[3]
PROBE = str(REPO / "examples" / "probe-point-mass-dmt.toml")


def _input(tmp_path: Path, name: str, kind: str) -> str:
    """``/dev/zero`` (as a symbolic link, keeping the extension) or a 2 GiB sparse file."""
    p = tmp_path / name
    if p.is_symlink() or p.exists():
        p.unlink()
    if kind == "zero":
        p.symlink_to("/dev/zero")
    else:
        with open(p, "wb") as f:
            f.truncate(2 << 30)
    return str(p)


KINDS = [pytest.param("zero", marks=pytest.mark.skipif(not os.path.exists("/dev/zero"),
                                                       reason="no /dev/zero")), "sparse"]


@pytest.mark.parametrize("kind", KINDS)
def test_every_file_keyword_refuses_endless_and_huge_files(tmp_path: Path, kind: str) -> None:
    probe = _input(tmp_path, "p.toml", kind)
    with pytest.raises(ValueError, match="larger than 1048576 bytes"):
        afmdyn.modes(probe=probe)
    with pytest.raises(ValueError, match="larger than 1048576 bytes"):
        afmdyn.image(probe=PROBE, sample=probe, setpoint=0.7)
    for ext, cap in [("csv", "1048576 bytes|536870912 bytes"),
                     ("npy", "not an NPY file|134283276 bytes")]:
        heights = _input(tmp_path, f"h.{ext}", kind)
        with pytest.raises(ValueError, match=cap):
            afmdyn.image(probe=PROBE, sample="size = [1e-6, 0]\n", setpoint=0.7,
                         height_map=heights)


SWEEP = dict(from_=2.4, to=2.9, steps=2, starts=0, max_periods=100, threads=1, progress=False)
CHART_STORE = dict(x="omega", x_from=2.6, x_to=3.0, x_steps=2, y="drive_amplitude",
                   y_from=0.1, y_to=0.12, y_steps=1, starts=1, tile=1, lyapunov_periods=20,
                   progress=False)


def _snapshot(store: Path) -> list:
    """Every file of the store but its lock: name and link target, length or bytes."""
    out = []
    for p in sorted(store.iterdir()):
        if p.name == ".afmdyn.lock":
            continue
        if p.is_symlink():
            out.append((p.name, os.readlink(p)))
        elif p.stat().st_size > 1 << 20:
            out.append((p.name, p.stat().st_size))
        else:
            out.append((p.name, p.read_bytes()))
    return out


@pytest.mark.parametrize("kind", KINDS)
def test_a_resumed_store_refuses_endless_and_huge_files_and_keeps_them(tmp_path: Path,
                                                                        kind: str) -> None:
    sweep = tmp_path / "sweep"
    afmdyn.bifurcation(**SWEEP, store=str(sweep))
    chart = tmp_path / "chart"
    afmdyn.chart(**CHART_STORE, store=str(chart))

    def resume_sweep() -> None:
        afmdyn.bifurcation(**SWEEP, store=str(sweep), resume=True)

    def resume_chart() -> None:
        afmdyn.chart(**CHART_STORE, store=str(chart), resume=True)

    cases = [(sweep, ".bifurcation.run.json", resume_sweep),
             (sweep, "bifurcation.csv", resume_sweep),
             (chart, ".chart.run.json", resume_chart),
             (chart, ".chart.tiles.jsonl", resume_chart)]
    for store, name, call in cases:
        saved = (store / name).read_bytes()
        _input(store, name, kind)
        before = _snapshot(store)
        with pytest.raises(ValueError, match=f"{name}.*(bytes|NUL)"):
            call()
        assert _snapshot(store) == before, f"{name}: the refused resume changed the store"
        (store / name).unlink()
        (store / name).write_bytes(saved)
