"""Attractors and their basin fractions continued over a parameter (``afmdyn attractors
--sweep``): the library's global continuation as an ``xarray.Dataset``."""

from __future__ import annotations

import json
from typing import Any, Dict

import xarray as xr

from . import _layout
from ._common import _door, _params, _request


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
