//! A number as a user writes it, with an optional SI unit ([`Quantity`]: `20nm`, `300kHz`,
//! `0.5 nN`, `-3e-9`), and what its unit measures ([`Dim`]): the one reader of such numbers, for
//! the command line's flags (`--z-c 20nm`) and Python's keywords (`z_c="20nm"`). A keyword
//! that takes an SI value with a probe takes a dimensionless one without (g₀, Ω, F̃), so a
//! unit without a probe is refused ([`Quantity::si`]).

/// What an SI unit suffix measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dim {
    /// m, mm, µm (um), nm, pm.
    Length,
    /// Hz, kHz, MHz.
    Frequency,
    /// N, mN, µN (uN), nN, pN.
    Force,
}

impl Dim {
    /// The dimension a request schema names in a field's `x-dim` (`"length"`, `"frequency"`,
    /// `"force"`), or `None` for another key.
    pub fn of_key(key: &str) -> Option<Dim> {
        match key {
            "length" => Some(Dim::Length),
            "frequency" => Some(Dim::Frequency),
            "force" => Some(Dim::Force),
            _ => None,
        }
    }

    /// Its SI unit.
    pub fn unit(self) -> &'static str {
        match self {
            Dim::Length => "m",
            Dim::Frequency => "Hz",
            Dim::Force => "N",
        }
    }

    /// What it measures, with its SI unit: `a length (m)`.
    pub fn name(self) -> &'static str {
        match self {
            Dim::Length => "a length (m)",
            Dim::Frequency => "a frequency (Hz)",
            Dim::Force => "a force (N)",
        }
    }
}

/// A number as a user writes it, with an optional SI unit: `20nm`, `20 nm`, `0.1nm`,
/// `300kHz`, `-3e-9` (the value in the base unit, m, Hz or N, and the unit's dimension).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantity {
    /// The value in m, Hz or N when a unit was written, else as written.
    pub value: f64,
    /// The unit's dimension, when a unit was written.
    pub dim: Option<Dim>,
}

/// The SI units a number may carry, with their powers of ten to m, Hz or N.
const UNITS: [(&str, i32, Dim); 15] = [
    ("pm", -12, Dim::Length),
    ("nm", -9, Dim::Length),
    ("um", -6, Dim::Length),
    ("µm", -6, Dim::Length),
    ("mm", -3, Dim::Length),
    ("m", 0, Dim::Length),
    ("kHz", 3, Dim::Frequency),
    ("MHz", 6, Dim::Frequency),
    ("Hz", 0, Dim::Frequency),
    ("pN", -12, Dim::Force),
    ("nN", -9, Dim::Force),
    ("uN", -6, Dim::Force),
    ("µN", -6, Dim::Force),
    ("mN", -3, Dim::Force),
    ("N", 0, Dim::Force),
];

/// [`unit_slip`] of a frequency-shift column: its largest |Δf| against the resonance `f0`
/// (10⁻⁶ f₀ to half of it).
pub(crate) fn shift_slip(shift: &[f64], f0: f64) -> Option<String> {
    unit_slip(
        "frequency_shift",
        "the largest |Δf|",
        largest_magnitude(shift),
        Dim::Frequency,
        (1e-6 * f0, 0.5 * f0),
    )
}

/// A data column checked against the probe (issue 77 item 4): `magnitude`, a positive size of
/// the column (its span, or its largest |value|), against the `typical` range (lo, hi) in SI
/// that the probe gives it; outside, the warning names the column, the range and the unit the
/// data were likely written in (the one of `dim` that brings `magnitude` into the range), for
/// data are read in SI. `None` within the range, or for no magnitude (an empty or constant
/// column).
pub(crate) fn unit_slip(
    column: &str,
    what: &str,
    magnitude: f64,
    dim: Dim,
    typical: (f64, f64),
) -> Option<String> {
    let (lo, hi) = typical;
    if !(magnitude.is_finite() && magnitude > 0.0) || (lo..=hi).contains(&magnitude) {
        return None;
    }
    let unit = dim.unit();
    // of the units that bring it into the range, the one nearest the range's middle (in
    // decades)
    let off = |p: i32| (magnitude * 10f64.powi(p) / (lo * hi).sqrt()).log10().abs();
    let likely = UNITS
        .iter()
        .filter(|(name, p, d)| *d == dim && *p != 0 && *name != "um")
        .filter(|(_, p, _)| (lo..=hi).contains(&(magnitude * 10f64.powi(*p))))
        .min_by(|a, b| off(a.1).total_cmp(&off(b.1)))
        .map_or("; check its unit".to_string(), |(name, p, _)| {
            let read = magnitude * 10f64.powi(*p);
            format!(": written in {name}? (in {name} it would be {read:.3e} {unit}; data are read in SI)")
        });
    Some(warning!(
        "data.unit-slip",
        "Check the column's unit: data are read in SI (m, N, s, Hz).",
        "{column}: {what} is {magnitude:.3e} {unit}, outside the {lo:.0e}..{hi:.0e} {unit} this \
         probe's data take{likely}"
    ))
}

/// The smallest and largest of the finite values of `v` ((∞, −∞) for none).
pub(crate) fn extent(v: &[f64]) -> (f64, f64) {
    // eight independent lanes, so that a long column's pass vectorises (a map's curves of
    // 24 000 rows); a value not finite becomes NaN, which f64::min and max pass over
    const LANES: usize = 8;
    let mut lo = [f64::INFINITY; LANES];
    let mut hi = [f64::NEG_INFINITY; LANES];
    let finite = |x: f64| if x.is_finite() { x } else { f64::NAN };
    let chunks = v.chunks_exact(LANES);
    let rest = chunks.remainder();
    for c in chunks {
        for i in 0..LANES {
            lo[i] = lo[i].min(finite(c[i]));
            hi[i] = hi[i].max(finite(c[i]));
        }
    }
    for (i, &x) in rest.iter().enumerate() {
        lo[i] = lo[i].min(finite(x));
        hi[i] = hi[i].max(finite(x));
    }
    let lo = lo.into_iter().fold(f64::INFINITY, f64::min);
    (lo, hi.into_iter().fold(f64::NEG_INFINITY, f64::max))
}

/// The span max − min of the finite values of `v` (0 for fewer than two).
pub(crate) fn span(v: &[f64]) -> f64 {
    let (lo, hi) = extent(v);
    (hi - lo).max(0.0)
}

/// The largest |value| of the finite values of `v` (0 for none).
pub(crate) fn largest_magnitude(v: &[f64]) -> f64 {
    v.iter()
        .filter(|x| x.is_finite())
        .fold(0.0, |m: f64, x| m.max(x.abs()))
}

impl std::str::FromStr for Quantity {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let t = s.trim();
        if let Ok(v) = t.parse::<f64>() {
            return Ok(Quantity {
                value: v,
                dim: None,
            });
        }
        for (unit, exp, dim) in UNITS {
            if let Some(num) = t.strip_suffix(unit).map(str::trim_end) {
                if let Ok(v) = num.parse::<f64>() {
                    // `7nm` reads as `7e-9` exactly (7 × 1e-9 would be one ulp off)
                    let value = if num.contains(['e', 'E']) {
                        v * 10f64.powi(exp)
                    } else {
                        format!("{num}e{exp}")
                            .parse()
                            .unwrap_or(v * 10f64.powi(exp))
                    };
                    return Ok(Quantity {
                        value,
                        dim: Some(dim),
                    });
                }
            }
        }
        Err(format!(
            "'{s}': expected a number, optionally with a unit (pm, nm, um, mm, m, Hz, kHz, MHz, pN, nN, uN, mN, N)"
        ))
    }
}

/// A plain number (a request's default): no unit.
impl From<f64> for Quantity {
    fn from(value: f64) -> Self {
        Quantity { value, dim: None }
    }
}

/// As written without a unit (the `[default: …]` of `--help`: `3.0`, as a number's `Debug`).
impl std::fmt::Display for Quantity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}", self.value)
    }
}

impl Quantity {
    /// The value of the keyword `name` (as a front end spells it: `--z-c`, `z_c`), which takes
    /// `want` in SI when `si` (with a probe, `probe` as the front end spells it: `--probe`,
    /// `probe=`), else a dimensionless number.
    ///
    /// # Errors
    /// A message naming `name` for a unit of another dimension, or a unit without a probe.
    pub fn si(self, name: &str, probe: &str, want: Dim, si: bool) -> Result<f64, String> {
        match self.dim {
            Some(d) if d != want => Err(format!(
                "{name}: the unit makes it {}, but {name} takes {}",
                d.name(),
                want.name()
            )),
            Some(_) if !si => Err(format!(
                "{name}: a value with a unit needs {probe} (without one, {name} is \
                 dimensionless: g0 or Ω)"
            )),
            _ => Ok(self.value),
        }
    }
}

#[cfg(test)]
mod tests {

    /// The lanes' extent is the plain one: finite values only, any length, none at all.
    #[test]
    fn extent_is_the_finite_values_min_and_max() {
        for n in [0, 1, 7, 8, 9, 23, 100] {
            let mut v: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
            if n > 3 {
                v[1] = f64::NAN;
                v[2] = f64::INFINITY;
                v[n - 1] = f64::NEG_INFINITY;
            }
            let finite = v.iter().copied().filter(|x| x.is_finite());
            let want = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
            assert_eq!(super::extent(&v), want, "{n}");
        }
    }
    /// The likely unit of a slip is the one that brings the column nearest the middle of its
    /// range; within the range, or for an empty column, nothing is said.
    #[test]
    fn a_unit_slip_names_the_likely_unit() {
        use super::{unit_slip, Dim};
        let w = unit_slip("height", "the span", 3230.0, Dim::Length, (1e-9, 1e-4)).unwrap();
        assert!(
            w.contains("written in nm?") && w.contains("3.230e-6 m"),
            "{w}"
        );
        let w = unit_slip("force", "the span", 36.6, Dim::Force, (2e-11, 2e-6)).unwrap();
        assert!(w.contains("written in nN?"), "{w}");
        let w = unit_slip(
            "frequency_shift",
            "the largest",
            0.08,
            Dim::Frequency,
            (0.3, 1.5e5),
        );
        assert!(w.unwrap().contains("written in kHz?"));
        assert!(unit_slip("height", "the span", 2e-6, Dim::Length, (1e-9, 1e-4)).is_none());
        assert!(unit_slip("height", "the span", 0.0, Dim::Length, (1e-9, 1e-4)).is_none());
        let w = unit_slip("force", "the span", 1e30, Dim::Force, (2e-11, 2e-6)).unwrap();
        assert!(w.ends_with("check its unit"), "{w}");
    }

    use super::{Dim, Quantity};

    #[test]
    fn numbers_read_with_and_without_units() {
        let q = |s: &str| s.parse::<Quantity>().unwrap();
        assert_eq!(
            q("7nm"),
            Quantity {
                value: 7e-9,
                dim: Some(Dim::Length)
            }
        );
        assert_eq!(
            q(" 0.5 nm "),
            Quantity {
                value: 0.5e-9,
                dim: Some(Dim::Length)
            }
        );
        assert_eq!(
            q("-3e-9"),
            Quantity {
                value: -3e-9,
                dim: None
            }
        );
        assert_eq!(q("300kHz").value, 300e3);
        assert_eq!(q("1.2MHz").value, 1.2e6);
        assert_eq!(q("2e1nm").value, 20e-9);
        assert_eq!(q("5µm").value, 5e-6);
        assert!("7 parsecs".parse::<Quantity>().is_err());
        assert!("nm".parse::<Quantity>().is_err());
    }
}
