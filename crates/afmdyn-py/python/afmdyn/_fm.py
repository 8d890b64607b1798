"""The constant-amplitude FM-AFM curve (``afmdyn fm``): the library's exact periodic orbits
under an ideal PLL and amplitude controller as an ``xarray.Dataset``, built from the library's
JSON document (no numerics here)."""

from __future__ import annotations

import json
from typing import Any, Dict

import numpy as np
import xarray as xr

from ._common import _door, _params, _request

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


def _finish_fm(a: Dict[str, Any]) -> xr.Dataset:
    request = _request(a)
    p, probe = _params(a["params"], a["model"])
    d = _door("fm", "fm", a["progress"], p, probe, request)
    return fm_dataset(json.loads(d["json"]))
