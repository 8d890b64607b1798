"""Behaviour charts over two parameters (``afmdyn chart``): the request, its tasks and its
dataset, shared by :func:`afmdyn.chart` (this machine) and :func:`afmdyn.dask.chart` (a Dask
cluster). The chart, its limits, its tasks and its result layout are the library's; this
module builds the request and wraps the arrays in an ``xarray.Dataset``."""

from __future__ import annotations

import json
import os
from typing import TYPE_CHECKING, Any, Dict, Optional, Union

import numpy as np
import xarray as xr

from . import _afmdyn as _core
from . import _layout
from ._afmdyn import Params
from ._common import _DEFAULTS, Model, _probe_text, _request, _typed, _warn
from ._progress import ProgressArg, reporter

if TYPE_CHECKING:
    from typing_extensions import Unpack

def study(
    params: Optional[Params],
    model: Dict[str, Any],
    **request: Any,
) -> "_core.ChartStudy":
    """The validated chart of the options ``request`` (the library's ``ChartRequest``) over
    ``params`` with the ``model`` keywords (``probe`` a probe file's path)."""
    if params is not None and not isinstance(params, Params):
        raise TypeError(f"params: expected afmdyn.Params or None, got {type(params).__name__}")
    model = dict(model)
    text = _probe_text(model)
    return _core.ChartStudy.build(request, params, text, model)


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


@_typed
def chart(
    params: Optional[Params] = None,
    /,
    *,
    x: str = _DEFAULTS["chart"]["x"],
    x_from: float = _DEFAULTS["chart"]["x_from"],
    x_to: float = _DEFAULTS["chart"]["x_to"],
    x_steps: int = _DEFAULTS["chart"]["x_steps"],
    y: str = _DEFAULTS["chart"]["y"],
    y_from: float = _DEFAULTS["chart"]["y_from"],
    y_to: float = _DEFAULTS["chart"]["y_to"],
    y_steps: int = _DEFAULTS["chart"]["y_steps"],
    starts: int = _DEFAULTS["chart"]["starts"],
    seed: int = _DEFAULTS["chart"]["seed"],
    tile: int = _DEFAULTS["chart"]["tile"],
    cluster_tol: float = _DEFAULTS["chart"]["cluster_tol"],
    lyapunov_periods: int = _DEFAULTS["chart"]["lyapunov_periods"],
    max_attractors: int = _DEFAULTS["chart"]["max_attractors"],
    threads: Optional[int] = None,
    tol: float = _DEFAULTS["chart"]["tol"],
    max_periods: Optional[int] = None,
    max_period: int = _DEFAULTS["chart"]["max_period"],
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = _DEFAULTS["chart"]["tolerance"],
    progress: ProgressArg = None,
    store: Union[str, "os.PathLike[str]", None] = None,
    resume: bool = False,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Behaviour chart over two parameters (``afmdyn chart``): every attractor that each cell's
    ``starts`` random starts and the continuation from its neighbours along x reach, on all
    cores (``threads``). Ctrl-C stops it within one task.

    An axis is any real model parameter by name or alias (``"omega"``, ``"alpha2"`` /
    ``"drive_amplitude"``, ``"gap"``, ``"restitution"``, ``"hamaker"``, …) and, with
    ``probe=``, ``"z_c"`` (m), ``"drive_frequency"`` (Hz) and the probe file's own values
    ``"free_amplitude"`` (m), ``"sample_modulus"`` (Pa), ``"quality_factor"``,
    ``"spring_constant"`` (N/m), ``"tip_radius"`` (m). ``store`` keeps the command
    line's resumable store there (``afmdyn chart --out DIR``), ``resume=True`` continues it.

    Raises:
        ValueError: an axis that is not a real model parameter, a value out of its range, an
            option out of its limits (each named), or ``resume`` on another request's store.
        SimulationError: no cell found any attractor.

    Returns:
        ``xarray.Dataset`` with dims ``(y, x, attractor)``: per cell ``attractors``,
        ``failures``, ``dominant_period``; per attractor slot (most random starts first;
        ``max_attractors`` slots, empty ones with period 0 and NaN) ``period`` (−1
        nonperiodic), ``motion`` (1 periodic, 2 chaotic: λ₁ > 2 × its error, 3 quasi-periodic:
        |λ₁| ≤ 2 × its error, 4 unsettled: λ₁ < −2 × its error, 5 nonperiodic without λ₁),
        ``lyapunov`` (λ₁ per unit τ of a nonperiodic attractor), ``lyapunov_error``, ``x_max``,
        ``v_t_min`` (g0), ``contacts_per_period``, ``contact_fraction``, ``fraction``
        (basin fraction among the random starts). The same values as ``chart.nc``.

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    s = study(params, model, **_request(locals()))
    with reporter(progress, "chart") as cb:
        d, doc = s.run(
            threads=threads,
            progress=cb,
            store=None if store is None else os.fspath(store),
            resume=resume,
        )
    _warn(doc)
    return dataset(s, d)
