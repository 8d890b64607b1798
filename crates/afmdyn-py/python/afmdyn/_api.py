"""The analyses (those with result objects of their own: :mod:`._orbits`, :mod:`._attractors`;
the shared machinery: :mod:`._common`). Each takes the model as a :class:`Params` and/or keyword arguments, runs the
Rust engine with the GIL released (Ctrl-C raises ``KeyboardInterrupt``; long runs show a
progress bar) and returns NumPy arrays in xarray datasets or small result objects.

Units (paper eq. 5): time τ in t0 = √(mL⁴/EI), displacements in the beam gap g0, forces in
EI g0/L³, energies in EI g0²/L³. Model keywords: ``modes``, ``tip_mass_ratio``/``alpha1``,
``drive_amplitude``/``alpha2``, ``beam_damping``/``alpha3``, ``contact_stiffness``/``alpha4``,
``gap``/``alpha5``, ``contact_damping``/``alpha6``, ``omega`` (see :class:`Params`).

Errors: ``ValueError`` for input out of range (the message names the field and its range),
``TypeError`` for an unknown keyword or a wrong type, :class:`SimulationError` when a
computation fails (chattering, divergence, Newton not converging). The keywords of an
analysis are its library request's (``_afmdyn.request_defaults(name)`` gives their defaults):
they go through serde into the request, which checks them.
"""

from __future__ import annotations

import json
import os
from typing import TYPE_CHECKING, Any, Dict, Optional, Sequence, Union

import numpy as np
import xarray as xr

from . import _afmdyn as _core
from ._afmdyn import Params
from ._common import (  # noqa: F401 (_params, _probe_text, _typed, _warn: used by _chart, dask)
    _DEFAULTS,
    Model,
    StateLike,
    _attrs,
    _door,
    _params,
    _probe_text,
    _request,
    _start,
    _state,
    _typed,
    _warn,
    summary,
)
from . import _layout
from ._progress import ProgressArg
from ._results import RegionSpectrum, Spectrum

if TYPE_CHECKING:  # annotations only (PEP 692): editors complete and check the keywords
    from typing_extensions import Unpack


@_typed
def modes(params: Optional[Params] = None, /, **model: Unpack[Model]) -> Spectrum:
    """Natural frequencies and damped eigenvalues of the free and contact systems
    (paper eqs. 19–23).

    Returns a :class:`Spectrum` (``.free``, ``.contact``: ω float64 ``[N]``, eigenvalues
    complex128, ζ); ``to_dict()`` is ``afmdyn modes --json``.
    """
    p, probe = _params(params, model)
    d = _door("modes", "modes", False, p, probe)

    def region(name: str) -> RegionSpectrum:
        v = _layout.variables(d["datasets"][name])
        return RegionSpectrum(v["omega"][1], v["eigenvalues"][1], v["zeta"][1])

    return Spectrum(p, region("free"), region("contact"), d["json"])


@_typed
def simulate(
    params: Optional[Params] = None,
    /,
    *,
    periods: Optional[float] = None,
    tau_end: Optional[float] = None,
    transient: float = _DEFAULTS["simulate"]["transient"],
    initial: StateLike = None,
    samples_per_period: int = _DEFAULTS["simulate"]["samples_per_period"],
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = _DEFAULTS["simulate"]["tolerance"],
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Integrate one trajectory (``afmdyn simulate``).

    Args:
        periods: drive periods recorded after the transient (default 50), or
        tau_end: the end time τ instead.
        transient: drive periods run and discarded first.
        initial: initial state (a₁…a_N, ȧ₁…ȧ_N), ``[2N]``, or an :class:`Attractor` /
            :class:`Orbit` (its state at drive phase 0); default: rest.
        samples_per_period: samples per drive period (1..=100000).
        integrator: ``"exact"``, ``"split"``, ``"taylor"``, ``"rk4"``,
            ``"rk4-naive"`` or ``"adaptive"``; default (``None``) the command line's default
            (exact for the linear law, split for Hertz and impact, taylor for DMT);
            steps_per_period: rk4's fixed steps (default 2000); tolerance: the adaptive one's.
        progress: ``None`` (a bar for long runs), ``True``, ``False`` or ``callable(done, total)``.

    Returns:
        ``xarray.Dataset`` with dims ``tau`` (S samples), ``mode`` (N), ``event`` (E
        switchings), ``section`` (P section points τ = 2πk/Ω), ``component`` (2N) and ``cycle``
        (C complete drive periods): ``v_t``, ``v_t_dot``, ``w_tip``, ``w_tip_dot``,
        ``in_contact``, ``contact_force`` ``[S]``; ``a``, ``a_dot`` ``[S, N]``;
        ``event_tau``, ``event_to_contact``, ``event_v_t_dot`` ``[E]``; ``section_tau``,
        ``section_v_t``, ``section_w_tip``, ``section_w_tip_dot`` ``[P]``, ``section_state``
        ``[P, 2N]``; the energy balance per period ``[C]``; ``spectrum`` ``[F]`` over dim
        ``frequency`` (the amplitude spectrum of W(1,τ) over the last ≤ 2²⁰ samples, the
        command line's ``spectrum.csv``). ``attrs["summary"]`` holds
        ``afmdyn simulate --json`` (see :func:`summary`). Units: the model's (τ in t0,
        lengths in g0, forces E I g0/L³, or k g0 for the point mass); with ``probe`` every
        array is in SI, as the command line's files — times (the coordinate ``t``, named
        ``tau`` without a probe; events, sections) in s, lengths in m, velocities in m/s, forces in N, energies in J, the
        spectrum's frequencies in Hz — each variable's unit in its attrs.
    """
    req = _request(locals(), initial=_state(initial))
    p, probe = _params(params, model)
    d = _door("simulate", "simulate", progress, p, probe, req)
    f = d["facts"]
    attrs = _attrs(
        p,
        summary=d["json"],
        tau_end=f["tau_end"],
        switchings=f["switchings"],
        body_contact=int(f["body_contact"]),
        integrator=f["integrator"],
        transient_tau=f["transient_tau"],
        samples_per_period=samples_per_period,
    )
    # with a probe the library laid every array out in SI (report::simulate_layout)
    return _layout.dataset(d["datasets"]["simulate"], attrs)


@_typed
def converge(
    params: Optional[Params] = None,
    /,
    *,
    max_modes: int = _DEFAULTS["converge"]["max_modes"],
    periods: int = _DEFAULTS["converge"]["periods"],
    samples_per_period: int = _DEFAULTS["converge"]["samples_per_period"],
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = _DEFAULTS["converge"]["tolerance"],
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Mode-number convergence (paper Fig. 4, ``afmdyn converge``): the steady tip motion
    for N = 1..max_modes. Without ``params`` the model defaults to Ω = 4.1 (eq. 24 with the
    damping of eq. 26), as on the command line.

    Returns:
        ``xarray.Dataset`` with dims ``n_modes`` (max_modes) and ``sample`` (K):
        ``w_tip``, ``v_t``, ``tau`` ``[n_modes, K]`` over ``periods`` drive periods from a
        section point; ``period`` ``[n_modes]`` (−1: nonperiodic); ``rms_change``
        ``[n_modes]`` (RMS of W_tip(N) − W_tip(N−1), NaN for N = 1); coordinate
        ``tau_from_section`` ``[K]``.

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    req = _request(locals())
    p, probe = _params(params, model, default=Params(omega=4.1))
    d = _door("converge", "converge", progress, p, probe, req)
    attrs = _attrs(p, summary=d["json"])
    return _layout.dataset(d["datasets"]["converge"], attrs, coords=("tau_from_section",))


@_typed
def bifurcation(
    params: Optional[Params] = None,
    /,
    *,
    param: str = _DEFAULTS["bifurcation"]["param"],
    from_: float = _DEFAULTS["bifurcation"]["from"],
    to: float = _DEFAULTS["bifurcation"]["to"],
    steps: int = _DEFAULTS["bifurcation"]["steps"],
    values: Optional[Sequence[float]] = None,
    starts: int = _DEFAULTS["bifurcation"]["starts"],
    seed: int = _DEFAULTS["bifurcation"]["seed"],
    continuation: bool = _DEFAULTS["bifurcation"]["continuation"],
    threads: Optional[int] = None,
    tol: float = _DEFAULTS["bifurcation"]["tol"],
    max_periods: Optional[int] = None,
    max_period: int = _DEFAULTS["bifurcation"]["max_period"],
    integrator: Optional[str] = None,
    steps_per_period: Optional[int] = None,
    tolerance: float = _DEFAULTS["bifurcation"]["tolerance"],
    progress: ProgressArg = None,
    store: Union[str, "os.PathLike[str]", None] = None,
    resume: bool = False,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Bifurcation diagram (paper Fig. 5, ``afmdyn bifurcation``): the steady state at each
    value of ``param`` by forward and backward continuation and ``starts`` random starts, in
    parallel (``threads`` workers, default all cores). Ctrl-C stops it within one point.

    With ``store``, each finished point is also written to that directory (created if needed;
    the layout of ``afmdyn bifurcation --out DIR``: ``bifurcation.csv`` when finished, the
    ledger ``.bifurcation.run.json`` and the partial rows of an unfinished sweep), and
    ``resume=True`` continues the sweep stored there, computing only the points not yet
    written (``--resume``): an interrupted sweep, from Python or the command line, resumes;
    a finished one is read back without computing anything. Without ``resume`` the store is
    started over.

    Args:
        param: ``"omega"`` or ``"alpha1"``…``"alpha6"`` (or the descriptive names).
        from_, to, steps: ``steps`` evenly spaced values (``from`` is a Python keyword), or
        values: explicit values.
        starts, seed: random initial states per value; continuation: forward/backward chains.
        tol, max_periods, max_period: steady-state detection (as ``--tol`` etc.).
        store: directory checkpointing the sweep; resume: continue the sweep stored there.

    Raises:
        ValueError: ``resume=True`` on a store made by another request (the message names the
            first field that differs and both values, e.g. ``steps = 60 in the interrupted
            run, 30 now``), on a store holding rows without a ledger, or without ``store``.
        OSError: the store cannot be read or written.

    Returns:
        ``xarray.Dataset`` in long format, dim ``point`` (one row per section point, in the
        order of the command line's ``bifurcation.csv``: by value index, then ``forward``,
        ``backward``, ``start-0``, ``start-1``, …, then ``k``): coordinates
        ``value``, ``index``, ``branch`` (``"forward"``, ``"backward"``, ``"start-k"``);
        ``status`` (``"periodic"``, ``"nonperiodic"``, ``"error"``), ``period`` (−1
        nonperiodic, −2 error), ``k`` (position in the cycle), ``n_points``, ``tau``,
        ``v_t``, ``w_tip``, ``x_max``, ``v_t_min``, ``contact_fraction``,
        ``contacts_per_period``, ``transient_periods``, ``message``, ``a_1``…``a_N``,
        ``a_dot_1``…``a_dot_N``. ``.to_dataframe()`` gives the tidy table.

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    req = _request(locals())
    if values is not None:
        req["values"] = np.asarray(values, dtype=np.float64).ravel().tolist()
    p, probe = _params(params, model)
    # the sweep's records carry no JSON document, so no "si" block: the probe only resolved p
    d = _door("bifurcation", "bifurcation", progress, p, None, req, store, resume, stored=True)
    return _sweep_dataset(p, d, starts, seed)


def _sweep_dataset(p: Params, d: Dict[str, Any], starts: int, seed: int) -> xr.Dataset:
    """The long-format dataset of a sweep's records ``d`` (``bifurcation``'s, and
    ``afmdyn.dask.bifurcation``'s), laid out by the library."""
    f = d["facts"]
    attrs = _attrs(p, param=f["param"], values=f["values"], starts=starts, seed=seed)
    ds = _layout.dataset(d["datasets"]["bifurcation"], attrs)
    return ds.set_coords(["value", "index", "branch"])


@_typed
def continuation(
    params: Optional[Params] = None,
    /,
    *,
    param: str = _DEFAULTS["continuation"]["param"],
    from_: float = _DEFAULTS["continuation"]["from"],
    to: float = _DEFAULTS["continuation"]["to"],
    period: Optional[int] = None,
    switch: bool = _DEFAULTS["continuation"]["switch"],
    initial: StateLike = None,
    tol: float = _DEFAULTS["continuation"]["steady"]["tol"],
    max_periods: Optional[int] = None,
    max_period: int = _DEFAULTS["continuation"]["steady"]["max_period"],
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Pseudo-arclength continuation of a period-n branch from ``from_`` towards ``to``, with
    located folds, period doublings, Neimark–Sacker and grazing points (``afmdyn continue``).

    Args:
        param: continued parameter (``"omega"``, ``"alpha1"``…``"alpha6"``).
        period: n (default: the period of the steady state at ``from_``).
        switch: at each period doubling also continue the period-2n branch.
        initial: starting guess (``[2N]``, an :class:`Attractor` or :class:`Orbit`);
            default: the steady state reached from rest at ``from_``.

    Returns:
        ``xarray.Dataset`` with dim ``point`` (all branches in order): ``branch`` (0 the
        main branch, 1… switched ones), ``period``, ``s`` (arclength), ``value``, ``stable``,
        ``max_multiplier``, ``critical``, ``switchings``, ``grazing_distance``, ``event``
        (``""`` or ``"fold"``, ``"period-doubling"``, ``"neimark-sacker"``, ``"grazing"``);
        ``w_tip_section`` ``[point, k]`` (W(1,τ) at the section points, NaN-padded),
        ``multipliers`` ``[point, 2N]`` complex128, ``state`` ``[point, 2N]``.
        ``attrs["summary"]`` is ``afmdyn continue --json``.

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    req = _start(_request(locals(), initial=_state(initial)))
    p, probe = _params(params, model)
    d = _door("continuation", "continuation", progress, p, probe, req)
    attrs = _attrs(p, param=d["facts"]["param"], summary=d["json"])
    ds = _layout.dataset(d["datasets"]["continuation"], attrs)
    return ds.set_coords("value")


def probe(
    path: Union[str, "os.PathLike[str]", Dict[str, Any]],
    cantilever: Optional[str] = None,
    medium: Optional[str] = None,
) -> Dict[str, Any]:
    """Read a probe in SI units (the command line's ``--probe FILE``; format and mapping in
    ``docs/afm-workflow.md``): a file's path, its TOML text or a dict of its sections, with
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


@_typed
def observe(
    params: Optional[Params] = None,
    /,
    *,
    initial: StateLike = None,
    periods: int = _DEFAULTS["observe"]["periods"],
    harmonics: int = _DEFAULTS["observe"]["harmonics"],
    tol: float = _DEFAULTS["observe"]["steady"]["tol"],
    max_periods: Optional[int] = None,
    max_period: int = _DEFAULTS["observe"]["steady"]["max_period"],
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Observables of the steady state reached from ``initial`` (default: rest): first-harmonic
    amplitude and phase lag of the tip deflection, harmonics and THD, mean deflection, peak and
    minimum force, indentation, contact fraction and time, minimum distance, impacts, the energy
    dissipated in the sample, the virial, the per-mode energy balance and the closed forms
    (Cleveland/Anczykowski E_dis, San Paulo & García virial) beside the direct integrals.

    The steady state is found as by :func:`orbit` and, when periodic, polished by Newton
    shooting; ``periods`` orbit periods are integrated on the dense output (no sampling).

    Returns:
        An ``xarray.Dataset`` in SI with a probe (m, N, J, s; the model's units g₀, F̃, F̃·g₀,
        τ otherwise; ``units`` in each variable's attrs), phases in degrees: scalars
        ``amplitude``, ``amplitude_ratio``, ``phase_deg``, ``mean_deflection``,
        ``peak_force``, ``min_force``, ``indentation``, ``contact_fraction``,
        ``min_distance``, ``energy_dissipated``, ``virial``, ``harmonic_distortion``, ``higher_mode_fraction``,
        ``contact_time``, ``mean_force``, ``impacts_per_period``, ``impact_loss``, ``period``
        (NaN when not periodic); ``harmonic_amplitude``/``harmonic_phase_deg`` over
        ``harmonic``; the energy balance ``mode_drive``, ``mode_sample``, … over ``mode``;
        ``state`` ``[2N]`` (a, ȧ). ``ds.afmdyn.to_dict()`` is the library's document
        (dimensionless, phases in radians, the closed forms; its ``reported`` block holds the
        dataset's values).

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    req = _start(_request(locals(), initial=_state(initial)))
    p, probe = _params(params, model)
    d = _door("observe", "observe", progress, p, probe, req)
    ds = _layout.dataset(d["datasets"]["observe"])
    doc: Dict[str, Any] = json.loads(d["json"])
    doc["state"] = [float(v) for v in ds["state"].values]
    doc["period"] = d["facts"]["period"]
    ds.attrs = {"title": "afmdyn observe", "summary": json.dumps(doc)}
    return ds


def _curve(
    desc: str,
    progress: ProgressArg,
    params: Optional[Params],
    model: Any,
    request: Dict[str, Any],
    store: Union[str, "os.PathLike[str]", None] = None,
    resume: bool = False,
) -> xr.Dataset:
    """Run a stepped-curve analysis (:func:`approach`, :func:`resonance`) — in the command
    line's resumable store ``store`` when given — and return its dataset
    (the library's layout of its document, ``afmdyn::request::curve_layout``; in SI with a
    probe; ``attrs["summary"]`` is the document)."""
    p, probe = _params(params, model)
    d = _door(desc, desc, progress, p, probe, request, store, resume)
    attrs = {"title": f"afmdyn {desc}", "summary": d["json"]}
    free = json.loads(d["json"]).get("free_amplitude")
    if free is not None:  # attrs must be storable in NetCDF
        attrs["free_amplitude"] = free
    traces = tuple(f"trace_{x}" for x in ("z_c", "frequency_hz", "omega"))
    return _layout.dataset(d["datasets"]["curve"], attrs, coords=traces)


@_typed
def approach(
    params: Optional[Params] = None,
    /,
    *,
    from_: Optional[float] = None,
    to: Optional[float] = None,
    step: Optional[float] = None,
    points: Optional[int] = None,
    branches: bool = _DEFAULTS["approach"]["branches"],
    tolerance: float = _DEFAULTS["approach"]["tolerance"],
    setpoint: Optional[float] = None,
    traces: Optional[int] = None,
    store: Union[str, "os.PathLike[str]", None] = None,
    resume: bool = False,
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """The amplitude-modulation approach–retract curve over the rest distance z_c
    (``afmdyn approach``): the steady state stepped from ``from_`` down to ``to`` and back, each
    value continued from the previous orbit, plus the periodic-orbit branches continued in z_c
    with Floquet stability, the folds, the bistable ranges and the jumps.

    Args:
        from_, to: the z_c range (default 1.2 A₀ to 0.1 A₀ above contact), in m with
            ``probe``, else in g₀.
        step, points: the grid (a step in the same unit, or the number of values; default 120).
        branches: also continue the branches.
        tolerance: of the adaptive integrator.
        traces: samples per drive period of one steady-state cycle recorded at every z_c of
            the approach (``traces`` in the document: ``z_c``, ``time_periods``, and per z_c
            ``deflection``, ``distance`` V_T and ``force``; the force–distance loop's area is
            E_dis).
        setpoint: the amplitude setpoint A_sp/A₀ in (0, 1]: the document gains ``setpoint``
            (``ratio``, ``amplitude``, ``points``: per stable branch crossing its ``source``,
            ``z_c``, ``regime`` (attractive/repulsive), phase, peak force, indentation, E_dis…).
        probe: a probe file (a model keyword, as ``--probe``): it sets the model, and its
            scales give SI inputs (``from_``, ``to``, ``step`` in m) and outputs.
        store: a directory for the command line's resumable store of the curve's points
            (``afmdyn approach --out DIR``); ``resume=True`` continues an interrupted curve of
            the same request from its last stored point (refused, naming the option, for
            another request's store).

    Returns:
        An ``xarray.Dataset`` (SI with a probe: m, N, J, degrees; ``units`` in each variable's
        attrs) over ``z_c`` (the approach's grid) and ``sweep`` = ``approach``/``retract``:
        ``amplitude``, ``amplitude_ratio``, ``phase_deg``, ``mean_deflection``,
        ``peak_force``, ``min_force``, ``indentation``, ``contact_fraction``,
        ``min_distance``, ``energy_dissipated``, ``virial``, ``harmonic_distortion``, ``higher_mode_fraction``,
        ``stable``, ``period``, ``reached``; the branches along ``branch_point``
        (``branch``, ``branch_z_c``, ``branch_amplitude``, …, ``branch_event``); with
        ``traces``, ``trace_deflection``/``trace_distance``/``trace_force`` over (``trace``,
        ``trace_time``). ``ds.afmdyn.to_dict()`` is the ``afmdyn approach --json`` document
        (``folds``, ``bistable``, ``jumps``, ``setpoint``, ``warnings``;
        ``docs/outputs.md``).

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    return _curve("approach", progress, params, model, _request(locals()),
                  store, resume)


@_typed
def bimodal(
    params: Optional[Params] = None,
    /,
    *,
    from_: Optional[float] = None,
    to: Optional[float] = None,
    step: Optional[float] = None,
    points: Optional[int] = None,
    branches: bool = _DEFAULTS["approach"]["branches"],
    tolerance: float = _DEFAULTS["approach"]["tolerance"],
    traces: Optional[int] = None,
    average: bool = False,
    exact: bool = False,
    setpoint: Optional[float] = None,
    store: Union[str, "os.PathLike[str]", None] = None,
    resume: bool = False,
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """The bimodal (multifrequency) AM approach–retract curve (``afmdyn bimodal``): the
    approach curve of a drive with two or more components — a probe whose ``[drive]`` gives
    ``free_amplitude = [A01, A02]`` and ``frequency = [f1, f2]`` (or each component at its
    mode's resonance), on the eigenmode model (``model = "eigenmodes"``), the beam or the point
    mass. The frequency ratio is taken as a fraction p/q (within 1e-6), the steady state is the
    periodic orbit of the common period q/f1, and each component's amplitude, phase, virial
    and dissipated energy come from demodulation over it (Lozano & García, Phys. Rev. Lett.
    100, 076102 (2008); García & Proksch, Eur. Polym. J. 49, 1897 (2013)). A ratio whose
    common period exceeds 1000 primary periods (incommensurate) is averaged in time instead.

    Args:
        from_, to, step, points, branches, tolerance, traces, store, resume: as
            :func:`approach` (the default range from 1.2 to 0.1 times the sum of the free
            amplitudes).
        average: demodulate a time average (a Hann² window over many primary periods, after
            the transient has settled) instead of the periodic orbit — what an incommensurate
            ratio always gets; branches and traces are then off.
        exact: the exact periodic orbit of the common period at every point, with branches,
            also for a two-frequency drive that repeats only after more than 32 primary
            periods (f2/f1 = 6.27 = 627/100), whose points are otherwise measured on the
            invariant circle of the stroboscopic map (the exact orbit where the circle is not
            smooth; per point in ``ds.afmdyn.to_dict()["invariant_circle"]``, counted in the
            warnings; no branches on circles).
        setpoint: A1/A01 in (0, 1] of the first component, the amplitude the feedback holds:
            ``ds.afmdyn.to_dict()["setpoint"]["points"]`` gives the operating points where the
            curve reaches it, with every component's ``amplitude_i``, ``phase_i_deg``,
            ``virial_i`` and ``energy_dissipated_i`` there (as :func:`approach`'s).
        probe: the probe file with the multifrequency ``[drive]`` (a model keyword).

    Raises:
        ValueError: for a single-frequency drive (naming ``[drive].free_amplitude``), and as
            :func:`approach`.

    Returns:
        The dataset of :func:`approach` plus, over (``sweep``, ``z_c``), ``amplitude_i``,
        ``phase_i_deg``, ``virial_i`` and ``energy_dissipated_i`` (per cycle of component i)
        for each component i = 1, 2, … (1 the primary; SI with a probe); the branches' as
        ``branch_amplitude_2`` …; the frequencies, ratios and free amplitudes in
        ``ds.afmdyn.to_dict()["drive_components"]``; for a time average, each point's periods,
        whether it settled, and its amplitude and phase error estimates per component in
        ``ds.afmdyn.to_dict()["time_average"]`` (an unsettled point also in the warnings).

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    return _curve("bimodal", progress, params, model, _request(locals()),
                  store, resume)


@_typed
def resonance(
    params: Optional[Params] = None,
    /,
    *,
    mode: int = _DEFAULTS["resonance"]["mode"],
    from_: Optional[float] = None,
    to: Optional[float] = None,
    step: Optional[float] = None,
    points: Optional[int] = None,
    branches: bool = _DEFAULTS["resonance"]["branches"],
    tolerance: float = _DEFAULTS["resonance"]["tolerance"],
    traces: Optional[int] = None,
    store: Union[str, "os.PathLike[str]", None] = None,
    resume: bool = False,
    progress: ProgressArg = None,
    **model: Unpack[Model],
) -> xr.Dataset:
    """Amplitude and phase against the drive frequency near mode ``mode``
    (``afmdyn resonance``): up- and down-sweep, each value continued from the previous orbit,
    plus the branches continued in Ω with their folds (the bent, multivalued resonance curves of
    tapping mode).

    Args:
        from_, to: the band (default ω_k (1 ∓ max(6/Q_k, 0.02))), in Hz with ``probe``, else Ω.
        step, points, branches, tolerance, traces, store, resume: as :func:`approach`
            (traces per frequency of the up-sweep; the store of ``afmdyn resonance --out
            DIR``); ``probe`` (a model keyword) sets the model and gives frequencies in Hz.

    Returns:
        An ``xarray.Dataset`` as :func:`approach`'s over ``frequency_hz`` (with a probe) or
        ``omega`` and ``sweep`` = ``up``/``down``; ``ds.afmdyn.to_dict()`` is the
        ``afmdyn resonance --json`` document.

    ``progress``: ``None`` (a bar for runs over a second in a terminal or Jupyter, none in a
    log), ``True`` (a bar at once), ``False`` or ``callable(done, total)``.
    """
    return _curve("resonance", progress, params, model, _request(locals()),
                  store, resume)
