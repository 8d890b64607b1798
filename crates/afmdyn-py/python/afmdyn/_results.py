"""Small result objects: spectra, attractors, orbits, Lyapunov spectra.

Each keeps the command line's JSON document for the same arguments; ``to_dict()`` returns a
fresh copy of it (``json.loads`` of the text the library built), so it equals
``afmdyn <command> --json`` key for key and value for value.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Dict, Iterator, List, Optional, Sequence, overload

import numpy as np

from ._afmdyn import Params

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    import xarray as xr


class _Document:
    _json: str

    def to_dict(self) -> Dict[str, Any]:
        """The command line's ``--json`` document for the same arguments (a new dict)."""
        return json.loads(self._json)


@dataclass(frozen=True)
class RegionSpectrum:
    """Spectrum of one region (free: tip off the sample; contact: tip on it).

    Attributes:
        omega: undamped natural frequencies ω_i, ascending, float64 ``[N]`` (units 1/t0).
        eigenvalues: damped eigenvalues λ of eqs. 20–21 with Im λ ≥ 0, sorted by Im,
            complex128 ``[k]`` (k = N when every mode is underdamped).
        zeta: damping ratios ζ = −Re λ/|λ|, float64 ``[k]``.
    """

    omega: np.ndarray
    eigenvalues: np.ndarray
    zeta: np.ndarray


@dataclass(frozen=True, repr=False)
class Spectrum(_Document):
    """Natural frequencies and damped eigenvalues (paper eqs. 19–23) of both regions;
    ``to_dict()`` is ``afmdyn modes --json``."""

    params: Params
    free: RegionSpectrum
    contact: RegionSpectrum
    _json: str = field(repr=False)

    def __repr__(self) -> str:
        f = ", ".join(f"{w:.4g}" for w in self.free.omega)
        c = ", ".join(f"{w:.4g}" for w in self.contact.omega)
        return f"Spectrum(free ω = [{f}], contact ω = [{c}])"


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
        from . import _api

        options.setdefault("period", self.period or 1)
        return _api.orbit(self.params, initial=self.state, **options)

    def simulate(self, periods: Optional[float] = None, **options: Any) -> "xr.Dataset":
        """Time series on the attractor from τ = 0 (drive phase 0), ``periods`` drive periods
        (default: max(period, 2), or 8 for a nonperiodic motion, as the command line plots).
        Options as :func:`afmdyn.simulate`."""
        from . import _api

        if periods is None:
            periods = max(self.period or 8, 2)
        return _api.simulate(self.params, periods=periods, initial=self.state, **options)

    def __repr__(self) -> str:
        kind = f"period-{self.period}" if self.period else "nonperiodic"
        return (
            f"Attractor({kind}, basin {100 * self.basin_fraction:.1f} %, "
            f"X_max = {self.x_max:.4f}, min V_T = {self.v_t_min:.4f})"
        )


class Attractors(_Document, Sequence[Attractor]):
    """Coexisting attractors, most frequent first (a sequence of :class:`Attractor`);
    ``to_dict()`` is ``afmdyn attractors --json``.

    Attributes:
        params: the parameters; samples: random starts; failures: error messages of the
        starts that failed.
    """

    def __init__(
        self,
        params: Params,
        samples: int,
        attractors: List[Attractor],
        failures: List[str],
        doc: str,
    ) -> None:
        self.params = params
        self.samples = samples
        self.attractors = attractors
        self.failures = failures
        self._json = doc

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
            [
                {
                    "period": a.period,
                    "basin_fraction": a.basin_fraction,
                    "count": a.count,
                    "x_max": a.x_max,
                    "x_min": a.x_min,
                    "v_t_min": a.v_t_min,
                    "contact_fraction": a.contact_fraction,
                    "contacts_per_period": a.contacts_per_period,
                    "body_contact": a.body_contact,
                    "transient_periods": a.transient_periods,
                }
                for a in self.attractors
            ],
            index=pd.RangeIndex(1, len(self.attractors) + 1, name="attractor"),
        )

    def __repr__(self) -> str:
        inner = "\n".join(f"  {k + 1}: {a!r}" for k, a in enumerate(self.attractors))
        return (
            f"Attractors({len(self)} from {self.samples} starts at Ω = {self.params.omega}, "
            f"{len(self.failures)} failed)\n{inner}"
        )


@dataclass(frozen=True, repr=False)
class Orbit(_Document):
    """A period-n orbit of the stroboscopic map found by Newton shooting;
    ``to_dict()`` is ``afmdyn orbit --json``.

    Attributes:
        params: the parameters; period: n.
        state: the state at τ = 0 (drive phase 0), float64 ``[2N]``.
        section: the n section states z, P(z), …, Pⁿ⁻¹(z), float64 ``[n, 2N]``.
        poincare_v_t, poincare_w_tip: V_T and W(1,τ) at the section points (g0), ``[n]``.
        monodromy: the monodromy matrix of Pⁿ (with saltation), float64 ``[2N, 2N]``.
        multipliers: Floquet multipliers (its eigenvalues), decreasing modulus, complex128
            ``[2N]``.
        stable: all multipliers inside the unit circle; critical: how the largest one would
            cross it (``"fold"``, ``"period-doubling"``, ``"neimark-sacker"``).
        grazing, grazing_distance: near-grazing flag and distance (g0, and |dV_T/dτ|/Ω).
        switchings: switchings per cycle; newton_residuals: ‖Pⁿ(z) − z‖ per iteration.
    """

    params: Params
    period: int
    state: np.ndarray
    section: np.ndarray
    poincare_v_t: np.ndarray
    poincare_w_tip: np.ndarray
    monodromy: np.ndarray
    multipliers: np.ndarray
    stable: bool
    critical: str
    grazing: bool
    grazing_distance: float
    switchings: int
    newton_residuals: np.ndarray
    _json: str = field(repr=False)

    def __repr__(self) -> str:
        return (
            f"Orbit(period-{self.period}, {'stable' if self.stable else 'unstable'}, "
            f"max |μ| = {abs(self.multipliers[0]):.6f}, {self.switchings} switchings per cycle)"
        )


@dataclass(frozen=True, repr=False)
class Lyapunov(_Document):
    """Lyapunov spectrum and 0–1 test; ``to_dict()`` is ``afmdyn lyapunov --json``.

    Attributes:
        params: the parameters.
        exponents: Lyapunov exponents per unit τ (1/t0), decreasing, float64 ``[2N]``.
        uncertainty: their standard errors over the blocks, float64 ``[2N]``.
        volume_rate: mean phase-volume contraction rate (= sum of the exponents).
        zero_one: the 0–1 test statistic K (≈ 0 regular, ≈ 1 chaotic; NaN below 100 periods).
        periods: drive periods averaged; verdict: ``"periodic"``, ``"quasiperiodic"``,
            ``"chaotic"`` or ``"undecided"``.
    """

    params: Params
    exponents: np.ndarray
    uncertainty: np.ndarray
    volume_rate: float
    zero_one: float
    periods: int
    verdict: str
    _json: str = field(repr=False)

    def __repr__(self) -> str:
        ex = ", ".join(f"{e:+.4g}" for e in self.exponents)
        return f"Lyapunov([{ex}], K = {self.zero_one:.3f}, {self.verdict})"
