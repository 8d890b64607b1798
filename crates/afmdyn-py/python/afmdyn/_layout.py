"""Results as the library lays them out (``afmdyn::layout::Layout``): every variable's name,
dimensions, units and long name are declared once in the library, which also writes the
command line's NetCDF files from the same declaration; this module turns a layout into an
``xarray.Dataset`` (with the accessor ``ds.afmdyn``) and gives the Dask Zarr writer its per-cell
variables."""

from __future__ import annotations

import json
from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import xarray as xr

#: One variable of a layout: (name, dims, units, long name, flat values, further attributes).
Variable = Tuple[str, List[str], str, str, Any, Dict[str, Any]]


def variables(
    layout: Dict[str, Any],
) -> Dict[str, Tuple[Tuple[str, ...], np.ndarray, Dict[str, Any]]]:
    """Every variable of ``layout`` as (dims, values reshaped to the dims, attributes)."""
    dims = dict(layout["dims"])
    out = {}
    for name, vdims, units, long_name, values, extra in layout["variables"]:
        shape = tuple(dims[d] for d in vdims)
        # words have no units (CF): an empty unit is left out
        attrs = {"long_name": long_name, **({"units": units} if units else {}), **extra}
        # words are str, also where there are none
        a = np.asarray(values, dtype=str) if isinstance(values, list) else np.asarray(values)
        out[name] = (tuple(vdims), a.reshape(shape), attrs)
    return out


def dataset(
    layout: Dict[str, Any],
    attrs: Optional[Dict[str, Any]] = None,
    coords: Tuple[str, ...] = (),
) -> xr.Dataset:
    """The ``xarray.Dataset`` of ``layout``: a variable named as its one dimension is that
    dimension's coordinate, and so is every one named in ``coords``; every other one a data
    variable."""
    data, coord = {}, {}
    for name, v in variables(layout).items():
        (coord if v[0] == (name,) or name in coords else data)[name] = v
    return xr.Dataset(data_vars=data, coords=coord, attrs=attrs or {})


def over(layout: Dict[str, Any], lead: Tuple[str, ...]) -> List[str]:
    """The names of the variables whose leading dimensions are ``lead`` (a chart's per-cell
    variables: ``("y", "x")``)."""
    n = len(lead)
    return [v[0] for v in layout["variables"] if tuple(v[1][:n]) == lead]


@xr.register_dataset_accessor("afmdyn")
class AfmdynAccessor:
    """``ds.afmdyn``: the command line's document of a dataset afmdyn returned."""

    def __init__(self, ds: xr.Dataset) -> None:
        self._ds = ds

    def to_dict(self) -> Dict[str, Any]:
        """The ``--json`` document for the same request (a new dict; Python-only analyses
        such as ``observe`` give the library's document). Raises KeyError for a dataset
        afmdyn did not make."""
        if "summary" not in self._ds.attrs:
            raise KeyError("this dataset carries no afmdyn document (attrs['summary'])")
        return json.loads(self._ds.attrs["summary"])
