"""Behaviour charts over two parameters (``afmdyn chart``): the request, its tasks and its
dataset, shared by :func:`afmdyn.chart` (this machine) and :func:`afmdyn.dask.chart` (a Dask
cluster). The chart, its limits, its tasks and its result layout are the library's; this
module builds the request and wraps the arrays in an ``xarray.Dataset`` (the public
function is generated, :mod:`._wrappers`)."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Optional

import numpy as np
import xarray as xr

from . import _afmdyn as _core
from . import _layout
from ._afmdyn import Params
from ._common import _inputs, _request, _warn
from ._progress import reporter


def study(
    params: Optional[Params],
    model: Dict[str, Any],
    **request: Any,
) -> "_core.ChartStudy":
    """The validated chart of the options ``request`` (the library's ``ChartRequest``) over
    ``params`` with the ``model`` keywords (``probe`` a probe file's path)."""
    return _core.ChartStudy.build(request, *_inputs(params, model))


def dataset(s: "_core.ChartStudy", d: Dict[str, Any]) -> xr.Dataset:
    """The ``xarray.Dataset`` of a chart's layout ``d`` (dims ``y``, ``x``, ``attractor``; the
    variables and their attributes as ``chart.nc`` has them)."""
    req = json.loads(s.fingerprint())["chart"]
    (xname, _), (yname, _) = s.axes()
    failures = _layout.variables(d)["failures"][1]
    return _layout.dataset(
        d,
        {
            "x_name": xname,
            "y_name": yname,
            "starts": req["starts"],
            "seed": req["seed"],
            "fingerprint": s.fingerprint(),
            "failed_runs": int(np.asarray(failures).sum()),
        },
    )


def _finish_chart(a: Dict[str, Any]) -> xr.Dataset:
    """Run the chart of :func:`afmdyn.chart`'s keywords ``a`` (its ``locals()``) here."""
    s = study(a["params"], a["model"], **_request(a))
    store = a["store"]
    with reporter(a["progress"], "chart") as cb:
        d, doc = s.run(
            threads=a["threads"],
            progress=cb,
            store=None if store is None else os.fspath(store),
            resume=a["resume"],
        )
    _warn(doc)
    return dataset(s, d)
