"""Off-resonance (PeakForce) tapping (``afmdyn peakforce``): the library's steady tap of the
modulation period as an ``xarray.Dataset`` built from its layouts (no numerics here)."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, List, Optional, Sequence, Union

import xarray as xr

from ._afmdyn import Params
from ._common import Model, _door, _params, _request
from ._layout import dataset
from ._progress import ProgressArg

if TYPE_CHECKING:  # annotations only (PEP 692)
    from typing_extensions import Unpack


def peakforce(
    params: Optional[Params] = None,
    /,
    *,
    z_c: Union[float, Sequence[float], None] = None,
    setpoint: Optional[float] = None,
    modulation_frequency: Optional[Sequence[float]] = None,
    samples: int = 4096,
    fit_band: Optional[List[float]] = None,
    filter_cutoff: Optional[float] = None,
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """The steady tap of off-resonance tapping (``afmdyn peakforce``; the probe's ``[drive]
    mode = "off-resonance"``): the periodic orbit of the modulation period found by shooting,
    with its Floquet multipliers, the instrument's channels and the PF-QNM DMT fit.

    Args:
        z_c: the mean rest separation (m with ``probe``, else g₀); excludes ``setpoint``. A
            sequence sweeps it: the channels over a ``z_c`` dimension, each tap continued
            from the previous tap's orbit.
        setpoint: the peak force the ideal feedback holds (N with ``probe``): z_c is found.
        modulation_frequency: values of f_m to sweep (Hz with ``probe``, else Ω): the
            channels over a ``modulation_frequency`` dimension (with ``setpoint``, the
            feedback holds the peak force at each).
        samples: points of the cycle, 2000..=1000000.
        fit_band: the DMT fit's band, fractions [lo, hi] of the retract's force range
            (default [0.3, 0.9]).
        filter_cutoff: the instrument's low-pass filter (Hz with ``probe``, else cycles per
            τ): a causal second-order Butterworth filter on the measured force k × deflection;
            the curve gains ``approach_filtered_force`` and ``retract_filtered_force``.
        probe: a probe file (a model keyword, as ``--probe``): SI inputs and outputs.

    Returns:
        An ``xarray.Dataset`` of one cycle over ``sample`` (time, deflection, distance, force)
        and the force–distance curve, in SI with a probe; attributes: the channels
        (``peak_force``, ``adhesion``, ``deformation``, ``dissipation``, ``contact_time``,
        ``snap_off_time``, ``ringing_amplitude``, ``modulus_dmt``, ``taps_per_cycle``) and
        ``summary`` (the ``afmdyn peakforce --json`` document). With a sweep the channels
        (and ``modulus_dmt``, ``z_c``, ``period``) are variables over its dimension, NaN where
        a value failed; the cycle and curve are the first computed value's. Warnings (period-2 tapping,
        double taps, an unstable tap) are raised as :class:`afmdyn.AfmdynWarning`.

    Raises:
        ValueError: naming the option or the model parameter.

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    request = _request(locals())
    if fit_band is None:
        del request["fit_band"]
    del request["modulation_frequency"]
    if modulation_frequency is not None:
        values = [float(v) for v in modulation_frequency]
        request["sweep"] = {"quantity": "modulation_frequency", "values": values}
    elif z_c is not None and not isinstance(z_c, (int, float)):
        request["sweep"] = {"quantity": "z_c", "values": [float(v) for v in z_c]}
        request["z_c"] = None
    p, probe = _params(params, model)
    d = _door("peakforce", "peakforce", progress, p, probe, request)
    doc = json.loads(d["json"])
    ds = xr.merge(
        [dataset(layout) for layout in d["datasets"].values()], combine_attrs="drop"
    )
    if doc.get("sweep") is None:
        ds.attrs = {k: v for k, v in doc["channels"].items() if v is not None}
    else:
        ds.attrs = {}
    ds.attrs["summary"] = json.dumps(doc)
    return ds
