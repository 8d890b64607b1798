"""The constant-amplitude FM-AFM curve (``afmdyn fm``): the library's exact periodic orbits
under an ideal PLL and amplitude controller as an ``xarray.Dataset``, built from the library's
layout (``study::fm::layout``) and document (no numerics here)."""

from __future__ import annotations

import json
from typing import Any, Dict

import xarray as xr

from ._common import _door, _params, _request
from ._layout import dataset


def _finish_fm(a: Dict[str, Any]) -> xr.Dataset:
    """Run the curve of :func:`afmdyn.fm`'s keywords ``a`` (its ``locals()``): every array of
    the document's ``curve`` over ``z_c`` as the library lays them out; the document's
    constants as attributes, the document in ``attrs["summary"]``."""
    request = _request(a)
    p, probe = _params(a["params"], a["model"])
    d = _door("fm", "fm", a["progress"], p, probe, request)
    doc = json.loads(d["json"])
    attrs = {k: doc[k] for k in ("mode", "amplitude", "resonance_frequency", "spring_constant")}
    attrs.update(folds_z_c=[f["z_c"] for f in doc["folds"]], method=doc["method"],
                 summary=json.dumps(doc))
    return dataset(d["datasets"]["fm"], attrs)
