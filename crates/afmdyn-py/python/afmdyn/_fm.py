"""The constant-amplitude FM-AFM curve (``afmdyn fm``): the library's exact periodic orbits
under an ideal PLL and amplitude controller as an ``xarray.Dataset``, built from the library's
JSON document (no numerics here)."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any, Dict, Optional

import numpy as np
import xarray as xr

from ._afmdyn import Params
from ._common import _DEFAULTS, Model, _door, _params, _request, _typed
from ._progress import ProgressArg

if TYPE_CHECKING:  # annotations only (PEP 692)
    from typing_extensions import Unpack

#: The long names of the curve's variables (the document's ``curve`` arrays).
_LONG = {
    "frequency_shift": "frequency shift Δf = f − f_K",
    "frequency": "drive frequency the PLL locks at",
    "excitation": "excitation relative to the free lever's at its resonance",
    "amplitude": "first-harmonic amplitude A1",
    "phase_deg": "lag of the first harmonic behind the drive",
    "energy_dissipated": "energy dissipated in the sample per cycle",
    "virial": "virial ⟨F_c W⟩",
    "mean_deflection": "mean deflection",
    "min_distance": "tip–sample distance at the lower turning point",
    "peak_force": "largest tip–sample force",
    "mean_force": "mean tip–sample force",
    "law_force": "the law's conservative force at the lower turning point",
    "indentation": "largest indentation",
    "max_multiplier": "largest Floquet multiplier modulus under the locked drive",
    "stable": "Floquet-stable under the locked drive",
    "loop_residual": "loop residual max(|A1/A − 1|, |φ1 − φ_set|)",
    "iterations": "Newton iterations on (Ω, α2)",
}


def fm_dataset(doc: Dict[str, Any]) -> xr.Dataset:
    """The dataset of an ``afmdyn fm`` document: every array of ``curve`` over ``z_c``, units
    from the document's ``units``; the document in ``attrs["summary"]``."""
    units: Dict[str, str] = doc["units"]
    curve = doc["curve"]
    data = {}
    for name, long in _LONG.items():
        values = np.asarray(curve[name])
        attrs = {"long_name": long}
        if name in units:
            attrs["units"] = units[name]
        elif name == "phase_deg":
            attrs["units"] = "deg"
        data[name] = ("z_c", values, attrs)
    return xr.Dataset(
        data,
        coords={"z_c": ("z_c", np.asarray(curve["z_c"], dtype=np.float64),
                        {"units": units["z_c"], "long_name": "rest distance z_c"})},
        attrs={
            "mode": doc["mode"],
            "amplitude": doc["amplitude"],
            "resonance_frequency": doc["resonance_frequency"],
            "spring_constant": doc["spring_constant"],
            "folds_z_c": [f["z_c"] for f in doc["folds"]],
            "method": doc["method"],
            "summary": json.dumps(doc),
        },
    )


@_typed
def fm(
    params: Optional[Params] = None,
    /,
    *,
    amplitude: Optional[float] = None,
    mode: int = _DEFAULTS["fm"]["mode"],
    from_: Optional[float] = None,
    to: Optional[float] = None,
    step: Optional[float] = None,
    points: Optional[int] = None,
    tolerance: float = _DEFAULTS["fm"]["tolerance"],
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """The frequency-modulation (FM-AFM) curve at constant amplitude over the rest distance
    z_c (``afmdyn fm``): at each z_c the exact periodic orbit of the cantilever driven at the
    frequency where its first harmonic lags the drive by the free lever's phase at resonance
    (an ideal PLL), with the excitation that holds the first-harmonic amplitude at ``amplitude``
    (an ideal amplitude controller), continued from the previous z_c.

    Args:
        amplitude: the oscillation amplitude A (m with ``probe``, else g₀; default the probe's
            free amplitude A₀).
        mode: the mode K the PLL tracks (1..N).
        from_, to: the z_c range, m with ``probe``, else g₀ (default: from where the frequency
            shift has decayed to 0.5 % of its value at ``to`` — Giessibl's first-order shift of
            the law's force; 2A + a₀ for a law without a force before contact — down to
            A + a₀, the lower turning point at the contact distance a₀).
        step, points: the grid (a step in the same unit, or the number of values; default 120).
        tolerance: of the loop conditions, |A₁/A − 1| and the phase error (rad).
        probe: a probe file (a model keyword, as ``--probe``): SI inputs and outputs.

    Returns:
        An ``xarray.Dataset`` over ``z_c``: ``frequency_shift`` (Hz with a probe),
        ``frequency``, ``excitation`` (relative to the free lever's), ``amplitude``,
        ``phase_deg``, ``energy_dissipated``, ``virial``, ``mean_deflection``,
        ``min_distance``, ``peak_force``, ``mean_force``, ``indentation``,
        ``max_multiplier``, ``stable``, ``loop_residual``, ``iterations``; attributes
        ``spring_constant``, ``resonance_frequency``, ``amplitude``, ``mode``, ``folds_z_c``
        and ``summary`` (the ``afmdyn fm --json`` document). A z_c not reached ends the curve
        with an :class:`afmdyn.AfmdynWarning`. ``afmdyn.reconstruct(fm=ds)`` inverts it.

    Raises:
        ValueError: naming the option (``amplitude``, ``mode``, ``tolerance``, ``from``, ``to``,
            ``step``, ``points``) or the model parameter.

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    request = _request(locals())
    p, probe = _params(params, model)
    d = _door("fm", "fm", progress, p, probe, request)
    return fm_dataset(json.loads(d["json"]))
