"""Small result objects: spectra, orbits, Lyapunov spectra (the attractors' are in
``_attractors``, with the analysis their methods continue).

Each keeps the command line's JSON document for the same arguments; ``to_dict()`` returns a
fresh copy of it (``json.loads`` of the text the library built), so it equals
``afmdyn <command> --json`` key for key and value for value.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Dict

import numpy as np

from ._afmdyn import Params

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
        zeta: damping ratios ζ = −Re λ/``|λ|``, float64 ``[k]``.
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
        grazing, grazing_distance: near-grazing flag and distance (g0, and ``|dV_T/dτ|``/Ω).
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
