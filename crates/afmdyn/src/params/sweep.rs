//! The continuous parameters that sweeps and continuation vary.

use super::*;

/// A continuous parameter that sweeps and continuation can vary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum SweepParam {
    /// Ω, drive frequency.
    Omega,
    /// α1, tip-mass ratio.
    Alpha1,
    /// α2, drive amplitude.
    Alpha2,
    /// α3, beam damping.
    Alpha3,
    /// α4, contact stiffness.
    Alpha4,
    /// α5, gap.
    Alpha5,
    /// α6, contact damping.
    Alpha6,
}

impl SweepParam {
    /// Canonical name (`omega`, `alpha1` … `alpha6`).
    pub fn name(self) -> &'static str {
        match self {
            SweepParam::Omega => "omega",
            SweepParam::Alpha1 => "alpha1",
            SweepParam::Alpha2 => "alpha2",
            SweepParam::Alpha3 => "alpha3",
            SweepParam::Alpha4 => "alpha4",
            SweepParam::Alpha5 => "alpha5",
            SweepParam::Alpha6 => "alpha6",
        }
    }

    /// Paper symbol (Ω, α1 … α6).
    pub fn symbol(self) -> &'static str {
        match self {
            SweepParam::Omega => "Ω",
            SweepParam::Alpha1 => "α1",
            SweepParam::Alpha2 => "α2",
            SweepParam::Alpha3 => "α3",
            SweepParam::Alpha4 => "α4",
            SweepParam::Alpha5 => "α5",
            SweepParam::Alpha6 => "α6",
        }
    }
}

impl fmt::Display for SweepParam {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SweepParam {
    type Err = String;
    /// Accepts `omega`, `alpha1`…`alpha6` and the descriptive names (`tip-mass-ratio`,
    /// `drive-amplitude`, `beam-damping`, `contact-stiffness`, `gap`, `contact-damping`), with `-` or `_`.
    fn from_str(s: &str) -> Result<Self, String> {
        let k = s.trim().to_ascii_lowercase().replace('_', "-");
        Ok(match k.as_str() {
            "omega" | "Ω" => SweepParam::Omega,
            "alpha1" | "tip-mass-ratio" => SweepParam::Alpha1,
            "alpha2" | "drive-amplitude" => SweepParam::Alpha2,
            "alpha3" | "beam-damping" => SweepParam::Alpha3,
            "alpha4" | "contact-stiffness" => SweepParam::Alpha4,
            "alpha5" | "gap" => SweepParam::Alpha5,
            "alpha6" | "contact-damping" => SweepParam::Alpha6,
            _ => {
                return Err(format!(
                    "unknown parameter '{s}': expected omega, alpha1..alpha6 or tip-mass-ratio, \
                     drive-amplitude, beam-damping, contact-stiffness, gap, contact-damping"
                ))
            }
        })
    }
}
