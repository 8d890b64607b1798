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
