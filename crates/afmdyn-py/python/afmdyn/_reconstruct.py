"""The tip–sample force behind a frequency-modulation curve (``afmdyn reconstruct``): the
library's Sader–Jarvis inversion, or its exact correction, as an ``xarray.Dataset`` in SI (the
public function is generated, :mod:`._wrappers_afm`)."""

from __future__ import annotations

import json
from typing import Any, Dict, Optional, Union

import xarray as xr

from . import _afmdyn as _core
from ._common import _real_array, _warn
from ._layout import dataset
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
    return _dataset(d)


def _document(d: Union[xr.Dataset, Dict[str, Any]]) -> str:
    """The JSON text of a document given as its dataset or as a dict."""
    return d.attrs["summary"] if isinstance(d, xr.Dataset) else json.dumps(d)


def _dataset(d: Dict[str, Any]) -> xr.Dataset:
    """The dataset of a reconstruction's outcome ``d`` (``_afmdyn.run``'s): its layout
    ``reconstruct``, the document's constants as attributes; its warnings issued as
    :class:`afmdyn.AfmdynWarning`."""
    doc = json.loads(d["json"])
    _warn(doc)
    attrs = {k: doc[k] for k in ("spring_constant", "resonance_frequency", "amplitude", "method")}
    attrs.update(inversion=doc.get("inversion", "matrix"), summary=json.dumps(doc))
    return dataset(d["datasets"]["reconstruct"], attrs)
