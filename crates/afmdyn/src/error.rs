//! Typed errors of the library. Every message names the offending field and the allowed range.

use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use thiserror::Error;

/// A model parameter outside its allowed range (see [`crate::Params`]).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ParamError {
    /// The number of Galerkin modes N is outside 1..=20.
    ///
    /// What to do: give `modes` between 1 and 20.
    #[error("modes = {0}: the number of Galerkin modes N must be an integer in 1..=20")]
    Modes(usize),
    /// A non-negative coefficient (α1, α2, α3, α4, α6) is negative or not finite.
    ///
    /// What to do: give the coefficient a finite value ≥ 0.
    #[error("{name} = {}: must be finite and >= 0", number(*value))]
    NonNegative {
        /// Field name with its paper symbol, e.g. `alpha4 (contact stiffness α4)`.
        name: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// The gap α5 is not finite.
    ///
    /// What to do: give a finite gap (`alpha5`, or `z_c` with a probe).
    #[error("alpha5 (gap α5) = {}: must be a finite number", number(*.0))]
    Gap(f64),
    /// The drive frequency Ω is not finite or not positive.
    ///
    /// What to do: give a finite drive frequency > 0.
    #[error("omega (drive frequency Ω) = {}: must be finite and > 0", number(*.0))]
    Omega(f64),
    /// A group given for a law it does not belong to.
    ///
    /// What to do: set `contact_law` to the law the group belongs to, or leave the group out.
    #[error("{group} is a group of the {owner} law, not of contact_law = {law} (set contact_law = {owner})")]
    Group {
        /// The group, e.g. `restitution`.
        group: &'static str,
        /// The law it belongs to.
        owner: &'static str,
        /// The law in force.
        law: &'static str,
    },
    /// A group of the tip–sample law (see [`crate::contact::ContactLaw`]) is out of range.
    ///
    /// What to do: give the group a value in the range the message names (the law's page in
    /// the book gives each group's meaning).
    #[error("{name} = {}: must satisfy {range}", number(*value))]
    Law {
        /// The group's name with its symbol.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The allowed range.
        range: &'static str,
    },
    /// A finite value beyond the range where the numerics are meaningful (see the limits in
    /// [`crate::params`]).
    ///
    /// What to do: give a value inside the range the message names; the reason says why the
    /// numerics need it.
    #[error("{name} = {}: must lie in {range} ({reason})", number(*value))]
    Magnitude {
        /// Field name with its paper symbol.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The allowed range, e.g. `[0, 1e4]`.
        range: &'static str,
        /// Why the limit exists.
        reason: &'static str,
    },
    /// A parameter the structural model does not allow (see [`crate::params::Structure`]).
    ///
    /// What to do: give the value the message names as allowed for this structural model.
    #[error("{name}: got {}", number(*value))]
    Structure {
        /// Field and the allowed value.
        name: &'static str,
        /// The rejected value (NaN when it is not a number).
        value: f64,
    },
}

/// A physical-unit input outside its allowed range (see [`crate::units`]).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum UnitsError {
    /// A quantity that must be finite and strictly positive is not.
    ///
    /// What to do: give a finite value > 0 in the unit the message names.
    #[error("{name} = {}: must be finite and > 0 ({unit})", number(*value))]
    Positive {
        /// Field name.
        name: &'static str,
        /// Rejected value.
        value: f64,
        /// SI unit of the field.
        unit: &'static str,
    },
    /// A quantity that must be finite and non-negative is not.
    ///
    /// What to do: give a finite value ≥ 0 in the unit the message names.
    #[error("{name} = {}: must be finite and >= 0 ({unit})", number(*value))]
    NonNegative {
        /// Field name.
        name: &'static str,
        /// Rejected value.
        value: f64,
        /// SI unit of the field.
        unit: &'static str,
    },
    /// A Poisson ratio outside (-1, 0.5].
    ///
    /// What to do: give a Poisson ratio in (-1, 0.5] (0.3 for most solids, 0.5 for an
    /// incompressible one).
    #[error("{name} = {}: a Poisson ratio must lie in (-1, 0.5]", number(*value))]
    Poisson {
        /// Field name.
        name: &'static str,
        /// Rejected value.
        value: f64,
    },
    /// A quantity that must be finite is not.
    ///
    /// What to do: give a finite number in the unit the message names.
    #[error("{name} = {}: must be a finite number ({unit})", number(*value))]
    Finite {
        /// Field name.
        name: &'static str,
        /// Rejected value.
        value: f64,
        /// SI unit of the field.
        unit: &'static str,
    },
    /// Two mutually exclusive inputs were both given, or neither.
    ///
    /// What to do: give exactly one of the inputs the message names.
    #[error("{0}")]
    Choice(String),
    /// The derived dimensionless set is invalid.
    ///
    /// What to do: see the error it wraps (ParamError).
    #[error(transparent)]
    Params(#[from] ParamError),
}

/// `v` as a reader writes it, rounded to at most 6 significant digits: plain between 1e-4 and
/// 1e16, else in scientific notation (Rust's `{}` spells 1e-300 with 300 zeros, and a value
/// derived from the user's one carries 16 digits of round-off). Every number of an error
/// message goes through it.
pub fn number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    // rounded to 6 significant digits, then written in the shortest form that reads back as
    // that rounded value
    let r: f64 = format!("{v:.5e}").parse().unwrap_or(v);
    if (1e-4..1e16).contains(&r.abs()) {
        format!("{r}")
    } else {
        format!("{r:e}")
    }
}

/// [`number`] of a value given as text: a float (or an integer of more than 15 digits, as
/// Rust writes 1e300) rounded; a count, a name or a pair as given.
fn number_text(value: &str) -> String {
    if value.contains(['.', 'e', 'E']) || value.trim_start_matches('-').len() > 15 {
        match value.parse::<f64>() {
            Ok(v) => number(v),
            Err(_) => value.to_string(),
        }
    } else {
        value.to_string()
    }
}

/// The operating system's reason of an I/O error in words (`No space left on device`, without
/// the `(os error 28)` of its `Display`), and for an error that only has a kind the kind's
/// words (`io_kind_message`).
pub fn io_message(e: &std::io::Error) -> String {
    if e.raw_os_error().is_some() {
        let text = e.to_string();
        match text.rfind(" (os error ") {
            Some(i) => text[..i].to_string(),
            None => text,
        }
    } else if e.get_ref().is_some() {
        e.to_string()
    } else {
        io_kind_message(e.kind())
    }
}

/// An I/O error kind in words, as the operating system says it where it has the kind's
/// errno (`StorageFull` is "no space left on device"), else the standard library's words.
pub(crate) fn io_kind_message(kind: std::io::ErrorKind) -> String {
    use std::io::ErrorKind as K;
    match kind {
        K::StorageFull => "no space left on device".into(),
        K::PermissionDenied => "permission denied".into(),
        K::NotFound => "no such file or directory".into(),
        K::BrokenPipe => "broken pipe".into(),
        k => std::io::Error::from(k).to_string(),
    }
}

/// Failure of a trajectory computation.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SimError {
    /// Invalid model parameters.
    ///
    /// What to do: see the error it wraps (ParamError).
    #[error(transparent)]
    Params(#[from] ParamError),
    /// A physical (SI) input out of range ([`crate::units`], [`crate::hydro`]).
    ///
    /// What to do: see the error it wraps (UnitsError).
    #[error(transparent)]
    Units(#[from] UnitsError),
    /// A state vector has the wrong length.
    ///
    /// What to do: give as many values as the message expects (N for positions, 2N for a
    /// state of N modes).
    #[error("{name}: expected {expected} values, got {got}")]
    StateLength {
        /// Which input.
        name: &'static str,
        /// Expected length (N or 2N).
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// A state component or a time is NaN or infinite.
    ///
    /// What to do: give a finite number.
    #[error("{name} = {}: must be a finite number", number(*value))]
    NotFinite {
        /// Which input.
        name: &'static str,
        /// Rejected value.
        value: f64,
    },
    /// A probe file (or a chart's probe with one of its values set) that does not resolve:
    /// the probe reader's message.
    ///
    /// What to do: correct the probe file (or the value set) as the message says; the probe
    /// keys' reference gives each key's unit and ranges.
    #[error("{0}")]
    Probe(String),
    /// A run length, count or tolerance is out of range.
    ///
    /// What to do: give a value in the range the message names (each flag's and keyword's
    /// range is in the commands' and the Python reference).
    #[error("{name} = {}: {allowed}", number_text(value))]
    OutOfRange {
        /// Which input.
        name: &'static str,
        /// Rejected value (as text, it may be an integer).
        value: String,
        /// The allowed range in words.
        allowed: std::borrow::Cow<'static, str>,
    },
    /// Repeated switchings with vanishing intervals (chattering / sliding).
    ///
    /// What to do: the contact grazes or slides there; integrate more finely (more steps per
    /// period, or the adaptive integrator), or move the gap or amplitude off the grazing.
    #[error(
        "chattering at tau = {tau}: {count} switchings within {window:e} of dimensionless time"
    )]
    Chattering {
        /// Time at which the chattering was detected.
        tau: f64,
        /// Number of switchings in the window.
        count: usize,
        /// Width of the window.
        window: f64,
    },
    /// The state grew beyond any physical bound (a diverging integration).
    ///
    /// What to do: integrate more finely (more steps per period, or an adaptive
    /// integrator), or check the parameters for a physically impossible combination.
    #[error("diverged at tau = {tau}: |z| = {norm:e}")]
    Diverged {
        /// Time of divergence.
        tau: f64,
        /// State norm.
        norm: f64,
    },
    /// Newton's method (shooting or continuation) did not converge.
    ///
    /// What to do: start nearer the solution (another start or a smaller continuation
    /// step), or check that the orbit exists at these parameters (`simulate`).
    #[error("{what} did not converge: residual {residual:e} after {iterations} iterations")]
    NoConvergence {
        /// Which solver.
        what: &'static str,
        /// Iterations made.
        iterations: usize,
        /// Final residual.
        residual: f64,
    },
    /// An orbit search without a given period found none: the steady-state search from the
    /// start saw no period of at most `max_period` drive periods within its transient cap of
    /// `periods`, and Newton from the motion's states found no period-1 orbit either — the
    /// motion is not periodic within `max_period` (a chaotic one, or the taps and missed taps
    /// of a grazing JKR contact, docs/contact-laws.md).
    ///
    /// What to do: give the period, another start or more `max_periods`; or take the motion
    /// itself (`simulate`) or its time average (an approach curve).
    #[error(
        "no periodic orbit found: the motion from this start did not repeat with a period of at \
         most {max_period} drive periods within {periods} periods, and Newton from its states \
         found no period-1 orbit (residual {}): it is not periodic within max_period — \
         `simulate` gives the motion itself, and an approach curve its time average \
         (reached = \"averaged\"); or give the period, another start or more max_periods",
        number(*residual)
    )]
    NoPeriod {
        /// The longest period the search tested (drive periods).
        max_period: usize,
        /// The transient the search integrated (drive periods, its cap).
        periods: usize,
        /// The residual ‖Pⁿ(z) − z‖ of the last Newton search tried.
        residual: f64,
    },
    /// The chosen integrator cannot integrate the chosen contact law.
    ///
    /// What to do: use the integrator the message's hint names.
    #[error("integrator '{integrator}' cannot integrate the '{law}' contact law: {hint}")]
    Unsupported {
        /// The integrator's name.
        integrator: &'static str,
        /// The law's name.
        law: &'static str,
        /// What to use instead.
        hint: &'static str,
    },
    /// An analysis that needs the cantilever's Galerkin structure was given another
    /// [`crate::tip_sample::TipSampleSystem`].
    ///
    /// What to do: run the analysis on the cantilever model.
    #[error("{analysis} needs the cantilever model (its Galerkin matrices and mode shapes); this system is not one")]
    NotCantilever {
        /// The analysis.
        analysis: &'static str,
    },
    /// Every independent run of an analysis failed (every random start of an attractor census,
    /// every point of a sweep): there is no answer to report.
    ///
    /// What to do: read the first run's error, which is the cause; correct its input.
    #[error("every one of the {runs} {what} failed; the first: {first}")]
    EveryRunFailed {
        /// What the runs are ("random starts", "sweep points").
        what: &'static str,
        /// How many there were.
        runs: usize,
        /// The first one's error.
        first: String,
    },
    /// A result's document holds no finite value in any of its results (`report`'s audit of
    /// the door): there is no answer to report.
    ///
    /// What to do: check the request's ranges and the model: every result is NaN; run one
    /// point (`simulate`, `orbit`) to see why.
    #[error(
        "{what}: no finite value in any of its results ({arrays}): there is no answer to report"
    )]
    NoFiniteValue {
        /// The request.
        what: &'static str,
        /// The result arrays, every value of them missing.
        arrays: String,
    },
    /// The caller cancelled the run ([`crate::analysis::progress::Progress::cancel`]).
    ///
    /// What to do: nothing: the run was stopped by its caller (Ctrl-C, or `progress.cancel()`).
    #[error("cancelled")]
    Cancelled,
    /// The adaptive oracle integrator reported a failure.
    ///
    /// What to do: use another integrator (the default), or a larger tolerance.
    #[error("adaptive integrator failed at tau = {tau}: {message}")]
    Adaptive {
        /// Time of the failure.
        tau: f64,
        /// The crate's message.
        message: String,
    },
    /// A file of the run could not be written (the message names it).
    ///
    /// What to do: check that the path the message names can be written (its directory,
    /// permissions, free space).
    #[error("{0}")]
    File(String),
    /// A run would exceed a documented memory or work budget; refused before allocating.
    ///
    /// What to do: do what the message's hint says: a coarser grid, fewer points or a shorter run.
    #[error("{what}: {needed} exceeds the budget of {budget} ({hint})")]
    Budget {
        /// What would be too large.
        what: &'static str,
        /// The estimate, with its unit.
        needed: String,
        /// The budget, with its unit.
        budget: String,
        /// How to stay within it.
        hint: &'static str,
    },
}

impl SimError {
    /// The message with the parameter of an [`SimError::OutOfRange`] or
    /// [`SimError::NotFinite`] spelled as a front end spells it (`samples_per_period` is
    /// `--samples-per-period` on the command line); other errors as [`std::fmt::Display`].
    pub fn spelled(&self, spell: impl Fn(&str) -> String) -> String {
        match self {
            SimError::OutOfRange {
                name,
                value,
                allowed,
            } => format!("{} = {}: {allowed}", spell(name), number_text(value)),
            SimError::NotFinite { name, value } => {
                format!(
                    "{} = {}: must be a finite number",
                    spell(name),
                    number(*value)
                )
            }
            other => other.to_string(),
        }
    }

    /// Whether the error is about the input (a value out of range, a state of the wrong length,
    /// a non-finite number, an integrator that cannot integrate the law, a run beyond a budget)
    /// rather than a computation that failed: the command line's exit code 2 against 1, and
    /// Python's `ValueError` against `afmdyn.SimulationError`.
    pub fn is_input_error(&self) -> bool {
        matches!(
            self,
            SimError::Params(_)
                | SimError::Units(_)
                | SimError::Probe(_)
                | SimError::StateLength { .. }
                | SimError::NotFinite { .. }
                | SimError::OutOfRange { .. }
                | SimError::Unsupported { .. }
                | SimError::Budget { .. }
        )
    }

    /// Shorthand for [`SimError::OutOfRange`].
    pub(crate) fn out_of_range(
        name: &'static str,
        value: impl ToString,
        allowed: impl Into<std::borrow::Cow<'static, str>>,
    ) -> Self {
        SimError::OutOfRange {
            name,
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }
}

/// Check that `value` lies in `range` (a NaN lies in none), naming `name` and what is
/// `allowed` in the error.
pub(crate) fn within<T: PartialOrd + ToString>(
    name: &'static str,
    value: T,
    range: impl std::ops::RangeBounds<T>,
    allowed: impl Into<std::borrow::Cow<'static, str>>,
) -> Result<(), SimError> {
    if range.contains(&value) {
        Ok(())
    } else {
        Err(SimError::out_of_range(name, value, allowed))
    }
}

/// [`within`] an inclusive range, the error spelling it: `must be in 1..=64`.
pub(crate) fn in_range<T: PartialOrd + std::fmt::Display>(
    name: &'static str,
    value: T,
    range: std::ops::RangeInclusive<T>,
) -> Result<(), SimError> {
    let allowed = format!("must be in {}..={}", range.start(), range.end());
    within(name, value, range, allowed)
}

/// Check that `value` is finite, naming `name` in the error.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64, SimError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(SimError::NotFinite { name, value })
    }
}

// The cancel flag a run's loops watch (`crate::analysis::progress`: the door installs it,
// every loop that integrates checks it), here below the integrators that check it.
thread_local! {
    /// The cancel flag of the run on this thread (`Progress::watch`).
    static WATCHED: RefCell<Option<Arc<AtomicBool>>> = const { RefCell::new(None) };
}

/// The cancel flag this thread watches, to carry onto another thread ([`watching`]).
pub(crate) fn watched() -> Option<Arc<AtomicBool>> {
    WATCHED.with(|w| w.borrow().clone())
}

/// Run `f` with `flag` as this thread's watched cancel flag, the one before restored after.
pub(crate) fn watching<T>(flag: Option<Arc<AtomicBool>>, f: impl FnOnce() -> T) -> T {
    struct Restore(Option<Arc<AtomicBool>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let before = self.0.take();
            WATCHED.with(|w| *w.borrow_mut() = before);
        }
    }
    let _restore = Restore(WATCHED.with(|w| w.replace(flag)));
    f()
}

/// `Ok` while the run on this thread may go on (no flag watched, or not set).
///
/// # Errors
/// [`SimError::Cancelled`] once the watched flag is set.
pub(crate) fn cancelled() -> Result<(), SimError> {
    let set = WATCHED.with(|w| {
        w.borrow()
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    });
    if set {
        Err(SimError::Cancelled)
    } else {
        Ok(())
    }
}
