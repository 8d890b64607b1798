"""Basins of attraction over a plane of initial conditions (``afmdyn basins``): the library's
map and measures, as an ``xarray.Dataset``."""

from __future__ import annotations

import json
import os
from typing import TYPE_CHECKING, Any, List, Optional, Union

import numpy as np
import xarray as xr

from . import _layout
from ._afmdyn import Params
from ._common import _DEFAULTS, Model, _door, _params, _request, _typed
from ._progress import ProgressArg

if TYPE_CHECKING:
    from typing_extensions import Unpack


@_typed
def basins(
    params: Optional[Params] = None,
    /,
    *,
    x: str = _DEFAULTS["basins"]["x"],
    x_from: float = _DEFAULTS["basins"]["x_from"],
    x_to: float = _DEFAULTS["basins"]["x_to"],
    x_steps: int = _DEFAULTS["basins"]["x_steps"],
    y: str = _DEFAULTS["basins"]["y"],
    y_from: float = _DEFAULTS["basins"]["y_from"],
    y_to: float = _DEFAULTS["basins"]["y_to"],
    y_steps: int = _DEFAULTS["basins"]["y_steps"],
    base: Optional[List[float]] = None,
    near_tol: float = _DEFAULTS["basins"]["near_tol"],
    cell: float = _DEFAULTS["basins"]["cell"],
    basin_hits: int = _DEFAULTS["basins"]["basin_hits"],
    discover_after: int = _DEFAULTS["basins"]["discover_after"],
    stride: int = _DEFAULTS["basins"]["stride"],
    cluster_tol: float = _DEFAULTS["basins"]["cluster_tol"],
    tol: float = _DEFAULTS["basins"]["tol"],
    max_periods: Optional[int] = None,
    max_period: int = _DEFAULTS["basins"]["max_period"],
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = _DEFAULTS["basins"]["tolerance"],
    threads: Optional[int] = None,
    store: Union[str, "os.PathLike[str]", None] = None,
    resume: bool = False,
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Basins of attraction (``afmdyn basins``) over two coordinates of the initial state at
    τ = 0 (``"a1"``…``"aN"``, ``"adot1"``…``"adotN"``, ``"w"``, ``"wdot"``; the others from
    ``base``, 2N values a1…aN, ȧ1…ȧN, default at rest): each start stops as soon as it is near
    a known periodic attractor (3 returns within ``near_tol``) or its returns recur in
    state-space cells of one basin (``basin_hits`` returns in cells of side ``cell``), else the
    steady-state search decides. Where the plane is the whole section (N = 1, a position and a
    velocity) the map is made in passes from a coarse grid (``stride``; 0 automatic, 1 one
    pass): a later start stops when a return lands inside a coarse cell of one basin.
    ``store`` keeps the command line's resumable store of rows there (``afmdyn basins --out
    DIR``), ``resume=True`` continues an interrupted map of the same request (refused, naming
    the option, for another request's store).

    Returns:
        ``xarray.Dataset`` with dims ``(y, x)``: ``label`` (attractor id, −2 failed),
        ``decided`` (``"near"``, ``"recurrence"``, ``"grid"``, ``"steady"``, ``"failed"``),
        ``periods``; dim ``attractor``: ``period`` (−1 nonperiodic), ``x_max``, ``v_t_min``
        (g0), ``basin_fraction``, ``stable`` (1/0 from the Floquet multipliers of the orbit
        polished by shooting; NaN nonperiodic), ``lyapunov`` (λ₁ of a nonperiodic attractor);
        attributes ``basin_entropy``, ``boundary_basin_entropy`` (Daza et al. 2016; NaN when
        undefined), ``uncertainty_exponent`` (Grebogi et al. 1983) and ``summary`` (the
        command line's JSON document).

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    req = _request(locals())
    p, probe = _params(params, model)
    d = _door("basins", "starts", progress, p, probe, req, store, resume)
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
