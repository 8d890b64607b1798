"""Generate the analyses' public functions of the Python package: ``afmdyn/_wrappers.py``
(``afmdyn.simulate``, …), ``afmdyn/_wrappers_starts.py`` (``afmdyn.attractors``, …),
``afmdyn/_wrappers_afm.py`` (``afmdyn.approach``, …, ``afmdyn.image``),
``afmdyn/_dask_wrappers.py`` (``afmdyn.dask.chart``, …) and ``afmdyn/_model.py`` (the
``Model`` keywords).

Each function's keyword-only signature (names, types, defaults) and the "Args:" of its
docstring come from its request's JSON Schema (``docs/schema/requests/*.json``, the library's
request types: field types, ``Default``, doc comments), with the few Python keywords of its
own and the widened types listed in :data:`FILES`; the table of variables in "Returns:" of a
function returning a dataset from the library's result layouts
(``docs/schema/layouts/<name>.json``, written by
``cargo test -p afmdyn --lib integration::layouts::``: each variable's name, dims, units and long
name, as the binding builds the dataset from them); its
summary, the prose of "Returns" and "Raises" come from ``scripts/wrapper_docs.py``. The body hands ``locals()`` to a hand-written finisher
(``_finish_<name>`` in the module :data:`FILES` names) that runs the request through the one
door (``_afmdyn.run``) and builds the result. ``scripts/gen_stubs.py`` calls :func:`generate`
and :func:`generate_model` and writes (or, with ``--check``, compares) the files.
"""

from __future__ import annotations

import json
import re
import sys
import textwrap
from pathlib import Path
from typing import Dict, List, Tuple

ROOT = Path(__file__).resolve().parent.parent
SCHEMAS = ROOT / "docs" / "schema" / "requests"
LAYOUTS = ROOT / "docs" / "schema" / "layouts"
PACKAGE = ROOT / "crates" / "afmdyn-py" / "python" / "afmdyn"

STORE = 'Union[str, "os.PathLike[str]", None]'
#: Python's own keywords (annotation, default), after the request's
STORE_KW = [("store", STORE, "None"), ("resume", "bool", "False")]
PROGRESS = [("progress", "ProgressArg", "None")]
#: the keywords of the Dask versions (``afmdyn.dask``), before the request's
CLIENT = [("client", 'Optional["distributed.Client"]', "None")]
DASK_KW = CLIENT + [("store", STORE, "None"), ("resume", "bool", "True")]
#: an image's probe and sample map (``afmdyn.image``, ``afmdyn.setpoint_study``)
IMAGE_INPUTS = [("probe", 'Union[str, "os.PathLike[str]", Dict[str, Any]]'),
                ("sample", 'Union[str, "os.PathLike[str]"]')]
#: an image's positional parameters and options (``afmdyn.image``, ``afmdyn.dask.image``)
IMAGE = {"positional": IMAGE_INPUTS + [("setpoint", "float")], "model": False,
         "omit": ("temperature",),  # (one of Python's own: the PI scan's or PeakForce's)
         "override": {k: ("Optional[int]", "None") for k in ("pixels", "curve_points")}}
#: an image's keywords of Python's own (``afmdyn.dask.image`` takes no feedback nor threads)
IMAGE_KW = [("height_map", "Optional[Any]", "None"), ("feedback", "str", '"ideal"'),
            ("scan_rate", "Optional[float]", "None"),
            ("gains", "Optional[Tuple[float, float]]", "None"),
            ("time_constant", "Optional[float]", "None"),
            ("temperature", "Optional[float]", "None"), ("seed", "int", "0"),
            ("threads", "Optional[int]", "None"), ("mode", "str", '"am"')]
OPTIONAL_FLOAT = ("Optional[float]", "None")

#: the generated modules: file -> the analyses it holds, each name -> (schema stem or None,
#: finisher, return annotation, options). Options: ``own`` (keywords of Python's own,
#: (name, annotation, default), documented in :data:`COMMON_ARGS` or ``DOCS[name]["args"]``),
#: ``first`` (such keywords before the request's), ``omit`` (request fields Python does not
#: take), ``override`` (a field's annotation and default in Python, wider than the
#: request's: the finisher converts it), ``rename`` (a field's keyword in Python), ``typed``
#: (False: no ``@_typed`` check of the keywords), ``positional`` ((name, annotation) of the
#: parameters before the keywords, a request's field or Python's own, instead of ``params``)
#: and ``model`` (False: no model keywords)
FILES: Dict[str, Dict[str, Tuple[object, str, str, Dict[str, object]]]] = {
    "_wrappers.py": {
        "modes": (None, "_api", "Spectrum", {"own": []}),
        "simulate": ("simulate", "_api", "xr.Dataset", {}),
        "converge": ("converge", "_api", "xr.Dataset", {}),
        "bifurcation": ("bifurcation", "_api", "xr.Dataset", {"own": PROGRESS + STORE_KW}),
        "continuation": ("continuation", "_api", "xr.Dataset", {}),
        "orbit": ("orbit", "_orbits", "Orbit", {}),
        "lyapunov": ("lyapunov", "_orbits", "Lyapunov", {}),
        "chart": ("chart", "_chart", "xr.Dataset", {"own": PROGRESS + STORE_KW}),
    },
    "_wrappers_starts.py": {
        "attractors": ("attractors", "_attractors", "Attractors", {}),
        "basins": ("basins", "_basins", "xr.Dataset", {"own": STORE_KW + PROGRESS}),
        "global_continuation": ("global_continuation", "_basins", "xr.Dataset",
                                {"own": STORE_KW + PROGRESS}),
    },
    "_wrappers_afm.py": {
        "observe": ("observe", "_api", "xr.Dataset", {}),
        "approach": ("approach", "_api", "xr.Dataset",
                     {"own": STORE_KW + PROGRESS, "omit": ("average", "exact")}),
        "bimodal": ("approach", "_api", "xr.Dataset", {"own": STORE_KW + PROGRESS}),
        "resonance": ("resonance", "_api", "xr.Dataset", {"own": STORE_KW + PROGRESS}),
        "fm": ("fm", "_fm", "xr.Dataset", {}),
        "thermal": ("thermal", "_api", "xr.Dataset", {}),
        "calibrate": ("calibrate", "_api", "xr.Dataset", {
            "override": {"frequency": ("Optional[Sequence[float]]", "None"),
                         "spectral_density": ("Optional[Sequence[float]]", "None"),
                         "bands": ("Optional[Sequence[float]]", "None")}}),
        "peakforce": ("peakforce", "_peakforce", "xr.Dataset", {
            "omit": ("sweep",),
            "override": {"z_c": ("Union[float, Sequence[float], None]", "None"),
                         "fit_band": ("Optional[Sequence[float]]", "None")},
            "own": [("modulation_frequency", "Optional[Sequence[float]]", "None")] + PROGRESS}),
        "fit": ("fit", "_fit", "xr.Dataset", {
            "omit": ("force", "height", "sigma", "time"), "rename": {"range": "fit_range"},
            "override": {
                "data": ('Union[str, "os.PathLike[str]", Mapping[str, Sequence[float]], Any, None]',
                         "None"),
                "fit": ("Optional[Sequence[str]]", "None"),
                "range": ("Optional[Tuple[float, float]]", "None")},
            "own": [("curve", "int", "0")] + PROGRESS}),
        "fit_map": ("fit_map", "_fit_map", "xr.Dataset", {
            "rename": {"range": "fit_range"},
            "override": {
                "data": ('Union[str, "os.PathLike[str]", Sequence[Any], None]', "None"),
                "fit": ("Optional[Sequence[str]]", "None"),
                "range": ("Optional[Tuple[float, float]]", "None")},
            "own": STORE_KW + PROGRESS}),
        "image": ("image", "_image", "xr.Dataset", {**IMAGE, "own": IMAGE_KW + PROGRESS}),
        "setpoint_study": ("image", "_image", "xr.Dataset", {
            "positional": IMAGE_INPUTS + [("ratios", "Sequence[float]")], "model": False,
            "omit": ("setpoint", "pixels", "lines", "temperature"), "own": [],
            "override": {"curve_points": ("Optional[int]", "None")}}),
        "reconstruct": ("reconstruct", "_reconstruct", "xr.Dataset", {
            "positional": [], "model": False, "omit": ("law_force",),
            "override": {"frequency_shift": ("Optional[Sequence[float]]", "None"),
                         **{k: OPTIONAL_FLOAT for k in ("spring_constant",
                                                        "resonance_frequency", "amplitude")}},
            "own": [(k, "Optional[Union[xr.Dataset, Dict[str, Any]]]", "None")
                    for k in ("fm", "am")] + PROGRESS}),
    },
    "_dask_wrappers.py": {
        "chart": ("chart", "_dask", "xr.Dataset",
                  {"first": DASK_KW + [("checkpoint_seconds", "float", "2.0")],
                   "omit": ("threads",), "typed": False}),
        "bifurcation": ("bifurcation", "_dask", "xr.Dataset",
                        {"first": DASK_KW, "omit": ("threads",), "typed": False}),
        "basins": ("basins", "_dask", "xr.Dataset",
                   {"first": CLIENT + PROGRESS, "omit": ("threads",), "own": [],
                    "typed": False}),
        "image": ("image", "_dask", "xr.Dataset", {
            **IMAGE, "first": CLIENT + PROGRESS, "typed": False,
            "own": [k for k in IMAGE_KW if k[0] not in ("feedback", "threads")]}),
        "fit_map": ("fit_map", "_dask", "xr.Dataset", {
            "first": DASK_KW, "omit": ("threads",), "typed": False,
            "rename": {"range": "fit_range"},
            "override": {
                "data": ('Union[str, "os.PathLike[str]", Sequence[Any], None]', "None"),
                "fit": ("Optional[Sequence[str]]", "None"),
                "range": ("Optional[Tuple[float, float]]", "None")}}),
    },
}

#: the Python annotation of a keyword whose request type Python widens (the value is
#: converted by the finisher, or ``None`` stands for the request's default)
OVERRIDES = {
    "initial": ("StateLike", "None"),
    "integrator": ("Optional[str]", "None"),
}

#: the "Args:" lines of the keywords a request does not describe (Python's own)
COMMON_ARGS = {
    "initial": "+An :class:`Attractor` or :class:`Orbit` is also taken (its state at drive "
               "phase 0).",
    "store": "a directory for the command line's resumable store (``afmdyn {name} --out DIR``; "
             "created if needed, started over without ``resume``).",
    "resume": "continue the study stored in ``store`` from its last stored point (refused, "
              "naming the first field that differs, for another request's store).",
    "progress": "``None`` (a bar for runs over a second in a terminal or Jupyter, none in a "
                "log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.",
    "model": "the model keywords (:class:`Model`), ``probe=`` a probe in SI.",
}

# per generated file and analysis: the summary, "Returns:", "Raises:" and Python's own "Args:"
sys.path.insert(0, str(Path(__file__).resolve().parent))
from wrapper_docs import DOCS, MODEL_DOC  # noqa: E402
from gen_cli import number  # noqa: E402  (one format of a constant for the help and the docs)


def _clean(text: str) -> str:
    """A request's doc comment as reStructuredText: rustdoc links become literals."""
    text = re.sub(r"\[`(?:crate::)?([^`\]]+)`\]", r"``\1``", text)
    text = re.sub(r"(?<!`)`([^`]+)`(?!`)", r"``\1``", text)
    return _bars(" ".join(text.split()))


def _bars(text: str) -> str:
    """``text`` with each absolute value ``|x|`` a literal: reStructuredText reads ``|x|`` as
    a substitution (Sphinx's autodoc of the docstrings, docs/reference/python.md)."""
    return re.sub(r"(?<![`\w|])\|([^|\s`][^|`]*?)\|(?![`\w|])", r"``|\1|``", text)


def _literal(value: object) -> str:
    return json.dumps(value) if isinstance(value, str) else repr(value)


def _annotation(prop: dict, defs: dict) -> str:
    """The Python annotation of a request field."""
    ref = prop.get("$ref", "")
    if ref:
        return "str"  # an enum of names: checked by the library, which lists them
    if any("$ref" in a for a in prop.get("anyOf", ())):
        return "Optional[str]"  # an optional enum of names
    t = prop.get("type")
    types = t if isinstance(t, list) else [t]
    base = [x for x in types if x != "null"][0]
    if base == "array":
        items = prop["items"].get("type")
        ann = "Sequence[float]" if items == "number" else "Sequence[str]"
    else:
        ann = {"integer": "int", "number": "float", "boolean": "bool", "string": "str"}[base]
    return f"Optional[{ann}]" if "null" in types else ann


def _fields(stem: str, omit: Tuple[str, ...], override: Dict[str, Tuple[str, str]]
            ) -> List[Tuple[str, str, str, str]]:
    """(keyword, annotation, default, description) of a request's fields, a nested request
    (``steady``) flattened into its own fields."""
    schema = json.loads((SCHEMAS / f"{stem}.json").read_text())
    defs = schema.get("$defs", {})
    out = []
    for key, prop in schema.get("properties", {}).items():
        if key in omit:
            continue
        ref = prop.get("$ref", "").rsplit("/", 1)[-1]
        if ref and defs[ref].get("type") == "object":
            for k, p in defs[ref]["properties"].items():
                default = prop.get("default", {}).get(k, p.get("default"))
                out.append((k, _annotation(p, defs), _literal(default), _described(p)))
            continue
        ann, default = {**OVERRIDES, **override}.get(
            key, (_annotation(prop, defs), _literal(prop.get("default"))))
        out.append((key, ann, default, _described(prop)))
    return out


def _described(prop: dict) -> str:
    """A field's description with each constant its ``"x-constants"`` gives as its value
    (``[`MAX_PERIOD`]`` → ``64``, written as the command line's help writes it)."""
    constants = prop.get("x-constants", {})

    def constant(m: re.Match) -> str:
        last = m.group(1).rsplit("::", 1)[-1]
        return number(constants[last]) if last in constants else m.group(0)

    return re.sub(r"\[`([^`\]]+)`\](?:\([^)]*\))?", constant, prop.get("description", ""))


def _arg_lines(name: str, text: str) -> List[str]:
    return textwrap.wrap(f"{name}: {text}", 92, initial_indent=" " * 8,
                         subsequent_indent=" " * 12)


def _layout_rows(stem: str, dims: Tuple[Tuple[str, ...], ...]
                 ) -> List[Tuple[str, str, str, str]]:
    """(name, dims, units, long name) of every variable of the layouts of
    ``docs/schema/layouts/<stem>.json`` (the datasets of one result merged, as the finishers
    merge them: a name once); with ``dims``, only the variables over one of them."""
    doc = json.loads((LAYOUTS / f"{stem}.json").read_text())
    rows: Dict[str, Tuple[str, str, str, str]] = {}
    for ds in doc["datasets"]:
        for v in ds["variables"]:
            if v["name"] in rows or (dims and tuple(v["dims"]) not in dims):
                continue
            over = ", ".join(v["dims"]) or "scalar"
            rows[v["name"]] = (f"``{v['name']}``", over, v["units"] or "—", v["long_name"])
    return list(rows.values())


def _entries(rows: List[Tuple[str, str, str, str]]) -> List[str]:
    """One entry per variable: ``- ``name`` (dims) [units]: meaning``, wrapped."""
    out = []
    for var, over, unit, meaning in rows:
        out += textwrap.wrap(f"- {var} ({over}) [{unit}]: {_bars(meaning)}", 88,
                             subsequent_indent="  ", break_on_hyphens=False)
    return out


def _layout_table(stem: str, dims: Tuple[Tuple[str, ...], ...], lead: str = "Its",
                  si: bool = False) -> List[str]:
    """The variables of the dataset laid out in ``docs/schema/layouts/<stem>.json``, one entry
    each (name, dims, units: meaning; a table as a list, its meanings too long for columns),
    after the sentence that sources them (``si``: an analysis in SI without a probe too).
    With ``<stem>.si.json`` (the same request under a probe) each unit is followed by its SI
    unit after a bar where they differ, and the variables named otherwise under a probe
    follow."""
    probe = json.loads((LAYOUTS / f"{stem}.json").read_text())["example"]["probe"]
    si_path = LAYOUTS / f"{stem}.si.json"
    units = (f"under ``{probe}``, in SI" if probe else "in SI" if si else
             "in the model's units" + (
                 "; after a bar, in SI with a probe" if si_path.exists() else
                 "; SI with a probe, as each variable's ``units`` attribute says"))
    intro = textwrap.wrap(
        f"{lead} variables (name (dims) [units]: meaning), as the library lays them out "
        f"(``docs/schema/layouts/{stem}.json``: its example request, {units}):", 88,
        break_on_hyphens=False)
    rows = _layout_rows(stem, dims)
    if not si_path.exists():
        return intro + [""] + _entries(rows)
    si = {r[0]: r for r in _layout_rows(si_path.stem, dims)}
    out = intro + [""] + _entries([
        (v, d, u if v not in si or si[v][2] == u else f"{u} | {si[v][2]}", m)
        for v, d, u, m in rows])
    gone = [r[0] for r in rows if r[0] not in si]
    new = [r for name, r in si.items() if name not in {x[0] for x in rows}]
    if gone or new:
        si_probe = json.loads(si_path.read_text())["example"]["probe"]
        out += [""] + textwrap.wrap(
            f"With a probe (``docs/schema/layouts/{si_path.stem}.json``: the request under "
            f"``{si_probe}``), in place of {', '.join(gone) or 'nothing'}:", 88,
            break_on_hyphens=False)
        out += [""] + _entries(new)
    return out


def _layout_tables(name: str, doc: Dict[str, object]) -> List[str]:
    """The tables of analysis ``name``'s dataset: its layout's, then each variant's
    (``<name>.<variant>.json``, introduced by ``doc["layout_variants"][variant]``)."""
    dims = tuple(tuple(d) for d in doc.get("layout_dims", ()))  # type: ignore
    si = doc.get("layout_units") == "in SI"
    out = _layout_table(name, dims, si=si)
    for path in sorted(LAYOUTS.glob(f"{name}.*.json")):
        variant = path.stem.split(".", 1)[1]
        if variant == "si":  # in the table's units (``_layout_table``)
            continue
        lead = f"With {doc['layout_variants'][variant]}, its"  # type: ignore
        out += [""] + _layout_table(path.stem, dims, lead, si)
    return out


#: the dimensions a keyword's text with a unit may have (a request field's ``x-dim``)
SI_DIMS = ("length", "frequency", "force")


def _dims(stem: str, rename: Dict[str, str]) -> Dict[str, str]:
    """The keywords of request ``stem`` that take an SI value with a probe, by their Python
    name, and their dimension (``x-dim``): ``@_typed(si=...)`` reads their text with a unit."""
    props = json.loads((SCHEMAS / f"{stem}.json").read_text()).get("properties", {})
    return {{"from": "from_", **rename}.get(k, k): p["x-dim"] for k, p in props.items()
            if p.get("x-dim") in SI_DIMS}


def _decorator(opts: Dict[str, object], dims: Dict[str, str]) -> List[str]:
    """``@_typed``, with the SI keywords' dimensions where the function has some."""
    if not opts.get("typed", True):
        return []
    if not dims:
        return ["@_typed"]
    return ["@_typed(si={" + ", ".join(f'"{k}": "{v}"' for k, v in dims.items()) + "})"]


def _function(file: str, name: str) -> str:
    stem, module, returns, opts = FILES[file][name]
    omit, override = tuple(opts.get("omit", ())), dict(opts.get("override", {}))  # type: ignore
    rename = dict(opts.get("rename", {}))  # type: ignore
    fields = _fields(str(stem), omit, override) if stem else []
    first = [(*k, "") for k in opts.get("first", [])]  # type: ignore
    own = [(*k, "") for k in opts.get("own", PROGRESS)]  # type: ignore
    # the positional parameters (default: the parameter set), a request's field taken there
    given = opts.get("positional")
    positional = [(k, ann, "") for k, ann in given or []]  # type: ignore
    described = {f[0]: f[3] for f in fields}
    fields = [f for f in fields if f[0] not in {k for k, _, _ in positional}]
    doc = DOCS[file][name]
    sig = [f"    {k}: {ann}," for k, ann, _ in positional] if given is not None else [
        "    params: Optional[Params] = None,", "    /,"]
    sig += ["    *,"] if fields or own or first else []
    args = []
    for key, ann, default, desc in [(k, a, None, described.get(k, "")) for k, a, _ in positional
                                    ] + first + fields + own:
        kw = {"from": "from_", **rename}.get(key, key)
        if default is not None:
            sig.append(f"    {kw}: {ann} = {default},")
        # the request's description, with Python's addition ("+…"), or Python's own text
        extra = doc.get("args", {}).get(key, COMMON_ARGS.get(key, ""))
        if desc and (not extra or extra.startswith("+")):
            desc = (_clean(desc) + " " + extra[1:]).strip()
        else:
            desc = extra
        args += _arg_lines(kw, desc.replace("{name}", name))
    if opts.get("model", True):
        sig.append("    **model: Unpack[Model],")
        args += _arg_lines("**model", COMMON_ARGS["model"])
    body = [doc["summary"].rstrip(), "", "Args:", *[a[4:] for a in args]]
    for section in ("returns", "warns", "raises"):
        if section in doc:
            body += ["", doc[section].rstrip()]
        # a dataset's variables, from the library's layouts (not for the Dask versions, which
        # return their local function's dataset)
        if section == "returns" and returns == "xr.Dataset" and file != "_dask_wrappers.py" \
                and (LAYOUTS / f"{name}.json").exists():
            body += [""] + ["    " + t if t else "" for t in _layout_tables(name, doc)]
    text = textwrap.indent("\n".join(body), "    ").replace("\n    \n", "\n\n")
    taken = {{"from": "from_", **rename}.get(f[0], f[0]) for f in fields} | {
        k for k, _, _ in positional}
    dims = {k: v for k, v in (_dims(str(stem), rename) if stem else {}).items() if k in taken}
    lines = _decorator(opts, dims) + [
        f"def {name}(", *sig, f") -> {returns}:", f'    """{text.strip()}', '    """',
        f"    return {module}._finish_{name}(locals())"]
    return "\n".join(line.rstrip() for line in lines)


HEADER = """\
# generated by scripts/gen_stubs.py (scripts/gen_wrappers.py) from docs/schema/requests and
# scripts/wrapper_docs.py: do not edit (CI runs `python3 scripts/gen_stubs.py --check`)
\"\"\"{doc}

The signature of each function is its library request's (the keywords, their types and
defaults, their descriptions in "Args:"), its body a call of its hand-written finisher
(``_finish_NAME``), which runs the request and builds the result.\"\"\"

from __future__ import annotations

import os
from typing import {typing}

import xarray as xr

{imports}

if TYPE_CHECKING:  # annotations only (PEP 692): editors complete and check the keywords
    from typing_extensions import Unpack
{checking}
__all__ = [
{names}
]
"""

#: per generated file: its docstring's first line, its imports, its imports for annotations
HEADS = {
    "_wrappers.py": (
        "The public functions of the dynamics' analyses (``afmdyn.simulate``, …, their\n"
        "finishers in :mod:`._api`, :mod:`._orbits` and :mod:`._chart`; the studies of random\n"
        "starts' are in :mod:`._wrappers_starts`, the AFM measurements' in\n"
        ":mod:`._wrappers_afm`). Each checks its keywords' types first (``TypeError`` naming the\n"
        "keyword); the library checks the values (``ValueError`` naming the field and its range).",
        "from . import _api, _chart, _orbits\n"
        "from ._afmdyn import Params\n"
        "from ._common import Model, StateLike, _typed\n"
        "from ._progress import ProgressArg\n"
        "from ._results import Lyapunov, Orbit, Spectrum",
        "",
    ),
    "_wrappers_starts.py": (
        "The public functions of the studies of random starts (``afmdyn.attractors``,\n"
        "``basins``, ``global_continuation``; their finishers in :mod:`._attractors` and\n"
        ":mod:`._basins`), apart from :mod:`._wrappers` so that an :class:`Attractor` continues\n"
        "into its ``orbit`` and ``simulate`` without an import circle. Each checks its keywords'\n"
        "types first (``TypeError`` naming the keyword); the library checks the values\n"
        "(``ValueError`` naming the field and its range).",
        "from . import _attractors, _basins\n"
        "from ._afmdyn import Params\n"
        "from ._attractors import Attractors\n"
        "from ._common import Model, _typed\n"
        "from ._progress import ProgressArg",
        "",
    ),
    "_wrappers_afm.py": (
        "The public functions of the AFM measurements (``afmdyn.observe``, ``approach``,\n"
        "``bimodal``, ``resonance``, ``fm``, ``peakforce``, ``fit``, ``image``,\n"
        "``setpoint_study``, ``reconstruct``; their finishers in :mod:`._api`, :mod:`._fm`,\n"
        ":mod:`._peakforce`, :mod:`._fit`, :mod:`._image` and :mod:`._reconstruct`). Those marked\n"
        "``@_typed`` check their keywords' types first (``TypeError`` naming the keyword); the\n"
        "library checks the values (``ValueError`` naming the field and its range).",
        "from . import _api, _fit, _fit_map, _fm, _image, _peakforce, _reconstruct\n"
        "from ._afmdyn import Params\n"
        "from ._common import Model, StateLike, _typed\n"
        "from ._progress import ProgressArg",
        "",
    ),
    "_dask_wrappers.py": (
        "The public functions of :mod:`afmdyn.dask` (their finishers are in :mod:`afmdyn.dask`).",
        "from . import _dask\n"
        "from ._afmdyn import Params\n"
        "from ._progress import ProgressArg",
        "    import distributed\n\n    from ._common import Model\n",
    ),
}


def generate(file: str = "_wrappers.py") -> str:
    """The text of the generated module ``file``."""
    doc, imports, checking = HEADS[file]
    names = "\n".join(f'    "{n}",' for n in FILES[file])
    head = (HEADER.replace("{doc}", doc).replace("{imports}", imports)
            .replace("{checking}", checking).replace("{names}", names))
    functions = [_function(file, n) for n in FILES[file]]
    used = [n for n in ("Any", "Dict", "Mapping", "Optional", "Sequence", "Tuple", "Union")
            if re.search(rf"\b{n}\[|\b{n}\b,|\b{n}\]", "\n".join(functions))]
    head = head.replace("{typing}", ", ".join(["TYPE_CHECKING"] + used))
    parts = [head.rstrip()] + functions
    return "\n\n\n".join(parts) + "\n"


MODEL_HEAD = '''\
# generated by scripts/gen_stubs.py (scripts/gen_wrappers.py) from docs/schema/requests/model.json
# and scripts/wrapper_docs.py: do not edit (CI runs `python3 scripts/gen_stubs.py --check`)
"""The model keywords every analysis takes (:class:`Model`): the library's model request's
fields (``ModelSpec``; the paper's ``alpha1`` … ``alpha6`` beside the names they alias) and
the probe's keywords."""

from __future__ import annotations

import os
from typing import Any, Dict, Literal, TypedDict, Union


class Model(TypedDict, total=False):
    """{doc}"""

'''

#: the model keywords of Python's own (the command line's ``--probe``, ``--cantilever``,
#: ``--medium``)
PROBE_KEYS = [("probe", 'Union[str, "os.PathLike[str]", Dict[str, Any]]'), ("cantilever", "str"),
              ("medium", "str")]


def generate_model() -> str:
    """The text of ``_model.py``: the ``Model`` TypedDict of ``model.json``'s fields (each
    ``αk`` field followed by its alias ``alphak``) and the probe's keywords."""
    schema = json.loads((SCHEMAS / "model.json").read_text())
    defs = schema.get("$defs", {})
    keys = []
    for key, prop in schema["properties"].items():
        ref = next((p["$ref"] for p in prop.get("anyOf", []) if "$ref" in p), "")
        if ref:
            d = defs[ref.rsplit("/", 1)[-1]]
            consts = [v["const"] for v in d.get("oneOf", []) if "const" in v]
            ann = "Literal[" + ", ".join(json.dumps(c) for c in consts) + "]"
        else:
            ann = _annotation(prop, defs)[len("Optional["):-1]
        keys.append((key, ann))
        alias = re.fullmatch(r"α(\d)\.", prop.get("description", ""))
        if alias:
            keys.append((f"alpha{alias.group(1)}", ann))
    doc = textwrap.indent(MODEL_DOC.strip(), "    ").strip()
    body = "".join(f"    {k}: {ann}\n" for k, ann in keys + PROBE_KEYS)
    return MODEL_HEAD.replace("{doc}", doc) + body
