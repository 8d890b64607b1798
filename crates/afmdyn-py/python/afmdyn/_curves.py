"""The datasets of :func:`afmdyn.approach`, :func:`afmdyn.resonance` and :func:`afmdyn.observe`,
built from the library's JSON document (the command line's ``--json``; no numerics here: the
library converts to SI and degrees, ``afmdyn::report``). The document itself is kept in
``attrs["summary"]`` and comes back as ``ds.afmdyn.to_dict()`` (or :func:`afmdyn.summary`).
"""

from __future__ import annotations

import json
from typing import Any, Dict, List, Optional, Sequence

import numpy as np
import xarray as xr

from . import _afmdyn as _core

# the per-point columns of a stepped curve, as the library declares them
# (``afmdyn::report::CURVE_COLUMNS``): name → (kind of unit in the document's ``units`` block,
# long name)
COLUMNS: Dict[str, tuple] = {name: (kind, long) for name, kind, long in _core.CURVE_COLUMNS}

# the stepped curves: command → (abscissa keys in order of preference, the two sweeps)
SWEEPS = {
    "approach": (("z_c",), ("approach", "retract")),
    "bimodal": (("z_c",), ("approach", "retract")),
    "resonance": (("frequency_hz", "omega"), ("up", "down")),
}

ABSCISSA = {
    "z_c": ("length", "rest distance z_c of the tip above the sample"),
    "frequency_hz": ("Hz", "drive frequency"),
    "omega": ("Ω", "dimensionless drive frequency Ω"),
}


def _unit(units: Dict[str, str], kind: Optional[str]) -> str:
    if kind is None:
        return "1"
    return units.get(kind, kind)


def _attrs(units: Dict[str, str], kind: Optional[str], long_name: str) -> Dict[str, str]:
    return {"units": _unit(units, kind), "long_name": long_name}


def _floats(values: Sequence[Any]) -> np.ndarray:
    """A JSON list of numbers with nulls as a float64 array with NaN."""
    return np.array([np.nan if v is None else v for v in values], dtype=np.float64)


def _abscissa(doc: Dict[str, Any], command: str) -> str:
    keys, (first, _) = SWEEPS[command]
    return next(k for k in keys if k in doc[first])


def curve_dataset(command: str, doc: Dict[str, Any]) -> xr.Dataset:
    """The dataset of a stepped-curve document (``approach`` or ``resonance``).

    Dimensions: the abscissa (``z_c``, ``frequency_hz`` or ``omega``: the values of the first
    sweep, in its order) and ``sweep`` (``approach``/``retract`` or ``up``/``down``); the
    columns of both sweeps over (sweep, abscissa) with ``stable``, ``period`` (NaN when not
    period-n) and ``reached``. The branches concatenated along ``branch_point`` (``branch`` is
    the branch index, ``event`` "" where none); with traces, ``trace_deflection``,
    ``trace_distance``, ``trace_force`` over (``trace``, ``trace_time`` in drive periods).
    Folds, bistable ranges, jumps and the setpoint are in the summary.
    """
    units: Dict[str, str] = doc["units"]
    x = _abscissa(doc, command)
    sweeps = SWEEPS[command][1]
    grid = list(doc[sweeps[0]][x])
    index = {v: i for i, v in enumerate(grid)}
    kind, name = ABSCISSA[x]
    coords: Dict[str, Any] = {
        x: (x, np.array(grid, dtype=np.float64), _attrs(units, kind, name)),
        "sweep": ("sweep", list(sweeps)),
    }
    data: Dict[str, Any] = {}

    def grid_of(values: Sequence[Any], xs: Sequence[float], fill: Any, dtype: Any) -> np.ndarray:
        out = np.full(len(grid), fill, dtype=dtype)
        for v, at in zip(values, xs):
            if at in index:
                out[index[at]] = fill if v is None else v
        return out

    # the curve's columns, then under a multifrequency drive each component's
    # (``drive_components.columns``: amplitude_i, phase_i_deg, virial_i, energy_dissipated_i)
    columns = dict(COLUMNS)
    for name, k, long_name in (doc.get("drive_components") or {}).get("columns", []):
        columns[name] = (k, long_name)
    for col, (k, long_name) in columns.items():
        rows = [grid_of(doc[s][col], doc[s][x], np.nan, np.float64) for s in sweeps]
        data[col] = (("sweep", x), np.stack(rows), _attrs(units, k, long_name))
    data["stable"] = (
        ("sweep", x),
        np.stack([grid_of(doc[s]["stable"], doc[s][x], False, bool) for s in sweeps]),
        {"long_name": "every Floquet multiplier inside the unit circle"},
    )
    data["period"] = (
        ("sweep", x),
        np.stack([grid_of(doc[s]["period"], doc[s][x], np.nan, np.float64) for s in sweeps]),
        {"units": "1", "long_name": "n of the period-n motion (NaN: not periodic)"},
    )
    data["reached"] = (
        ("sweep", x),
        np.stack([grid_of(doc[s]["reached"], doc[s][x], "", object) for s in sweeps]).astype(str),
        {"long_name": "how the point's steady state was reached"},
    )
    branches: List[Dict[str, Any]] = doc.get("branches") or []
    ids = [i for i, b in enumerate(branches) for _ in b[x]]
    data["branch"] = ("branch_point", np.array(ids, dtype=np.int64), {"long_name": "branch index"})
    data[f"branch_{x}"] = (
        "branch_point",
        _floats([v for b in branches for v in b[x]]),
        _attrs(units, kind, name),
    )
    for col, (k, long_name) in columns.items():
        data[f"branch_{col}"] = (
            "branch_point",
            _floats([v for b in branches for v in b[col]]),
            _attrs(units, k, long_name),
        )
    data["branch_stable"] = (
        "branch_point",
        np.array([v for b in branches for v in b["stable"]], dtype=bool),
        {"long_name": "every Floquet multiplier inside the unit circle"},
    )
    data["branch_period"] = (
        "branch_point",
        _floats([v for b in branches for v in b["period"]]),
        {"units": "1", "long_name": "n of the period-n orbit"},
    )
    data["branch_event"] = (
        "branch_point",
        np.array([v or "" for b in branches for v in b["event"]], dtype=str),
        {"long_name": "event at the point (fold, period-doubling, grazing, ...)"},
    )
    traces = doc.get("traces")
    if traces:
        coords["trace_time"] = (
            "trace_time",
            np.array(traces["time_periods"], dtype=np.float64),
            {"units": "drive periods", "long_name": "time within the recorded cycle"},
        )
        coords[f"trace_{x}"] = ("trace", np.array(traces[x], dtype=np.float64),
                                _attrs(units, kind, name))
        for var, k, long_name in (
            ("deflection", "length", "tip deflection W(1,tau)"),
            ("distance", "length", "tip-sample distance V_T (<= 0 in contact)"),
            ("force", "force", "tip-sample force F_c (> 0 repulsive, < 0 attractive)"),
        ):
            values = np.array(traces[var], dtype=np.float64).reshape(
                len(traces[x]), len(traces["time_periods"])
            )
            data[f"trace_{var}"] = (("trace", "trace_time"), values, _attrs(units, k, long_name))
    attrs: Dict[str, Any] = {"title": f"afmdyn {command}", "summary": json.dumps(doc)}
    if doc.get("free_amplitude") is not None:  # attrs must be storable in NetCDF
        attrs["free_amplitude"] = doc["free_amplitude"]
    return xr.Dataset(data, coords=coords, attrs=attrs)


def observe_dataset(doc: Dict[str, Any]) -> xr.Dataset:
    """The dataset of an ``observe`` document: its ``reported`` block (SI with a probe, phases
    in degrees) as scalar variables, ``harmonic_amplitude`` and ``harmonic_phase_deg`` over
    ``harmonic`` (n), the per-mode energy balance ``mode_drive``, ``mode_beam_damping``,
    ``mode_sample``, ``mode_coupling``, ``mode_energy_change``, ``mode_residual`` over ``mode``,
    ``state`` (the start, ``[2N]`` as (a, ȧ)) and ``period`` (NaN when not periodic); under a
    multifrequency drive ``component_amplitude``, ``component_phase_deg``, ``component_virial``,
    ``component_energy_dissipated`` (with their closed forms and free values) over
    ``component`` (1, 2, …)."""
    r: Dict[str, Any] = doc["reported"]
    units: Dict[str, str] = r["units"]
    data: Dict[str, Any] = {}
    for col, (k, long_name) in COLUMNS.items():
        data[col] = ((), _floats([r[col]])[0], _attrs(units, k, long_name))
    extra = {
        "contact_time": ("time", "time in contact per drive period"),
        "mean_force": ("force", "time-averaged tip-sample force"),
        "impacts_per_period": (None, "entries into contact (impacts) per drive period"),
        "impact_loss": ("energy", "kinetic energy lost in impacts per drive period"),
    }
    for col, (k, long_name) in extra.items():
        data[col] = ((), _floats([r[col]])[0], _attrs(units, k, long_name))
    h = r["harmonics"]
    data["harmonic_amplitude"] = (
        "harmonic", _floats(h["amplitude"]), _attrs(units, "length", "amplitude of harmonic n"))
    data["harmonic_phase_deg"] = (
        "harmonic", _floats(h["phase_deg"]), _attrs(units, "phase", "phase of harmonic n"))
    b = r["mode_balance"]
    for term in ("drive", "beam_damping", "sample", "coupling", "energy_change", "residual"):
        data[f"mode_{term}"] = (
            "mode", _floats(b[term]),
            _attrs(units, "energy", f"energy balance of the mode per drive period: {term}"),
        )
    comp = r.get("components")
    if comp:  # a multifrequency drive: per component (the first first)
        for key, k, long_name in (
            ("amplitude", "length", "tip amplitude at the component's frequency"),
            ("phase_deg", "phase", "phase lag behind the component's drive"),
            ("free_amplitude", "length", "free amplitude at the component's frequency"),
            ("free_phase_deg", "phase", "the free response's lag"),
            ("virial", "energy", "<F_ts z_i>, z_i the motion at the component's frequency"),
            ("energy_dissipated", "energy", "energy dissipated per cycle of the component"),
            ("closed_virial", "energy", "closed form -(k A A0/(2Q)) cos(phase)"),
            ("closed_energy_dissipated", "energy",
             "closed form (pi k A^2/Q)[(A0/A) sin(phase) - f/f0]"),
        ):
            data[f"component_{key}"] = ("component", _floats(comp[key]),
                                        _attrs(units, k, long_name))
        data["component_ratio"] = ("component", _floats(comp["ratio"]),
                                   {"units": "1", "long_name": "frequency over the first's"})
    data["state"] = ("state_index", np.asarray(doc["state"], dtype=np.float64),
                     {"long_name": "state (a, da/dtau) at tau = 0 the observables start from"})
    period = doc.get("period")
    data["period"] = ((), np.nan if period is None else float(period),
                      {"units": "1", "long_name": "n of the period-n motion (NaN: not periodic)"})
    coords = {
        "harmonic": ("harmonic", np.array(h["n"], dtype=np.int64)),
        "mode": ("mode", np.array(b["mode"], dtype=np.int64)),
    }
    if comp:
        coords["component"] = ("component", np.arange(1, len(comp["ratio"]) + 1))
    summary = dict(doc)
    summary["state"] = [float(v) for v in doc["state"]]
    return xr.Dataset(
        data, coords=coords, attrs={"title": "afmdyn observe", "summary": json.dumps(summary)}
    )


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
