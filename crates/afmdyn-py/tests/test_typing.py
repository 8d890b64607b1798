"""The package is typed (py.typed, _afmdyn.pyi, PEP 692 keywords): mypy accepts correct use
and flags a wrong keyword or type, as an editor would."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import afmdyn

from conftest import REPO

# kept between runs (numpy, pandas and xarray take most of mypy's time)
CACHE = REPO / "target" / "mypy-cache"

GOOD = """
import numpy as np
import afmdyn

p = afmdyn.Params(omega=2.8, contact_stiffness=20.0)
ds = afmdyn.simulate(p, periods=3, transient=1.0, samples_per_period=50)
o: afmdyn.Orbit = afmdyn.orbit(p, period=2)
mu: np.ndarray = o.multipliers
atts = afmdyn.attractors(omega=2.8, samples=4)
first: afmdyn.Attractor = atts[0]
n: int = p.modes
doc: dict = afmdyn.lyapunov(alpha1=0.0, periods=10, blocks=2).to_dict()
"""

BAD = """
import afmdyn

afmdyn.simulate(omega="fast")
afmdyn.bifurcation(omegaa=2.0)
afmdyn.Params(modes=2).omega = 3.0
"""


def _mypy(tmp_path: Path, code: str) -> subprocess.CompletedProcess:
    f = tmp_path / "snippet.py"
    f.write_text(textwrap.dedent(code))
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "mypy",
            "--strict",
            "--allow-any-generics",
            "--cache-dir",
            str(CACHE),
            str(f),
        ],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )


def test_package_ships_type_information():
    pkg = Path(afmdyn.__file__).parent
    assert (pkg / "py.typed").exists() and (pkg / "_afmdyn.pyi").exists()


def test_mypy_accepts_correct_use_and_flags_mistakes(tmp_path):
    pytest.importorskip("mypy")
    good = _mypy(tmp_path, GOOD)
    assert good.returncode == 0, good.stdout
    bad = _mypy(tmp_path, BAD)
    assert bad.returncode == 1
    assert (
        'Argument "omega" to "simulate" has incompatible type "str"; expected "float"' in bad.stdout
    )
    assert 'Unexpected keyword argument "omegaa" for "bifurcation"' in bad.stdout
    assert 'Property "omega" defined in "Params" is read-only' in bad.stdout


def test_the_request_stubs_are_generated_from_the_schemas() -> None:
    """The requests' TypedDicts and the compiled functions in ``_afmdyn.pyi`` are what
    ``scripts/gen_stubs.py`` writes from ``docs/schema/requests`` (the library's request
    types): a stub left stale after a request changed fails here."""
    script = REPO / "scripts" / "gen_stubs.py"
    run = subprocess.run([sys.executable, str(script), "--check"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    # the installed stub is the repository's
    installed = Path(afmdyn.__file__).parent / "_afmdyn.pyi"
    source = REPO / "crates" / "afmdyn-py" / "python" / "afmdyn" / "_afmdyn.pyi"
    assert installed.read_text() == source.read_text(), "reinstall the package (pip install)"


def test_the_defaults_are_the_requests() -> None:
    """Every keyword default of an analysis that the request holds is the request's
    ``Default`` (``request_defaults``): one signature, no literals in the front end."""
    import inspect

    from afmdyn import _afmdyn as core

    for fn, name in [(afmdyn.simulate, "simulate"), (afmdyn.bifurcation, "bifurcation"),
                     (afmdyn.attractors, "attractors"), (afmdyn.lyapunov, "lyapunov"),
                     (afmdyn.resonance, "resonance"), (afmdyn.basins, "basins"),
                     (afmdyn.global_continuation, "global_continuation"), (afmdyn.chart, "chart")]:
        d = core.request_defaults(name)
        for key, prm in inspect.signature(fn).parameters.items():
            k = "from" if key == "from_" else key
            if k in d and d[k] is not None and prm.default is not None:
                assert prm.default == d[k], (name, key)
