"""The tip–sample force behind a frequency-modulation curve (``afmdyn reconstruct``): the
library's Sader–Jarvis inversion, or its exact correction, as an ``xarray.Dataset`` in SI."""

from __future__ import annotations

import json
from typing import Any, Dict, Optional, Sequence, Union

import numpy as np
import xarray as xr

from . import _afmdyn as _core
from ._common import _real_array, _warn
from ._progress import ProgressArg, reporter


def _values(name: str, v: Optional[Any]) -> Optional[list]:
    return None if v is None else _real_array(name, v, 1).tolist()


def reconstruct(
    *,
    frequency_shift: Optional[Sequence[float]] = None,
    spring_constant: Optional[float] = None,
    resonance_frequency: Optional[float] = None,
    amplitude: Optional[float] = None,
    distance: Optional[Sequence[float]] = None,
    z_c: Optional[Sequence[float]] = None,
    fm: Optional[Union[xr.Dataset, Dict[str, Any]]] = None,
    am: Optional[Union[xr.Dataset, Dict[str, Any]]] = None,
    inversion: str = "sader-jarvis",
    progress: ProgressArg = None,
) -> xr.Dataset:
    """The tip–sample force F(d) and potential U(d) behind a frequency-modulation curve, by
    the Sader–Jarvis inversion (J. E. Sader and S. P. Jarvis, Appl. Phys. Lett. 84, 1801
    (2004); ``afmdyn reconstruct``) or its exact correction (``inversion="exact"``).

    Args:
        frequency_shift: Δf = f − f0 (Hz) at each distance.
        distance: the distances of closest approach d (m), monotonic; or
        z_c: the rest distances (m), d = z_c − A.
        spring_constant: k (N/m). resonance_frequency: f0 (Hz). amplitude: A (m).
        fm: instead of the curve, the dataset of :func:`afmdyn.fm` with a probe (or its
            document, ``afmdyn.summary(ds)``): its distances of closest approach
            (``min_distance``), shifts, k, f0 and A; ``spring_constant``,
            ``resonance_frequency``, ``amplitude`` given replace the document's.
        am: instead, the dataset of :func:`afmdyn.approach` with a point-mass probe (or its
            document): its attractive run (phase lag above 90°) inverted at each point's
            amplitude by the matrix method (``afmdyn reconstruct --am``); the constants are
            the probe's.
        inversion: ``"sader-jarvis"`` (the default: within a few per cent, the more robust on
            noisy data) or ``"exact"`` (the Sader–Jarvis estimate corrected through
            Giessibl's forward relation until the two agree: exact for the first-order
            relation; the document's ``exact`` records its steps and forward residual). Not
            with ``am``.

    Returns:
        ``xarray.Dataset`` over ``distance`` (m, increasing): ``force`` (N, attractive < 0),
        ``potential`` (J, ∫_d^{d_max} F), and from ``fm=`` ``law`` (N, the model's force at d); attributes ``spring_constant``,
        ``resonance_frequency``, ``amplitude`` and ``summary`` (the command line's JSON
        document). The force near the largest distance is not reconstructed (the inversion
        integrates the shift beyond each distance): take data out to where Δf has decayed.
        On an evenly spaced grid (every distance within 1e-9 of a spacing of d0 + i h) the
        inversion takes O(N log N) by FFT, up to 2 000 000 points; on another grid O(N²), up
        to 20 000 points. Ctrl-C stops it.

    Warns:
        AfmdynWarning: a constant outside its typical range (A 10 pm–1 µm, f0 1 kHz–10 MHz,
            k 0.01–1e6 N/m: a likely unit slip, named); data that end while |Δf| is still
            above 1 % of its extreme.

    Raises:
        ValueError: naming the field — fewer than 3 points, distances not monotonic, lengths
            that differ, constants missing or outside their physical range (A 1e-15–1e-3 m,
            f0 1–1e10 Hz, k 1e-6–1e9 N/m), neither or both of ``distance`` and ``z_c``, more
            points than the limits above; ``fm`` not an SI ``fm`` document.
        KeyboardInterrupt: on Ctrl-C.

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    if am is not None:
        given = [n for n, v in (("fm", fm), ("frequency_shift", frequency_shift),
                                ("spring_constant", spring_constant), ("amplitude", amplitude),
                                ("resonance_frequency", resonance_frequency)) if v is not None]
        if given:
            raise ValueError(f"am: the approach curve carries its constants; {given[0]} not taken")
        if inversion != "sader-jarvis":
            raise ValueError("inversion: the AM curve is inverted by the matrix method")
        request: Dict[str, Any] = dict(am=_document(am))
    elif fm is not None:
        if frequency_shift is not None or distance is not None or z_c is not None:
            raise ValueError("fm: give the fm curve or frequency_shift with distance/z_c, not both")
        consts = (("spring_constant", spring_constant), ("amplitude", amplitude),
                  ("resonance_frequency", resonance_frequency))
        request = dict(fm=_document(fm), inversion=inversion,
                       **{k: None if v is None else float(v) for k, v in consts})
    else:
        for name, v in (("frequency_shift", frequency_shift),
                        ("spring_constant", spring_constant),
                        ("resonance_frequency", resonance_frequency), ("amplitude", amplitude)):
            if v is None:
                raise ValueError(f"{name}: missing (give the curve and k, f0, A, or fm=)")
        request = dict(
            frequency_shift=_values("frequency_shift", frequency_shift),
            distance=_values("distance", distance),
            z_c=_values("z_c", z_c),
            spring_constant=float(spring_constant),
            resonance_frequency=float(resonance_frequency),
            amplitude=float(amplitude),
            inversion=inversion,
        )
    name = "reconstruct" if "frequency_shift" in request else "reconstruct_document"
    with reporter(progress, "reconstruct") as cb:
        d = _core.run(name, request, None, None, cb)
    return _dataset(json.loads(d["json"]))


def _document(d: Union[xr.Dataset, Dict[str, Any]]) -> str:
    """The JSON text of a document given as its dataset or as a dict."""
    return d.attrs["summary"] if isinstance(d, xr.Dataset) else json.dumps(d)


def _dataset(doc: Dict[str, Any]) -> xr.Dataset:
    """The dataset of a reconstruction document, its warnings issued as
    :class:`afmdyn.AfmdynWarning`."""
    _warn(doc)
    f = doc["force"]
    units = doc["units"]
    law = {}
    if "law" in f:
        law["law"] = ("distance", np.asarray(f["law"]),
                      {"units": units["force"],
                       "long_name": "the model's force at d (a curve from afmdyn.fm)"})
    return xr.Dataset(
        {
            **law,
            "force": ("distance", np.asarray(f["force"]),
                      {"units": units["force"], "long_name": "tip–sample force F(d)"}),
            "potential": ("distance", np.asarray(f["potential"]),
                          {"units": units["potential"],
                           "long_name": "potential U(d), integral of F from d to the last distance"}),
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
