//! The one declaration of every SI input's ranges (`SI_RANGES`), by its probe key: the
//! physical range, outside which a value is refused, and the typical range of AFM probes and
//! samples, outside which it is accepted with a warning naming the likely unit slip. The probe
//! reader, the FM request and the Sader–Jarvis reconstruction (whose constants are the probe's
//! quantities: amplitude, resonance frequency, spring constant) all read it, so a range is
//! written once and means the same on every front end.
//!
//! Sources of the typical ranges: tip radii 1 nm–50 µm (sharp tips to colloidal probes); free
//! amplitudes 10 pm–1 µm (qPlus FM at small amplitude to large tapping); spring constants
//! 0.005–1e6 N/m (soft contact levers, qPlus sensors at 1.8 kN/m, length-extension
//! resonators at 540 kN/m); resonances 1 kHz–10 MHz;
//! Hamaker constants 1e-21–5e-19 J (Israelachvili, *Intermolecular and Surface Forces*, 3rd ed.
//! 2011, table 13.2: 0.4e-20 J for hydrocarbons in water to 40e-20 J for metals); surface
//! tensions 0.01–0.6 N/m (CRC Handbook, 97th ed.: the highest liquid at room temperature is
//! mercury, 0.485 N/m); works of adhesion 1e-3–1 J/m² (polymers 0.03–0.1 J/m², water on silica
//! 0.14 J/m², clean metals up to ~3 J/m²: Israelachvili 2011, ch. 13 and 17); lever lengths
//! 5 µm–1 mm; lock-in time constants 1 µs–0.1 s (the PI scan's `time_constant`, section
//! `feedback`: a quarter of the lever's amplitude time 2Q/ω₀, 8 µs for a Q = 2 lever at 20 kHz
//! in liquid, 0.1 ms for a tapping lever, 26 ms for Q = 10⁵ in vacuum; SR830 and HF2 lock-ins
//! offer 1 µs to 30 ks, and no image waits 1 000 s per pixel).

/// Largest |SI distance| (m) of a tip–sample rest distance or an approach range: 100 µm.
/// Tapping-mode distances are nanometres; a value beyond this is a length meant in nm but
/// written in m (1e9 too large), refused with that hint before it becomes a gap α5 the user
/// never wrote (issues 27 and 28). The physical range of `[sample] z_c` ([`SI_RANGES`]) and of
/// the requests' distances ([`crate::request::limits::si_distance`]).
pub(crate) const MAX_SI_DISTANCE: f64 = 1e-4;

/// A bound of a physical range: the value beyond which a value is refused, and the refusal's
/// words (`{x}` stands for the value as given).
pub type Bound = (f64, &'static str);

/// The ranges of one SI input (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SiRange {
    /// The probe file's `[section]`s holding the keys.
    pub sections: &'static [&'static str],
    /// Its keys in the section (more than one where they share the ranges).
    pub keys: &'static [&'static str],
    /// Its SI unit.
    pub unit: &'static str,
    /// The prefixes a value outside the typical range may have been meant in, with their
    /// factors (`("k", 1e3)`): the warning names the one that brings it into the range.
    pub slips: &'static [(&'static str, f64)],
    /// Refused below this.
    pub below: Option<Bound>,
    /// Refused above this.
    pub above: Option<Bound>,
    /// The range compares |x| (a signed distance).
    pub magnitude: bool,
    /// The typical range [lo, hi] (a warning outside it), its words and the unit reminder;
    /// zero counts as typical when `zero_typical` (no Hamaker attraction at all).
    pub typical: Option<(f64, f64, &'static str, &'static str)>,
    /// Zero is typical (a term switched off).
    pub zero_typical: bool,
}

/// Every SI input with a physical or typical range beyond its sign (module doc).
pub(crate) const SI_RANGES: &[SiRange] = &[
    SiRange {
        sections: &["tip"],
        keys: &["radius"],
        unit: "m",
        slips: &[("n", 1e-9), ("µ", 1e-6)],
        // a continuum tip is at least an atom across (issue 77: R = 1e-308 m was accepted and
        // read a DMT modulus of 1e149 Pa)
        below: Some((1e-10, "below 0.1 nm, smaller than an atom: no continuum tip; probe files are in metres: 10 nm is 10e-9")),
        above: Some((1e-4, "longer than 100 µm for a tip radius; probe files are in metres: {x} nm is {x}e-9")),
        typical: Some((1e-9, 5e-5, "1 nm–50 µm of tips and colloidal probes", "radii are in m (10 nm is 10e-9)")),
        ..SiRange::NONE
    },
    SiRange {
        // an indenter's angle (contact::indenter): the half angles of AFM cones and pyramids
        // are about 10–45° (nanite's default cone, 25°); a value in radians reads as < 1.6°
        sections: &["tip"],
        keys: &["half_angle", "face_angle"],
        unit: "degree",
        below: Some((0.0, "must be in (0, 90) degrees")),
        above: Some((90.0, "must be in (0, 90) degrees")),
        typical: Some((10.0, 45.0, "10–45° of AFM cones and pyramids", "angles are in degrees, not radians (25° is 25, not 0.436)")),
        ..SiRange::NONE
    },
    SiRange {
        sections: &["drive"],
        keys: &["free_amplitude"],
        unit: "m",
        slips: &[("n", 1e-9), ("p", 1e-12), ("µ", 1e-6)],
        below: Some((1e-12, "below 1 pm, under the lever's thermal motion (probe files are in metres: 10 nm is 10e-9)")),
        // lengths are in units of A₀: beyond 10 µm (a thousand times the tapping-mode amplitudes)
        // every tip–sample length vanishes against it (A₀ = 1 m ran for minutes; issue 27)
        above: Some((1e-5, "must be ≤ 1e-5 m (10 µm; tapping-mode amplitudes are nanometres)")),
        typical: Some((1e-11, 1e-6, "10 pm–1 µm of dynamic AFM", "amplitudes are in m (10 nm is 10e-9)")),
        ..SiRange::NONE
    },
    SiRange {
        // off-resonance (PeakForce) tapping: the z-modulation's frequency, 0.25–8 kHz on
        // commercial instruments (Bruker PeakForce, JPK QI, Asylum FFV)
        sections: &["drive"],
        keys: &["modulation_frequency"],
        unit: "Hz",
        slips: &[("k", 1e3)],
        below: Some((1.0, "below 1 Hz for an off-resonance modulation; frequencies are in Hz: {x} kHz is {x}e3")),
        above: Some((1e6, "above 1 MHz, not off resonance for any lever; frequencies are in Hz")),
        typical: Some((100.0, 1e4, "0.1–10 kHz of off-resonance tapping", "frequencies are in Hz (2 kHz is 2e3)")),
        ..SiRange::NONE
    },
    SiRange {
        // the z-modulation's amplitude, 10–300 nm on commercial instruments
        sections: &["drive"],
        keys: &["modulation_amplitude"],
        unit: "m",
        slips: &[("n", 1e-9), ("µ", 1e-6)],
        below: Some((1e-10, "below 0.1 nm for an off-resonance modulation (probe files are in metres: 100 nm is 100e-9)")),
        above: Some((1e-5, "must be ≤ 1e-5 m (10 µm; off-resonance modulations are 10–300 nm)")),
        typical: Some((5e-9, 5e-7, "5–500 nm of off-resonance tapping", "amplitudes are in m (100 nm is 100e-9)")),
        ..SiRange::NONE
    },
    SiRange {
        sections: &["sample"],
        keys: &["intermolecular_distance"],
        unit: "m",
        above: Some((1e-6, "longer than 1 µm for a₀ (0.165e-9 m typical); probe files are in metres: {x} nm is {x}e-9")),
        ..SiRange::NONE
    },
    SiRange {
        sections: &["sample"],
        keys: &["z_c"],
        unit: "m",
        above: Some((MAX_SI_DISTANCE, "longer than 100 µm for a rest distance; probe files are in metres: {x} nm is {x}e-9")),
        magnitude: true,
        ..SiRange::NONE
    },
    SiRange {
        sections: &["cantilever"],
        keys: &["length"],
        unit: "m",
        slips: &[("µ", 1e-6), ("m", 1e-3)],
        above: Some((1e-2, "longer than 1 cm for a cantilever; probe files are in metres: {x} µm is {x}e-6")),
        typical: Some((5e-6, 1e-3, "5 µm–1 mm of AFM levers", "lengths are in m (125 µm is 125e-6)")),
        ..SiRange::NONE
    },
    SiRange {
        sections: &["cantilever"],
        keys: &["width", "thickness"],
        unit: "m",
        above: Some((1e-2, "longer than 1 cm for a cantilever; probe files are in metres: {x} µm is {x}e-6")),
        ..SiRange::NONE
    },
    SiRange {
        sections: &["tip"],
        keys: &["youngs_modulus"],
        unit: "Pa",
        below: Some((1e6, "below 1 MPa for a tip; moduli are in Pa: {x} GPa is {x}e9")),
        ..SiRange::NONE
    },
    SiRange {
        sections: &["sample"],
        keys: &["youngs_modulus"],
        unit: "Pa",
        // hydrogels, brain tissue and cells reach 10 Pa and below (issue 77: two gel curves that
        // nanite fits at 56 and 73 Pa were held at a bound of 100 Pa)
        below: Some((1.0, "below 1 Pa (softer than the softest gels); moduli are in Pa: {x} MPa is {x}e6, {x} GPa is {x}e9")),
        typical: Some((10.0, 1.2e12, "10 Pa–1.2 TPa of soft gels to diamond", "moduli are in Pa (4 GPa is 4e9)")),
        ..SiRange::NONE
    },
    SiRange {
        // the lever's resonance and the drive's frequency: the same range
        sections: &["cantilever", "drive"],
        keys: &["resonance_frequency", "frequency"],
        unit: "Hz",
        slips: &[("k", 1e3), ("M", 1e6)],
        below: Some((1e3, "below 1 kHz for a cantilever; frequencies are in Hz: {x} kHz is {x}e3")),
        above: Some((1e10, "above 10 GHz, beyond any cantilever; frequencies are in Hz")),
        typical: Some((1e3, 1e7, "1 kHz–10 MHz of AFM levers", "frequencies are in Hz (300 kHz is 300e3)")),
        ..SiRange::NONE
    },
    SiRange {
        sections: &["cantilever"],
        keys: &["spring_constant"],
        unit: "N/m",
        slips: &[("m", 1e-3), ("k", 1e3)],
        below: Some((1e-6, "below 1 µN/m, softer than any lever; spring constants are in N/m")),
        above: Some((1e9, "above 1e9 N/m, stiffer than any sensor; spring constants are in N/m: {x} mN/m is {x}e-3")),
        typical: Some((5e-3, 1e6, "0.005–1e6 N/m of AFM levers, qPlus sensors and length-extension resonators", "stiffnesses are in N/m (40 N/m is 40.0)")),
        ..SiRange::NONE
    },
    SiRange {
        sections: &["sample"],
        keys: &["hamaker"],
        unit: "J",
        above: Some((1e-17, "above 1e-17 J (Hamaker constants are ~1e-20 J); in J: {x}e-20")),
        typical: Some((1e-21, 5e-19, "1e-21–5e-19 J of Hamaker constants", "they are in J (6.6e-20 J for polystyrene)")),
        zero_typical: true,
        ..SiRange::NONE
    },
    SiRange {
        sections: &["sample"],
        keys: &["surface_tension"],
        unit: "N/m",
        slips: &[("m", 1e-3)],
        above: Some((1.0, "above 1 N/m, beyond any liquid (water 0.072 N/m, mercury 0.485 N/m); surface tensions are in N/m: {x} mN/m is {x}e-3")),
        typical: Some((0.01, 0.6, "0.01–0.6 N/m of liquids", "surface tensions are in N/m (water 0.072 N/m is 72e-3)")),
        ..SiRange::NONE
    },
    SiRange {
        sections: &["sample"],
        keys: &["adhesion_energy"],
        unit: "J/m²",
        slips: &[("m", 1e-3)],
        above: Some((10.0, "above 10 J/m², beyond any solid's work of adhesion (polymers 0.03–0.1 J/m², metals up to ~3 J/m²); in J/m²: {x} mJ/m² is {x}e-3")),
        typical: Some((1e-3, 1.0, "1e-3–1 J/m² of works of adhesion", "they are in J/m² (50 mJ/m² is 50e-3)")),
        ..SiRange::NONE
    },
    SiRange {
        sections: &["feedback"],
        keys: &["time_constant"],
        unit: "s",
        slips: &[("µ", 1e-6), ("m", 1e-3)],
        above: Some((1e3, "above 1000 s for a lock-in's time constant (an imaging lock-in's is µs to ms); time constants are in s: {x} µs is {x}e-6")),
        typical: Some((1e-6, 0.1, "1 µs–0.1 s of imaging lock-ins", "time constants are in s (100 µs is 100e-6)")),
        zero_typical: true,
        ..SiRange::NONE
    },
];

/// The ranges of `[section].key`, if it has any beyond its sign.
pub(crate) fn si_range(section: &str, key: &str) -> Option<&'static SiRange> {
    SI_RANGES
        .iter()
        .find(|r| r.sections.contains(&section) && r.keys.contains(&key))
}

impl SiRange {
    /// The fields an entry of [`SI_RANGES`] leaves out: no slips, no physical or typical range,
    /// the signed value compared, zero not typical.
    const NONE: SiRange = SiRange {
        sections: &[],
        keys: &[],
        unit: "",
        slips: &[],
        below: None,
        above: None,
        magnitude: false,
        typical: None,
        zero_typical: false,
    };

    /// Why `x` is refused (outside the physical range: a unit slip rather than a measurement),
    /// or `None`.
    pub(crate) fn refusal(&self, x: f64) -> Option<String> {
        let v = if self.magnitude { x.abs() } else { x };
        let words = match (self.below, self.above) {
            (Some((lo, w)), _) if v < lo => w,
            (_, Some((hi, w))) if v > hi => w,
            _ => return None,
        };
        // the value as the refusal names it: at most 6 significant digits (1e300, not 301 digits)
        Some(words.replace("{x}", &crate::error::number(x)))
    }

    /// The warning's words for `x` outside the typical range (`outside the typical …: …`):
    /// the prefix it was likely meant in, when one of [`SiRange::slips`] brings it into the
    /// range (`was it meant in kHz? (300 kHz is 300000 Hz)`), else the unit reminder; `None`
    /// inside the typical range.
    pub(crate) fn warning(&self, x: f64) -> Option<String> {
        let (lo, hi, range, reminder) = self.typical?;
        if (self.zero_typical && x == 0.0) || (lo..=hi).contains(&x) {
            return None;
        }
        let unit = self.unit;
        let meant = self
            .slips
            .iter()
            .find(|(_, f)| (lo..=hi).contains(&(x * f)));
        Some(match meant {
            Some((prefix, f)) => warning!(
                "probe.unit-slip",
                "Write the value in SI units (the probe reader takes SI), or keep it if \
                 it is meant.",
                "outside the typical {range}: was it meant in {prefix}{unit}? ({} {prefix}{unit} \
                 is {} {unit})",
                crate::error::number(x),
                crate::error::number(x * f)
            ),
            None => warning!(
                "probe.atypical",
                "Check the value and its unit (SI); keep it if it is meant.",
                "outside the typical {range}: {reminder}"
            ),
        })
    }
}

/// Why `[section].key = x` is refused (`SiRange::refusal`), if it is.
pub fn refusal(section: &str, key: &str, x: f64) -> Option<String> {
    si_range(section, key)?.refusal(x)
}

/// [`refusal`] as the error of an option `name` given `x` (in the range's unit).
///
/// # Errors
/// [`crate::SimError::OutOfRange`] naming `name`, where `x` is outside the physical range.
pub(crate) fn refuse(
    name: &'static str,
    (section, key): (&str, &str),
    x: f64,
) -> Result<(), crate::SimError> {
    let Some(r) = si_range(section, key) else {
        return Ok(());
    };
    let value = || format!("{} {}", crate::error::number(x), r.unit);
    r.refusal(x).map_or(Ok(()), |why| {
        Err(crate::SimError::out_of_range(name, value(), why))
    })
}

/// The warning of an option `name` given `x` outside the typical range of `[section].key`
/// (`name = x unit is outside the typical …`, [`SiRange::warning`]), if any.
pub(crate) fn warn(name: &str, (section, key): (&str, &str), x: f64) -> Option<String> {
    let r = si_range(section, key)?;
    let why = r.warning(x)?;
    Some(format!(
        "{name} = {} {} is {why}",
        crate::error::number(x),
        r.unit
    ))
}

/// The typical-range warning of `[section].key = x` ([`SiRange::warning`]), if any.
pub(crate) fn warning(section: &str, key: &str, x: f64) -> Option<String> {
    si_range(section, key)?.warning(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every declared range is a range: lo < hi, typical inside physical.
    #[test]
    fn ranges_are_ordered_and_nested() {
        for r in SI_RANGES {
            let lo = r.below.map_or(f64::NEG_INFINITY, |b| b.0);
            let hi = r.above.map_or(f64::INFINITY, |b| b.0);
            assert!(lo < hi, "{:?}.{:?}", r.sections, r.keys);
            if let Some((tl, th, _, _)) = r.typical {
                assert!(
                    lo <= tl && tl < th && th <= hi,
                    "{:?}.{:?}",
                    r.sections,
                    r.keys
                );
            }
        }
    }

    /// The slips of issue 60 §A2: a 10 m amplitude and a 300 Hz resonance are refused, 72 N/m
    /// of surface tension is refused, 0.5 N/m is typical and 0.9 N/m warned.
    #[test]
    fn the_unit_slips_are_refused_or_warned() {
        assert!(refusal("drive", "free_amplitude", 10.0).is_some());
        assert!(refusal("cantilever", "resonance_frequency", 300.0).is_some());
        assert!(refusal("sample", "surface_tension", 72.0).is_some());
        assert!(warning("sample", "surface_tension", 0.5).is_none());
        assert!(warning("sample", "surface_tension", 0.9).is_some());
        assert!(warning("sample", "hamaker", 0.0).is_none());
        assert!(refusal("sample", "z_c", -2e-4).is_some());
        // issue 60 D: the PI scan's lock-in time constant of 1e300 s is refused, 100 (meant
        // in µs) warned naming µs, 0 (no filter) and 0.1 ms typical
        assert!(refusal("feedback", "time_constant", 1e300).is_some());
        assert!(refusal("feedback", "time_constant", 1e3).is_none());
        let why = warning("feedback", "time_constant", 100.0).unwrap();
        assert!(why.contains("µs"), "{why}");
        assert!(warning("feedback", "time_constant", 0.0).is_none());
        assert!(warning("feedback", "time_constant", 1e-4).is_none());
    }

    /// Issue 60: a refusal names the value with at most 6 significant digits (1e300 was
    /// written out in 301 digits).
    #[test]
    fn a_refusal_names_the_value_briefly() {
        let why = refusal("cantilever", "spring_constant", 1e300).unwrap();
        assert!(why.contains(": 1e300 mN/m is 1e300e-3"), "{why}");
        let why = refusal("cantilever", "spring_constant", 1.234567891e10).unwrap();
        assert!(why.contains(": 12345700000 mN/m"), "{why}");
    }
}
