"""Type stubs of the compiled core ``afmdyn._afmdyn`` (use the ``afmdyn`` package: its
functions wrap these and build the datasets and result objects)."""

import os
from typing import Any, Callable, Dict, List, Literal, Optional, Tuple, Union

ProgressCallback = Callable[[int, Optional[int]], object]

POLL_SECONDS: float

def cancel_running() -> None: ...
#: The one table of model parameters (the library's ``afmdyn::request::MODEL_PARAMETERS``):
#: (name, alias or name, unit, range, help).
MODEL_PARAMETERS: List[Tuple[str, str, str, str, str]]

FORCE_SIGN: str
#: The per-point columns of a stepped curve (``afmdyn::report::CURVE_COLUMNS``): (name, kind of
#: unit — "length", "force", "energy", "phase" or None for a pure number — long name).
CURVE_COLUMNS: List[Tuple[str, Optional[str], str]]

class SimulationError(RuntimeError):
    """A computation failed (chattering, divergence, Newton not converging, integrator
    failure); bad input raises ``ValueError`` instead."""

class Params:
    """Dimensionless model parameters (paper eq. 7), validated on construction.

    Keywords: ``modes`` (N, 1..=20), ``tip_mass_ratio``/``alpha1`` (≥ 0),
    ``drive_amplitude``/``alpha2`` (≥ 0), ``beam_damping``/``alpha3`` (≥ 0),
    ``contact_stiffness``/``alpha4`` (≥ 0), ``gap``/``alpha5`` (finite),
    ``contact_damping``/``alpha6`` (≥ 0), ``omega`` (Ω > 0), ``contact_law`` (``"linear"``,
    ``"hertz"``, ``"dmt"``, ``"impact"``) with its groups ``restitution`` (0..=1, impact),
    ``hamaker`` (≥ 0) and ``intermolecular_distance`` (> 0, DMT); the others keep the paper's
    Figs. 5–14 set. Raises ``ValueError`` (field and range) or ``TypeError`` (unknown keyword,
    wrong type).
    """

    def __init__(
        self,
        *,
        modes: int = ...,
        tip_mass_ratio: float = ...,
        alpha1: float = ...,
        drive_amplitude: float = ...,
        alpha2: float = ...,
        beam_damping: float = ...,
        alpha3: float = ...,
        contact_stiffness: float = ...,
        alpha4: float = ...,
        gap: float = ...,
        alpha5: float = ...,
        contact_damping: float = ...,
        alpha6: float = ...,
        omega: float = ...,
        contact_law: Literal["linear", "hertz", "dmt", "impact"] = ...,
        restitution: float = ...,
        hamaker: float = ...,
        intermolecular_distance: float = ...,
    ) -> None: ...
    def replace(
        self,
        *,
        modes: int = ...,
        tip_mass_ratio: float = ...,
        alpha1: float = ...,
        drive_amplitude: float = ...,
        alpha2: float = ...,
        beam_damping: float = ...,
        alpha3: float = ...,
        contact_stiffness: float = ...,
        alpha4: float = ...,
        gap: float = ...,
        alpha5: float = ...,
        contact_damping: float = ...,
        alpha6: float = ...,
        omega: float = ...,
        contact_law: Literal["linear", "hertz", "dmt", "impact"] = ...,
        restitution: float = ...,
        hamaker: float = ...,
        intermolecular_distance: float = ...,
    ) -> "Params":
        """A validated copy with the given keywords changed."""
    @staticmethod
    def from_toml(path: Union[str, "os.PathLike[str]"], **model: Any) -> "Params":
        """Read a model config file (``--config FILE.toml`` of the command line); ``**model``
        overrides it."""
    @staticmethod
    def from_probe(path: Union[str, "os.PathLike[str]", Dict[str, Any]], **model: Any) -> "Params":
        """The dimensionless set of a probe file in SI units (``--probe FILE``); ``**model``
        takes ``modes``, ``restitution``, ``z_c`` (m) and ``drive_frequency`` (Hz); a
        dimensionless keyword of a value the probe sets (``gap``, ``omega``, ``hamaker``, …)
        raises ``ValueError`` naming the probe key or SI keyword to use. Raises ``ValueError``
        listing every problem of the file."""
    @property
    def structure(self) -> Literal["beam", "point-mass"]: ...
    @property
    def modes(self) -> int: ...
    @property
    def alpha1(self) -> float: ...
    @property
    def alpha2(self) -> float: ...
    @property
    def alpha3(self) -> float: ...
    @property
    def alpha4(self) -> float: ...
    @property
    def alpha5(self) -> float: ...
    @property
    def alpha6(self) -> float: ...
    @property
    def omega(self) -> float: ...
    @property
    def contact_law(self) -> Literal["linear", "hertz", "dmt", "impact"]: ...
    @property
    def restitution(self) -> Optional[float]: ...
    @property
    def hamaker(self) -> Optional[float]: ...
    @property
    def intermolecular_distance(self) -> Optional[float]: ...
    @property
    def tip_mass_ratio(self) -> float: ...
    @property
    def drive_amplitude(self) -> float: ...
    @property
    def beam_damping(self) -> float: ...
    @property
    def contact_stiffness(self) -> float: ...
    @property
    def gap(self) -> float: ...
    @property
    def contact_damping(self) -> float: ...
    @property
    def period(self) -> float:
        """Drive period T = 2π/Ω (in t0)."""
    def to_dict(self) -> Dict[str, Any]:
        """The ``"params"`` object of the command line's JSON documents."""
    def __eq__(self, other: object) -> bool: ...
    def __reduce__(self) -> Tuple[Any, Tuple[str]]: ...

def modes(params: Params, probe: Optional[str] = None) -> Dict[str, Any]: ...
def simulate(
    params: Params,
    periods: Optional[float] = None,
    tau_end: Optional[float] = None,
    transient: float = 0.0,
    initial: Optional[List[float]] = None,
    samples_per_period: int = 200,
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = 1e-12,
    progress: Optional[ProgressCallback] = None,
    probe: Optional[str] = None,
) -> Dict[str, Any]: ...
def converge(
    params: Params,
    max_modes: int = 4,
    periods: int = 1,
    samples_per_period: int = 200,
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = 1e-12,
    progress: Optional[ProgressCallback] = None,
    probe: Optional[str] = None,
) -> Dict[str, Any]: ...
def bifurcation(
    params: Params,
    param: str = "omega",
    values: Optional[List[float]] = None,
    from_: float = 1.0,
    to: float = 5.0,
    steps: int = 400,
    starts: int = 0,
    seed: int = 1,
    continuation: bool = True,
    threads: Optional[int] = None,
    tol: float = 1e-8,
    max_periods: Optional[int] = None,
    max_period: int = 64,
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = 1e-12,
    progress: Optional[ProgressCallback] = None,
    store: Optional[str] = None,
    resume: bool = False,
) -> Dict[str, Any]: ...
def attractors(
    params: Params,
    samples: int = 64,
    seed: int = 1,
    cluster_tol: float = 1e-5,
    tol: float = 1e-8,
    max_periods: Optional[int] = None,
    max_period: int = 64,
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = 1e-12,
    progress: Optional[ProgressCallback] = None,
    probe: Optional[str] = None,
) -> Dict[str, Any]: ...
def cantilevers() -> str: ...
def global_continuation(
    params: Params,
    param: str = "omega",
    from_: float = 1.5,
    to: float = 3.0,
    steps: int = 16,
    values: Optional[List[float]] = None,
    match_tol: float = 0.1,
    samples: int = 16,
    seed: int = 1,
    cluster_tol: float = 1e-5,
    tol: float = 1e-8,
    max_periods: Optional[int] = None,
    max_period: int = 64,
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = 1e-12,
    progress: Optional[ProgressCallback] = None,
    probe: Optional[str] = None,
) -> Dict[str, Any]: ...
def orbit(
    params: Params,
    period: Optional[int] = None,
    initial: Optional[List[float]] = None,
    tol: float = 1e-8,
    max_periods: Optional[int] = None,
    max_period: int = 64,
    progress: Optional[ProgressCallback] = None,
    probe: Optional[str] = None,
) -> Dict[str, Any]: ...
def continuation(
    params: Params,
    param: str = "omega",
    from_: float = 5.0,
    to: float = 1.0,
    period: Optional[int] = None,
    switch: bool = False,
    initial: Optional[List[float]] = None,
    tol: float = 1e-8,
    max_periods: Optional[int] = None,
    max_period: int = 64,
    progress: Optional[ProgressCallback] = None,
    probe: Optional[str] = None,
) -> Dict[str, Any]: ...
def lyapunov(
    params: Params,
    initial: Optional[List[float]] = None,
    transient: Optional[int] = None,
    periods: int = 4000,
    blocks: int = 10,
    progress: Optional[ProgressCallback] = None,
    probe: Optional[str] = None,
) -> Dict[str, Any]: ...
def probe(text: str) -> Tuple[Params, str]: ...
def probe_source(
    probe: Union[str, "os.PathLike[str]", Dict[str, Any]], cantilever: Optional[str] = None
) -> str: ...
def resolve(
    params: Optional[Params] = None,
    default: Optional[Params] = None,
    probe: Optional[str] = None,
    model: Optional[Dict[str, Any]] = None,
) -> Params: ...
def observe(
    params: Params,
    initial: Optional[List[float]] = None,
    periods: int = 1,
    harmonics: int = 10,
    tol: float = 1e-8,
    max_periods: Optional[int] = None,
    max_period: int = 64,
    progress: Optional[ProgressCallback] = None,
    probe: Optional[str] = None,
) -> Dict[str, Any]: ...
def approach(
    params: Params,
    from_: Optional[float] = None,
    to: Optional[float] = None,
    step: Optional[float] = None,
    points: Optional[int] = None,
    branches: bool = True,
    tolerance: float = 1e-10,
    setpoint: Optional[float] = None,
    traces: Optional[int] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...
def resonance(
    params: Params,
    mode: int = 1,
    from_: Optional[float] = None,
    to: Optional[float] = None,
    step: Optional[float] = None,
    points: Optional[int] = None,
    branches: bool = True,
    tolerance: float = 1e-10,
    traces: Optional[int] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

class ChartStudy:
    """A behaviour chart planned as independent tasks (tiles of cells); pickles as its recipe."""

    def __init__(self, recipe: str) -> None: ...
    @staticmethod
    def build(
        request: str,
        params: Optional[Params] = None,
        probe: Optional[str] = None,
        model: Optional[Dict[str, Any]] = None,
        integrator: Optional[str] = None,
        steps_per_period: Optional[int] = None,
        tolerance: float = 1e-12,
    ) -> ChartStudy: ...
    @property
    def recipe(self) -> str: ...
    def fingerprint(self) -> str: ...
    def compare(self, then: str) -> Optional[Tuple[str, str, str]]: ...
    def axes(self) -> Tuple[Tuple[str, str], Tuple[str, str]]: ...
    def tasks(self) -> int: ...
    def tile(self, t: int) -> Tuple[int, int, int]: ...
    def run_task(self, t: int) -> str: ...
    def arrays(
        self,
        tasks: List[str],
        origin: Optional[Tuple[int, int]] = None,
        size: Optional[Tuple[int, int]] = None,
    ) -> Dict[str, Any]: ...
    def document(self, tasks: List[str]) -> str: ...
    def run(
        self,
        threads: Optional[int] = None,
        progress: Optional[ProgressCallback] = None,
        store: Optional[str] = None,
        resume: bool = False,
    ) -> Tuple[Dict[str, Any], str]: ...

class StoreLock:
    """The lock of a store directory, released when dropped or by release()."""

    def __init__(self, path: str) -> None: ...
    def release(self) -> None: ...

class SweepStudy:
    """A bifurcation sweep planned as independent tasks (coarse passes, then segments and
    random starts); pickles as its recipe."""

    def __init__(self, recipe: str) -> None: ...
    @staticmethod
    def build(
        request: str,
        params: Params,
        integrator: Optional[str] = None,
        steps_per_period: Optional[int] = None,
        tolerance: float = 1e-12,
    ) -> SweepStudy: ...
    @property
    def recipe(self) -> str: ...
    def tasks(self, stage: int) -> int: ...
    def coarse(self, k: int) -> str: ...
    def run_task(
        self, k: int, forward: Optional[str] = None, backward: Optional[str] = None
    ) -> List[str]: ...
    def records(self, rows: List[str]) -> Dict[str, Any]: ...

class SweepStore:
    """The command line's store of a sweep, written by an executor running its tasks elsewhere."""

    def __init__(self, path: str) -> None: ...
    def open(self, study: SweepStudy, resume: bool) -> Optional[List[int]]: ...
    def append(self, rows: List[str]) -> None: ...
    def finish(self, study: SweepStudy) -> None: ...
    def records(self, study: SweepStudy) -> Dict[str, Any]: ...
    def release(self) -> None: ...

def basins(
    params: Params,
    x: str,
    x_from: float,
    x_to: float,
    x_steps: int,
    y: str,
    y_from: float,
    y_to: float,
    y_steps: int,
    near_tol: float,
    cell: float,
    basin_hits: int,
    discover_after: int,
    stride: int,
    cluster_tol: float,
    tol: float,
    max_periods: Optional[int],
    max_period: int,
    base: Optional[List[float]] = None,
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = 1e-12,
    threads: Optional[int] = None,
    progress: Optional[ProgressCallback] = None,
    probe: Optional[str] = None,
) -> Dict[str, Any]: ...
