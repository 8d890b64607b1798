"""Attractors and their basin fractions continued over a parameter (``afmdyn attractors
--sweep``): the library's global continuation as an ``xarray.Dataset``."""

from __future__ import annotations

import json
import os
from typing import TYPE_CHECKING, List, Optional, Union

import xarray as xr

from . import _layout
from ._afmdyn import Params
from ._common import _DEFAULTS, Model, _door, _params, _request, _typed
from ._progress import ProgressArg

if TYPE_CHECKING:
    from typing_extensions import Unpack


@_typed
def global_continuation(
    params: Optional[Params] = None,
    /,
    *,
    param: str = _DEFAULTS["global_continuation"]["param"],
    from_: float = _DEFAULTS["global_continuation"]["from"],
    to: float = _DEFAULTS["global_continuation"]["to"],
    steps: int = _DEFAULTS["global_continuation"]["steps"],
    values: Optional[List[float]] = None,
    match_tol: float = _DEFAULTS["global_continuation"]["match_tol"],
    samples: int = _DEFAULTS["global_continuation"]["samples"],
    seed: int = _DEFAULTS["global_continuation"]["seed"],
    cluster_tol: float = _DEFAULTS["global_continuation"]["cluster_tol"],
    tol: float = _DEFAULTS["global_continuation"]["tol"],
    max_periods: Optional[int] = None,
    max_period: int = _DEFAULTS["global_continuation"]["max_period"],
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = _DEFAULTS["global_continuation"]["tolerance"],
    store: Union[str, "os.PathLike[str]", None] = None,
    resume: bool = False,
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Attractors continued over ``param`` (``afmdyn attractors --sweep``; Datseris, Rossi &
    Wagemakers, Chaos 33, 073151 (2023)): at every value (``from_`` … ``to`` in ``steps``, or
    ``values`` in the order given) a census of ``samples`` random starts plus one start from
    each attractor of the previous value; the attractors are matched to the previous value's
    by the distance between their Poincaré point sets (``match_tol``, relative), so an id is
    one attractor followed over the parameter. The basin fractions count the random starts
    only (an attractor found only from the previous value has fraction 0). ``store`` keeps the
    command line's resumable store of values there (``afmdyn attractors --sweep --out DIR``),
    ``resume=True`` continues an interrupted continuation of the same request from its last
    stored value (refused, naming the option, for another request's store).

    Returns:
        ``xarray.Dataset`` with dims ``(value, id)``: ``basin_fraction`` (0 where the id has no
        attractor), ``period`` (−1 nonperiodic, 0 absent), ``x_max`` and ``v_t_min`` (g0, NaN
        absent), ``stable`` (1/0 from the Floquet multipliers of the orbit polished by shooting,
        NaN otherwise); dim ``value``: ``failures`` (runs that failed). Attribute ``summary``:
        the command line's JSON document (Poincaré points, multipliers of every attractor).

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    req = _request(locals())
    p, probe = _params(params, model)
    d = _door("global_continuation", "starts", progress, p, probe, req, store, resume)
    layout = d["datasets"]["global_continuation"]
    doc = json.loads(d["json"])
    # the library's layout (the command line's attractors-sweep.nc)
    return _layout.dataset(
        layout,
        {"param": doc["param"], "samples": samples, "match_tol": match_tol,
         "summary": json.dumps(doc)},
    )
