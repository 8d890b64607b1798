"""Fitting a measured force curve (``afmdyn fit``): the library's preprocessing, least
squares, intervals and warnings, returned as an ``xarray.Dataset`` built from its document
and layouts (no numerics here)."""

from __future__ import annotations

import json
import os
import warnings
from typing import TYPE_CHECKING, Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import xarray as xr

from ._afmdyn import Params
from ._common import AfmdynWarning, Model, _door, _params
from ._layout import dataset
from ._progress import ProgressArg

if TYPE_CHECKING:  # annotations only (PEP 692)
    from typing_extensions import Unpack


def fit(
    params: Optional[Params] = None,
    /,
    *,
    data: Union[str, "os.PathLike[str]", Mapping[str, Sequence[float]], Any, None] = None,
    fit: Optional[List[str]] = None,
    curve: int = 0,
    approach_rows: Optional[int] = None,
    segment: str = "approach",
    fit_range: Optional[Tuple[float, float]] = None,
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Fit a quasi-static force curve with the probe's contact law (``afmdyn fit``; hertz,
    dmt or jkr), its contact point and baseline: nanite's preprocessing (tip position
    height + F/k, force and tip offsets at the contact point), Levenberg–Marquardt, standard
    errors, 95 % profile-likelihood intervals, correlations and identifiability warnings.

    Args:
        data: the force curve: a CSV file with the columns ``height`` (m, the piezo height,
            decreasing into the sample), ``force`` (N, repulsion positive) and optionally
            ``sigma`` (N); or a mapping (a ``pandas.DataFrame``, a dict) with those columns;
            or an instrument's curve read by afmformats (Müller et al.; JPK ``.jpk-force``,
            ``.jpk-force-map``, ``.jpk-qi-data``, Asylum ``.ibw``, afmformats ``.h5``/``.tab``):
            a file of those kinds, or an ``afmformats`` force-distance object (a
            ``nanite.Indentation`` too), whose ``height (measured)`` (else ``height
            (piezo)``) and ``force`` columns are taken.
        curve: which curve of an afmformats file with several (a force map), from 0.
        approach_rows: the number of rows of the approach (the rest is the retract); default
            the instrument's segments for an afmformats curve (its ``segment`` column), else
            up to the lowest height, inclusive.
        fit: the parameters fitted, by their probe keys (default ``sample.youngs_modulus``
            and ``contact_point``): also ``tip.radius``, ``baseline``, ``sample.hamaker``
            (dmt), ``sample.adhesion_energy`` (jkr). The others are held at the probe's.
        segment: ``"approach"`` (up to the lowest height) or ``"retract"``.
        fit_range: the tip positions fitted (lo, hi) in m, after the contact-point offset.
        probe: a probe file (a model keyword, as ``--probe``): required.

    Returns:
        An ``xarray.Dataset``: over ``row`` the fitted rows' ``tip_position``, ``force``,
        ``fit`` and ``residual``; over ``parameter`` the ``estimate``, ``standard_error``,
        ``interval_low`` and ``interval_high`` (95 %), and ``correlation`` over
        (``parameter``, ``parameter_2``); attributes ``chi2_dof``, ``noise`` and ``summary``
        (the ``afmdyn fit --json`` document). Warnings (a correlation above 0.99, a flat
        profile, an estimate at its bound, the noise estimated from the residuals) are raised
        as :class:`afmdyn.AfmdynWarning`.

    Raises:
        ValueError: naming the option, the data or the probe key.

    ``progress``: ``None``, ``True``, ``False`` or ``callable(done, total)``.
    """
    request: Dict[str, Any] = {"segment": segment}
    if fit is not None:
        request["fit"] = list(fit)
    if fit_range is not None:
        request["range"] = [float(fit_range[0]), float(fit_range[1])]
    data, k_file, segments = _instrument_curve(data, curve)
    if approach_rows is None:
        approach_rows = segments
    if approach_rows is not None:
        request["approach_rows"] = int(approach_rows)
    if isinstance(data, (str, os.PathLike)):
        request["data"] = os.fspath(data)
    elif data is not None:
        for key in ("height", "force", "sigma"):
            if key in data:
                request[key] = [float(v) for v in np.asarray(data[key], dtype=float)]
    p, probe = _params(params, model)
    d = _door("fit", "fit", progress, p, probe, request)
    doc = json.loads(d["json"])
    k = doc["preprocessing"]["spring_constant"]
    if k_file and abs(k_file / k - 1) > 0.01:
        warnings.warn(f"the file's spring constant {k_file:g} N/m differs from the probe's "
                      f"{k:g} N/m: the probe's is used (set [cantilever] spring_constant to "
                      "the file's to use it)", AfmdynWarning, stacklevel=2)
    ds = xr.merge([dataset(layout) for layout in d["datasets"].values()], combine_attrs="drop")
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
_AFMFORMATS = (".jpk-force", ".jpk-force-map", ".jpk-qi-data", ".jpk-qi-series", ".ibw", ".h5",
               ".tab", ".zip")
# the largest instrument file read (a JPK force map of 128 × 128 curves is ~ 0.5 GiB)
_MAX_INSTRUMENT_FILE = 1 << 30


def _instrument_curve(data: Any, curve: int) -> Tuple[Any, Optional[float], Optional[int]]:
    """``data`` as :func:`fit` takes it, the spring constant (N/m) its file states and the rows
    of its approach: an afmformats file or object becomes the mapping of its ``height``
    (``height (measured)``, else ``height (piezo)``, m) and ``force`` (N) columns, its approach
    the leading rows of its ``segment`` column that are 0; anything else is returned as it is."""
    if isinstance(data, (str, os.PathLike)):
        if not os.fspath(data).lower().endswith(_AFMFORMATS):
            return data, None, None
        try:
            import afmformats
        except ImportError as e:
            raise ValueError(f"data: reading {os.fspath(data)!r} needs the afmformats package "
                             "(pip install afmformats)") from e
        try:
            size = os.stat(data).st_size
        except OSError as e:
            raise ValueError(f"data: {os.fspath(data)!r}: {e.strerror}") from e
        if size > _MAX_INSTRUMENT_FILE:
            raise ValueError(f"data: {os.fspath(data)!r} is {size} bytes, over the "
                             f"{_MAX_INSTRUMENT_FILE >> 20} MiB read for one instrument file")
        curves = afmformats.load_data(os.fspath(data))
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
    return {"height": np.asarray(data[heights[0]], dtype=float),
            "force": np.asarray(data["force"], dtype=float)}, k_file, approach

