"""Basins of attraction over a plane of initial conditions (``afmdyn basins``): the library's
map and measures, as an ``xarray.Dataset``."""

from __future__ import annotations

import json
from typing import Any, Dict

import numpy as np
import xarray as xr

from . import _layout
from ._afmdyn import Params
from ._common import _door, _params, _request


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
            **{k: v for k, v in p.to_dict().items() if isinstance(v, (int, float, str))},
        },
    )
    decided = ds["decided"]
    meanings = dict(zip(decided.attrs["flag_values"], decided.attrs["flag_meanings"].split()))
    names = np.array([meanings.get(int(c), "") for c in decided.values.ravel()])
    attrs = {k: v for k, v in decided.attrs.items() if not k.startswith("flag_")}
    ds["decided"] = (decided.dims, names.reshape(decided.shape), attrs)
    return ds.assign_coords(attractor=("attractor", np.arange(ds.sizes["attractor"])))
