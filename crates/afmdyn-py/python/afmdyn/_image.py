"""Images of a heterogeneous sample (``afmdyn image``): the library's AM image (ideal or PI
feedback) or PeakForce image (ideal peak-force feedback) as an ``xarray.Dataset`` in SI (the
public functions are generated, :mod:`._wrappers_afm`)."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Tuple

import numpy as np
import xarray as xr

from . import _afmdyn as _core
from . import _layout
from ._common import _real_array, _warn
from ._progress import reporter

Args = Dict[str, Any]


def _keywords(a: Args, feedback: str) -> Tuple[str, Args]:
    """The probe's TOML text and the library's ``ImageKeywords`` of an image's arguments ``a``
    (the public function's ``locals()``) under ``feedback``."""
    height_map, gains, sample, mode = a["height_map"], a["gains"], a["sample"], a["mode"]
    rows = None
    if isinstance(height_map, (str, os.PathLike)):
        # a .csv or .npy file, read and checked by the library as the TOML key's file is
        rows = _core.read_height_map(os.fspath(height_map))
    elif height_map is not None:
        rows = _real_array("height_map", height_map, 2).tolist()
    if gains is not None and len(gains) != 2:
        raise ValueError("gains: must be two numbers (K_P, K_I in 1/s)")
    pi = dict(scan_rate=a["scan_rate"], time_constant=a["time_constant"],
              gains=None if gains is None else [float(g) for g in gains],
              temperature=a.get("temperature"), seed=a.get("seed") or 0)
    # the options and what else was given, checked together by the library
    # (ImageOptions::check, as the command line's flags are)
    given = [[k, repr(a[k])] for k in ("scan_rate", "gains", "time_constant", "temperature",
                                       "curve_points") if a.get(k) is not None]
    given += [["seed", repr(a["seed"])]] if a.get("seed") else []
    options = dict(mode=mode, feedback=feedback, threads=a.get("threads"))
    request = dict(sample=os.fspath(sample) if isinstance(sample, os.PathLike) else sample,
                   setpoint=a["setpoint"], pixels=a["pixels"], lines=a["lines"],
                   curve_points=a["curve_points"], height_map=rows,
                   # (a PeakForce image's temperature is its PI settings', ImageKeywords)
                   feedback=pi if feedback == "pi" or mode == "peakforce" else None,
                   threads=a.get("threads"),
                   mode=None if mode == "am" else mode,
                   options=dict(options=options, given=given))
    return _core.probe_source(a["probe"]), request


def _finish_image(a: Args) -> xr.Dataset:
    """Run the image of :func:`afmdyn.image`'s keywords ``a`` (its ``locals()``)."""
    mode, feedback = a["mode"], a["feedback"]
    if mode not in ("am", "peakforce"):
        raise ValueError(f"mode = {mode!r}: must be 'am' or 'peakforce'")
    if feedback not in ("ideal", "pi"):
        raise ValueError(f"feedback = {feedback!r}: must be 'ideal' or 'pi'")
    text, request = _keywords(a, feedback)
    lines_progress = feedback == "pi" or mode == "peakforce"
    with reporter(a["progress"] if lines_progress else False, "image", unit="line") as cb:
        out = _core.image(text, request, cb)
    return _dataset(out, a["setpoint"])


def _dataset(out: Dict[str, Any], setpoint: float) -> xr.Dataset:
    """The Dataset of an image (as ``_afmdyn.run`` returns it: the per-pixel document, the
    layout ``image``, the fact ``summary``), ideal or PI: its maps and
    flags as the library lays them out (``image.nc``'s variables, units and long names), its
    integer codes (regime, material, domain; a PI scan's ``_retrace`` ones) as the document's
    words; the command line's ``image.json`` (the summary) as ``summary``."""
    doc = json.loads(out["json"])
    summary = out["facts"]["summary"]
    _warn(summary)
    img = doc["image"]
    dims = ("y", "x")
    layout = _layout.variables(out["datasets"]["image"])
    data: Dict[str, Any] = {}
    for name, (vdims, values, attrs) in layout.items():
        if vdims != dims:
            continue
        if values.dtype.kind in "fb" or "flag_values" not in attrs:
            data[name] = (vdims, values, attrs)  # a measure (a count too): its units kept
        else:
            base, retrace, _ = name.partition("_retrace")
            block = img["retrace"] if retrace else img
            words = np.array([["" if v is None else v for v in row] for row in block[base]])
            data[name] = (dims, words, {"long_name": attrs["long_name"]})
    extra = {k: json.dumps(doc[k]) for k in ("scan", "artefacts") if k in doc}
    return xr.Dataset(
        data,
        coords={name: layout[name] for name in ("x", "y")},
        attrs={
            "setpoint": setpoint,
            "reference_z_c": doc["reference_z_c"],
            "feedback": doc["feedback"],
            **extra,
            "summary": json.dumps(summary),
        },
    )


def _finish_setpoint_study(a: Args) -> xr.Dataset:
    """The setpoint study of :func:`afmdyn.setpoint_study`'s keywords ``a`` (its ``locals()``):
    its layout ``setpoint_study`` (the library's), the study's JSON as ``summary``."""
    sample = a["sample"]
    text = _core.probe_source(a["probe"])
    source = os.fspath(sample) if isinstance(sample, os.PathLike) else sample
    values = _real_array("ratios", a["ratios"], 1).tolist()
    out = _core.setpoint_study(text, source, values, a["curve_points"])
    doc = json.loads(out["json"])
    _warn(doc)
    return _layout.dataset(out["datasets"]["setpoint_study"], {"summary": json.dumps(doc)})
