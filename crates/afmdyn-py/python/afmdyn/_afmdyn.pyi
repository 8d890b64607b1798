"""Type stubs of the compiled core ``afmdyn._afmdyn`` (use the ``afmdyn`` package: its
functions wrap these and build the datasets and result objects)."""

import os
from typing import Any, Callable, Dict, List, Literal, Optional, Tuple, TypedDict, Union, overload

ProgressCallback = Callable[[int, Optional[int]], object]

POLL_SECONDS: float

def cancel_running() -> None: ...
#: The one table of model parameters (the library's ``afmdyn::request::MODEL_PARAMETERS``):
#: (name, alias or name, unit, range, help).
MODEL_PARAMETERS: List[Tuple[str, str, str, str, str]]

FORCE_SIGN: str
#: The columns of a bifurcation sweep's records (``afmdyn::request::sweep::COLUMNS``, the CSV's)
#: and their numeric form (``NUMERIC_COLUMNS``, the ``.npy``'s): (name, unit, meaning).
SWEEP_COLUMNS: List[Tuple[str, str, str]]
SWEEP_NUMERIC_COLUMNS: List[Tuple[str, str, str]]

class SimulationError(RuntimeError):
    """A computation failed (chattering, divergence, Newton not converging, integrator
    failure); bad input raises ``ValueError`` instead."""

class Params:
    """Dimensionless model parameters (paper eq. 7), validated on construction.

    Keywords: ``modes`` (N, 1..=20), ``tip_mass_ratio``/``alpha1`` (≥ 0),
    ``drive_amplitude``/``alpha2`` (≥ 0), ``beam_damping``/``alpha3`` (≥ 0),
    ``contact_stiffness``/``alpha4`` (≥ 0), ``gap``/``alpha5`` (finite),
    ``contact_damping``/``alpha6`` (≥ 0), ``omega`` (Ω > 0), ``contact_law`` (``"linear"``,
    ``"hertz"``, ``"dmt"``, ``"electrostatic"``, ``"jkr"``, ``"capillary"``, ``"sls"``, ``"impact"``) with
    its groups
    ``restitution`` (0..=1, impact), ``hamaker`` (≥ 0) and ``intermolecular_distance`` (> 0,
    DMT and electrostatic), ``electrostatic`` (Ẽ ≥ 0) and ``tip_radius`` (R̃ > 0,
    electrostatic), ``adhesion`` (P̃ = πWR > 0, JKR), ``capillary`` (F̃_cap > 0), ``meniscus``
    (h̃) and ``rupture`` (D̃_r, capillary), ``maxwell_stiffness`` (κ > 0, sls),
    ``excitation`` (``"base"``, ``"tip"``: where the drive acts on the beam); the others keep
    the paper's
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
        contact_law: Literal["linear", "hertz", "dmt", "electrostatic", "jkr", "capillary", "sls", "impact"] = ...,
        excitation: Literal["base", "tip"] = ...,
        restitution: float = ...,
        hamaker: float = ...,
        intermolecular_distance: float = ...,
        electrostatic: float = ...,
        tip_radius: float = ...,
        adhesion: float = ...,
        capillary: float = ...,
        meniscus: float = ...,
        rupture: float = ...,
        maxwell_stiffness: float = ...,
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
        contact_law: Literal["linear", "hertz", "dmt", "electrostatic", "jkr", "capillary", "sls", "impact"] = ...,
        excitation: Literal["base", "tip"] = ...,
        restitution: float = ...,
        hamaker: float = ...,
        intermolecular_distance: float = ...,
        electrostatic: float = ...,
        tip_radius: float = ...,
        adhesion: float = ...,
        capillary: float = ...,
        meniscus: float = ...,
        rupture: float = ...,
        maxwell_stiffness: float = ...,
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
    def contact_law(self) -> Literal["linear", "hertz", "dmt", "electrostatic", "jkr", "capillary", "sls", "impact"]: ...
    @property
    def restitution(self) -> Optional[float]: ...
    @property
    def hamaker(self) -> Optional[float]: ...
    @property
    def intermolecular_distance(self) -> Optional[float]: ...
    @property
    def excitation(self) -> Literal["base", "tip"]: ...
    @property
    def electrostatic(self) -> Optional[float]: ...
    @property
    def tip_radius(self) -> Optional[float]: ...
    @property
    def adhesion(self) -> Optional[float]: ...
    @property
    def capillary(self) -> Optional[float]: ...
    @property
    def meniscus(self) -> Optional[float]: ...
    @property
    def rupture(self) -> Optional[float]: ...
    @property
    def maxwell_stiffness(self) -> Optional[float]: ...
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

def request_defaults(name: str) -> Dict[str, Any]:
    """The default request of analysis ``name`` (the library's ``Default``) as a dict."""

# --- generated by scripts/gen_stubs.py from docs/schema/requests: do not edit ---

SteadyRequest = TypedDict(
    "SteadyRequest",
    {
        "max_period": int,  # default 64
        "max_periods": Optional[int],  # default null
        "tol": float,  # default 1e-08
    },
    total=False,
)

PeakForceSweep = TypedDict(
    "PeakForceSweep",
    {
        "quantity": Literal["z_c", "modulation_frequency"],  # default null
        "values": List[float],  # default null
    },
    total=False,
)

SimulateRequest = TypedDict(
    "SimulateRequest",
    {
        "initial": Optional[List[float]],  # default null
        "integrator": Literal["auto", "exact", "rk4", "rk4-naive", "adaptive", "split", "taylor"],  # default "auto"
        "periods": Optional[float],  # default null
        "samples_per_period": int,  # default 200
        "steps_per_period": Optional[int],  # default null
        "tau_end": Optional[float],  # default null
        "tolerance": float,  # default 1e-12
        "transient": float,  # default 0.0
    },
    total=False,
)

ConvergeRequest = TypedDict(
    "ConvergeRequest",
    {
        "integrator": Literal["auto", "exact", "rk4", "rk4-naive", "adaptive", "split", "taylor"],  # default "auto"
        "max_modes": int,  # default 4
        "periods": int,  # default 1
        "samples_per_period": int,  # default 200
        "steps_per_period": Optional[int],  # default null
        "tolerance": float,  # default 1e-12
    },
    total=False,
)

AttractorsRequest = TypedDict(
    "AttractorsRequest",
    {
        "cluster_tol": float,  # default 1e-05
        "integrator": Literal["auto", "exact", "rk4", "rk4-naive", "adaptive", "split", "taylor"],  # default "auto"
        "max_period": int,  # default 64
        "max_periods": Optional[int],  # default null
        "samples": int,  # default 64
        "seed": int,  # default 1
        "steps_per_period": Optional[int],  # default null
        "tol": float,  # default 1e-08
        "tolerance": float,  # default 1e-12
    },
    total=False,
)

GlobalContinuationRequest = TypedDict(
    "GlobalContinuationRequest",
    {
        "cluster_tol": float,  # default 1e-05
        "from": float,  # default 1.5
        "integrator": Literal["auto", "exact", "rk4", "rk4-naive", "adaptive", "split", "taylor"],  # default "auto"
        "match_tol": float,  # default 0.1
        "max_period": int,  # default 64
        "max_periods": Optional[int],  # default null
        "param": Literal["omega", "alpha1", "alpha2", "alpha3", "alpha4", "alpha5", "alpha6"],  # default "omega"
        "samples": int,  # default 16
        "seed": int,  # default 1
        "steps": int,  # default 16
        "steps_per_period": Optional[int],  # default null
        "to": float,  # default 3.0
        "tol": float,  # default 1e-08
        "tolerance": float,  # default 1e-12
        "values": Optional[List[float]],  # default null
    },
    total=False,
)

OrbitRequest = TypedDict(
    "OrbitRequest",
    {
        "initial": Optional[List[float]],  # default null
        "period": Optional[int],  # default null
        "steady": SteadyRequest,  # default {"max_period": 64, "max_periods": null, "tol": 1e-08}
    },
    total=False,
)

ContinuationRequest = TypedDict(
    "ContinuationRequest",
    {
        "from": float,  # default 5.0
        "initial": Optional[List[float]],  # default null
        "param": Literal["omega", "alpha1", "alpha2", "alpha3", "alpha4", "alpha5", "alpha6"],  # default "omega"
        "period": Optional[int],  # default null
        "steady": SteadyRequest,  # default {"max_period": 64, "max_periods": null, "tol": 1e-08}
        "switch": bool,  # default false
        "to": float,  # default 1.0
    },
    total=False,
)

LyapunovRequest = TypedDict(
    "LyapunovRequest",
    {
        "blocks": int,  # default 10
        "initial": Optional[List[float]],  # default null
        "periods": int,  # default 4000
        "transient": Optional[int],  # default null
    },
    total=False,
)

ObserveRequest = TypedDict(
    "ObserveRequest",
    {
        "harmonics": int,  # default 10
        "initial": Optional[List[float]],  # default null
        "periods": int,  # default 1
        "steady": SteadyRequest,  # default {"max_period": 64, "max_periods": null, "tol": 1e-08}
    },
    total=False,
)

ApproachRequest = TypedDict(
    "ApproachRequest",
    {
        "average": bool,  # default false
        "branches": bool,  # default true
        "exact": bool,  # default false
        "from": Optional[float],  # default null
        "points": Optional[int],  # default null
        "setpoint": Optional[float],  # default null
        "step": Optional[float],  # default null
        "to": Optional[float],  # default null
        "tolerance": float,  # default 1e-10
        "traces": Optional[int],  # default null
    },
    total=False,
)

ResonanceRequest = TypedDict(
    "ResonanceRequest",
    {
        "branches": bool,  # default true
        "from": Optional[float],  # default null
        "mode": int,  # default 1
        "points": Optional[int],  # default null
        "step": Optional[float],  # default null
        "to": Optional[float],  # default null
        "tolerance": float,  # default 1e-10
        "traces": Optional[int],  # default null
    },
    total=False,
)

BasinsRequest = TypedDict(
    "BasinsRequest",
    {
        "base": Optional[List[float]],  # default null
        "basin_hits": int,  # default 16
        "cell": float,  # default 0.01
        "cluster_tol": float,  # default 1e-05
        "discover_after": int,  # default 200
        "integrator": Literal["auto", "exact", "rk4", "rk4-naive", "adaptive", "split", "taylor"],  # default "auto"
        "max_period": int,  # default 64
        "max_periods": Optional[int],  # default null
        "near_tol": float,  # default 0.02
        "steps_per_period": Optional[int],  # default null
        "stride": int,  # default 0
        "threads": Optional[int],  # default null
        "tol": float,  # default 1e-08
        "tolerance": float,  # default 1e-12
        "x": str,  # default "a1"
        "x_from": float,  # default -0.6
        "x_steps": int,  # default 40
        "x_to": float,  # default 0.6
        "y": str,  # default "adot1"
        "y_from": float,  # default -1.2
        "y_steps": int,  # default 40
        "y_to": float,  # default 1.2
    },
    total=False,
)

FmRequest = TypedDict(
    "FmRequest",
    {
        "amplitude": Optional[float],  # default null
        "from": Optional[float],  # default null
        "mode": int,  # default 1
        "points": Optional[int],  # default null
        "step": Optional[float],  # default null
        "to": Optional[float],  # default null
        "tolerance": float,  # default 1e-09
    },
    total=False,
)

ReconstructRequest = TypedDict(
    "ReconstructRequest",
    {
        "amplitude": float,  # default 0.0
        "distance": Optional[List[float]],  # default null
        "frequency_shift": List[float],  # default []
        "inversion": Literal["sader-jarvis", "exact"],  # default "sader-jarvis"
        "law_force": Optional[List[float]],  # default null
        "resonance_frequency": float,  # default 0.0
        "spring_constant": float,  # default 0.0
        "z_c": Optional[List[float]],  # default null
    },
    total=False,
)

PeakForceRequest = TypedDict(
    "PeakForceRequest",
    {
        "filter_cutoff": Optional[float],  # default null
        "fit_band": List[float],  # default [0.3, 0.9]
        "samples": int,  # default 4096
        "setpoint": Optional[float],  # default null
        "sweep": Optional[PeakForceSweep],  # default null
        "z_c": Optional[float],  # default null
    },
    total=False,
)

FitRequest = TypedDict(
    "FitRequest",
    {
        "approach_rows": Optional[int],  # default null
        "data": Optional[str],  # default null
        "fit": List[str],  # default ["sample.youngs_modulus", "contact_point"]
        "force": List[float],  # default []
        "height": List[float],  # default []
        "profiles": Optional[bool],  # default null
        "range": Optional[List[float]],  # default null
        "segment": Optional[Literal["approach", "retract", "whole"]],  # default null
        "sigma": Optional[List[float]],  # default null
        "time": List[float],  # default []
    },
    total=False,
)

BifurcationRequest = TypedDict(
    "BifurcationRequest",
    {
        "continuation": bool,  # default true
        "from": float,  # default 1.0
        "integrator": Literal["auto", "exact", "rk4", "rk4-naive", "adaptive", "split", "taylor"],  # default "auto"
        "max_period": int,  # default 64
        "max_periods": Optional[int],  # default null
        "param": Literal["omega", "alpha1", "alpha2", "alpha3", "alpha4", "alpha5", "alpha6"],  # default "omega"
        "seed": int,  # default 1
        "starts": int,  # default 0
        "steps": int,  # default 400
        "steps_per_period": Optional[int],  # default null
        "threads": Optional[int],  # default null
        "to": float,  # default 5.0
        "tol": float,  # default 1e-08
        "tolerance": float,  # default 1e-12
        "values": Optional[List[float]],  # default null
    },
    total=False,
)

ChartRequest = TypedDict(
    "ChartRequest",
    {
        "cluster_tol": float,  # default 1e-05
        "integrator": Literal["auto", "exact", "rk4", "rk4-naive", "adaptive", "split", "taylor"],  # default "auto"
        "lyapunov_periods": int,  # default 500
        "max_attractors": int,  # default 8
        "max_period": int,  # default 64
        "max_periods": Optional[int],  # default null
        "seed": int,  # default 1
        "starts": int,  # default 4
        "steps_per_period": Optional[int],  # default null
        "threads": Optional[int],  # default null
        "tile": int,  # default 8
        "tol": float,  # default 1e-08
        "tolerance": float,  # default 1e-12
        "x": str,  # default "omega"
        "x_from": float,  # default 2.6
        "x_steps": int,  # default 9
        "x_to": float,  # default 3.0
        "y": str,  # default "drive_amplitude"
        "y_from": float,  # default 0.1
        "y_steps": int,  # default 2
        "y_to": float,  # default 0.12
    },
    total=False,
)

@overload
def run(
    name: Literal["modes"],
    request: Optional[Dict[str, Any]] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["simulate"],
    request: Optional[SimulateRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["converge"],
    request: Optional[ConvergeRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["attractors"],
    request: Optional[AttractorsRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["global_continuation"],
    request: Optional[GlobalContinuationRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["orbit"],
    request: Optional[OrbitRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["continuation"],
    request: Optional[ContinuationRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["lyapunov"],
    request: Optional[LyapunovRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["observe"],
    request: Optional[ObserveRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["approach"],
    request: Optional[ApproachRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["bimodal"],
    request: Optional[ApproachRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["resonance"],
    request: Optional[ResonanceRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["basins"],
    request: Optional[BasinsRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["fm"],
    request: Optional[FmRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["reconstruct"],
    request: Optional[ReconstructRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["peakforce"],
    request: Optional[PeakForceRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: Literal["fit"],
    request: Optional[FitRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run(
    name: str,
    request: Optional[Dict[str, Any]] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
) -> Dict[str, Any]: ...

@overload
def run_stored(
    name: Literal["bifurcation"],
    request: Optional[BifurcationRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
    store: Optional[str] = None,
    resume: bool = False,
) -> Dict[str, Any]: ...

@overload
def run_stored(
    name: Literal["basins"],
    request: Optional[BasinsRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
    store: Optional[str] = None,
    resume: bool = False,
) -> Dict[str, Any]: ...

@overload
def run_stored(
    name: Literal["global_continuation"],
    request: Optional[GlobalContinuationRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
    store: Optional[str] = None,
    resume: bool = False,
) -> Dict[str, Any]: ...

@overload
def run_stored(
    name: Literal["approach"],
    request: Optional[ApproachRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
    store: Optional[str] = None,
    resume: bool = False,
) -> Dict[str, Any]: ...

@overload
def run_stored(
    name: Literal["bimodal"],
    request: Optional[ApproachRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
    store: Optional[str] = None,
    resume: bool = False,
) -> Dict[str, Any]: ...

@overload
def run_stored(
    name: Literal["resonance"],
    request: Optional[ResonanceRequest] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
    store: Optional[str] = None,
    resume: bool = False,
) -> Dict[str, Any]: ...

@overload
def run_stored(
    name: str,
    request: Optional[Dict[str, Any]] = None,
    params: Optional[Params] = None,
    probe: Optional[str] = None,
    progress: Optional[ProgressCallback] = None,
    store: Optional[str] = None,
    resume: bool = False,
) -> Dict[str, Any]: ...

# --- end of the generated block ---

def image(
    probe: str,
    request: Dict[str, Any],
    progress: Optional[Callable[[int, Optional[int]], object]] = None,
) -> Dict[str, Any]: ...
def read_height_map(path: str) -> List[List[float]]: ...
def setpoint_study(
    probe: str,
    sample: str,
    ratios: List[float],
    curve_points: Optional[int] = None,
) -> Dict[str, Any]: ...
def cantilevers() -> str: ...
def probe(text: str) -> Tuple[Params, str]: ...
def probe_source(
    probe: Union[str, "os.PathLike[str]", Dict[str, Any]],
    cantilever: Optional[str] = None,
    medium: Optional[str] = None,
) -> str: ...
def resolve(
    params: Optional[Params] = None,
    default: Optional[Params] = None,
    probe: Optional[str] = None,
    model: Optional[Dict[str, Any]] = None,
) -> Params: ...

class ChartStudy:
    """A behaviour chart planned as independent tasks (tiles of cells); pickles as its recipe."""

    def __init__(self, recipe: str) -> None: ...
    @staticmethod
    def build(
        request: Optional[Dict[str, Any]] = None,
        params: Optional[Params] = None,
        probe: Optional[str] = None,
        model: Optional[Dict[str, Any]] = None,
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
    def check(self, attractors: List[int]) -> None: ...
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

class Plan:
    """A study planned as stages of numbered tasks (the library's ``study::plan``: a
    bifurcation sweep, a basin map, a PI scan; the tasks of ``afmdyn.dask``); pickles as its
    recipe. Starts and results travel as text."""

    def __init__(self, recipe: str) -> None: ...
    @staticmethod
    def build(
        name: str,
        request: Optional[Dict[str, Any]] = None,
        params: Optional[Params] = None,
        probe: Optional[str] = None,
    ) -> Plan: ...
    @property
    def recipe(self) -> str: ...
    def stages(self) -> int: ...
    def stage(self, stage: int, results: List[str]) -> Tuple[str, List[int]]: ...
    def run(self, start: str, task: int) -> str: ...
    def outcome(self, results: List[str]) -> Dict[str, Any]: ...
    def store(self, path: str) -> PlanStore: ...

class PlanStore:
    """A plan's resumable store (the command line's), locked until released."""

    def open(self, resume: bool) -> Optional[List[int]]: ...
    def append(self, result: str) -> None: ...
    def finish(self) -> None: ...
    def outcome(self) -> Dict[str, Any]: ...
    def release(self) -> None: ...
