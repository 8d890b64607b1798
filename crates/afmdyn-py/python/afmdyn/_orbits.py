"""Periodic orbits and the Lyapunov spectrum: :func:`orbit` (Newton shooting, Floquet
multipliers) and :func:`lyapunov`."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Optional

import numpy as np

from . import _layout
from ._afmdyn import Params
from ._common import (
    _DEFAULTS,
    Model,
    StateLike,
    _door,
    _params,
    _request,
    _start,
    _start_period,
    _state,
    _typed,
)
from ._progress import ProgressArg
from ._results import Lyapunov, Orbit

if TYPE_CHECKING:
    from typing_extensions import Unpack


@_typed
def orbit(
    params: Optional[Params] = None,
    /,
    *,
    period: Optional[int] = None,
    initial: StateLike = None,
    tol: float = _DEFAULTS["orbit"]["steady"]["tol"],
    max_periods: Optional[int] = None,
    max_period: int = _DEFAULTS["orbit"]["steady"]["max_period"],
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> Orbit:
    """A period-n orbit by Newton shooting, with Floquet multipliers (``afmdyn orbit``).

    Args:
        period: n (1..=64); default: the period of the steady state reached from rest (or
            the attractor's period when ``initial`` is an :class:`Attractor`), else 1.
        initial: start of Newton's iteration (``[2N]``, an :class:`Attractor` or an
            :class:`Orbit`); default: the steady state reached from rest.
        tol, max_periods, max_period: steady-state detection for the default start.

    Returns:
        :class:`Orbit`; ``to_dict()`` is ``afmdyn orbit --json``. Raises
        :class:`SimulationError` when Newton's method does not converge.

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    names = dict(locals())
    p, probe = _params(params, model)
    if period is None:
        period = _start_period(initial)
    req = _start(_request(names, period=period, initial=_state(initial)))
    d = _door("orbit", "orbit", progress, p, probe, req)
    doc = json.loads(d["json"])
    v = {k: x[1] for k, x in _layout.variables(d["datasets"]["orbit"]).items()}
    return Orbit(
        params=p,
        period=doc["period"],
        state=v["state"],
        section=v["section"],
        poincare_v_t=np.asarray(doc["poincare"]["v_t"], dtype=np.float64),
        poincare_w_tip=np.asarray(doc["poincare"]["w_tip"], dtype=np.float64),
        monodromy=v["monodromy"],
        multipliers=v["multipliers"],
        stable=doc["stable"],
        critical=doc["critical"],
        grazing=doc["grazing"],
        grazing_distance=doc["grazing_distance"],
        switchings=doc["switchings"],
        newton_residuals=v["newton_residuals"],
        _json=d["json"],
    )


@_typed
def lyapunov(
    params: Optional[Params] = None,
    /,
    *,
    initial: StateLike = None,
    transient: Optional[int] = None,
    periods: int = _DEFAULTS["lyapunov"]["periods"],
    blocks: int = _DEFAULTS["lyapunov"]["blocks"],
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> Lyapunov:
    """Lyapunov spectrum (tangent dynamics with saltation matrices) and the 0–1 test for chaos
    (``afmdyn lyapunov``), from ``initial`` (default rest) after ``transient`` drive periods,
    averaged over ``periods`` in ``blocks`` blocks (periods ≥ blocks ≥ 2).

    Returns:
        :class:`Lyapunov`; ``to_dict()`` is ``afmdyn lyapunov --json``.

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    req = _request(locals(), initial=_state(initial))
    p, probe = _params(params, model)
    d = _door("lyapunov", "lyapunov", progress, p, probe, req)
    doc = json.loads(d["json"])
    v = _layout.variables(d["datasets"]["lyapunov"])
    return Lyapunov(
        params=p,
        exponents=v["exponents"][1],
        uncertainty=v["uncertainty"][1],
        volume_rate=doc["volume_rate"],
        zero_one=float("nan") if doc["zero_one"] is None else doc["zero_one"],
        periods=doc["periods"],
        verdict=doc["verdict"],
        _json=d["json"],
    )
