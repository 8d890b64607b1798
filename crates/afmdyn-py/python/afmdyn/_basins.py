"""The studies of random starts as ``xarray.Dataset`` objects: basins of attraction over a plane
of initial conditions (``afmdyn basins``: the library's map and measures), and attractors with
their basin fractions continued over a parameter (``afmdyn attractors --sweep``: the library's
global continuation; its finisher :func:`_finish_global_continuation`)."""

from __future__ import annotations

import json
from typing import Any, Dict

import numpy as np
import xarray as xr

from . import _layout
from ._afmdyn import Params
from ._common import _door, _param_attrs, _params, _request


def _finish_basins(a: Dict[str, Any]) -> xr.Dataset:
    req = _request(a)
    p, probe = _params(a["params"], a["model"])
    d = _door("basins", "starts", a["progress"], p, probe, req, a["store"], a["resume"])
    return _dataset(d["datasets"]["basins"], json.loads(d["json"]), p)


def _dataset(layout: Any, doc: Any, p: Params) -> xr.Dataset:
    """The dataset of a basin map from its layout and document (as the core returns them)."""

    def num(v: Any) -> float:
        return float("nan") if v is None else float(v)

    # the variables as the library lays them out (basins.nc's), `decided` given by its meanings
    ds = _layout.dataset(
        layout,
        {
            "basin_entropy": num(doc["basin_entropy"]),
            "boundary_basin_entropy": num(doc["boundary_basin_entropy"]),
            "uncertainty_exponent": num(doc["uncertainty_exponent"]),
            "summary": json.dumps(doc),
            **_param_attrs(p),
        },
    )
    decided = ds["decided"]
    meanings = dict(zip(decided.attrs["flag_values"], decided.attrs["flag_meanings"].split()))
    names = np.array([meanings.get(int(c), "") for c in decided.values.ravel()])
    attrs = {k: v for k, v in decided.attrs.items() if not k.startswith("flag_")}
    ds["decided"] = (decided.dims, names.reshape(decided.shape), attrs)
    return ds.assign_coords(attractor=("attractor", np.arange(ds.sizes["attractor"])))


def _finish_global_continuation(a: Dict[str, Any]) -> xr.Dataset:
    req = _request(a)
    p, probe = _params(a["params"], a["model"])
    d = _door("global_continuation", "starts", a["progress"], p, probe, req, a["store"],
              a["resume"])
    layout = d["datasets"]["global_continuation"]
    doc = json.loads(d["json"])
    # the library's layout (the command line's attractors-sweep.nc)
    return _layout.dataset(
        layout,
        {"param": doc["param"], "samples": a["samples"], "match_tol": a["match_tol"],
         "summary": json.dumps(doc)},
    )
