"""Fitting a measured force curve (``afmdyn fit``): the library's preprocessing, least
squares, intervals and warnings, returned as an ``xarray.Dataset`` built from its document
and layouts (no numerics here)."""

from __future__ import annotations

import json
import os
from typing import TYPE_CHECKING, Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import xarray as xr

from ._afmdyn import Params
from ._common import Model, _door, _params
from ._layout import dataset
from ._progress import ProgressArg

if TYPE_CHECKING:  # annotations only (PEP 692)
    from typing_extensions import Unpack


def fit(
    params: Optional[Params] = None,
    /,
    *,
    data: Union[str, "os.PathLike[str]", Mapping[str, Sequence[float]], None] = None,
    fit: Optional[List[str]] = None,
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
            ``sigma`` (N); or a mapping (a ``pandas.DataFrame``, a dict) with those columns.
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
    if isinstance(data, (str, os.PathLike)):
        request["data"] = os.fspath(data)
    elif data is not None:
        for key in ("height", "force", "sigma"):
            if key in data:
                request[key] = [float(v) for v in np.asarray(data[key], dtype=float)]
    p, probe = _params(params, model)
    d = _door("fit", "fit", progress, p, probe, request)
    doc = json.loads(d["json"])
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
