//! Tip–sample force laws F_c(δ, δ̇), in the paper's dimensionless units.
//!
//! δ = −V_T is the indentation (V_T of eq. 8) and δ̇ = −dV_T/dτ its rate. F_c is **repulsive
//! positive** (it pushes the tip away from the sample) and enters the modal equations as the tip
//! force φ(1)·F_c:
//!
//! M ä + C ȧ + K a = F^I(τ) + φ(1) F_c(δ, δ̇)   (eqs. 11–14 with the contact at ξ = 1).
//!
//! For the linear law F_c = α4 δ + α6 δ̇ this is exactly eqs. 15–18 (K^II = K^I + α4 φφᵀ,
//! C^II = C^I + α6 φφᵀ, F^II = F^I − φ(α4(α2 sin Ωτ + α5) + α6 α2 Ω cos Ωτ)).
//! A force is the scaled force F̃ = F L³/(EI g₀), the unit of α4 V_T.
//!
//! # The registry
//! A law is one module (its groups, force, potential, guards, jet piece and descriptors: the
//! `Law` trait) and one line of the `laws!` registry below, which generates [`ContactLaw`]
//! (one variant per law, serialized as `{"law": name, groups…}`), [`LawKind`], the parser, the
//! static dispatch of every `Law` method and [`LAWS`], the descriptors the front ends read
//! (schema, CLI help, Python, docs, conformance suite). The laws, each documented in its module:
//! [`linear`], [`hertz`], [`dmt`], [`electrostatic`], [`jkr`], [`capillary`], [`sls`],
//! [`impact`].

/// The sign convention of every tip–sample force afmdyn outputs (the `contact_force` column of
/// `simulate`, the approach's `peak_force`, `min_force`, `max_abs_force` and force traces,
/// Python's `contact_force`): F_c is the force the sample exerts on the tip along the outward
/// normal of the sample, the law's F_c(δ, δ̇) with δ = −V_T.
pub const FORCE_SIGN: &str = "positive when the sample pushes the tip away (repulsion, e.g. at \
    the deepest indentation), negative when it pulls the tip towards it (attraction, e.g. DMT's \
    van der Waals force in free flight)";

use serde::{Deserialize, Serialize};

/// Largest damping coefficients α3 and α6 (the beam's and the contact's, and a law's dashpot
/// that makes α6, [`sls`]): the damping rate sets the stiffness of the system, and the exact
/// grid needs about α·T steps per drive period (see `GRID_BUDGET_BYTES`).
pub(crate) const DAMPING_MAX: f64 = 1e4;
use std::fmt;
use std::str::FromStr;

/// The registry: `name => Variant { groups } : module::Struct`. Generates the law modules,
/// [`ContactLaw`], [`LawKind`], their dispatch and [`LAWS`]. A `#[cfg(..)]` before an entry
/// compiles the law only under it.
macro_rules! laws {
    ($(
        $(#[cfg($cfg:meta)])?
        $name:ident => $Variant:ident $({ $($field:ident),* $(,)? })? : $Law:ident
    ),* $(,)?) => {
        $(
            $(#[cfg($cfg)])?
            pub mod $name;
            $(#[cfg($cfg)])?
            pub use $name::$Law;
        )*

        /// A tip–sample law and its own dimensionless groups (each variant's fields are its
        /// law struct's, documented there). The stiffness α4 and damping α6 of
        /// [`crate::Params`] are shared by the laws. Serialized as `{"law": name, groups…}`.
        #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
        #[serde(tag = "law", rename_all = "snake_case")]
        pub enum ContactLaw {
            $(
                $(#[cfg($cfg)])?
                #[doc = concat!("The `", stringify!($name), "` law ([`", stringify!($Law), "`]).")]
                $Variant $({ $(
                    #[doc = concat!("[`", stringify!($Law), "::", stringify!($field), "`].")]
                    $field: f64
                ),* })?,
            )*
        }

        /// The kind of a law without its groups, parsed from its name ([`LAWS`]).
        ///
        /// One parser for every front end: the name is taken in any case (`"HERTZ"`, `"DMT"` as
        /// the literature writes it) on the command line, in a `--config` file, a probe file and
        /// from Python ([`FromStr`], which [`Deserialize`] calls).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
        #[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
        #[serde(rename_all = "snake_case")]
        pub enum LawKind {
            $(
                $(#[cfg($cfg)])?
                #[doc = concat!("[`ContactLaw::", stringify!($Variant), "`].")]
                $Variant,
            )*
        }

        /// The registered laws' descriptors, in registry order.
        pub const LAWS: &[LawInfo] = &[$(
            $(#[cfg($cfg)])?
            LawInfo {
                name: stringify!($name),
                aliases: <$Law as Law>::ALIASES,
                doc: <$Law as Law>::DOC,
                params: <$Law as Law>::PARAMS,
                sample_keys: <$Law as Law>::SAMPLE_KEYS,
                tip_radius: <$Law as Law>::TIP_RADIUS,
            },
        )*];

        impl LawKind {
            /// Every registered kind, in registry order (that of [`LAWS`]).
            pub const ALL: &'static [LawKind] = &[$( $(#[cfg($cfg)])? LawKind::$Variant, )*];

            /// The kind's name, as requests and files spell it.
            pub fn name(self) -> &'static str {
                match self {
                    $( $(#[cfg($cfg)])? LawKind::$Variant => stringify!($name), )*
                }
            }

            /// The law of this kind from a probe file's sample in SI (`Law::from_si`), with
            /// α4 and α6.
            ///
            /// # Errors
            /// The law's message: a value it cannot take, or that a probe file cannot give it.
            pub fn from_si(self, si: &SampleSi) -> Result<(ContactLaw, f64, f64), String> {
                match self {
                    $(
                        $(#[cfg($cfg)])?
                        LawKind::$Variant => {
                            #[allow(unused_variables)]
                            let (law, alpha4, alpha6) = <$Law as Law>::from_si(si)?;
                            Ok((ContactLaw::$Variant $({ $($field: law.$field),* })?, alpha4, alpha6))
                        }
                    )*
                }
            }

            /// Build the law, filling groups that are not given with the law's defaults
            /// (`Param::default` of its `Law::PARAMS`).
            pub fn with_groups(self, groups: LawGroups) -> ContactLaw {
                match self {
                    $(
                        $(#[cfg($cfg)])?
                        LawKind::$Variant => ContactLaw::$Variant $({ $(
                            $field: groups.get(stringify!($field)).unwrap_or_else(|| {
                                default_of(<$Law as Law>::PARAMS, stringify!($field))
                            })
                        ),* })?,
                    )*
                }
            }
        }

        impl ContactLaw {
            /// The law's kind without its groups.
            pub fn kind(&self) -> LawKind {
                match self {
                    $( $(#[cfg($cfg)])? ContactLaw::$Variant { .. } => LawKind::$Variant, )*
                }
            }

            /// The groups of the law (those it has), by their names.
            pub fn groups(&self) -> LawGroups {
                #[allow(unused_mut)]
                let mut groups = LawGroups::default();
                match *self {
                    $(
                        $(#[cfg($cfg)])?
                        ContactLaw::$Variant { $($($field),*)? } => {
                            $($( groups.set(stringify!($field), Some($field)); )*)?
                        }
                    )*
                }
                groups
            }
        }

        prepared_contact! {
            [$( [$(#[cfg($cfg)])?] $Variant $Law [$($($field)*)?] )*]
        }

        law_methods! {
            [$( [$(#[cfg($cfg)])?] $Variant $Law [$($($field)*)?] )*]
            /// Check the law's own groups (`Law::validate`).
            ///
            /// # Errors
            /// [`crate::error::ParamError::Law`] naming the group and its allowed range.
            fn validate() -> Result<(), crate::error::ParamError>;
            /// Check the law's groups against the shared α4 and α6 (`Law::validate_shared`).
            ///
            /// # Errors
            /// [`crate::error::ParamError::Law`] naming α4 or α6 and the range the law needs.
            fn validate_shared(alpha4: f64, alpha6: f64) -> Result<(), crate::error::ParamError>;
            /// `Law::force` of the law.
            fn law_force(k: f64, c: f64, contact: bool, delta: f64, rate: f64) -> ForceEval = force;
            /// `Law::potential` of the law.
            fn law_potential(k: f64, contact: bool, delta: f64) -> f64 = potential;
            /// `Law::dissipative` of the law, in contact.
            fn law_dissipative(k: f64, c: f64, delta: f64, rate: f64) -> f64 = dissipative;
            /// Whether the law exerts a force outside contact (DMT's, the electrostatic law's).
            fn acts_outside() -> bool;
            /// Distance d − V_T between tip–sample distance and switching function: ã₀ for DMT
            /// and the electrostatic law (d = a₀ + V_T, contact at d ≤ a₀), 0 for the other laws
            /// (contact at d = V_T ≤ 0).
            fn distance_offset() -> f64;
            /// The long-range attraction at tip–sample distance d > 0: [F(d), dF/dd, U(d)] with
            /// F = −dU/dd (`Law::long_range`); zeros for the laws without one.
            fn long_range(d: f64) -> [f64; 3];
            /// A hysteretic law's cycle (`ContactLaw::release_distance` > 0) in the law's
            /// units, with Hertz group `alpha4`: where the contact is left, the largest pull and
            /// the energy each tap loses to the hysteresis; `None` for the other laws.
            fn hysteresis(alpha4: f64) -> Option<Hysteresis>;
            /// The number m of internal states the law adds to the state `z: [f64; 2N + m]`
            /// after (a, ȧ): 1 for SLS (the dashpot's extension u, [`Zener`]), 0 for the
            /// other laws.
            fn internal_states() -> usize;
            /// The law's internal state as a [`Zener`] solid of α4, α6 (SLS), if it has one.
            fn zener(alpha4: f64, alpha6: f64) -> Option<Zener>;
            /// Whether each region is affine in the state (the exact propagator applies).
            fn is_affine() -> bool;
            /// Coefficient of restitution of the impact law.
            fn restitution() -> Option<f64>;
            /// Whether the contact damper is Kelvin–Voigt's α6 √δ δ̇ (DMT, electrostatic,
            /// capillary): its ∂/∂δ is singular at the contact's onset.
            fn kelvin_voigt() -> bool;
            /// The law's piece of the Taylor jet (`Law::jet`), with α4 `k` and α6 `c`.
            fn jet(k: f64, c: f64) -> Option<JetLaw>;
            /// Why the Taylor integrator refuses the law (`Law::taylor_hint`).
            fn taylor_hint() -> &'static str;
            /// Why the law does not apply in a liquid medium, if it does not
            /// (`Law::not_in_liquid`: the capillary meniscus, the electrostatic force).
            fn not_in_liquid() -> Option<&'static str>;
        }
    };
}

/// [`PreparedContact`] (one variant per law, holding its [`Law::Prepared`]),
/// [`ContactLaw::prepare`] and the static dispatch of its evaluations.
macro_rules! prepared_contact {
    ([$( [$(#[cfg($cfg:meta)])?] $Variant:ident $Law:ident [$($field:ident)*] )*]) => {
        /// A law with its constants prepared once from its groups and α4, α6
        /// ([`ContactLaw::prepare`]): each variant holds its law's `Law::Prepared`.
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum PreparedContact {
            $(
                $(#[cfg($cfg)])?
                #[doc = concat!("[`", stringify!($Law), "`]'s prepared constants.")]
                $Variant(<$Law as Law>::Prepared),
            )*
        }

        impl ContactLaw {
            /// The law's prepare step (`Law::prepare`) with α4 = `alpha4` and α6 = `alpha6`:
            /// its constants, computed once per model.
            pub fn prepare(&self, alpha4: f64, alpha6: f64) -> PreparedContact {
                match *self {
                    $(
                        $(#[cfg($cfg)])?
                        ContactLaw::$Variant { $($field),* } => PreparedContact::$Variant(
                            Law::prepare(&$Law { $($field),* }, alpha4, alpha6),
                        ),
                    )*
                }
            }
        }

        impl PreparedForce for PreparedContact {
            fn force(&self, contact: bool, delta: f64, rate: f64) -> ForceEval {
                match self {
                    $( $(#[cfg($cfg)])? PreparedContact::$Variant(p) => p.force(contact, delta, rate), )*
                }
            }

            fn potential(&self, contact: bool, delta: f64) -> f64 {
                match self {
                    $( $(#[cfg($cfg)])? PreparedContact::$Variant(p) => p.potential(contact, delta), )*
                }
            }

            fn dissipative(&self, delta: f64, rate: f64) -> f64 {
                match self {
                    $( $(#[cfg($cfg)])? PreparedContact::$Variant(p) => p.dissipative(delta, rate), )*
                }
            }
        }
    };
}

/// One dispatching method of [`ContactLaw`] per given signature (`= method` when the law's
/// method is named otherwise): a `match` over the registered laws, statically dispatched.
macro_rules! law_methods {
    ($laws:tt $( $(#[doc = $doc:expr])* fn $f:ident($($a:ident: $t:ty),*) -> $r:ty $(= $g:ident)?; )*) => {
        impl ContactLaw {
            $(
                $(#[doc = $doc])*
                pub fn $f(&self $(, $a: $t)*) -> $r {
                    law_dispatch!(self, $laws, [$f $($g)?], ($($a),*))
                }
            )*
        }
    };
}

/// `match *self` over the registered laws, calling the [`Law`] method on each law's struct.
macro_rules! law_dispatch {
    (@go $self:ident, [$( [$(#[cfg($cfg:meta)])?] $Variant:ident $Law:ident [$($field:ident)*] )*], $m:ident, $args:tt) => {
        match *$self {
            $(
                $(#[cfg($cfg)])?
                ContactLaw::$Variant { $($field),* } => law_dispatch!(@call ($Law { $($field),* }), $m, $args),
            )*
        }
    };
    (@call $law:expr, $m:ident, ($($a:ident),*)) => {
        Law::$m(&$law $(, $a)*)
    };
    ($self:ident, $laws:tt, [$f:ident], $args:tt) => {
        law_dispatch!(@go $self, $laws, $f, $args)
    };
    ($self:ident, $laws:tt, [$f:ident $g:ident], $args:tt) => {
        law_dispatch!(@go $self, $laws, $g, $args)
    };
}

laws! {
    linear => Linear : LinearLaw,
    hertz => Hertz : HertzLaw,
    dmt => Dmt { hamaker, intermolecular_distance } : DmtLaw,
    electrostatic => Electrostatic { hamaker, intermolecular_distance, electrostatic, tip_radius } : ElectrostaticLaw,
    jkr => Jkr { adhesion } : JkrLaw,
    capillary => Capillary { capillary, meniscus, rupture } : CapillaryLaw,
    sls => Sls { maxwell_stiffness } : SlsLaw,
    impact => Impact { restitution } : ImpactLaw,
    #[cfg(feature = "toy-law")]
    spring_adhesion => SpringAdhesion { toy_adhesion } : SpringAdhesionLaw,
}

pub(crate) mod indenter;
mod law;
mod prepared;
pub use capillary::{
    Meniscus, CAPILLARY_DEFAULT_FORCE, CAPILLARY_DEFAULT_MENISCUS, CAPILLARY_DEFAULT_RUPTURE,
};
pub use dmt::{DMT_DEFAULT_A0, DMT_DEFAULT_HAMAKER};
pub use electrostatic::{ELECTROSTATIC_DEFAULT, ELECTROSTATIC_DEFAULT_RADIUS, VACUUM_PERMITTIVITY};
pub use jkr::{Jkr, PreparedJkr, JKR_BREAK_CUT, JKR_DEFAULT_ADHESION};
pub use law::{reduced_modulus, Law, LawInfo, Param, SampleSi};
pub use prepared::{AsGiven, PreparedForce, PreparedLaw};
pub use sls::{Zener, SLS_DEFAULT_MAXWELL};

impl Default for ContactLaw {
    /// The paper's linear law.
    fn default() -> Self {
        ContactLaw::Linear
    }
}

impl Default for LawKind {
    /// The paper's linear law.
    fn default() -> Self {
        LawKind::Linear
    }
}

/// The tip force as the Taylor recurrences carry it (`Law::jet`; the recurrences are
/// `integrate::taylor`'s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JetLaw {
    /// α4 δ^{3/2} + α6 δ̇ in contact, no force in free flight.
    Hertz {
        /// α4.
        k: f64,
        /// α6.
        c: f64,
    },
    /// −H̃/d² in free flight; −H̃/ã₀² + α4 δ^{3/2} + α6 √δ δ̇ in contact.
    Dmt {
        /// H̃.
        h: f64,
        /// ã₀.
        a0: f64,
        /// α4.
        k: f64,
        /// α6.
        c: f64,
    },
}

impl ContactLaw {
    /// The law's name ([`LawKind::name`]).
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }

    /// The law's descriptor in [`LAWS`].
    pub(crate) fn info(&self) -> &'static LawInfo {
        self.kind().info()
    }

    /// How far beyond the contact threshold (V_T = 0) the contact persists on retraction: the
    /// contact region is left where V_T rises to this value. |δ_f| = 3q_f⁴ for JKR (the neck,
    /// [`Jkr::release`]), the rupture distance D̃_r for the capillary meniscus, 0 for the other
    /// laws. A law with a positive value is **hysteretic**:
    /// for 0 < V_T < |δ_f| the region depends on the history, and [`crate::CantileverModel`]
    /// takes a start there as in contact when the tip moves away from the sample (leaving
    /// through its neck) and free when it moves towards it (approaching).
    pub(crate) fn release_distance(&self, alpha4: f64) -> f64 {
        self.hysteresis(alpha4).map_or(0.0, |h| h.release_distance)
    }
}

impl fmt::Display for ContactLaw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for LawKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let key = s.trim().to_ascii_lowercase();
        LawKind::ALL
            .iter()
            .copied()
            .find(|k| k.name() == key || k.info().aliases.contains(&key.as_str()))
            .ok_or_else(|| format!("contact law '{s}': expected {}", LawKind::EXPECTED))
    }
}

impl<'de> Deserialize<'de> for LawKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// The separator before the `i`-th of `n` names in [`LawKind::EXPECTED`].
const fn separator(i: usize, n: usize) -> &'static [u8] {
    if i == 0 {
        b""
    } else if i + 1 == n {
        b" or "
    } else {
        b", "
    }
}

/// The length of [`LawKind::EXPECTED`].
const fn expected_len() -> usize {
    let mut len = 0;
    let mut i = 0;
    while i < LAWS.len() {
        len += separator(i, LAWS.len()).len() + LAWS[i].name.len();
        i += 1;
    }
    len
}

/// The bytes of [`LawKind::EXPECTED`]: the names joined by `, ` and a last ` or `.
const EXPECTED_BYTES: [u8; expected_len()] = {
    let mut out = [0u8; expected_len()];
    let mut at = 0;
    let mut i = 0;
    while i < LAWS.len() {
        let parts = [separator(i, LAWS.len()), LAWS[i].name.as_bytes()];
        let mut p = 0;
        while p < parts.len() {
            let mut j = 0;
            while j < parts[p].len() {
                out[at] = parts[p][j];
                at += 1;
                j += 1;
            }
            p += 1;
        }
        i += 1;
    }
    out
};

impl LawKind {
    /// The names a front end accepts, for messages and help: `linear, hertz, … or impact`, the
    /// registry's names ([`LAWS`]) joined at compile time.
    pub const EXPECTED: &'static str = match std::str::from_utf8(&EXPECTED_BYTES) {
        Ok(s) => s,
        Err(_) => panic!("the laws' names are UTF-8"),
    };

    /// The kind's descriptor in [`LAWS`].
    pub(crate) fn info(self) -> &'static LawInfo {
        let i = LawKind::ALL
            .iter()
            .position(|&k| k == self)
            .expect("every kind is registered");
        &LAWS[i]
    }
}

/// Whether two names are equal (in a `const` context).
const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// Whether the `j`-th group of the `i`-th law of [`LAWS`] is the first of its name.
const fn first_of_name(i: usize, j: usize) -> bool {
    let name = LAWS[i].params[j].name;
    let mut l = 0;
    while l <= i {
        let params = LAWS[l].params;
        let end = if l == i { j } else { params.len() };
        let mut k = 0;
        while k < end {
            if same(params[k].name, name) {
                return false;
            }
            k += 1;
        }
        l += 1;
    }
    true
}

/// The number of distinct group names of the registered laws.
const fn group_count() -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < LAWS.len() {
        let mut j = 0;
        while j < LAWS[i].params.len() {
            if first_of_name(i, j) {
                n += 1;
            }
            j += 1;
        }
        i += 1;
    }
    n
}

/// Every law group, once, in registry order (a group two laws share, as DMT's `hamaker`, is
/// described by its first law's `Param`): the names requests, config files, CLI flags,
/// Python keywords and the schema take, all derived from the laws' `Law::PARAMS`.
pub const GROUPS: [Param; group_count()] = {
    let mut out = [Param::EMPTY; group_count()];
    let mut n = 0;
    let mut i = 0;
    while i < LAWS.len() {
        let mut j = 0;
        while j < LAWS[i].params.len() {
            if first_of_name(i, j) {
                out[n] = LAWS[i].params[j];
                n += 1;
            }
            j += 1;
        }
        i += 1;
    }
    out
};

/// The default of group `name` in `params` (a law's [`Law::PARAMS`]).
fn default_of(params: &[Param], name: &str) -> f64 {
    params
        .iter()
        .find(|p| p.name == name)
        .map_or(f64::NAN, |p| p.default)
}

/// The law groups a front end may give, by name ([`GROUPS`]; each `None` when not given): the
/// one argument of [`LawKind::with_groups`] and [`ContactLaw::from_parts`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LawGroups([Option<f64>; GROUPS.len()]);

impl LawGroups {
    /// The groups of `law` (those it has), e.g. to keep them when another group is changed.
    pub(crate) fn of(law: ContactLaw) -> LawGroups {
        law.groups()
    }

    /// The index of group `name` in [`GROUPS`].
    fn index(name: &str) -> Option<usize> {
        GROUPS.iter().position(|p| p.name == name)
    }

    /// The value of group `name`, if given (`None` as well for a name that is no group).
    pub fn get(&self, name: &str) -> Option<f64> {
        Self::index(name).and_then(|i| self.0[i])
    }

    /// Set (or clear) group `name`; `false`, and nothing set, when no law has a group of
    /// that name.
    pub fn set(&mut self, name: &str, value: Option<f64>) -> bool {
        match Self::index(name) {
            Some(i) => {
                self.0[i] = value;
                true
            }
            None => false,
        }
    }

    /// `self` with group `name` set to `value` (unchanged when no law has that group).
    pub fn with(mut self, name: &str, value: f64) -> LawGroups {
        self.set(name, Some(value));
        self
    }

    /// Each group by its name ([`Param::name`]), given or not, in the order of [`GROUPS`].
    pub(crate) fn entries(&self) -> impl Iterator<Item = (&'static str, Option<f64>)> + '_ {
        GROUPS.iter().zip(self.0).map(|(p, v)| (p.name, v))
    }

    /// The groups given, by name, in the order of [`GROUPS`].
    pub(crate) fn given(&self) -> impl Iterator<Item = (&'static str, f64)> + '_ {
        self.entries().filter_map(|(name, v)| Some((name, v?)))
    }

    /// Each group of `self`, or `other`'s where `self` has none.
    pub fn or(self, other: LawGroups) -> LawGroups {
        LawGroups(std::array::from_fn(|i| self.0[i].or(other.0[i])))
    }
}

impl ContactLaw {
    /// The law a front end asks for: its kind (or `base`'s when not given) and the groups it
    /// sets, the others kept from `base` when it is of that kind, else the defaults. One place
    /// for the CLI flags, the TOML keys and the Python keywords.
    ///
    /// # Errors
    /// [`crate::error::ParamError::Group`] for a group of another law (e.g. `restitution` with
    /// `contact_law = hertz`), naming the laws that own it (`LawInfo::params`); the groups'
    /// ranges are checked by [`ContactLaw::validate`].
    pub fn from_parts(
        kind: Option<LawKind>,
        groups: LawGroups,
        base: ContactLaw,
    ) -> Result<ContactLaw, crate::error::ParamError> {
        let kind = kind.unwrap_or(base.kind());
        for (group, value) in groups.entries() {
            let owns = |info: &LawInfo| info.params.iter().any(|p| p.name == group);
            if value.is_some() && !owns(kind.info()) {
                return Err(crate::error::ParamError::Group {
                    group,
                    owner: owners(group),
                    law: kind.name(),
                });
            }
        }
        // groups not given keep base's when base has them
        Ok(kind.with_groups(groups.or(LawGroups::of(base))))
    }
}

/// The laws owning `group`, for messages: `dmt or electrostatic` (built once per group).
pub(crate) fn owners(group: &str) -> &'static str {
    static OWNERS: std::sync::OnceLock<Vec<(&'static str, &'static str)>> =
        std::sync::OnceLock::new();
    let table = OWNERS.get_or_init(|| {
        let mut table: Vec<(&'static str, &'static str)> = Vec::new();
        for p in LAWS.iter().flat_map(|l| l.params) {
            if table.iter().any(|(g, _)| *g == p.name) {
                continue;
            }
            let names: Vec<&str> = LAWS
                .iter()
                .filter(|l| l.params.iter().any(|q| q.name == p.name))
                .map(|l| l.name)
                .collect();
            let owner = match names.split_last() {
                Some((last, [])) => (*last).to_string(),
                Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
                None => String::new(),
            };
            table.push((p.name, Box::leak(owner.into_boxed_str())));
        }
        table
    });
    table
        .iter()
        .find(|(g, _)| *g == group)
        .map_or("another law", |(_, o)| o)
}

/// F_c and its partial derivatives at (δ, δ̇).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ForceEval {
    /// F_c (repulsive positive).
    pub force: f64,
    /// ∂F_c/∂δ.
    pub d_delta: f64,
    /// ∂F_c/∂δ̇.
    pub d_rate: f64,
}

/// A tip–sample force law: the force in and out of contact with its partial derivatives, the
/// conservative potential (for the energy) and the dissipative part (for the dissipation rate).
pub trait TipSampleLaw {
    /// F_c(δ, δ̇) with partials; `contact` is the region (δ ≥ 0 in contact for a smooth law).
    fn force(&self, contact: bool, delta: f64, rate: f64) -> ForceEval;
    /// Potential U(δ) of the conservative part, with −dU/dV_T = dU/dδ = F_cons (0 at δ = 0 for
    /// the linear and Hertz laws; continuous across δ = 0).
    fn potential(&self, contact: bool, delta: f64) -> f64;
    /// Dissipative part F_d of F_c: the dissipation rate is F_d δ̇ ≥ 0.
    fn dissipative(&self, contact: bool, delta: f64, rate: f64) -> f64;
    /// Whether the law acts outside contact (δ < 0).
    fn acts_outside(&self) -> bool;
}

/// A law with its stiffness α4 and damping α6: what the model evaluates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipSample {
    /// The law.
    pub law: ContactLaw,
    /// α4: stiffness of the linear law, Hertz group of the Hertz and DMT laws.
    pub stiffness: f64,
    /// α6: damper of the linear and Hertz laws, Kelvin–Voigt group of DMT.
    pub damping: f64,
}

impl TipSampleLaw for TipSample {
    fn force(&self, contact: bool, delta: f64, rate: f64) -> ForceEval {
        self.law
            .law_force(self.stiffness, self.damping, contact, delta, rate)
    }

    fn potential(&self, contact: bool, delta: f64) -> f64 {
        self.law.law_potential(self.stiffness, contact, delta)
    }

    fn dissipative(&self, contact: bool, delta: f64, rate: f64) -> f64 {
        if !contact {
            return 0.0;
        }
        self.law
            .law_dissipative(self.stiffness, self.damping, delta, rate)
    }

    fn acts_outside(&self) -> bool {
        self.law.acts_outside()
    }
}

impl TipSample {
    /// The long-range attraction at tip–sample distance d > 0: [F(d), dF/dd, U(d)] with
    /// F = −dU/dd — DMT's van der Waals −H̃/d² (U = −H̃/d), and for the electrostatic law also
    /// the biased sphere over the plane −ẼR̃²/(d(d + R̃)) (Hudlet et al. 1998;
    /// U = −ẼR̃ ln((d + R̃)/d)); zeros for the other laws.
    pub fn long_range(&self, d: f64) -> [f64; 3] {
        self.law.long_range(d)
    }
}

/// A hysteretic law's cycle ([`ContactLaw::hysteresis`]), in the law's units (lengths in g₀,
/// forces in F̃, energies in F̃·g₀).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Hysteresis {
    /// V_T where the contact is left on retraction: JKR's |δ_b|, the meniscus's D̃_r.
    pub release_distance: f64,
    /// The largest pull of the contact (a positive magnitude): JKR's load-controlled pull-off
    /// (3/2)P̃ = (3/2)πWR, the meniscus's F̃_cap = 4πRγcosθ.
    pub pull_off_force: f64,
    /// The energy each tap loses to the hysteresis (formed, then left): JKR's E_hys, the
    /// meniscus's E_cap.
    pub energy_per_tap: f64,
}

#[cfg(test)]
mod tests;
