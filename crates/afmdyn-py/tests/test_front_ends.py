"""The command line and Python are two spellings of one request layer (the library's
``afmdyn::request``): for every analysis the same arguments give the same document
(``to_dict()`` equal to ``--json`` after sorting keys, SI inputs from a probe file included), and
the same bad value is refused with the same message, the parameter spelled the front end's way
(``--samples-per-period`` / ``samples_per_period``).

The reference is the ``afmdyn`` binary of the same checkout."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any, Callable, Dict, List

import pytest
import xarray as xr

import afmdyn

REPO = Path(__file__).resolve().parents[3]
PM = str(REPO / "examples" / "probe-point-mass-dmt.toml")
BEAM = str(REPO / "examples" / "probe-geometry-hertz.toml")


def _sorted(doc: Any) -> str:
    return json.dumps(doc, sort_keys=True)


def _doc(result: Any) -> Dict[str, Any]:
    """The command line's document of a Python result."""
    if isinstance(result, dict):
        return result
    if isinstance(result, xr.Dataset):
        return afmdyn.summary(result)  # datasets carry the --json summary
    return result.to_dict()


# (name, Python call, command line arguments): the same request through both front ends
def _units(path: str) -> Dict[str, Any]:
    """``afmdyn.probe`` as the document of ``afmdyn units --probe``."""
    p = afmdyn.probe(path)
    return {"params": p["params"].to_dict(), "si": p["si"]}


SAME = [
    ("units of a probe", lambda: _units(PM), ["units", "--probe", PM]),
    ("units of a beam probe", lambda: _units(BEAM), ["units", "--probe", BEAM]),
    ("modes with a probe", lambda: afmdyn.modes(probe=PM), ["modes", "--probe", PM]),
    (
        "orbit with a probe and z_c",
        lambda: afmdyn.orbit(probe=PM, z_c=8e-9),
        ["orbit", "--probe", PM, "--z-c", "8e-9"],
    ),
    (
        "orbit with a probe and a drive frequency",
        lambda: afmdyn.orbit(probe=PM, drive_frequency=299e3, z_c=9e-9),
        ["orbit", "--probe", PM, "--drive-frequency", "299e3", "--z-c", "9e-9"],
    ),
    (
        "attractors with a probe",
        lambda: afmdyn.attractors(probe=PM, samples=2, max_periods=300),
        ["attractors", "--probe", PM, "--samples", "2", "--max-periods", "300"],
    ),
    (
        "lyapunov with a beam probe",
        lambda: afmdyn.lyapunov(probe=BEAM, transient=20, periods=40, blocks=4),
        ["lyapunov", "--probe", BEAM, "--transient", "20", "--periods", "40", "--blocks", "4"],
    ),
    (
        "continuation",
        lambda: afmdyn.continuation(from_=3.0, to=2.8),
        ["continue", "--from", "3.0", "--to", "2.8"],
    ),
    (
        "converge with a beam probe",
        lambda: afmdyn.converge(probe=BEAM, max_modes=2),
        ["converge", "--probe", BEAM, "--max-modes", "2"],
    ),
    (
        "simulate with a probe",
        lambda: afmdyn.simulate(probe=PM, z_c=8e-9, periods=3, samples_per_period=20),
        [
            "simulate", "--probe", PM, "--z-c", "8e-9", "--periods", "3",
            "--samples-per-period", "20", "--files", "data",
        ],
    ),
    (
        "approach from a probe alone (the silent default beam before)",
        lambda: afmdyn.approach(probe=PM, from_=20e-9, to=2e-9, points=10, branches=False),
        [
            "approach", "--probe", PM, "--from", "20e-9", "--to", "2e-9", "--points", "10",
            "--no-branches", "--files", "none",
        ],
    ),
    (
        "resonance from a probe alone",
        lambda: afmdyn.resonance(probe=PM, points=5, branches=False),
        ["resonance", "--probe", PM, "--points", "5", "--no-branches", "--files", "none"],
    ),
]

# the subcommands that write files take an output directory
WRITES = ("simulate", "converge", "continue", "attractors", "bifurcation")


def _out(args: List[str], tmp_path: Path) -> List[str]:
    return ["--out", str(tmp_path / "out")] if args[0] in WRITES else []


# documents that carry wall-clock or file-system facts of their run
VOLATILE = ("outputs", "out", "elapsed_s", "files")


def _strip(doc: Dict[str, Any]) -> Dict[str, Any]:
    return {k: v for k, v in doc.items() if k not in VOLATILE}


@pytest.mark.parametrize("name,call,args", SAME, ids=[s[0] for s in SAME])
def test_the_same_request_gives_the_same_document(
    name: str, call: Callable[[], Any], args: List[str], cli_json: Any, tmp_path: Path
) -> None:
    ref = cli_json(*args, *_out(args, tmp_path))
    got = _doc(call())
    assert _sorted(_strip(got)) == _sorted(_strip(ref)), name


def test_a_probe_alone_runs_the_probe_not_the_paper_default() -> None:
    """`afmdyn.approach(probe=...)` ran the paper's linear beam scaled to SI (A = 4.6 nm for a
    probe with A0 = 10 nm): the probe's set is now the model, as `--probe` on the command
    line."""
    doc = afmdyn.approach(probe=PM, from_=20e-9, to=2e-9, points=10, branches=False).afmdyn.to_dict()
    probe = afmdyn.probe(PM)
    assert doc["params"] == probe["params"].to_dict()
    assert doc["params"]["structure"] == "point-mass"
    assert doc["params"]["contact_law"]["law"] == "dmt"
    # far from the sample the amplitude is the free amplitude A0 of the probe
    a0 = probe["si"]["free_amplitude_m"]
    assert abs(doc["approach"]["amplitude"][0] / a0 - 1) < 0.02


def test_params_and_a_probe_that_differ_are_refused() -> None:
    with pytest.raises(ValueError, match="params and probe both given and they differ"):
        afmdyn.orbit(afmdyn.Params(), probe=PM)
    # the documented pattern, the probe's own set with its file, stays valid
    same = afmdyn.orbit(afmdyn.Params.from_probe(PM), probe=PM, z_c=8e-9)
    assert same.to_dict() == afmdyn.orbit(probe=PM, z_c=8e-9).to_dict()


# (Python call, command line arguments): the same bad value in both front ends
REFUSED = [
    (lambda: afmdyn.simulate(samples_per_period=0), ["simulate", "--samples-per-period", "0"]),
    (lambda: afmdyn.simulate(periods=2e8), ["simulate", "--periods", "2e8"]),
    (
        lambda: afmdyn.simulate(tau_end=1.0, transient=10),
        ["simulate", "--tau-end", "1", "--transient", "10"],
    ),
    (lambda: afmdyn.attractors(samples=1000000), ["attractors", "--samples", "1000000"]),
    (lambda: afmdyn.attractors(max_period=65), ["attractors", "--max-period", "65"]),
    (lambda: afmdyn.attractors(cluster_tol=0.0), ["attractors", "--cluster-tol", "0"]),
    (lambda: afmdyn.orbit(period=65), ["orbit", "--period", "65"]),
    (lambda: afmdyn.orbit(tol=0.0), ["orbit", "--tol", "0"]),
    (lambda: afmdyn.continuation(period=65), ["continue", "--period", "65"]),
    (lambda: afmdyn.continuation(from_=-1.0), ["continue", "--from", "-1"]),
    (
        lambda: afmdyn.lyapunov(transient=10**8, periods=10**8),
        ["lyapunov", "--transient", "100000000", "--periods", "100000000"],
    ),
    (lambda: afmdyn.lyapunov(blocks=1), ["lyapunov", "--blocks", "1"]),
    (lambda: afmdyn.bifurcation(threads=2000), ["bifurcation", "--threads", "2000"]),
    (lambda: afmdyn.bifurcation(steps=0), ["bifurcation", "--steps", "0"]),
    (lambda: afmdyn.bifurcation(max_periods=0), ["bifurcation", "--max-periods", "0"]),
    (lambda: afmdyn.converge(max_modes=21), ["converge", "--max-modes", "21"]),
    (lambda: afmdyn.converge(periods=20000), ["converge", "--periods", "20000"]),
    (lambda: afmdyn.orbit(omega=-1.0), ["orbit", "--omega", "-1"]),
    (lambda: afmdyn.orbit(modes=21), ["orbit", "--modes", "21"]),
    (
        lambda: afmdyn.orbit(contact_law="impact", hamaker=1.0),
        ["orbit", "--contact-law", "impact", "--hamaker", "1"],
    ),
    (lambda: afmdyn.orbit(probe=PM, z_c=float("inf")), ["orbit", "--probe", PM, "--z-c", "inf"]),
    (
        lambda: afmdyn.orbit(probe=PM, drive_frequency=-3.0),
        ["orbit", "--probe", PM, "--drive-frequency", "-3"],
    ),
    (lambda: afmdyn.approach(probe=PM, points=1), ["approach", "--probe", PM, "--points", "1"]),
    (
        lambda: afmdyn.resonance(probe=PM, tolerance=1.0),
        ["resonance", "--probe", PM, "--tolerance", "1"],
    ),
]


def _spelled_as_python(message: str) -> str:
    """The command line's message with its flag spelling turned into Python's: the parameter
    before ` = ` in kebab-case becomes snake_case."""
    return re.sub(
        r"^([a-z][a-z0-9-]*) = ", lambda m: m.group(1).replace("-", "_") + " = ", message
    )


@pytest.mark.parametrize("call,args", REFUSED, ids=[" ".join(a) for _, a in REFUSED])
def test_the_same_bad_value_gets_the_same_message(
    call: Callable[[], Any], args: List[str], cli: Any, tmp_path: Path
) -> None:
    out = cli(*args, *_out(args, tmp_path))
    assert out.returncode == 2, (args, out.stderr)
    line = out.stderr.strip()
    assert line.count("\n") == 0 and line.startswith("afmdyn: "), line
    cli_message = _spelled_as_python(line[len("afmdyn: "):])
    with pytest.raises(ValueError) as refused:
        call()
    assert str(refused.value) == cli_message, args
    assert not (tmp_path / "out").exists(), "nothing written for a refused request"


def test_the_table_of_model_parameters_is_every_front_ends() -> None:
    """The one table (``afmdyn::request::MODEL_PARAMETERS``) names exactly the keywords of the
    ``Model`` TypedDict (the stubs' keywords) beside ``probe``, ``cantilever`` and ``medium``
    (the command line's ``--probe``, ``--cantilever`` and ``--medium``), and every row is a flag
    of every command line subcommand with its help."""
    from afmdyn import _afmdyn as core
    from afmdyn._api import Model

    names = set()
    for name, alias, _unit, _range, _help in core.MODEL_PARAMETERS:
        names.update({name, alias})
    assert names | {"probe", "cantilever", "medium"} == set(Model.__annotations__)


def test_the_stubs_and_docstrings_follow_the_table() -> None:
    """``Params(...)`` and ``Params.replace(...)`` in the stubs take exactly the table's
    dimensionless keywords (``z_c`` and ``drive_frequency`` need a probe: analyses only), and
    the Params docstring names each of them."""
    import ast

    from afmdyn import _afmdyn as core

    stub = Path(afmdyn.__file__).parent / "_afmdyn.pyi"
    tree = ast.parse(stub.read_text())
    params = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Params")
    si_only = {"z_c", "drive_frequency"}
    expected = set()
    for name, alias, unit, _range, _help in core.MODEL_PARAMETERS:
        if name not in si_only:
            expected.update({name, alias})
    for fn in params.body:
        if isinstance(fn, ast.FunctionDef) and fn.name in ("__init__", "replace"):
            assert {a.arg for a in fn.args.kwonlyargs} == expected, fn.name
    doc = afmdyn.Params.__doc__ or ""
    for name in expected:
        assert f"``{name}``" in doc, name
    with pytest.raises(ValueError, match="z_c = .*: needs a probe file"):
        afmdyn.Params(z_c=1e-9)
