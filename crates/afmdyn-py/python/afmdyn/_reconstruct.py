"""The tip–sample force behind a frequency-modulation curve (``afmdyn reconstruct``): the
library's Sader–Jarvis inversion, or its exact correction, as an ``xarray.Dataset`` in SI (the
public function is generated, :mod:`._wrappers_afm`)."""

from __future__ import annotations

import json
from typing import Any, Dict, Optional, Union

import numpy as np
import xarray as xr

from . import _afmdyn as _core
from ._common import _real_array, _warn
from ._progress import reporter


def _values(name: str, v: Optional[Any]) -> Optional[list]:
    return None if v is None else _real_array(name, v, 1).tolist()


def _finish_reconstruct(a: Dict[str, Any]) -> xr.Dataset:
    """Invert the curve of :func:`afmdyn.reconstruct`'s keywords ``a`` (its ``locals()``)."""
    fm, am, inversion, frequency_shift = a["fm"], a["am"], a["inversion"], a["frequency_shift"]
    consts = [(k, a[k]) for k in ("spring_constant", "amplitude", "resonance_frequency")]
    if am is not None:
        given = [n for n, v in [("fm", fm), ("frequency_shift", frequency_shift), *consts]
                 if v is not None]
        if given:
            raise ValueError(f"am: the approach curve carries its constants; {given[0]} not taken")
        if inversion != "sader-jarvis":
            raise ValueError("inversion: the AM curve is inverted by the matrix method")
        request: Dict[str, Any] = dict(am=_document(am))
    elif fm is not None:
        if any(a[k] is not None for k in ("frequency_shift", "distance", "z_c")):
            raise ValueError("fm: give the fm curve or frequency_shift with distance/z_c, not both")
        request = dict(fm=_document(fm), inversion=inversion,
                       **{k: None if v is None else float(v) for k, v in consts})
    else:
        for name in ("frequency_shift", "spring_constant", "resonance_frequency", "amplitude"):
            if a[name] is None:
                raise ValueError(f"{name}: missing (give the curve and k, f0, A, or fm=)")
        request = {k: _values(k, a[k]) for k in ("frequency_shift", "distance", "z_c")}
        request.update({k: float(v) for k, v in consts}, inversion=inversion)
    name = "reconstruct" if "frequency_shift" in request else "reconstruct_document"
    with reporter(a["progress"], "reconstruct") as cb:
        d = _core.run(name, request, None, None, cb)
    return _dataset(json.loads(d["json"]))


def _document(d: Union[xr.Dataset, Dict[str, Any]]) -> str:
    """The JSON text of a document given as its dataset or as a dict."""
    return d.attrs["summary"] if isinstance(d, xr.Dataset) else json.dumps(d)


#: The variables of a reconstruction: the document's ``force`` arrays, their units (the key of
#: the document's ``units``) and long names (``law`` only from an ``fm`` curve).
_VARIABLES = {
    "law": ("force", "the model's force at d (a curve from afmdyn.fm)"),
    "force": ("force", "tip–sample force F(d)"),
    "potential": ("potential", "potential U(d), integral of F from d to the last distance"),
}


def _dataset(doc: Dict[str, Any]) -> xr.Dataset:
    """The dataset of a reconstruction document, its warnings issued as
    :class:`afmdyn.AfmdynWarning`."""
    _warn(doc)
    f = doc["force"]
    units = doc["units"]
    return xr.Dataset(
        {
            name: ("distance", np.asarray(f[name]), {"units": units[unit], "long_name": long})
            for name, (unit, long) in _VARIABLES.items()
            if name in f
        },
        coords={"distance": ("distance", np.asarray(f["distance"]),
                             {"units": units["distance"],
                              "long_name": "distance of closest approach d"})},
        attrs={
            "spring_constant": doc["spring_constant"],
            "resonance_frequency": doc["resonance_frequency"],
            "amplitude": doc["amplitude"],
            "method": doc["method"],
            "inversion": doc.get("inversion", "matrix"),
            "summary": json.dumps(doc),
        },
    )
