//! The columns (name, unit, meaning) of the command line's CSV files that neither a `.npy.json`
//! nor a result layout describes, for the book's page of CSV files
//! (`docs/schema/csv-columns.json`, shown by `scripts/gen_reference.py`, which refuses a
//! declared name its file no longer has). A unit is the model's, with the probe's SI where a
//! run with `--probe` writes SI.

/// A declared column: name, unit, meaning.
pub type Column = (&'static str, &'static str, &'static str);

/// `events.csv` (`simulate`): one row per switching.
pub const EVENTS: [Column; 4] = [
    ("tau", "τ (s: `t` under a probe)", "time of the switching"),
    ("from", "–", "the region left: free or contact"),
    ("to", "–", "the region entered: free or contact"),
    (
        "v_t_dot",
        "g0 per unit τ (m/s under a probe)",
        "dV_T/dτ at the switching: the impact velocity on entering contact",
    ),
];

/// `energy.csv` (`simulate --energy-balance`): the balance over each interval between
/// consecutive sections (`integrate/exact/energy.rs`; 12-point Gauss–Legendre over the other
/// integrators' steps).
pub const ENERGY: [Column; 8] = [
    ("tau0", "τ (s: `t0` under a probe)", "start of the interval"),
    (
        "e_start",
        "EI g0²/L³ (J under a probe)",
        "stored energy ½ȦᵀMȦ + ½XᵀKX (plus ½α4V_T² in contact) at its start",
    ),
    (
        "e_end",
        "EI g0²/L³ (J under a probe)",
        "the stored energy at its end",
    ),
    (
        "base_work",
        "EI g0²/L³ (J under a probe)",
        "work of the base drive",
    ),
    (
        "beam_dissipation",
        "EI g0²/L³ (J under a probe)",
        "α3 ∫ ẊᵀẊ dτ",
    ),
    (
        "contact_dissipation",
        "EI g0²/L³ (J under a probe)",
        "α6 ∫ V̇_T² dτ in contact",
    ),
    (
        "residual",
        "EI g0²/L³ (J under a probe)",
        "(e_end − e_start) − (base_work − beam_dissipation − contact_dissipation): the \
         integration's error",
    ),
    ("tau1", "τ (s: `t1` under a probe)", "end of the interval"),
];

/// `spectrum.csv` (`simulate`): the one-sided amplitude spectrum of W(1,τ), mean removed, of
/// the recorded part (its last 2²⁰ samples when longer).
pub const SPECTRUM: [Column; 2] = [
    (
        "frequency",
        "Ω (Hz: `frequency_hz` under a probe)",
        "frequency; the drive is at Ω",
    ),
    (
        "amplitude",
        "g0 (m under a probe)",
        "amplitude of W(1,τ) at that frequency",
    ),
];

/// `basins.csv`: one row per cell (`x`, `y` are the basins layout's).
pub const BASINS: [Column; 5] = [
    ("ix", "–", "column of the cell"),
    ("iy", "–", "row of the cell"),
    ("label", "–", "attractor id; −2 the run failed"),
    (
        "decided",
        "–",
        "how the start was decided: near, recurrence, grid, steady or failed",
    ),
    ("periods", "drive periods", "drive periods the start ran"),
];

/// `attractors-sweep.csv`: one row per (value, attractor); the swept parameter's column is
/// named after it (`omega` in the run shown; the others not here are the global continuation
/// layout's).
pub const ATTRACTORS_SWEEP: [Column; 4] = [
    (
        "omega",
        "as the parameter",
        "the swept parameter's value (the column is named after the parameter: omega, alpha1 … \
         alpha6)",
    ),
    (
        "period",
        "drive periods",
        "period n of the attractor, or nonperiodic",
    ),
    ("contact_fraction", "1", "fraction of the time in contact"),
    (
        "stable",
        "–",
        "1 a stable periodic orbit (the Floquet multipliers of the orbit polished by shooting), \
         0 an unstable one; empty otherwise",
    ),
];

/// `continuation.csv` (`continue`): one row per branch point (`s`, `value`, `max_multiplier`,
/// `switchings`, `grazing_distance` are the continuation layout's).
pub const CONTINUATION: [Column; 6] = [
    (
        "branch",
        "–",
        "0 the continued branch; 1… the period-2n branches switched to at period doublings \
         (--switch), each ending where it rejoins the period-n branch",
    ),
    ("period", "drive periods", "period n"),
    (
        "stable",
        "–",
        "true when every Floquet multiplier is inside the unit circle",
    ),
    (
        "critical",
        "–",
        "type of the critical multiplier: fold, period-doubling or neimark-sacker",
    ),
    (
        "w_tip_section",
        "g0",
        "W(1,τ) at the n section points, space-separated",
    ),
    (
        "event",
        "–",
        "fold, period-doubling, neimark-sacker or grazing at a located bifurcation; empty \
         otherwise",
    ),
];

/// `fig3.csv` (`modes --sweep fig3`, paper Fig. 3): the first two natural frequencies of the
/// contact system over the free system's, over α1 and α4.
pub const FIG3: [Column; 4] = [
    ("alpha1", "1", "tip-mass ratio α1"),
    ("alpha4", "1", "contact stiffness α4"),
    (
        "omega1_over_omega01",
        "1",
        "first natural frequency in contact over the free one",
    ),
    (
        "omega2_over_omega02",
        "1",
        "second natural frequency in contact over the free one",
    ),
];

/// `fit_map.csv` (`fit-map`): one row per curve; each fitted parameter and its standard error
/// by its short name (the default fit's `youngs_modulus`, `contact_point` and `baseline`
/// shown); with a bottom-effect correction also `thickness` (m), the sample's thickness used.
pub const FIT_MAP: [Column; 13] = [
    ("x", "m", "position x of the curve"),
    ("y", "m", "position y of the curve"),
    (
        "flag",
        "–",
        "how the curve's fit ended (ok, or why not: the codes of fit_map.nc's flag)",
    ),
    (
        "youngs_modulus",
        "Pa",
        "the sample's Young's modulus E fitted",
    ),
    ("youngs_modulus_standard_error", "Pa", "its standard error"),
    ("contact_point", "m", "the contact point's offset fitted"),
    ("contact_point_standard_error", "m", "its standard error"),
    ("baseline", "N", "the force baseline fitted"),
    ("baseline_standard_error", "N", "its standard error"),
    (
        "chi2_dof",
        "N²",
        "χ²/dof (the force noise variance without σ)",
    ),
    (
        "contact_rows",
        "–",
        "rows indented beyond the contact point",
    ),
    ("topography", "m", "the contact point's piezo height"),
    (
        "spring_constant",
        "N/m",
        "the lever's spring constant the curve was fitted with (the file's, else the probe's)",
    ),
];
