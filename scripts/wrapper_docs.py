"""The docstrings' own parts of the generated analysis functions (``afmdyn/_wrappers.py``,
written by ``scripts/gen_wrappers.py``): per analysis its summary and its "Returns:" and
"Raises:" sections. The "Args:" come from the request schemas' field descriptions; ``args``
gives those of the keywords a request does not describe (or describes otherwise for Python;
a text starting with "+" is added to the request's)."""

WRAPPERS = {
    "modes": {
        "summary": """\
Natural frequencies and damped eigenvalues of the free and contact systems
(paper eqs. 19–23).""",
        "returns": """\
Returns:
    A :class:`Spectrum` (``.free``, ``.contact``: ω float64 ``[N]``, eigenvalues
    complex128, ζ); ``to_dict()`` is ``afmdyn modes --json``.""",
    },
    "simulate": {
        "summary": """\
Integrate one trajectory (``afmdyn simulate``); ``periods`` defaults to 50 when
``tau_end`` is not given either.""",
        "returns": """\
Returns:
    ``xarray.Dataset`` of the trajectory: over its samples (the coordinate ``tau``, named
    ``t`` with a probe), its modes, its switchings (``event``), the section points
    τ = 2πk/Ω (``section``), the state's components, the complete drive periods (``cycle``:
    the energy balance) and the amplitude spectrum of W(1,τ) over the last ≤ 2²⁰ samples
    (``frequency``, the command line's ``spectrum.csv``). ``attrs["summary"]`` holds
    ``afmdyn simulate --json`` (see :func:`summary`). With ``probe`` every array is in SI,
    as the command line's files.""",
    },
    "converge": {
        "summary": """\
Mode-number convergence (paper Fig. 4, ``afmdyn converge``): the steady tip motion
for N = 1..max_modes. Without ``params`` the model defaults to Ω = 4.1 (eq. 24 with the
damping of eq. 26), as on the command line.""",
        "returns": """\
Returns:
    ``xarray.Dataset`` over ``n_modes`` (N = 1..max_modes) and ``sample`` (K samples over
    ``periods`` drive periods from a section point, ``tau_from_section`` a coordinate).""",
    },
    "bifurcation": {
        "summary": """\
Bifurcation diagram (paper Fig. 5, ``afmdyn bifurcation``): the steady state at each
value of ``param`` (``"omega"`` or ``"alpha1"``…``"alpha6"``, or the descriptive names) by
forward and backward continuation and ``starts`` random starts, in parallel (``threads``
workers, default all cores). Ctrl-C stops it within one point. ``from_`` is ``from`` (a
Python keyword).

With ``store``, each finished point is also written to that directory (the layout of
``afmdyn bifurcation --out DIR``: ``bifurcation.csv`` when finished, the ledger
``.bifurcation.run.json`` and the partial rows of an unfinished sweep), and ``resume=True``
continues the sweep stored there, computing only the points not yet written (``--resume``):
an interrupted sweep, from Python or the command line, resumes; a finished one is read back
without computing anything.""",
        "raises": """\
Raises:
    ValueError: ``resume=True`` on a store made by another request (the message names the
        first field that differs and both values, e.g. ``steps = 60 in the interrupted
        run, 30 now``), on a store holding rows without a ledger, or without ``store``.
    OSError: the store cannot be read or written.""",
        "returns": """\
Returns:
    ``xarray.Dataset`` in long format, dim ``point`` (one row per section point, in the
    order of the command line's ``bifurcation.csv``: by value index, then ``forward``,
    ``backward``, ``start-0``, ``start-1``, …, then ``k``), with the coordinates ``value``,
    ``index`` and ``branch``, and the state at the section as ``a_1`` … ``a_N``,
    ``a_dot_1`` … ``a_dot_N`` (N = 3 in the example). ``.to_dataframe()`` gives the tidy
    table.""",
    },
    "continuation": {
        "summary": """\
Pseudo-arclength continuation of a period-n branch from ``from_`` towards ``to``, with
located folds, period doublings, Neimark–Sacker and grazing points (``afmdyn continue``).
The default start is the steady state reached from rest at ``from_``.""",
        "returns": """\
Returns:
    ``xarray.Dataset`` with dim ``point`` (all branches in order, ``value`` a coordinate;
    ``w_tip_section`` NaN-padded to the longest period). ``attrs["summary"]`` is
    ``afmdyn continue --json``.""",
    },
    "observe": {
        "summary": """\
Observables of the steady state reached from ``initial`` (default: rest): first-harmonic
amplitude and phase lag of the tip deflection, harmonics and THD, mean deflection, peak and
minimum force, indentation, contact fraction and time, minimum distance, impacts, the energy
dissipated in the sample, the virial, the per-mode energy balance and the closed forms
(Cleveland/Anczykowski E_dis, San Paulo & García virial) beside the direct integrals.

The steady state is found as by :func:`orbit` and, when periodic, polished by Newton
shooting; ``periods`` orbit periods are integrated on the dense output (no sampling).""",
        "returns": """\
Returns:
    An ``xarray.Dataset`` of the observables (scalars; ``period`` NaN when not periodic), the
    harmonics and the per-mode energy balance, in SI with a probe, phases in degrees.
    ``ds.afmdyn.to_dict()`` is the library's document (dimensionless, phases in radians, the
    closed forms; its ``reported`` block holds the dataset's values).""",
    },
    "approach": {
        "summary": """\
The amplitude-modulation approach–retract curve over the rest distance z_c
(``afmdyn approach``): the steady state stepped from ``from_`` down to ``to`` and back, each
value continued from the previous orbit, plus the periodic-orbit branches continued in z_c
with Floquet stability, the folds, the bistable ranges and the jumps. The default range is
1.2 A₀ to 0.1 A₀ above contact (m with ``probe``, else g₀); with ``traces`` the document's
``traces`` hold ``z_c``, ``time_periods`` and per z_c ``deflection``, ``distance`` V_T and
``force`` (the force–distance loop's area is E_dis).""",
        "returns": """\
Returns:
    An ``xarray.Dataset`` (SI with a probe: m, N, J, degrees) over ``z_c`` (the approach's
    grid) and ``sweep`` = ``approach``/``retract``, the branches concatenated along
    ``branch_point``, and with ``traces`` the recorded cycles over (``trace``,
    ``trace_time``). ``ds.afmdyn.to_dict()`` is the ``afmdyn approach --json`` document
    (``folds``, ``bistable``, ``jumps``, ``setpoint`` (per stable branch crossing its
    ``source``, ``z_c``, ``regime``, phase, peak force, indentation, E_dis…), ``warnings``;
    ``docs/outputs.md``).""",
    },
    "bimodal": {
        "summary": """\
The bimodal (multifrequency) AM approach–retract curve (``afmdyn bimodal``): the
approach curve of a drive with two or more components — a probe whose ``[drive]`` gives
``free_amplitude = [A01, A02]`` and ``frequency = [f1, f2]`` (or each component at its
mode's resonance), on the eigenmode model (``model = "eigenmodes"``), the beam or the point
mass. The frequency ratio is taken as a fraction p/q (within 1e-6), the steady state is the
periodic orbit of the common period q/f1, and each component's amplitude, phase, virial
and dissipated energy come from demodulation over it (Lozano & García, Phys. Rev. Lett.
100, 076102 (2008); García & Proksch, Eur. Polym. J. 49, 1897 (2013)). A ratio whose
common period exceeds 1000 primary periods (incommensurate) is averaged in time instead.
The keywords are :func:`approach`'s (the default range from 1.2 to 0.1 times the sum of
the free amplitudes); ``setpoint`` is A1/A01 of the first component, and
``ds.afmdyn.to_dict()["setpoint"]["points"]`` gives every component's ``amplitude_i``,
``phase_i_deg``, ``virial_i`` and ``energy_dissipated_i`` there. With ``exact``, points
otherwise measured on invariant circles are per point in
``ds.afmdyn.to_dict()["invariant_circle"]``. With ``temperature`` every exact orbit gains
each component's lock-in noise: ``amplitude_noise`` and ``phase_noise_deg`` (the first
component's), ``amplitude_noise_i`` and ``phase_noise_i_deg`` (component i ≥ 2), by linear
response over the common period (``afmdyn.approach``'s ``"thermal"`` block).""",
        "raises": """\
Raises:
    ValueError: for a single-frequency drive (naming ``[drive].free_amplitude``), and as
        :func:`approach`.""",
        "returns": """\
Returns:
    The dataset of :func:`approach` plus, per cycle of each component i = 1, 2, … (1 the
    primary; SI with a probe), its amplitude, phase, virial and dissipated energy, on the
    sweeps and the branches (the ``_1``, ``_2`` variables below); the frequencies, ratios
    and free amplitudes in ``ds.afmdyn.to_dict()["drive_components"]``; for a time average,
    each point's periods, whether it settled, and its amplitude and phase error estimates
    per component in ``ds.afmdyn.to_dict()["time_average"]`` (an unsettled point also in the
    warnings).""",
    },
    "resonance": {
        "summary": """\
Amplitude and phase against the drive frequency near mode ``mode``
(``afmdyn resonance``): up- and down-sweep, each value continued from the previous orbit,
plus the branches continued in Ω with their folds (the bent, multivalued resonance curves of
tapping mode). The default band is ω_k (1 ∓ max(6/Q_k, 0.02)), in Hz with ``probe``, else
Ω; the other keywords are as :func:`approach`'s (traces per frequency of the up-sweep).""",
        "returns": """\
Returns:
    An ``xarray.Dataset`` as :func:`approach`'s over ``frequency_hz`` (with a probe) or
    ``omega`` and ``sweep`` = ``up``/``down``; ``ds.afmdyn.to_dict()`` is the
    ``afmdyn resonance --json`` document.""",
    },
    "orbit": {
        "summary": """\
A period-n orbit by Newton shooting, with Floquet multipliers (``afmdyn orbit``). The
default period is the attractor's when ``initial`` is an :class:`Attractor`.""",
        "returns": """\
Returns:
    :class:`Orbit`; ``to_dict()`` is ``afmdyn orbit --json``. Raises
    :class:`SimulationError` when Newton's method does not converge.""",
    },
    "lyapunov": {
        "summary": """\
Lyapunov spectrum (tangent dynamics with saltation matrices) and the 0–1 test for chaos
(``afmdyn lyapunov``), from ``initial`` (default rest) after ``transient`` drive periods,
averaged over ``periods`` in ``blocks`` blocks (periods ≥ blocks ≥ 2).""",
        "returns": """\
Returns:
    :class:`Lyapunov`; ``to_dict()`` is ``afmdyn lyapunov --json``.""",
    },
    "attractors": {
        "summary": """\
Coexisting attractors and basin fractions (paper Figs. 6–17, ``afmdyn attractors``)
from ``samples`` seeded random initial states, in parallel.""",
        "returns": """\
Returns:
    :class:`Attractors`, a sequence of :class:`Attractor` (most frequent first);
    ``to_dict()`` is ``afmdyn attractors --json``, ``to_dataframe()`` a summary table.""",
    },
    "basins": {
        "summary": """\
Basins of attraction (``afmdyn basins``) over two coordinates of the initial state at
τ = 0 (``"a1"``…``"aN"``, ``"adot1"``…``"adotN"``, ``"w"``, ``"wdot"``; the others from
``base``, 2N values a1…aN, ȧ1…ȧN, default at rest): each start stops as soon as it is near
a known periodic attractor (3 returns within ``near_tol``) or its returns recur in
state-space cells of one basin (``basin_hits`` returns in cells of side ``cell``), else the
steady-state search decides. Where the plane is the whole section (N = 1, a position and a
velocity) the map is made in passes from a coarse grid (``stride``; 0 automatic, 1 one
pass): a later start stops when a return lands inside a coarse cell of one basin.""",
        "returns": """\
Returns:
    ``xarray.Dataset`` over the plane ``(y, x)`` and the attractors found (``attractor``, a
    coordinate 0, 1, …); ``decided`` as its words (``"near"``, ``"recurrence"``,
    ``"grid"``, ``"steady"``, ``"failed"``); attributes ``basin_entropy``,
    ``boundary_basin_entropy`` (Daza et al. 2016; NaN when undefined),
    ``uncertainty_exponent`` (Grebogi et al. 1983) and ``summary`` (the command line's JSON
    document).""",
    },
    "global_continuation": {
        "summary": """\
Attractors continued over ``param`` (``afmdyn attractors --sweep``; Datseris, Rossi &
Wagemakers, Chaos 33, 073151 (2023)): at every value (``from_`` … ``to`` in ``steps``, or
``values`` in the order given) a census of ``samples`` random starts plus one start from
each attractor of the previous value; the attractors are matched to the previous value's
by the distance between their Poincaré point sets (``match_tol``, relative), so an id is
one attractor followed over the parameter. The basin fractions count the random starts
only (an attractor found only from the previous value has fraction 0).""",
        "args": {
            "store": "a directory for the command line's resumable store of values (``afmdyn "
                     "attractors --sweep --out DIR``; created if needed, started over without "
                     "``resume``).",
        },
        "returns": """\
Returns:
    ``xarray.Dataset`` over ``(value, id)``, an id one attractor followed over the
    parameter. Attribute ``summary``: the command line's JSON document (Poincaré points,
    multipliers of every attractor).""",
    },
    "fm": {
        "summary": """\
The frequency-modulation (FM-AFM) curve at constant amplitude over the rest distance
z_c (``afmdyn fm``): at each z_c the exact periodic orbit of the cantilever driven at the
frequency where its first harmonic lags the drive by the free lever's phase at resonance
(an ideal PLL), with the excitation that holds the first-harmonic amplitude at ``amplitude``
(an ideal amplitude controller; m with ``probe``, else g₀; default the probe's free
amplitude A₀), continued from the previous z_c. The default range runs from where the
frequency shift has decayed to 0.5 % of its value at ``to`` (Giessibl's first-order shift
of the law's force; 2A + a₀ for a law without a force before contact) down to A + a₀.""",
        "returns": """\
Returns:
    An ``xarray.Dataset`` over ``z_c``, one entry per z_c reached (the variables below);
    attributes ``spring_constant``, ``resonance_frequency``, ``amplitude``, ``mode``,
    ``folds_z_c``, ``method`` and ``summary`` (the ``afmdyn fm --json`` document). A z_c
    not reached ends the curve with an :class:`afmdyn.AfmdynWarning`.
    ``afmdyn.reconstruct(fm=ds)`` inverts it.""",
        "raises": """\
Raises:
    ValueError: naming the option (``amplitude``, ``mode``, ``tolerance``, ``from``, ``to``,
        ``step``, ``points``) or the model parameter.""",
    },
}

WRAPPERS["calibrate"] = {
    "summary": """\
A lever's spring constant from its measured thermal spectrum (``afmdyn calibrate``; a probe is
needed for its modes, their correction factors and, for Sader's method, its plan and fluid):
each mode's peak fitted by a simple harmonic oscillator on a white floor, with standard errors;
the static and each mode's effective spring constant by the thermal method (Butt & Jaschke
1995, the model's correction factor) and by Sader's method (Sader, Chon & Mulvaney 1999;
Lozano et al. 2010) and their agreement; the InvOLS of a force curve's contact slope. The
spectrum is a CSV file ``psd`` (columns ``frequency``, ``psd``), an Igor binary wave ``psd``
(``.ibw``, as Asylum Research's software saves a thermal) or the arrays ``frequency`` and
``spectral_density``.""",
    "args": {
        "psd": "+In Python also an Igor binary wave (``.ibw``, read by ``igor2``: ``pip install "
               "igor2``): one-dimensional, its x scaling the frequency in Hz, its data units a "
               "PSD's (``m^2/Hz``, ``V^2/Hz``) or an amplitude spectral density's (``m/√Hz``, "
               "``V/√Hz``; squared), which also set ``volts``; other units are refused, and a "
               "bin at 0 Hz is dropped.",
    },
    "returns": """\
Returns:
    An ``xarray.Dataset`` over ``frequency`` (Hz) with ``psd`` and ``fitted`` (m²/Hz), and over
    ``mode`` the ``modes_*`` variables (``modes_frequency`` Hz, ``modes_quality_factor``,
    ``modes_spring_constant_thermal``, ``modes_spring_constant_sader``,
    ``modes_static_spring_constant_thermal``, ``modes_static_spring_constant_sader`` N/m,
    each with its ``…_standard_error``); attributes ``temperature`` (K) and ``summary`` (the
    ``afmdyn calibrate --json`` document).""",
    "raises": """\
Raises:
    ValueError: naming the option (``psd``, ``peaks``, ``bands``, ``invols``, ``volts``,
        ``force_curve``, ``temperature``, ``spot``), the missing probe or the model
        parameter.""",
}

WRAPPERS["thermal"] = {
    "summary": """\
The free lever's thermal spectrum at ``temperature`` (``afmdyn thermal``; a probe is
needed): from the fluctuation–dissipation theorem on the lever's dynamic compliance over every
Galerkin mode (the tip mass, the medium's added mass and damping per mode), the one-sided power
spectral densities of the tip's deflection and of the optical lever's apparent deflection (the
slope at the laser ``spot``, a fraction of the length, converted with the static end-load
factor; Butt & Jaschke 1995), and each mode's frequency, Q, effective spring constant,
mean-square deflection and the thermal method's correction factors (0.971 and 0.817 for the
first mode of a uniform lever).""",
    "returns": """\
Returns:
    An ``xarray.Dataset`` over ``frequency`` (Hz) with ``deflection`` and
    ``apparent_deflection`` (m²/Hz), and over ``mode`` the ``modes_*`` variables
    (``modes_frequency`` Hz, ``modes_quality_factor``, ``modes_effective_spring_constant``
    N/m, ``modes_mean_square_deflection`` and ``modes_mean_square_apparent_deflection`` m²,
    ``modes_deflection_factor``, ``modes_optical_lever_factor``); attributes
    ``temperature`` (K), ``spring_constant`` (the static stiffness, N/m), ``spot`` and
    ``summary`` (the ``afmdyn thermal --json`` document).""",
    "raises": """\
Raises:
    ValueError: naming the option (``temperature``, ``spot``, ``to``, ``points``), the
        missing probe or the model parameter.""",
}

WRAPPERS["chart"] = {
    "summary": """\
Behaviour chart over two parameters (``afmdyn chart``): every attractor that each cell's
``starts`` random starts and the continuation from its neighbours along x reach, on all
cores (``threads``). Ctrl-C stops it within one task.

An axis is any real model parameter by name or alias (``"omega"``, ``"alpha2"`` /
``"drive_amplitude"``, ``"gap"``, ``"restitution"``, ``"hamaker"``, …) and, with
``probe=``, ``"z_c"`` (m), ``"drive_frequency"`` (Hz) and the probe file's own values
``"free_amplitude"`` (m), ``"sample_modulus"`` (Pa), ``"quality_factor"``,
``"spring_constant"`` (N/m), ``"tip_radius"`` (m).""",
    "raises": """\
Raises:
    ValueError: an axis that is not a real model parameter, a value out of its range, an
        option out of its limits (each named), or ``resume`` on another request's store.
    SimulationError: no cell found any attractor.""",
    "returns": """\
Returns:
    ``xarray.Dataset`` over ``(y, x, attractor)``: per cell, and per attractor slot (most
    random starts first; ``max_attractors`` slots, empty ones with period 0 and NaN); a
    ``motion`` is chaotic where λ₁ > 2 × its error, quasi-periodic where ``|λ₁|`` ≤ 2 × its
    error, unsettled where λ₁ < −2 × its error. The same values as ``chart.nc``.""",
}

#: the Dask versions (:mod:`afmdyn.dask`)
DASK = {
    "chart": {
        "summary": """\
:func:`afmdyn.chart` with its tasks mapped over a Dask cluster: ``client`` (default: a
``LocalCluster`` of this machine's cores, closed at the end). With ``store`` (a Zarr
directory, locked during the run) each finished task is written there at once and a
rerun resumes (``resume=False`` starts the store over); another request on the same store
is refused, naming the first option that differs. Finished tasks reach the store in
batches, at least every ``checkpoint_seconds`` (0: each task as it arrives) and at the
end: a killed driver loses at most that much work.""",
        "returns": """\
Returns:
    The same ``xarray.Dataset`` as :func:`afmdyn.chart` with the same arguments.""",
        "args": {
            "client": "a ``dask.distributed.Client`` (default: a ``LocalCluster``).",
            "store": "a Zarr directory keeping the finished tasks (locked during the run).",
            "resume": "resume the store (``False``: start it over).",
            "checkpoint_seconds": "the longest time finished tasks wait to be written (>= 0).",
        },
    },
    "bifurcation": {
        "summary": """\
:func:`afmdyn.bifurcation` with its tasks mapped over a Dask cluster (``client``;
default a ``LocalCluster`` of this machine's cores, closed at the end): the two coarse
continuation passes first, then every chain segment and random start, seeded by them.

With ``store`` (a directory, locked during the run) the sweep is kept in the command
line's layout (``afmdyn bifurcation --out DIR``): each finished task's points are
appended as they arrive, and a rerun with the same request resumes — from a run of this
function, of ``afmdyn.bifurcation(store=...)`` or of the command line — computing only the
tasks with points not stored (``resume=False`` starts over; another request is refused).""",
        "returns": """\
Returns:
    The same ``xarray.Dataset`` as :func:`afmdyn.bifurcation` with the same arguments, bit
    for bit.""",
        "args": {
            "client": "a ``dask.distributed.Client`` (default: a ``LocalCluster``).",
            "store": "a directory keeping the sweep in the command line's layout.",
            "resume": "resume the stored sweep (``False``: start it over).",
        },
    },
}

WRAPPERS["peakforce"] = {
    "layout_variants": {"sweep": "a sweep (here ``z_c`` a sequence)"},
    "summary": """\
The steady tap of off-resonance tapping (``afmdyn peakforce``; the probe's ``[drive]
mode = "off-resonance"``): the periodic orbit of the modulation period found by shooting,
with its Floquet multipliers, the instrument's channels and the PF-QNM DMT fit.""",
    "args": {
        "z_c": "+A sequence sweeps it: the channels over a ``z_c`` dimension.",
        "modulation_frequency": "values of f_m to sweep (Hz with ``probe``, else Ω): the "
        "channels over a ``modulation_frequency`` dimension (with ``setpoint``, the feedback "
        "holds the peak force at each).",
    },
    "returns": """\
Returns:
    An ``xarray.Dataset`` of one cycle over ``sample`` and the force–distance curve, in SI
    with a probe; attributes: the channels (``peak_force``, ``adhesion``, ``deformation``,
    ``dissipation``, ``contact_time``, ``snap_off_time``, ``ringing_amplitude``,
    ``modulus_dmt``, ``taps_per_cycle``) and ``summary`` (the ``afmdyn peakforce --json``
    document). With a sweep the channels are variables over its dimension, NaN where a
    value failed; the cycle and curve are the first computed value's. Warnings (period-2 tapping, double taps, an unstable tap) are
    raised as :class:`afmdyn.AfmdynWarning`.""",
    "raises": """\
Raises:
    ValueError: naming the option or the model parameter.""",
}

WRAPPERS["fit_map"] = {
    "summary": """\
Fit every curve of a force-volume or QI map (``afmdyn fit-map``) as :func:`fit` fits one
(nanite's preprocessing, the probe's law, Levenberg–Marquardt, Wald intervals), the results
over the map's grid: a modulus map, a topography and a flag per curve (fitted, at a bound,
not constrained, too few contact rows, failed). ``probe`` (a model keyword, as ``--probe``)
is required; a curve's own spring constant (an instrument file's) replaces the probe's.""",
    "args": {
        "data": "the map: an instrument file afmformats reads (JPK ``.jpk-force-map``, "
        "``.jpk-qi-data``, …; each curve's grid index, position and spring constant from its "
        "metadata), a list of afmformats curves or of mappings (``x``, ``y``, ``height``, "
        "``force``, optionally ``ix``, ``iy``, ``segment``, ``time``, ``spring_constant``), "
        "both written through :func:`afmdyn.export_map` to a temporary NetCDF file; or a "
        "long-format CSV or an ``export_map`` NetCDF file, streamed as they are.",
    },
    "returns": """\
Returns:
    An ``xarray.Dataset`` over (``y``, ``x``) (m): per fitted parameter its value,
    ``_standard_error``, ``_lower`` and ``_upper`` (the 95 % Wald interval), ``chi2_dof``,
    ``contact_rows``, ``topography`` (the contact point's piezo height, m) and ``flag`` (the
    flag's name per curve, ``no_curve`` where the grid has none); attributes ``law`` and
    ``summary`` (the ``afmdyn fit-map --json`` document: counts per flag, the median and
    16th–84th percentiles, every curve's estimates and reason). Warnings (curves flagged) are
    raised as :class:`afmdyn.AfmdynWarning`.""",
    "raises": """\
Raises:
    ValueError: naming the option, the map file or the probe key.""",
}

WRAPPERS["fit"] = {
    "layout_variants": {"sls": "the ``sls`` law (a curve with times)"},
    "summary": """\
Fit a quasi-static force curve with the probe's contact law (``afmdyn fit``; hertz,
dmt, jkr, or sls on a curve with times and a dwell), its contact point and baseline
(and an AM, FM or bimodal curve against the dynamic model): nanite's preprocessing (tip position
height + F/k, force and tip offsets at the contact point), Levenberg–Marquardt, standard
errors, 95 % profile-likelihood intervals, correlations and identifiability warnings.
``probe`` (a model keyword, as ``--probe``) is required.""",
    "args": {
        "data": "the force curve: a CSV file with the columns ``height`` (m, the piezo "
        "height, decreasing into the sample), ``force`` (N, repulsion positive) and optionally "
        "``sigma`` (N) and ``time`` (s, which the ``sls`` law needs); or a mapping (a "
        "``pandas.DataFrame``, a dict) with those columns; or an "
        "instrument's curve read by afmformats (Müller et al.; JPK ``.jpk-force``, "
        "``.jpk-force-map``, ``.jpk-qi-data``, Asylum ``.ibw``, afmformats ``.h5``/``.tab``): a "
        "file of those kinds, or an ``afmformats`` force-distance object (a "
        "``nanite.Indentation`` too), whose ``height (measured)`` (else ``height (piezo)``), "
        "``force`` and ``time`` columns are taken.",
        "curve": "which curve of an afmformats file with several (a force map), from 0.",
        "approach_rows": "+For an afmformats curve the default is the instrument's segments.",
    },
    "returns": """\
Returns:
    An ``xarray.Dataset``: the fitted rows (the variables below) and, from the document,
    over ``parameter`` the ``estimate``, ``standard_error``, ``interval_low`` and
    ``interval_high`` (95 %), and ``correlation`` over (``parameter``, ``parameter_2``);
    attributes ``chi2_dof``, ``noise``, ``law`` and ``summary`` (the ``afmdyn fit --json``
    document). Warnings (a correlation above 0.99, a flat profile, an estimate at its
    bound, the noise estimated from the residuals) are raised as
    :class:`afmdyn.AfmdynWarning`.""",
    "raises": """\
Raises:
    ValueError: naming the option, the data or the probe key.""",
}

#: an image's probe and sample map (``image``, ``setpoint_study`` and ``afmdyn.dask.image``)
IMAGE_ARGS = {
    "probe": "the probe (path, TOML text or dict, as ``afmdyn.probe``): the lever, tip, drive "
    "and the background sample.",
    "sample": "the sample map (path or TOML text): ``size = [Lx, Ly]`` (m) and ``[[domain]]`` "
    "entries with ``name``, ``x``, ``y``, ``height`` (m) and ``[domain.sample]``; its "
    "``height_map`` the rows inline or a ``.csv`` / ``.npy`` file (a relative path from the "
    "sample file's directory, or from the current one for TOML text).",
    "setpoint": "+With ``mode=\"peakforce\"`` the peak force (N).",
    "height_map": "a 2D array of heights (m), rows from y = 0 to Ly and columns from x = 0 to "
    "Lx, interpolated bilinearly and added to the map's topography (replaces the map's own "
    "``height_map``); or the path of a ``.csv`` or ``.npy`` file holding them.",
    "feedback": "``\"ideal\"`` or ``\"pi\"`` (a scan in the time domain).",
    "scan_rate": "the PI scan's line rate (Hz; ``None``: the lever's default).",
    "gains": "the PI controller's (K_P, K_I in 1/s; ``None``: the lever's defaults).",
    "time_constant": "the PI scan's lock-in time constant (s), refused above 1000 s and "
    "warned outside 1 µs–0.1 s (``None``: the lever's default).",
    "temperature": "the temperature (K; ``None``: no thermal noise). A PI scan's: the lever's "
    "thermal force on every line (every law), so that the amplitude, phase, height "
    "and error images carry the noise of the lock-in's bandwidth. With ``mode=\"peakforce\"``: "
    "the maps ``peak_force_noise`` and ``deformation_noise``, each pixel's σ from cycle to cycle "
    "(its material's tap at the setpoint, by linear response).",
    "seed": "the seed of the PI scan's thermal force (with ``temperature``): the image is a "
    "function of it, whatever the threads or the executor.",
    "threads": "the cores a PI scan's or PeakForce image's lines run on (default all).",
    "mode": "``\"am\"`` or ``\"peakforce\"`` (an off-resonance probe).",
}

WRAPPERS["image"] = {
    # the dataset keeps the maps over (y, x) and the coordinates; the layout's scalars are its
    # attributes (``_image._dataset``)
    "layout_dims": (("y", "x"), ("x",), ("y",)),
    "layout_variants": {"pi": '``feedback="pi"``', "peakforce": '``mode="peakforce"``'},
    "summary": """\
The image an amplitude feedback records over a heterogeneous sample
(``afmdyn image``). ``feedback="ideal"``: at every pixel the operating point of the local
material where the amplitude equals the setpoint, the regime kept from the previous pixel
where the material allows it, each line engaged from far. ``feedback="pi"``: each line
scanned in the time domain, trace and retrace, under a lock-in and a PI z controller
updating once per drive period, its lines on ``threads`` cores with ``progress``; Ctrl-C
stops it. ``mode="peakforce"`` (an off-resonance probe): the image an ideal peak-force
feedback records, ``setpoint`` the peak force (N), each pixel's steady tap exact (issue 61
§3), its lines on ``threads`` cores.""",
    "args": IMAGE_ARGS,
    "returns": """\
Returns:
    ``xarray.Dataset`` over ``y`` and ``x`` (m), NaN where the setpoint is not reached; the
    codes ``regime``, ``material`` and ``domain`` as their words; attributes ``setpoint``,
    ``reference_z_c`` (m) and ``summary`` (the command line's JSON document, with each
    material's operating points): the maps of ``afmdyn image``'s ``image.nc``. With
    ``feedback="pi"`` the recorded trace and retrace (``_retrace``) and the attributes
    ``scan`` (the settings) and ``artefacts`` (JSON: per direction the height error against
    the ideal image, the overshoot, the error image's RMS, the pixels that lost contact);
    with ``mode="peakforce"`` the channels of the ideal peak-force feedback.""",
    "raises": """\
Raises:
    ValueError: naming the field — a setpoint outside (0, 1), pixels or lines outside
        1..=4096 (lines = 1 for a line map), a sample map's key, a scan setting
        (scan_rate, gains, time_constant, temperature: a law other than the linear one is
        refused with it).""",
}

WRAPPERS["setpoint_study"] = {
    "summary": """\
Every domain's apparent height, phase lag and dissipated energy against the setpoint
under an ideal feedback (``afmdyn image --setpoint-study``): at each ratio a line engaged
on the background crosses onto each domain — the contrast inversion of AM-AFM (García &
San Paulo, Phys. Rev. B 61, R13381 (2000)). Arguments as :func:`image`'s.""",
    "args": {**IMAGE_ARGS, "ratios": "the setpoints A_sp/A0 in (0, 1)."},
    "returns": """\
Returns:
    ``xarray.Dataset`` over ``domain`` (``background`` first) and ``setpoint`` (the
    variables below; NaN, and an empty ``regime``, where a material has no operating
    point); attribute ``summary`` (the JSON).""",
}

WRAPPERS["reconstruct"] = {
    # its layouts are in SI without a probe too (the curve's units)
    "layout_units": "in SI",
    "layout_variants": {"fm": "``fm=`` (a curve of :func:`afmdyn.fm`: the model's force too)"},
    "summary": """\
The tip–sample force F(d) and potential U(d) behind a frequency-modulation curve, by
the Sader–Jarvis inversion (J. E. Sader and S. P. Jarvis, Appl. Phys. Lett. 84, 1801
(2004); ``afmdyn reconstruct``) or its exact correction (``inversion="exact"``).""",
    "args": {
        "fm": "instead of the curve, the dataset of :func:`afmdyn.fm` with a probe (or its "
        "document, ``afmdyn.summary(ds)``): its distances of closest approach "
        "(``min_distance``), shifts, k, f0 and A; ``spring_constant``, "
        "``resonance_frequency``, ``amplitude`` given replace the document's.",
        "am": "instead, the dataset of :func:`afmdyn.approach` with a point-mass probe (or its "
        "document): its attractive run (phase lag above 90°) inverted at each point's "
        "amplitude by the matrix method (``afmdyn reconstruct --am``); the constants are the "
        "probe's.",
        "inversion": "+``\"sader-jarvis\"`` is within a few per cent and the more robust on "
        "noisy data; ``\"exact\"`` corrects it through Giessibl's forward relation until the "
        "two agree (the document's ``exact`` records its steps and forward residual). Not "
        "with ``am``.",
    },
    "returns": """\
Returns:
    ``xarray.Dataset`` over ``distance`` (m, increasing; the variables below, the force
    attractive < 0); attributes ``spring_constant``, ``resonance_frequency``,
    ``amplitude``, ``method``, ``inversion`` and ``summary`` (the command line's JSON
    document). The force near the largest distance is not reconstructed (the inversion
    integrates the shift beyond each distance): take data out to where Δf has decayed. On an evenly spaced grid (every distance within 1e-9 of a
    spacing of d0 + i h) the inversion takes O(N log N) by FFT, up to 2 000 000 points; on
    another grid O(N²), up to 20 000 points. Ctrl-C stops it.""",
    "warns": """\
Warns:
    AfmdynWarning: a constant outside its typical range (A 10 pm–1 µm, f0 1 kHz–10 MHz,
        k 0.01–1e6 N/m: a likely unit slip, named); data that end while ``|Δf|`` is still
        above 1 % of its extreme.""",
    "raises": """\
Raises:
    ValueError: naming the field — fewer than 3 points, distances not monotonic, lengths
        that differ, constants missing or outside their physical range (A 1e-15–1e-3 m,
        f0 1–1e10 Hz, k 1e-6–1e9 N/m), neither or both of ``distance`` and ``z_c``, more
        points than the limits above; ``fm`` not an SI ``fm`` document.
    KeyboardInterrupt: on Ctrl-C.""",
}

DASK["basins"] = {
    "summary": """\
:func:`afmdyn.basins` (the same keywords but ``store``, ``resume`` and ``threads``)
with the rows of each pass mapped over a Dask cluster (``client``; default a
``LocalCluster`` of this machine's cores, closed at the end). The passes run in turn: the
start of a pass — the attractors and the coarse grid of the passes before it, made by the
library from their finished rows — is sent to the workers once, and each row is a task.""",
    "returns": """\
Returns:
    The same ``xarray.Dataset`` as :func:`afmdyn.basins` with the same arguments, bit
    for bit (a row is a pure function of its pass's start).""",
    "args": {"client": "a ``dask.distributed.Client`` (default: a ``LocalCluster``)."},
}

DASK["image"] = {
    "summary": """\
:func:`afmdyn.image` with ``feedback="pi"`` (the same keywords but ``threads``) with
its lines mapped over a Dask cluster (``client``; default a ``LocalCluster`` of this
machine's cores, closed at the end): each line is a task, a pure function of the request
and its number, so the Dataset equals :func:`afmdyn.image`'s bit for bit. With
``mode="peakforce"`` the PeakForce image (``setpoint`` the peak force, N): the materials'
engages are the first stage's tasks, the lines the second's.""",
    "returns": """\
Returns:
    The same ``xarray.Dataset`` as :func:`afmdyn.image` with the same arguments.""",
    "args": {**IMAGE_ARGS, "client": "a ``dask.distributed.Client`` (default: a "
             "``LocalCluster``)."},
}

DASK["fit_map"] = {
    "summary": """\
:func:`afmdyn.fit_map` (the same keywords but ``threads``) with the lines of the map
mapped over a Dask cluster (``client``; default a ``LocalCluster`` of this machine's
cores, closed at the end): each line is a task, its curves read by the worker from the map
file and fitted as :func:`afmdyn.fit_map` fits them. The map file (``data``, or the NetCDF
file curves given as data are exported to: into ``store``, else a temporary directory of
this machine) must be readable by every worker at the same path: a ``LocalCluster`` shares
this machine's files; a cluster of several machines needs the map (and ``store``) on a
shared filesystem, named by an absolute path.

With ``store`` (a directory, locked during the run) the fits are kept in the command
line's layout (``afmdyn fit-map --out DIR``, ``afmdyn.fit_map(store=...)``): each finished
line is appended as it arrives, and a rerun with the same request resumes — from a run of
this function, of :func:`afmdyn.fit_map` or of the command line — fitting only the lines
not stored (``resume=False`` starts over; another request or map is refused).""",
    "returns": """\
Returns:
    The same ``xarray.Dataset`` as :func:`afmdyn.fit_map` with the same arguments, bit for
    bit (a line's fits are a pure function of the request and the map). Warnings (curves
    flagged) are raised as :class:`afmdyn.AfmdynWarning`.""",
    "raises": WRAPPERS["fit_map"].get("raises", ""),
    "args": {
        "client": "a ``dask.distributed.Client`` (default: a ``LocalCluster``).",
        "store": "a directory keeping the fits in the command line's layout.",
        "resume": "resume the stored map (``False``: start it over).",
        **WRAPPERS["fit_map"]["args"],
    },
}

AFM = ("observe", "approach", "bimodal", "resonance", "fm", "thermal", "calibrate", "peakforce", "fit", "fit_map", "image",
       "setpoint_study", "reconstruct")
STARTS = ("attractors", "basins", "global_continuation")
DOCS = {"_wrappers.py": {k: v for k, v in WRAPPERS.items() if k not in AFM + STARTS},
        "_wrappers_starts.py": {k: WRAPPERS[k] for k in STARTS},
        "_wrappers_afm.py": {k: WRAPPERS[k] for k in AFM}, "_dask_wrappers.py": DASK}

#: the docstring of ``afmdyn.Model`` (the model keywords)
MODEL_DOC = """\
The model keywords every analysis takes (see :class:`Params` for their ranges; the one
table of them is ``afmdyn._afmdyn.MODEL_PARAMETERS``). ``probe`` is a probe in SI (the
command line's ``--probe``): a file's path, its TOML text (a ``str`` with a line break or
``=``) or a dict of its sections (``{"cantilever": {...}, "sample": {...}, ...}``); it sets
every parameter in SI, ``z_c`` (m) and ``drive_frequency`` (Hz) set α5 and Ω through its
scales, ``modes`` and ``restitution`` are taken, and the dimensionless keywords of the
values it sets (``gap``, ``omega``, the α's, ``hamaker``, ``intermolecular_distance``,
``contact_law``) raise ``ValueError`` naming the probe key or SI keyword to use; the
result's ``to_dict()`` then carries the command line's ``"si"`` block. ``cantilever`` names
a cantilever of the library (:func:`afmdyn.cantilevers`) for the probe, as
``--cantilever`` does: it fills the keys the probe leaves out and wins over a name in it."""
