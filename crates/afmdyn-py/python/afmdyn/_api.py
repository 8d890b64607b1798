"""The finishers of the analyses whose public functions (:mod:`._wrappers`,
:mod:`._wrappers_afm`, generated from the library's request schemas) return datasets or
spectra, :func:`probe` and :func:`cantilevers` (the cantilever library, as a
``pandas.DataFrame``). A finisher takes the
public function's ``locals()`` (its keywords, ``params``, ``model``, ``progress``), runs the
request through the one door (:func:`._common._door`) and builds the result from the library's
layouts (:mod:`._layout`); the other finishers are in :mod:`._orbits`, :mod:`._attractors`,
:mod:`._basins` (and global continuation) and :mod:`._fm`.

Units (paper eq. 5): time τ in t0 = √(mL⁴/EI), displacements in the beam gap g0, forces in
EI g0/L³, energies in EI g0²/L³ (SI with a probe).
"""

from __future__ import annotations

import functools
import json
import os
from typing import TYPE_CHECKING, Any, Dict, Optional, Union

import numpy as np
import xarray as xr

from . import _afmdyn as _core
from ._afmdyn import Params
from ._common import Model  # noqa: F401 (afmdyn._api.Model, as before)
from ._common import _attrs, _door, _params, _probe_text, _request, _start, _state
from . import _ibw, _layout
from ._results import RegionSpectrum, Spectrum

if TYPE_CHECKING:
    import pandas as pd

Args = Dict[str, Any]


def _finish_modes(a: Args) -> Spectrum:
    p, probe = _params(a["params"], a["model"])
    d = _door("modes", "modes", False, p, probe)

    def region(name: str) -> RegionSpectrum:
        v = _layout.variables(d["datasets"][name])
        return RegionSpectrum(v["omega"][1], v["eigenvalues"][1], v["zeta"][1])

    return Spectrum(p, region("free"), region("contact"), d["json"])


def _finish_simulate(a: Args) -> xr.Dataset:
    req = _request(a, initial=_state(a["initial"]))
    p, probe = _params(a["params"], a["model"])
    d = _door("simulate", "simulate", a["progress"], p, probe, req)
    f = d["facts"]
    facts = {k: f[k] for k in ("tau_end", "switchings", "integrator", "transient_tau")}
    attrs = _attrs(p, summary=d["json"], **facts, body_contact=int(f["body_contact"]),
                   samples_per_period=a["samples_per_period"])
    # with a probe the library laid every array out in SI (report::simulate_layout)
    return _layout.dataset(d["datasets"]["simulate"], attrs)


def _finish_converge(a: Args) -> xr.Dataset:
    req = _request(a)
    p, probe = _params(a["params"], a["model"], default=Params(omega=4.1))
    d = _door("converge", "converge", a["progress"], p, probe, req)
    attrs = _attrs(p, summary=d["json"])
    return _layout.dataset(d["datasets"]["converge"], attrs, coords=("tau_from_section",))


def _sweep_request(a: Args) -> Args:
    """The request of a sweep's keywords ``a`` (``bifurcation``'s, and
    ``afmdyn.dask.bifurcation``'s): its ``values`` as a flat list."""
    req = _request(a)
    if a["values"] is not None:
        req["values"] = np.asarray(a["values"], dtype=np.float64).ravel().tolist()
    return req


def _finish_bifurcation(a: Args) -> xr.Dataset:
    req = _sweep_request(a)
    p, _ = _params(a["params"], a["model"])
    # the sweep's records carry no JSON document, so no "si" block: the probe only resolved p
    d = _door("bifurcation", "bifurcation", a["progress"], p, None, req, a["store"],
              a["resume"], stored=True)
    return _sweep_dataset(p, d, a["starts"], a["seed"])


def _sweep_dataset(p: Params, d: Dict[str, Any], starts: int, seed: int) -> xr.Dataset:
    """The long-format dataset of a sweep's records ``d`` (``bifurcation``'s, and
    ``afmdyn.dask.bifurcation``'s), laid out by the library."""
    f = d["facts"]
    attrs = _attrs(p, param=f["param"], values=f["values"], starts=starts, seed=seed)
    ds = _layout.dataset(d["datasets"]["bifurcation"], attrs)
    return ds.set_coords(["value", "index", "branch"])


def _finish_continuation(a: Args) -> xr.Dataset:
    req = _start(_request(a, initial=_state(a["initial"])))
    p, probe = _params(a["params"], a["model"])
    d = _door("continuation", "continuation", a["progress"], p, probe, req)
    attrs = _attrs(p, param=d["facts"]["param"], summary=d["json"])
    ds = _layout.dataset(d["datasets"]["continuation"], attrs)
    return ds.set_coords("value")


def probe(
    path: Union[str, "os.PathLike[str]", Dict[str, Any]],
    cantilever: Optional[str] = None,
    medium: Optional[str] = None,
) -> Dict[str, Any]:
    """Read a probe in SI units (the command line's ``--probe FILE``; format and mapping in
    ``docs/getting-started.md``): a file's path, its TOML text or a dict of its sections, with
    ``cantilever`` as ``--cantilever`` and ``medium`` (``"water"``, ``"air"``, ``"none"``) as
    ``--medium``.

    Returns:
        ``{"params": Params, "si": dict}``: the dimensionless set, and the ``"si"`` block of the
        command line's JSON documents — ``scales`` (``length_m`` = A₀, ``time_s`` per unit τ,
        ``force_n``, ``energy_j``, ``power_w``), ``calibration`` (k, f₀, Q), the drive in Hz, the
        period in s, ``free_amplitude_m`` and ``z_c_m``, and with a fluid ``medium`` (the
        lever's vacuum values, each mode's wet frequency, Q and added mass; Sader 1998).
        Raises ``ValueError`` listing every problem of the file.
    """
    p, si = _core.probe(
        _probe_text({"probe": path, "cantilever": cantilever, "medium": medium})
    )
    return {"params": p, "si": json.loads(si)}


def cantilevers() -> "pd.DataFrame":
    """The cantilever library (``afmdyn cantilevers``): nominal datasheet values of common
    tapping-mode, soft-tapping and biological-imaging cantilevers, one row per cantilever,
    indexed by name: ``maker``, ``spring_constant`` (N/m), ``resonance_frequency`` (Hz),
    ``quality_factor`` (in air; ``q_typical`` True where it is the lever class's typical value,
    not the datasheet's), ``radius`` (tip radius, m), ``source``. A probe file names one with
    ``[cantilever] name = "RTESPA-300"``; its own keys override the library's."""
    import pandas as pd

    doc = json.loads(_core.cantilevers())
    return pd.DataFrame(doc["cantilevers"]).set_index("name")


def _finish_observe(a: Args) -> xr.Dataset:
    req = _start(_request(a, initial=_state(a["initial"])))
    p, probe = _params(a["params"], a["model"])
    d = _door("observe", "observe", a["progress"], p, probe, req)
    ds = _layout.dataset(d["datasets"]["observe"])
    doc: Dict[str, Any] = json.loads(d["json"])
    doc["state"] = [float(v) for v in ds["state"].values]
    doc["period"] = d["facts"]["period"]
    ds.attrs = {"title": "afmdyn observe", "summary": json.dumps(doc)}
    return ds


def _finish_thermal(a: Args) -> xr.Dataset:
    """The free lever's thermal spectrum (``afmdyn thermal``): the one-sided PSDs of the tip's
    deflection and of the optical lever's apparent deflection over ``frequency`` (m²/Hz), each
    mode's share over ``mode`` (``modes_*`` variables); ``attrs["summary"]`` is the document."""
    p, probe = _params(a["params"], a["model"])
    d = _door("thermal", "thermal", a["progress"], p, probe, _request(a))
    return _with_modes(d, "thermal", "afmdyn thermal")


def _finish_calibrate(a: Args) -> xr.Dataset:
    """A lever's calibration from its measured thermal spectrum (``afmdyn calibrate``): the
    spectrum and the fitted oscillators over ``frequency``, each mode's estimates over ``mode``
    (``modes_*`` variables); ``attrs["summary"]`` is the document. A ``psd`` ending in
    ``.ibw`` is an Igor binary wave, read here (``_ibw``) into the arrays."""
    if a["psd"] is not None and str(a["psd"]).lower().endswith(".ibw"):
        a = _ibw_arrays(a)
    arrays = {k: [float(v) for v in a[k]] if a[k] is not None else []
              for k in ("frequency", "spectral_density", "bands")}
    p, probe = _params(a["params"], a["model"])
    d = _door("calibrate", "calibrate", a["progress"], p, probe, _request(a, **arrays))
    return _with_modes(d, "spectrum", "afmdyn calibrate")


def _ibw_arrays(a: Args) -> Args:
    """``a`` with the thermal wave ``psd`` (``.ibw``) read into ``frequency`` and
    ``spectral_density``, ``volts`` from its units."""
    if a["frequency"] is not None or a["spectral_density"] is not None:
        raise ValueError("psd: give the file psd or the arrays frequency and spectral_density, "
                         "not both")
    frequency, density, volts = _ibw.read_spectrum(str(a["psd"]))
    if a["volts"] and not volts:
        raise ValueError(f"volts: {a['psd']} is in m²/Hz (its data units), not the detector's "
                         "V²/Hz; drop volts")
    return {**a, "psd": None, "frequency": frequency, "spectral_density": density,
            "volts": volts}


def _with_modes(d: dict, main: str, title: str) -> xr.Dataset:
    """The door's dataset ``main`` with its ``modes`` dataset's variables as ``modes_*``, the
    document as ``attrs["summary"]`` and the numeric facts as attributes."""
    ds = _layout.dataset(d["datasets"][main])
    modes = _layout.dataset(d["datasets"]["modes"])
    for name, var in modes.data_vars.items():
        ds[f"modes_{name}"] = var
    ds.attrs = {"title": title, "summary": d["json"],
                **{k: v for k, v in d["facts"].items() if isinstance(v, (int, float))}}
    return ds


def _curve(desc: str, a: Args) -> xr.Dataset:
    """Run a stepped-curve analysis (``approach``, ``bimodal``, ``resonance``) — in the command
    line's resumable store ``store`` when given — and return its dataset
    (the library's layout of its document, ``afmdyn::request::curve_layout``; in SI with a
    probe; ``attrs["summary"]`` is the document)."""
    request = _request(a)
    p, probe = _params(a["params"], a["model"])
    d = _door(desc, desc, a["progress"], p, probe, request, a["store"], a["resume"])
    attrs = {"title": f"afmdyn {desc}", "summary": d["json"]}
    free = json.loads(d["json"]).get("free_amplitude")
    if free is not None:  # attrs must be storable in NetCDF
        attrs["free_amplitude"] = free
    traces = tuple(f"trace_{x}" for x in ("z_c", "frequency_hz", "omega"))
    return _layout.dataset(d["datasets"]["curve"], attrs, coords=traces)


_finish_approach = functools.partial(_curve, "approach")
_finish_bimodal = functools.partial(_curve, "bimodal")
_finish_resonance = functools.partial(_curve, "resonance")
