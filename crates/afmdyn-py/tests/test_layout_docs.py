"""The "Returns" of a generated analysis function names its dataset's variables from the
library's layouts (``docs/schema/layouts/<name>.json``, written by
``crates/afmdyn/tests/layouts.rs``; ``scripts/gen_wrappers.py`` builds the docstring): run on
the layout file's own example request, the function returns a dataset whose variables are
exactly those its docstring names, each over the dims it gives, in the units it gives (the
defining identity of building both the dataset and its documentation from one layout)."""

from __future__ import annotations

import functools
import json
import re
import warnings
from typing import Any, Dict, List, Tuple

import afmdyn
import pytest
import xarray as xr
from conftest import REPO

LAYOUTS = REPO / "docs" / "schema" / "layouts"

#: the layout files of the analyses whose dataset is its layouts as they are (the others add
#: variables from their document, ``fit``, or turn a code into words and add a coordinate,
#: ``basins``); ``image`` keeps the maps over (y, x), its scalars becoming attributes (the
#: docstring leaves them out), and has a variant per feedback and mode (``image.pi``, …);
#: ``peakforce.sweep`` is a sweep in z_c; ``reconstruct.fm`` inverts an ``fm`` curve
STEMS = ["simulate", "converge", "continuation", "observe", "approach", "resonance",
         "bifurcation", "global_continuation", "chart", "bimodal", "peakforce", "peakforce.sweep",
         "image", "image.pi", "image.peakforce", "fm", "reconstruct", "reconstruct.fm",
         "setpoint_study",
         "simulate.si", "observe.si", "approach.si", "resonance.si", "fm.si"]

ENTRY = re.compile(r"^\s*- ``([^`]+)`` \(([^)]*)\) \[([^]]*)\]:")
SOURCE = re.compile(r"``docs/schema/layouts/([^`]+)\.json``")


def entries(doc: str) -> List[str]:
    """The lines of ``doc``, each table entry's wrapped lines joined into one (a unit may be
    wrapped: ``1 (relative to the free lever's at its resonance)``)."""
    out: List[str] = []
    indent = lambda line: len(line) - len(line.lstrip())  # noqa: E731
    for line in doc.splitlines():
        if out and out[-1].lstrip().startswith("- ``") and line.strip() \
                and indent(line) > indent(out[-1]):
            out[-1] += " " + line.strip()
        else:
            out.append(line)
    return out


def documented(stem: str) -> Dict[str, Tuple[Tuple[str, ...], str]]:
    """The variables the docstring of ``afmdyn.<name>`` names in its table sourced from
    ``docs/schema/layouts/<stem>.json``: name -> (dims, units); for ``<name>.si`` (the same
    request under a probe) the main table's with the SI units (after a bar) and the variables
    named otherwise under a probe in place of those they replace (dims renamed alike)."""
    doc = getattr(afmdyn, stem.split(".")[0]).__doc__ or ""
    tables: Dict[str, Dict[str, Tuple[Tuple[str, ...], str]]] = {}
    table = None
    for line in entries(doc):
        m = ENTRY.match(line)
        if m and table is not None:
            dims = () if m.group(2) == "scalar" else tuple(m.group(2).split(", "))
            table[m.group(1)] = (dims, m.group(3))  # "unit | SI unit" where they differ
        elif SOURCE.search(line):
            table = tables.setdefault(SOURCE.search(line).group(1), {})  # type: ignore
    if stem.endswith(".si"):  # the main table's SI units, and the variables renamed
        main = tables[stem[:-3]]
        gone = re.search(rf"``docs/schema/layouts/{re.escape(stem)}\.json``.*?\), in place "
                         r"of ([^:]*):", " ".join(doc.split()))
        replaced = re.findall(r"``([^`]+)``", gone.group(1)) if gone else []
        new = tables.get(stem, {})
        rename = dict(zip(replaced, new))
        out = {name: (tuple(rename.get(d, d) for d in dims), units.split(" | ")[-1])
               for name, (dims, units) in main.items() if name not in replaced}
        return {**out, **new}
    assert stem in tables, f"afmdyn.{stem}: no table of variables in its docstring"
    return {name: (dims, units.split(" | ")[0]) for name, (dims, units) in tables[stem].items()}


def example(stem: str) -> Tuple[List[Any], Dict[str, Any]]:
    """The positional arguments and keywords of the layout file's example ``stem``."""
    ex = json.loads((LAYOUTS / f"{stem}.json").read_text())["example"]
    kw = {("from_" if k == "from" else k): v for k, v in ex["request"].items()}
    probe = None if ex["probe"] is None else str(REPO / ex["probe"])
    if stem.startswith("image"):
        if "feedback" in kw:  # a PI scan's settings: Python's keywords
            kw.update(kw.pop("feedback"), feedback="pi")
        return [probe, str(REPO / kw.pop("sample")), kw.pop("setpoint")], kw
    if stem == "setpoint_study":
        return [probe, str(REPO / kw.pop("sample")), kw.pop("ratios")], kw
    if stem == "reconstruct.fm":  # the dataset of the fm curve of this request, inverted
        fm = {("from_" if k == "from" else k): v for k, v in kw.pop("fm").items()}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
            return [], {"fm": afmdyn.fm(**fm, probe=probe)}
    if "sweep" in kw:  # a PeakForce sweep: its quantity a sequence
        sweep = kw.pop("sweep")
        kw[sweep["quantity"]] = sweep["values"]
    if probe is not None:
        kw["probe"] = probe
    return [], kw


@functools.lru_cache(maxsize=None)
def run(stem: str) -> xr.Dataset:
    """The analysis of ``stem`` on its layout file's example (run once; not modified)."""
    args, kw = example(stem)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", afmdyn.AfmdynWarning)
        ds = getattr(afmdyn, stem.split(".")[0])(*args, **kw)
    assert isinstance(ds, xr.Dataset)
    return ds


@pytest.mark.parametrize("name", STEMS)
def test_the_dataset_has_the_variables_its_docstring_names(name: str) -> None:
    ds = run(name)
    doc = documented(name)
    assert sorted(ds.variables) == sorted(doc), name
    for var, (dims, _) in doc.items():
        assert ds[var].dims == dims, (name, var)


@pytest.mark.parametrize("name", STEMS)
def test_each_variable_has_the_units_its_docstring_gives(name: str) -> None:
    ds = run(name)
    for var, (_, units) in documented(name).items():
        if ds[var].dtype.kind in "UO":
            continue  # words carry no units (CF), nor do the codes turned into words
        assert ds[var].attrs.get("units", "—") == units, (name, var)


def test_a_table_leaves_out_only_what_the_function_drops() -> None:
    """Every variable of a layout file is in its docstring's table but those the function
    does not return: ``image``'s scalars (its attributes)."""
    for stem in STEMS:
        layout = json.loads((LAYOUTS / f"{stem}.json").read_text())
        names = {v["name"] for d in layout["datasets"] for v in d["variables"]}
        scalars = {v["name"] for d in layout["datasets"] for v in d["variables"]
                   if not v["dims"]} if stem.startswith("image") else set()
        assert names - set(documented(stem)) == scalars, stem
