"""Off-resonance (PeakForce) tapping (``afmdyn peakforce``): the library's steady tap of the
modulation period as an ``xarray.Dataset`` built from its layouts (no numerics here; the
public function is generated, :mod:`._wrappers_afm`)."""

from __future__ import annotations

import json
from typing import Any, Dict

import xarray as xr

from ._common import _door, _params, _request
from ._layout import dataset


def _finish_peakforce(a: Dict[str, Any]) -> xr.Dataset:
    z_c, fit_band, modulation_frequency = a["z_c"], a["fit_band"], a["modulation_frequency"]
    request = _request(a)
    if fit_band is None:
        del request["fit_band"]
    del request["modulation_frequency"]
    if modulation_frequency is not None:
        values = [float(v) for v in modulation_frequency]
        request["sweep"] = {"quantity": "modulation_frequency", "values": values}
    elif z_c is not None and not isinstance(z_c, (int, float)):
        request["sweep"] = {"quantity": "z_c", "values": [float(v) for v in z_c]}
        request["z_c"] = None
    p, probe = _params(a["params"], a["model"])
    d = _door("peakforce", "peakforce", a["progress"], p, probe, request)
    doc = json.loads(d["json"])
    ds = xr.merge(
        [dataset(layout) for layout in d["datasets"].values()], combine_attrs="drop_conflicts"
    )
    if doc.get("sweep") is None:
        ds.attrs = {k: v for k, v in doc["channels"].items() if v is not None}
        # the thermal block's σ beside the channels they are the noise of (with temperature)
        for k in ("peak_force_noise", "deformation_noise"):
            if (doc.get("thermal") or {}).get(k) is not None:
                ds.attrs[k] = doc["thermal"][k]
    else:
        ds.attrs = {}
    ds.attrs["summary"] = json.dumps(doc)
    return ds
