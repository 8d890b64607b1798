"""Attractors and their basin fractions continued over a parameter (``afmdyn attractors
--sweep``): the library's global continuation as an ``xarray.Dataset``."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, List, Optional

import xarray as xr

from . import _afmdyn as _core
from . import _layout
from ._afmdyn import Params
from ._api import Model, _params, _run, _typed
from ._progress import ProgressArg

if TYPE_CHECKING:
    from typing_extensions import Unpack


@_typed
def global_continuation(
    params: Optional[Params] = None,
    /,
    *,
    param: str = "omega",
    from_: float = 1.5,
    to: float = 3.0,
    steps: int = 16,
    values: Optional[List[float]] = None,
    match_tol: float = 0.1,
    samples: int = 16,
    seed: int = 1,
    cluster_tol: float = 1e-5,
    tol: float = 1e-8,
    max_periods: Optional[int] = None,
    max_period: int = 64,
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = 1e-12,
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Attractors continued over ``param`` (``afmdyn attractors --sweep``; Datseris, Rossi &
    Wagemakers, Chaos 33, 073151 (2023)): at every value (``from_`` … ``to`` in ``steps``, or
    ``values`` in the order given) a census of ``samples`` random starts plus one start from
    each attractor of the previous value; the attractors are matched to the previous value's
    by the distance between their Poincaré point sets (``match_tol``, relative), so an id is
    one attractor followed over the parameter. The basin fractions count the random starts
    only (an attractor found only from the previous value has fraction 0).

    Returns:
        ``xarray.Dataset`` with dims ``(value, id)``: ``basin_fraction`` (0 where the id has no
        attractor), ``period`` (−1 nonperiodic, 0 absent), ``x_max`` and ``v_t_min`` (g0, NaN
        absent), ``stable`` (1/0 from the Floquet multipliers of the orbit polished by shooting,
        NaN otherwise); dim ``value``: ``failures`` (runs that failed). Attribute ``summary``:
        the command line's JSON document (Poincaré points, multipliers of every attractor).
    """
    p, probe = _params(params, model)
    d = _run(
        _core.global_continuation,
        "starts",
        progress,
        p,
        si=probe,
        param=param,
        from_=from_,
        to=to,
        steps=steps,
        values=values,
        match_tol=match_tol,
        samples=samples,
        seed=seed,
        cluster_tol=cluster_tol,
        tol=tol,
        max_periods=max_periods,
        max_period=max_period,
        integrator=integrator,
        steps_per_period=steps_per_period,
        tolerance=tolerance,
    )
    doc = json.loads(d["json"])
    # the library's layout (the command line's attractors-sweep.nc)
    return _layout.dataset(
        d["layout"],
        {"param": doc["param"], "samples": samples, "match_tol": match_tol,
         "summary": json.dumps(doc)},
    )
