"""The finishers of :func:`afmdyn.orbit` (Newton shooting, Floquet multipliers) and
:func:`afmdyn.lyapunov` (their public functions are generated, :mod:`._wrappers`)."""

from __future__ import annotations

import json
from typing import Any, Dict

import numpy as np

from . import _layout
from ._common import _door, _params, _request, _start, _start_period, _state
from ._results import Lyapunov, Orbit


def _finish_orbit(a: Dict[str, Any]) -> Orbit:
    p, probe = _params(a["params"], a["model"])
    period = a["period"]
    if period is None:  # an Attractor's own period
        period = _start_period(a["initial"])
    req = _start(_request(a, period=period, initial=_state(a["initial"])))
    d = _door("orbit", "orbit", a["progress"], p, probe, req)
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


def _finish_lyapunov(a: Dict[str, Any]) -> Lyapunov:
    req = _request(a, initial=_state(a["initial"]))
    p, probe = _params(a["params"], a["model"])
    d = _door("lyapunov", "lyapunov", a["progress"], p, probe, req)
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
