"""The "Returns" of a generated analysis function names its dataset's variables from the
library's layouts (``docs/schema/layouts/<name>.json``, written by
``crates/afmdyn/tests/layouts.rs``; ``scripts/gen_wrappers.py`` builds the docstring): run on
the layout file's own example request, the function returns a dataset whose variables are
exactly those its docstring names, each over the dims it gives, in the units it gives (the
defining identity of building both the dataset and its documentation from one layout)."""

from __future__ import annotations

import json
import re
import warnings
from typing import Any, Dict, List, Tuple

import afmdyn
import pytest
import xarray as xr
from conftest import REPO

LAYOUTS = REPO / "docs" / "schema" / "layouts"

#: the analyses whose dataset is its layouts as they are (the others add variables from their
#: document, ``fit``, or turn a code into words and add a coordinate, ``basins``); ``image``
#: keeps the maps over (y, x), its scalars becoming attributes (the docstring leaves them out)
ANALYSES = ["simulate", "converge", "continuation", "observe", "approach", "resonance",
            "bifurcation", "global_continuation", "chart", "bimodal", "peakforce", "image"]

ENTRY = re.compile(r"^\s*- ``([^`]+)`` \(([^)]*)\) \[([^]]*)\]:")


def documented(name: str) -> Dict[str, Tuple[Tuple[str, ...], str]]:
    """The variables the docstring of ``afmdyn.<name>`` names after "Its variables": name ->
    (dims, units)."""
    doc = getattr(afmdyn, name).__doc__ or ""
    _, found, table = doc.partition("Its variables")
    assert found, f"afmdyn.{name}: no variables in its docstring"
    out = {}
    for line in table.splitlines():
        m = ENTRY.match(line)
        if m:
            dims = () if m.group(2) == "scalar" else tuple(m.group(2).split(", "))
            out[m.group(1)] = (dims, m.group(3))
    return out


def example(name: str) -> Tuple[List[Any], Dict[str, Any]]:
    """The positional arguments and keywords of the layout file's example for ``name``."""
    ex = json.loads((LAYOUTS / f"{name}.json").read_text())["example"]
    kw = {("from_" if k == "from" else k): v for k, v in ex["request"].items()}
    probe = None if ex["probe"] is None else str(REPO / ex["probe"])
    if name == "image":
        return [probe, str(REPO / kw.pop("sample")), kw.pop("setpoint")], kw
    if probe is not None:
        kw["probe"] = probe
    return [], kw


def run(name: str) -> xr.Dataset:
    """``afmdyn.<name>`` on its layout file's example."""
    args, kw = example(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        ds = getattr(afmdyn, name)(*args, **kw)
    assert isinstance(ds, xr.Dataset)
    return ds


@pytest.mark.parametrize("name", ANALYSES)
def test_the_dataset_has_the_variables_its_docstring_names(name: str) -> None:
    ds = run(name)
    doc = documented(name)
    assert sorted(ds.variables) == sorted(doc), name
    for var, (dims, _) in doc.items():
        assert ds[var].dims == dims, (name, var)


#: ``afmdyn.peakforce`` merges its layouts' datasets with ``combine_attrs="drop"``
#: (``_peakforce.py``; ``_fit.py`` too), which drops every variable's units and long name
DROPS_UNITS = pytest.mark.xfail(strict=True, reason="xr.merge(combine_attrs='drop') drops "
                                "the variables' attrs (_peakforce.py)")


@pytest.mark.parametrize("name", [pytest.param(n, marks=DROPS_UNITS) if n == "peakforce" else n
                                  for n in ANALYSES])
def test_each_variable_has_the_units_its_docstring_gives(name: str) -> None:
    ds = run(name)
    for var, (_, units) in documented(name).items():
        if ds[var].dtype.kind in "UO":
            continue  # words carry no units (CF), nor do the codes turned into words
        assert ds[var].attrs.get("units", "—") == units, (name, var)


def test_a_layout_omits_nothing_the_docstring_shows() -> None:
    """Every variable of ``approach``'s layout file is in its docstring (nothing left out
    but what the function's docs omit, ``image``'s scalars)."""
    for name in ("approach", "image"):
        layout = json.loads((LAYOUTS / f"{name}.json").read_text())
        names = {v["name"] for d in layout["datasets"] for v in d["variables"]}
        left = names - set(documented(name))
        assert left == (set() if name == "approach" else {"setpoint", "reference_z_c"}), name
