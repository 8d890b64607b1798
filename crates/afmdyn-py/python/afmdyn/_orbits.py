"""The finishers of :func:`afmdyn.orbit` (Newton shooting, Floquet multipliers) and
:func:`afmdyn.lyapunov` (their public functions are generated, :mod:`._wrappers`)."""

from __future__ import annotations

import json
from typing import Any, Dict

import numpy as np

from . import _layout
from ._common import _door, _params, _request, _start, _start_period, _state
from ._results import Lyapunov, Orbit


#: The fields of an :class:`Orbit` from its layout (arrays) and from its document.
_ORBIT_ARRAYS = ("state", "section", "monodromy", "multipliers", "newton_residuals")
_ORBIT_FACTS = ("period", "stable", "critical", "grazing", "grazing_distance", "switchings")


def _finish_orbit(a: Dict[str, Any]) -> Orbit:
    p, probe = _params(a["params"], a["model"])
    period = a["period"]
    if period is None:  # an Attractor's own period
        period = _start_period(a["initial"])
    req = _start(_request(a, period=period, initial=_state(a["initial"])))
    d = _door("orbit", "orbit", a["progress"], p, probe, req)
    doc = json.loads(d["json"])
    v = {k: x[1] for k, x in _layout.variables(d["datasets"]["orbit"]).items()}
    poincare = {f"poincare_{k}": np.asarray(doc["poincare"][k], dtype=np.float64)
                for k in ("v_t", "w_tip")}
    return Orbit(params=p, **{k: v[k] for k in _ORBIT_ARRAYS}, **poincare,
                 **{k: doc[k] for k in _ORBIT_FACTS}, _json=d["json"])


def _finish_lyapunov(a: Dict[str, Any]) -> Lyapunov:
    req = _request(a, initial=_state(a["initial"]))
    p, probe = _params(a["params"], a["model"])
    d = _door("lyapunov", "lyapunov", a["progress"], p, probe, req)
    doc = json.loads(d["json"])
    v = _layout.variables(d["datasets"]["lyapunov"])
    zero_one = float("nan") if doc["zero_one"] is None else doc["zero_one"]
    return Lyapunov(params=p, **{k: v[k][1] for k in ("exponents", "uncertainty")},
                    **{k: doc[k] for k in ("volume_rate", "periods", "verdict")},
                    zero_one=zero_one, _json=d["json"])
