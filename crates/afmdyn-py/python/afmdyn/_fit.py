"""Fitting a measured force curve (``afmdyn fit``): the library's preprocessing, least
squares, intervals and warnings, returned as an ``xarray.Dataset`` built from its document
and layouts (no numerics here; the public function is generated, :mod:`._wrappers_afm`)."""

from __future__ import annotations

import json
import os
import warnings
from typing import Any, Dict, List, Mapping, Optional, Tuple

import numpy as np
import xarray as xr

from ._common import AfmdynWarning, _door, _params, _request, _user_level
from ._layout import dataset


#: the keywords of :func:`afmdyn.fit` that are not the request's as they are
_OWN = ("data", "curve", "fit", "fit_range", "approach_rows")


def _finish_fit(a: Dict[str, Any]) -> xr.Dataset:
    """Fit the curve of :func:`afmdyn.fit`'s keywords ``a`` (its ``locals()``)."""
    request = {k: v for k, v in _request(a).items() if v is not None and k not in _OWN}
    fit, fit_range, approach_rows = a["fit"], a["fit_range"], a["approach_rows"]
    if fit is not None:
        request["fit"] = list(fit)
    if fit_range is not None:
        request["range"] = [float(fit_range[0]), float(fit_range[1])]
    _check_data(a["data"])
    data, k_file, segments = _instrument_curve(a["data"], a["curve"])
    if approach_rows is None:
        approach_rows = segments
    if approach_rows is not None:
        request["approach_rows"] = int(approach_rows)
    if isinstance(data, (str, os.PathLike)):
        request["data"] = os.fspath(data)
    elif data is not None:
        for key in ("height", "force", "sigma", "time"):
            if key in data:
                request[key] = [float(v) for v in np.asarray(data[key], dtype=float)]
    # a force curve uses the probe's spring constant, tip and sample (the library refuses
    # an AM, FM or bimodal curve's fit on a probe read so)
    p, probe = _params(a["params"], a["model"], quasi_static=True)
    d = _door("fit", "fit", a["progress"], p, probe, request)
    doc = json.loads(d["json"])
    k = doc["preprocessing"]["spring_constant"]
    if k_file and abs(k_file / k - 1) > 0.01:
        warnings.warn(f"the file's spring constant {k_file:g} N/m differs from the probe's "
                      f"{k:g} N/m: the probe's is used (set [cantilever] spring_constant to "
                      "the file's to use it)", AfmdynWarning, stacklevel=_user_level())
    # (the variables keep their units and labels; the Dataset's attributes are set below)
    ds = xr.merge([dataset(layout) for layout in d["datasets"].values()],
                  combine_attrs="drop_conflicts")
    names = list(doc["estimates"])
    est = [doc["estimates"][n] for n in names]

    def col(key: str, i: Optional[int] = None) -> List[float]:
        vals = [e[key] if i is None else e[key][i] for e in est]
        return [np.nan if v is None else float(v) for v in vals]

    ds = ds.assign_coords(parameter=names, parameter_2=names)
    ds["estimate"] = ("parameter", col("value"))
    ds["standard_error"] = ("parameter", col("standard_error"))
    ds["interval_low"] = ("parameter", col("interval", 0))
    ds["interval_high"] = ("parameter", col("interval", 1))
    matrix = [[np.nan if v is None else v for v in row] for row in doc["correlation"]["matrix"]]
    shape = (len(names), len(names))
    ds["correlation"] = (("parameter", "parameter_2"), np.array(matrix, dtype=float).reshape(shape))
    ds.attrs = {"chi2_dof": doc["chi2_dof"], "noise": doc["noise"], "law": doc["law"]}
    ds.attrs["summary"] = json.dumps(doc)
    return ds


# the instrument formats read through afmformats (its ``supported_extensions`` without the
# plain-text ones, which are afmdyn's own CSV here)
def _check_data(data: Any) -> None:
    """A ``TypeError`` naming ``data`` for what is no curve: a path, a mapping of columns or a
    table with columns (pandas, afmformats) is one."""
    if data is None or isinstance(data, (str, os.PathLike, Mapping)) or hasattr(data, "columns"):
        return
    raise TypeError(f"fit(): data must be a path, a mapping of columns (height, force, …) or a "
                    f"table with columns (pandas, afmformats), got {type(data).__name__} {data!r}")


_AFMFORMATS = (".jpk-force", ".jpk-force-map", ".jpk-qi-data", ".jpk-qi-series", ".ibw", ".h5",
               ".tab", ".zip")
# the largest instrument file read (a JPK force map of 128 × 128 curves is ~ 0.5 GiB)
_MAX_INSTRUMENT_FILE = 1 << 30


def _instrument_file(path: "os.PathLike[str] | str") -> List[Any]:
    """The curves of the instrument file ``path``, read by afmformats (its size capped first).

    Raises:
        ValueError: naming ``data``: afmformats missing, the file unreadable or too large.
    """
    try:
        import afmformats
    except ImportError as e:
        raise ValueError(f"data: reading {os.fspath(path)!r} needs the afmformats package "
                         "(pip install afmformats)") from e
    try:
        size = os.stat(path).st_size
    except OSError as e:
        raise ValueError(f"data: {os.fspath(path)!r}: {e.strerror}") from e
    if size > _MAX_INSTRUMENT_FILE:
        raise ValueError(f"data: {os.fspath(path)!r} is {size} bytes, over the "
                         f"{_MAX_INSTRUMENT_FILE >> 20} MiB read for one instrument file")
    return list(afmformats.load_data(os.fspath(path)))


def _instrument_curve(data: Any, curve: int) -> Tuple[Any, Optional[float], Optional[int]]:
    """``data`` as :func:`fit` takes it, the spring constant (N/m) its file states and the rows
    of its approach: an afmformats file or object becomes the mapping of its ``height``
    (``height (measured)``, else ``height (piezo)``, m), ``force`` (N) and, where it has
    one, ``time`` (s; the ``sls`` law needs it) columns, its approach
    the leading rows of its ``segment`` column that are 0; anything else is returned as it is."""
    if isinstance(data, (str, os.PathLike)):
        if not os.fspath(data).lower().endswith(_AFMFORMATS):
            return data, None, None
        curves = _instrument_file(data)
        if not 0 <= curve < len(curves):
            raise ValueError(f"curve: {curve} is not in 0..{len(curves) - 1} "
                             f"(the file holds {len(curves)} curve(s))")
        data = curves[curve]
    columns = getattr(data, "columns", None)
    if columns is None or isinstance(data, Mapping) or "force" not in columns \
            or "height" in columns:  # (a DataFrame of afmdyn's own columns)
        return data, None, None
    heights = [c for c in ("height (measured)", "height (piezo)") if c in columns]
    if not heights:
        raise ValueError("data: the afmformats curve has no 'height (measured)' or "
                         "'height (piezo)' column")
    k_file = getattr(data, "metadata", {}).get("spring constant")
    approach = None
    if "segment" in columns:
        retract = np.flatnonzero(np.asarray(data["segment"]) != 0)
        # (no retract, or a curve that starts retracting: the library's default)
        approach = int(retract[0]) if retract.size and retract[0] > 0 else None
    out = {"height": np.asarray(data[heights[0]], dtype=float),
           "force": np.asarray(data["force"], dtype=float)}
    if "time" in columns:
        out["time"] = np.asarray(data["time"], dtype=float)
    return out, k_file, approach

