"""Images of a heterogeneous sample (``afmdyn image``): the library's AM image (ideal or PI
feedback) or PeakForce image (ideal peak-force feedback) as an ``xarray.Dataset`` in SI."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np
import xarray as xr

from . import _afmdyn as _core
from . import _layout
from ._common import _real_array, _typed, _warn
from ._progress import ProgressArg, reporter

def _keywords(probe: Any, sample: Any, setpoint: float, pixels: Optional[int],
             lines: Optional[int], curve_points: Optional[int], height_map: Any,
             feedback: str, scan_rate: Optional[float], gains: Optional[Sequence[float]],
             time_constant: Optional[float], threads: Optional[int],
             mode: str = "am") -> Tuple[str, Dict[str, Any]]:
    """The probe's TOML text and the library's ``ImageKeywords`` of an image's arguments."""
    rows = None
    if isinstance(height_map, (str, os.PathLike)):
        # a .csv or .npy file, read and checked by the library as the TOML key's file is
        rows = _core.read_height_map(os.fspath(height_map))
    elif height_map is not None:
        rows = _real_array("height_map", height_map, 2).tolist()
    if gains is not None and len(gains) != 2:
        raise ValueError("gains: must be two numbers (K_P, K_I in 1/s)")
    pi = dict(scan_rate=scan_rate, time_constant=time_constant,
              gains=None if gains is None else [float(g) for g in gains])
    request = dict(sample=os.fspath(sample) if isinstance(sample, os.PathLike) else sample,
                   setpoint=setpoint, pixels=pixels, lines=lines, curve_points=curve_points,
                   height_map=rows, feedback=pi if feedback == "pi" else None, threads=threads,
                   mode=None if mode == "am" else mode)
    return _core.probe_source(probe), request


@_typed
def image(
    probe: Union[str, "os.PathLike[str]", Dict[str, Any]],
    sample: Union[str, "os.PathLike[str]"],
    setpoint: float,
    *,
    pixels: Optional[int] = None,
    lines: Optional[int] = None,
    curve_points: Optional[int] = None,
    height_map: Optional[Any] = None,
    feedback: str = "ideal",
    scan_rate: Optional[float] = None,
    gains: Optional[Tuple[float, float]] = None,
    time_constant: Optional[float] = None,
    threads: Optional[int] = None,
    mode: str = "am",
    progress: ProgressArg = None,
) -> xr.Dataset:
    """The image an amplitude feedback records over a heterogeneous sample
    (``afmdyn image``). ``feedback="ideal"``: at every pixel the operating point of the local
    material where the amplitude equals the setpoint, the regime kept from the previous pixel
    where the material allows it, each line engaged from far. ``feedback="pi"``: each line
    scanned in the time domain, trace and retrace, under a lock-in and a PI z controller
    updating once per drive period (``scan_rate`` in Hz, ``gains`` = (K_P, K_I in 1/s),
    ``time_constant`` of the lock-in in s, refused above 1000 s and warned outside
    1 µs–0.1 s; ``None`` for the lever's defaults), its lines on ``threads`` cores with
    ``progress``; Ctrl-C stops it. ``mode="peakforce"`` (an off-resonance probe): the image
    an ideal peak-force feedback records, ``setpoint`` the peak force (N), each pixel's steady
    tap exact (issue 61 §3), its lines on ``threads`` cores.

    Args:
        probe: the probe (path, TOML text or dict, as ``afmdyn.probe``): the lever, tip,
            drive and the background sample.
        sample: the sample map (path or TOML text): ``size = [Lx, Ly]`` (m) and ``[[domain]]``
            entries with ``name``, ``x``, ``y``, ``height`` (m) and ``[domain.sample]``; its
            ``height_map`` the rows inline or a ``.csv`` / ``.npy`` file (a relative path from
            the sample file's directory, or from the current one for TOML text).
        setpoint: A_sp/A0 in (0, 1); with ``mode="peakforce"`` the peak force (N).
        pixels: pixels per line (default 64). lines: lines (default: as many as pixels, 1 for
            a line map). curve_points: points of each material's approach curve (default 120).
        height_map: a 2D array of heights (m), rows from y = 0 to Ly and columns from x = 0 to
            Lx, interpolated bilinearly and added to the map's topography (replaces the map's
            own ``height_map``); or the path of a ``.csv`` or ``.npy`` file holding them.

    Returns:
        ``xarray.Dataset`` over ``y`` and ``x`` (m): ``height``, ``true_height``, ``z_c``,
        ``amplitude``, ``phase_deg``, ``energy_dissipated``, ``virial``, ``peak_force``,
        ``indentation`` (NaN where the setpoint is not reached; units and long names as the
        library lays them out, the variables of ``afmdyn image``'s ``image.nc``), ``regime``,
        ``material`` and ``domain`` (strings); attributes ``setpoint``, ``reference_z_c`` (m) and ``summary``
        (the command line's JSON document, with each material's operating points).

        With ``feedback="pi"``: the recorded trace ``height``, ``amplitude``, ``phase_deg``,
        ``tracking_error``, ``energy_dissipated``, ``virial``, ``peak_force``, ``indentation``
        and ``lost_contact``, the same with ``_retrace``, ``ideal_height`` and
        ``true_height`` (m); attributes ``scan`` (the settings) and ``artefacts`` (JSON: per
        direction the height error against the ideal image, the overshoot, the error image's
        RMS, the pixels that lost contact).

        With ``mode="peakforce"``: ``height``, ``true_height``, ``z_c``, ``peak_force``,
        ``modulus_dmt``, ``adhesion``, ``deformation``, ``dissipation``, ``taps_per_cycle``,
        ``evaluations`` (steady taps computed at the pixel), ``material`` and ``domain``, as
        ``image.nc`` of ``afmdyn image --mode peakforce``.

    Raises:
        ValueError: naming the field — a setpoint outside (0, 1), pixels or lines outside
            1..=4096 (lines = 1 for a line map), a sample map's key, a scan setting
            (scan_rate, gains, time_constant).
    """
    if mode not in ("am", "peakforce"):
        raise ValueError(f"mode = {mode!r}: must be 'am' or 'peakforce'")
    if mode == "peakforce" and (feedback != "ideal" or curve_points is not None):
        raise ValueError("feedback, curve_points: not with mode='peakforce' (its ideal "
                         "peak-force feedback engages each material by its own setpoint search)")
    if feedback not in ("ideal", "pi"):
        raise ValueError(f"feedback = {feedback!r}: must be 'ideal' or 'pi'")
    if feedback == "ideal" and any(
        v is not None for v in (scan_rate, gains, time_constant)
        + ((threads,) if mode == "am" else ())
    ):
        raise ValueError(
            "scan_rate, gains, time_constant, threads: only with feedback='pi' "
            "(the ideal feedback has no loop)"
        )
    text, request = _keywords(probe, sample, setpoint, pixels, lines, curve_points, height_map,
                              feedback, scan_rate, gains, time_constant, threads, mode)
    lines_progress = feedback == "pi" or mode == "peakforce"
    with reporter(progress if lines_progress else False, "image", unit="line") as cb:
        out = _core.image(text, request, cb)
    return _dataset(out, setpoint)


def _dataset(out: Dict[str, Any], setpoint: float) -> xr.Dataset:
    """The Dataset of an image (as ``_afmdyn.run`` returns it: the per-pixel document, the
    layout ``image``, the fact ``summary``), ideal or PI: its maps and
    flags as the library lays them out (``image.nc``'s variables, units and long names), its
    integer codes (regime, material, domain; a PI scan's ``_retrace`` ones) as the document's
    words; the command line's ``image.json`` (the summary) as ``summary``."""
    doc = json.loads(out["json"])
    summary = out["facts"]["summary"]
    _warn(summary)
    img = doc["image"]
    dims = ("y", "x")
    layout = _layout.variables(out["datasets"]["image"])
    data: Dict[str, Any] = {}
    for name, (vdims, values, attrs) in layout.items():
        if vdims != dims:
            continue
        if values.dtype.kind in "fb":
            data[name] = (vdims, values, attrs)
        else:
            base, retrace, _ = name.partition("_retrace")
            block = img["retrace"] if retrace else img
            words = np.array([["" if v is None else v for v in row] for row in block[base]])
            data[name] = (dims, words, {"long_name": attrs["long_name"]})
    extra = {k: json.dumps(doc[k]) for k in ("scan", "artefacts") if k in doc}
    return xr.Dataset(
        data,
        coords={name: layout[name] for name in ("x", "y")},
        attrs={
            "setpoint": setpoint,
            "reference_z_c": doc["reference_z_c"],
            "feedback": doc["feedback"],
            **extra,
            "summary": json.dumps(summary),
        },
    )


@_typed
def setpoint_study(
    probe: Union[str, "os.PathLike[str]", Dict[str, Any]],
    sample: Union[str, "os.PathLike[str]"],
    ratios: Sequence[float],
    *,
    curve_points: Optional[int] = None,
) -> xr.Dataset:
    """Every domain's apparent height, phase lag and dissipated energy against the setpoint
    under an ideal feedback (``afmdyn image --setpoint-study``): at each ratio a line engaged
    on the background crosses onto each domain — the contrast inversion of AM-AFM (García &
    San Paulo, Phys. Rev. B 61, R13381 (2000)). Arguments as :func:`image`'s; ``ratios`` the
    setpoints A_sp/A0 in (0, 1).

    Returns:
        ``xarray.Dataset`` over ``domain`` (``background`` first) and ``setpoint``:
        ``apparent_height`` (m), ``phase_deg``, ``energy_dissipated`` (J) (NaN where a
        material has no operating point) and ``regime``; attribute ``summary`` (the JSON).
    """
    text = _core.probe_source(probe)
    source = os.fspath(sample) if isinstance(sample, os.PathLike) else sample
    values = _real_array("ratios", ratios, 1).tolist()
    doc = json.loads(_core.setpoint_study(text, source, values, curve_points))
    _warn(doc)
    dims = ("domain", "setpoint")
    num = lambda key: np.array(  # noqa: E731
        [[np.nan if v is None else v for v in d[key]] for d in doc["domains"]], dtype=np.float64
    )
    return xr.Dataset(
        {
            "apparent_height": (dims, num("apparent_height"), {"units": "m"}),
            "phase_deg": (dims, num("phase_deg"), {"units": "degree"}),
            "energy_dissipated": (dims, num("energy_dissipated"), {"units": "J"}),
            "regime": (
                dims,
                np.array([["" if v is None else v for v in d["regime"]] for d in doc["domains"]]),
            ),
        },
        coords={
            "domain": [d["name"] for d in doc["domains"]],
            "setpoint": np.asarray(doc["ratio"], dtype=np.float64),
        },
        attrs={"summary": json.dumps(doc)},
    )
