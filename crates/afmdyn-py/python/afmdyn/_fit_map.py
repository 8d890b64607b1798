"""Fitting a force map (``afmdyn fit-map``): every curve of a force-volume or QI map fitted by
the library, the results over the map's grid as an ``xarray.Dataset`` (no numerics here; the
public :func:`afmdyn.fit_map` is generated, :mod:`._wrappers_afm`), and
:func:`export_map`, which writes any map afmformats reads (or curves given as arrays) as the
NetCDF file the library streams."""

from __future__ import annotations

import json
import os
import tempfile
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Union

import numpy as np
import xarray as xr

from ._common import _door, _params, _request
from ._fit import _AFMFORMATS, _instrument_file
from ._layout import dataset

#: the keywords of :func:`afmdyn.fit_map` that are not the request's as they are
_OWN = ("data", "fit", "fit_range", "store", "resume", "progress")


def _map_request(a: Dict[str, Any]) -> Dict[str, Any]:
    """The request of :func:`afmdyn.fit_map`'s keywords ``a`` (also
    :func:`afmdyn.dask.fit_map`'s), but its ``data``."""
    request = {k: v for k, v in _request(a).items() if v is not None and k not in _OWN}
    request.pop("client", None)
    if a["fit"] is not None:
        request["fit"] = list(a["fit"])
    if a["fit_range"] is not None:
        request["range"] = [float(a["fit_range"][0]), float(a["fit_range"][1])]
    return request


def _map_dir(store: Any, tmp: str) -> str:
    """Where curves given as data are exported: into the store (a resumed run reads the same
    file), else ``tmp``."""
    if store is None:
        return tmp
    where = os.fspath(store)
    os.makedirs(where, exist_ok=True)
    return where


def _finish_fit_map(a: Dict[str, Any]) -> xr.Dataset:
    """Fit the map of :func:`afmdyn.fit_map`'s keywords ``a`` (its ``locals()``)."""
    request = _map_request(a)
    p, probe = _params(a["params"], a["model"], quasi_static=True)
    with tempfile.TemporaryDirectory(prefix="afmdyn-map-") as tmp:
        request["data"] = _map_file(a["data"], _map_dir(a["store"], tmp))
        d = _door("fit_map", "curves", a["progress"], p, probe, request, a["store"],
                  a["resume"], stored=True)
    return _map_dataset(d)


def _map_dataset(d: Dict[str, Any]) -> xr.Dataset:
    """The Dataset of a fitted map's outcome ``d`` (as ``_afmdyn.run`` returns it)."""
    doc = json.loads(d["json"])
    ds = dataset(d["datasets"]["fit_map"], {"law": doc["law"], "summary": json.dumps(doc)})
    flag = ds["flag"]
    meanings = dict(zip(flag.attrs["flag_values"], flag.attrs["flag_meanings"].split()))
    names = np.array([meanings.get(int(c), "") for c in flag.values.ravel()])
    attrs = {k: v for k, v in flag.attrs.items() if not k.startswith("flag_")}
    ds["flag"] = (flag.dims, names.reshape(flag.shape), attrs)
    return ds


def _map_file(data: Any, tmp: str) -> str:
    """The path of the map ``data`` as the library reads it: a CSV or NetCDF file as it is; an
    instrument file, afmformats' curves or arrays written by :func:`export_map` into ``tmp``."""
    if isinstance(data, (str, os.PathLike)) and not os.fspath(data).lower().endswith(_AFMFORMATS):
        return os.fspath(data)
    if data is None:
        raise ValueError("data: a map is needed: an instrument file afmformats reads, a "
                         "long-format CSV (x, y, height, force) or a NetCDF file of export_map")
    return os.fspath(export_map(data, os.path.join(tmp, "map.nc")))


def _curves(data: Any) -> List[Any]:
    """The curves of ``data``: an instrument file read by afmformats, or the sequence given."""
    if isinstance(data, (str, os.PathLike)):
        return _instrument_file(data)
    if isinstance(data, Mapping) or not isinstance(data, Iterable):
        raise TypeError(f"export_map(): data must be an instrument file, afmformats' curves or "
                        f"a sequence of curves (mappings with x, y, height, force), got "
                        f"{type(data).__name__}")
    return list(data)


def _column(curve: Any, names: Sequence[str]) -> Optional[np.ndarray]:
    """The first of the columns ``names`` that ``curve`` (a mapping or an afmformats curve)
    has, as floats; ``None`` when it has none."""
    columns = getattr(curve, "columns", None)
    for n in names:
        if (n in curve) if columns is None else (n in columns):
            return np.asarray(curve[n], dtype=float)
    return None


def _meta(curve: Any, key: str, fallback: str) -> Optional[float]:
    """A curve's ``key``: afmformats' metadata (``key``) or a mapping's entry (``fallback``)."""
    meta = getattr(curve, "metadata", None)
    if meta is not None and meta.get(key) is not None:
        return float(meta[key])
    if isinstance(curve, Mapping) and curve.get(fallback) is not None:
        return float(np.asarray(curve[fallback]).ravel()[0])
    return None


def export_map(
    data: Union[str, "os.PathLike[str]", Sequence[Any]],
    path: Union[str, "os.PathLike[str]"],
) -> "os.PathLike[str]":
    """Write a force map as the NetCDF-3 file ``afmdyn fit-map --data`` streams.

    Args:
        data: an instrument file afmformats reads (JPK ``.jpk-force-map``, ``.jpk-qi-data``, …;
            each curve's grid index, position and spring constant from its metadata), a list of
            afmformats force-distance curves, or a sequence of mappings with ``height`` (m),
            ``force`` (N), ``x``, ``y`` (m) and optionally ``ix``, ``iy`` (grid indices),
            ``segment`` (0 approach, 1 retract), ``time`` (s) and ``spring_constant`` (N/m).
        path: the file written (NetCDF-3, 64-bit offsets; the curves along the unlimited
            dimension ``curve``, their rows along ``row``, padded with NaN).

    Returns:
        ``path``, as a :class:`pathlib.Path`.

    Raises:
        ValueError: a curve without ``height`` or ``force``, or without a position.
    """
    from pathlib import Path

    from scipy.io import netcdf_file

    curves = _curves(data)
    if not curves:
        raise ValueError("data: no curve")
    rows = max(len(_column(c, ("force",)) if _column(c, ("force",)) is not None else []) for c in curves)
    has_time = all(_column(c, ("time",)) is not None for c in curves)
    out = Path(path)
    with netcdf_file(out, "w", version=2) as f:
        f.createDimension("curve", None)
        f.createDimension("row", rows)
        per_curve = {"x": "d", "y": "d", "ix": "i", "iy": "i", "rows": "i", "approach_rows": "i",
                     "spring_constant": "d"}
        v = {n: f.createVariable(n, t, ("curve",)) for n, t in per_curve.items()}
        for n in ("height", "force") + (("time",) if has_time else ()):
            v[n] = f.createVariable(n, "d", ("curve", "row"))
        for i, c in enumerate(curves):
            height = _column(c, ("height (measured)", "height (piezo)", "height"))
            force = _column(c, ("force",))
            if height is None or force is None:
                raise ValueError(f"data: curve {i} has no height or force column")
            x, y = _meta(c, "position x", "x"), _meta(c, "position y", "y")
            if x is None or y is None:
                raise ValueError(f"data: curve {i} has no position (x, y)")
            ix, iy = _meta(c, "grid index x", "ix"), _meta(c, "grid index y", "iy")
            segment = _column(c, ("segment",))
            approach = 0
            if segment is not None:
                retract = np.flatnonzero(segment != 0)
                approach = int(retract[0]) if retract.size else len(segment)
            n = len(force)
            pad = np.full(rows, np.nan)
            for name, col in (("height", height), ("force", force)):
                pad[:] = np.nan
                pad[:n] = col
                v[name][i] = pad
            if has_time:
                pad[:] = np.nan
                pad[:n] = _column(c, ("time",))
                v["time"][i] = pad
            k = _meta(c, "spring constant", "spring_constant")
            for name, value in (("x", x), ("y", y), ("rows", n), ("approach_rows", approach),
                                ("spring_constant", k or 0.0)):
                v[name][i] = value
            # without grid indices, the CSV's rule: the positions' rank (set after all curves)
            v["ix"][i] = -1 if ix is None else int(ix)
            v["iy"][i] = -1 if iy is None else int(iy)
        for axis, pos in (("ix", "x"), ("iy", "y")):
            if (v[axis][:] < 0).any():
                values = np.asarray(v[pos][:])
                v[axis][:] = np.searchsorted(np.unique(values), values)
    return out
