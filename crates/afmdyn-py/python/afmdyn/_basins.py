"""Basins of attraction over a plane of initial conditions (``afmdyn basins``): the library's
map and measures, as an ``xarray.Dataset``."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Optional

import numpy as np
import xarray as xr

from . import _afmdyn as _core
from ._afmdyn import Params
from ._api import Model, _params, _run, _typed
from ._progress import ProgressArg

if TYPE_CHECKING:
    from typing_extensions import Unpack


@_typed
def basins(
    params: Optional[Params] = None,
    /,
    *,
    x: str = "a1",
    x_from: float = -0.6,
    x_to: float = 0.6,
    x_steps: int = 40,
    y: str = "adot1",
    y_from: float = -1.2,
    y_to: float = 1.2,
    y_steps: int = 40,
    near_tol: float = 0.02,
    cell: float = 0.01,
    basin_hits: int = 16,
    discover_after: int = 200,
    cluster_tol: float = 1e-5,
    tol: float = 1e-8,
    max_periods: int = 1500,
    max_period: int = 64,
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = 1e-12,
    threads: Optional[int] = None,
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Basins of attraction (``afmdyn basins``) over two coordinates of the initial state at
    τ = 0 (``"a1"``…``"aN"``, ``"adot1"``…``"adotN"``, ``"w"``, ``"wdot"``; the others at
    rest): each start stops as soon as it is near a known periodic attractor (3 returns within
    ``near_tol``) or its returns recur in state-space cells of one basin (``basin_hits``
    returns in cells of side ``cell``), else the steady-state search decides.

    Returns:
        ``xarray.Dataset`` with dims ``(y, x)``: ``label`` (attractor id, −2 failed),
        ``decided`` (``"near"``, ``"recurrence"``, ``"steady"``, ``"failed"``), ``periods``;
        dim ``attractor``: ``period`` (−1 nonperiodic), ``x_max`` (g0), ``basin_fraction``,
        ``stable`` (1/0 from the Floquet multipliers of the orbit polished by shooting; NaN
        nonperiodic), ``lyapunov`` (λ₁ of a nonperiodic attractor);
        attributes ``basin_entropy``, ``boundary_basin_entropy`` (Daza et al. 2016; NaN when
        undefined) and ``uncertainty_exponent`` (Grebogi et al. 1983).
    """
    p, _probe = _params(params, model)
    d = _run(
        _core.basins,
        "basins",
        progress,
        p,
        x=x,
        x_from=x_from,
        x_to=x_to,
        x_steps=x_steps,
        y=y,
        y_from=y_from,
        y_to=y_to,
        y_steps=y_steps,
        near_tol=near_tol,
        cell=cell,
        basin_hits=basin_hits,
        discover_after=discover_after,
        cluster_tol=cluster_tol,
        tol=tol,
        max_periods=max_periods,
        max_period=max_period,
        integrator=integrator,
        steps_per_period=steps_per_period,
        tolerance=tolerance,
        threads=threads,
    )
    ny, nx = len(d["y"]), len(d["x"])
    labels = np.asarray(d["label"]).reshape(ny, nx)
    n = len(d["attractor_period"])

    def num(v: Any) -> float:
        return float("nan") if v is None else float(v)

    return xr.Dataset(
        data_vars={
            "label": (("y", "x"), labels, {"long_name": "attractor id (-2 failed)"}),
            "decided": (("y", "x"), np.array(d["decided"], dtype=str).reshape(ny, nx)),
            "periods": (("y", "x"), np.asarray(d["periods"]).reshape(ny, nx),
                        {"long_name": "drive periods the start ran"}),
            "period": ("attractor", d["attractor_period"], {"long_name": "period n (-1 nonperiodic)"}),
            "x_max": ("attractor", d["attractor_x_max"], {"units": "g0", "long_name": "X_max"}),
            "basin_fraction": ("attractor", d["basin_fraction"]),
            "stable": (
                "attractor",
                np.array([np.nan if v is None else float(v) for v in d["attractor_stable"]]),
                {"long_name": "1 stable periodic orbit (shooting), 0 unstable, NaN nonperiodic"},
            ),
            "lyapunov": ("attractor", d["attractor_lyapunov"],
                         {"units": "1/tau", "long_name": "λ₁ of a nonperiodic attractor"}),
        },
        coords={
            "x": ("x", d["x"], {"long_name": f"{d['x_name']} at τ = 0"}),
            "y": ("y", d["y"], {"long_name": f"{d['y_name']} at τ = 0"}),
            "attractor": ("attractor", np.arange(n)),
        },
        attrs={
            "basin_entropy": num(d["basin_entropy"]),
            "boundary_basin_entropy": num(d["boundary_basin_entropy"]),
            "uncertainty_exponent": num(d["uncertainty_exponent"]),
            **{k: v for k, v in p.to_dict().items() if isinstance(v, (int, float, str))},
        },
    )
