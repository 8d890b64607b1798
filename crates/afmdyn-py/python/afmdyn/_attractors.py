"""Coexisting attractors at fixed parameters: :func:`attractors`, and the result types
:class:`Attractor` (which continues into :meth:`Attractor.orbit` and
:meth:`Attractor.simulate`) and :class:`Attractors`."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Dict, Iterator, List, Optional, Sequence, overload

import numpy as np

from ._afmdyn import Params
from . import _layout
from ._common import _door, _params, _request
# (attractors() is generated apart, in ._wrappers_starts: ._wrappers does not import this module)
from ._wrappers import orbit as _orbit, simulate as _simulate
from ._results import Orbit, _Document


if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr


@dataclass(frozen=True, repr=False)
class Attractor:
    """One attractor found by :func:`afmdyn.attractors`.

    Attributes:
        params: the parameters.
        period: n of a period-n orbit of the stroboscopic map, ``None`` if nonperiodic.
        count: random starts that reached it; ``basin_fraction`` = count / successful starts.
        section_tau, section_v_t, section_w_tip: the recorded section points τ = 2πk/Ω,
            float64 ``[n]`` (n = period, or 64 for a nonperiodic motion); τ in t0, V_T and
            W(1,τ) in g0.
        section_state: the states (a, ȧ) at those points, float64 ``[n, 2N]``.
        state: ``section_state[0]``, a state on the attractor at drive phase 0 (what the
            command line's ``initial_modal`` string encodes).
        initial: the random initial state that reached it, float64 ``[2N]``.
        x_max, x_min, v_t_min, contact_fraction, contacts_per_period, body_contact: orbit
            statistics over the recorded periods (g0; fractions per time or per period).
        transient_periods: drive periods before the motion settled.
    """

    params: Params
    period: Optional[int]
    count: int
    basin_fraction: float
    section_tau: np.ndarray
    section_v_t: np.ndarray
    section_w_tip: np.ndarray
    section_state: np.ndarray
    initial: np.ndarray
    x_max: float
    x_min: float
    v_t_min: float
    contact_fraction: float
    contacts_per_period: float
    body_contact: bool
    transient_periods: int
    _doc: Dict[str, Any] = field(repr=False)

    @property
    def periodic(self) -> bool:
        return self.period is not None

    @property
    def state(self) -> np.ndarray:
        return self.section_state[0]

    def to_dict(self) -> Dict[str, Any]:
        """This attractor's entry of ``afmdyn attractors --json`` (a new dict)."""
        return json.loads(json.dumps(self._doc))

    def orbit(self, **options: Any) -> "Orbit":
        """Newton shooting from this attractor (its period, starting on it): Floquet
        multipliers and stability. Options as :func:`afmdyn.orbit`."""
        return _orbit(self.params, initial=self, **options)

    def simulate(self, periods: Optional[float] = None, **options: Any) -> "xr.Dataset":
        """Time series on the attractor from τ = 0 (drive phase 0), ``periods`` drive periods
        (default: max(period, 2), or 8 for a nonperiodic motion, as the command line plots).
        Options as :func:`afmdyn.simulate`."""
        if periods is None:
            periods = max(self.period or 8, 2)
        return _simulate(self.params, periods=periods, initial=self.state, **options)

    def __repr__(self) -> str:
        kind = f"period-{self.period}" if self.period else "nonperiodic"
        return (
            f"Attractor({kind}, basin {100 * self.basin_fraction:.1f} %, "
            f"X_max = {self.x_max:.4f}, min V_T = {self.v_t_min:.4f})"
        )


#: The columns of :meth:`Attractors.to_dataframe`: each attractor's scalars.
_COLUMNS = ("period", "basin_fraction", "count", "x_max", "x_min", "v_t_min", "contact_fraction",
            "contacts_per_period", "body_contact", "transient_periods")


@dataclass(repr=False, eq=False)
class Attractors(_Document, Sequence[Attractor]):
    """Coexisting attractors, most frequent first (a sequence of :class:`Attractor`);
    ``to_dict()`` is ``afmdyn attractors --json``.

    Attributes:
        params: the parameters; samples: random starts; failures: error messages of the
        starts that failed.
    """

    params: Params
    samples: int
    attractors: List[Attractor]
    failures: List[str]
    _json: str

    def __len__(self) -> int:
        return len(self.attractors)

    @overload
    def __getitem__(self, i: int) -> Attractor: ...

    @overload
    def __getitem__(self, i: slice) -> List[Attractor]: ...

    def __getitem__(self, i):  # type: ignore[no-untyped-def]
        return self.attractors[i]

    def __iter__(self) -> Iterator[Attractor]:
        return iter(self.attractors)

    def to_dataframe(self) -> "pd.DataFrame":
        """One row per attractor: period, basin fraction, count and orbit statistics."""
        import pandas as pd

        return pd.DataFrame(
            [{k: getattr(a, k) for k in _COLUMNS} for a in self.attractors],
            index=pd.RangeIndex(1, len(self.attractors) + 1, name="attractor"),
        )

    def __repr__(self) -> str:
        inner = "\n".join(f"  {k + 1}: {a!r}" for k, a in enumerate(self.attractors))
        return (
            f"Attractors({len(self)} from {self.samples} starts at Ω = {self.params.omega}, "
            f"{len(self.failures)} failed)\n{inner}"
        )


def _finish_attractors(a: Dict[str, Any]) -> Attractors:
    req = _request(a)
    p, probe = _params(a["params"], a["model"])
    d = _door("attractors", "attractors", a["progress"], p, probe, req)
    doc = json.loads(d["json"])
    # each attractor's layout (attractor-1, …): its arrays, and its scalars as Python's
    found_arrays = [
        {k: (v[1] if v[0] else v[1].item()) for k, v in _layout.variables(a).items()}
        for a in d["datasets"].values()
    ]
    found = [
        Attractor(params=p, period=entry["period"], _doc=entry, **a)
        for a, entry in zip(found_arrays, doc["attractors"])
    ]
    return Attractors(p, a["samples"], found, list(d["facts"]["failures"]), d["json"])
