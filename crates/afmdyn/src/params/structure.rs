//! The structural model of the cantilever: the paper's beam, the point mass, the eigenmodes.

use super::*;

/// The modes of the eigenmode model ([`Structure::Eigenmodes`]): stiffness at the tip and
/// natural frequency of each mode relative to mode 1's (k_j/k_1, ω_j/ω_1; entry 0 is 1, only
/// the first N entries are used). Their quality factors are the damping profile's
/// ([`Params::damping_profile`], set by [`crate::probe`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Eigenmodes {
    /// k_j/k_1.
    pub stiffness: [f64; 20],
    /// ω_j/ω_1.
    pub frequency: [f64; 20],
}

impl Eigenmodes {
    /// The modal mass of mode j in the model's units (k_1 and ω_1 of 1): (k_j/k_1)/(ω_j/ω_1)².
    pub(crate) fn mass(&self, j: usize) -> f64 {
        self.stiffness[j] / (self.frequency[j] * self.frequency[j])
    }
}

/// The structural model of the cantilever.
///
/// * `Beam` — the paper: N clamped–free Galerkin modes with a tip mass α1, driven by the base
///   displacement α2 sin Ωτ (eqs. 8–18); V_T = W(1,τ) + α2 sin Ωτ + α5.
/// * `PointMass` — the standard model of the AFM literature (García & Pérez, *Surf. Sci. Rep.*
///   47 (2002) 197, eq. 6; García & San Paulo, *Phys. Rev. B* 60 (1999) 4961): one eigenmode
///   driven by a force at the tip, m z̈ + (m ω₀/Q) ż + k z = F₀ cos ωt + F_ts(d, ḋ), d = z_c + z.
///   In the units τ = ω₀ t and lengths of g₀ (forces of k g₀) it reads
///   z'' + α3 z' + z = α2 cos Ωτ + F_c with α3 = 1/Q, α2 = F₀/(k g₀), Ω = ω/ω₀, and
///   V_T = z + α5 (the base does not move): N = 1, φ(1) = 1, M = 1, K = 1, α1 = 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Structure {
    /// The paper's Euler–Bernoulli beam in N Galerkin modes, base-driven.
    #[default]
    Beam,
    /// One eigenmode with a force drive (the point-mass model).
    PointMass,
    /// N eigenmodes with a force drive, each with its own stiffness k_j, frequency ω_j and
    /// quality factor Q_j at the tip, the tip displacement their sum: the model of the bimodal
    /// AFM literature (Lozano & García, *Phys. Rev. Lett.* 100 (2008) 076102; García & Proksch,
    /// *Eur. Polym. J.* 49 (2013) 1897, eq. 1): (k_j/ω_j²) z_j'' + (k_j/(ω_j Q_j)) z_j' + k_j z_j
    /// = F_drive + F_ts, V_T = Σ z_j + α5. In the units of the point mass (k_1, ω_1 of 1) the
    /// modal masses are (k_j/k_1)/(ω_j/ω_1)² ([`Eigenmodes`]).
    Eigenmodes,
}

impl Structure {
    /// `beam` or `point-mass`.
    pub fn name(self) -> &'static str {
        match self {
            Structure::Beam => "beam",
            Structure::PointMass => "point-mass",
            Structure::Eigenmodes => "eigenmodes",
        }
    }

    /// Whether the model is lumped at the tip (the point mass and the eigenmode model): a force
    /// drive, no beam body, the deflection the tip's everywhere.
    pub fn is_lumped(self) -> bool {
        match self {
            Structure::Beam => false,
            Structure::PointMass | Structure::Eigenmodes => true,
        }
    }
}

impl FromStr for Structure {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().replace('_', "-").as_str() {
            "beam" => Ok(Structure::Beam),
            "point-mass" | "pointmass" => Ok(Structure::PointMass),
            "eigenmodes" => Ok(Structure::Eigenmodes),
            _ => Err(format!(
                "model '{s}': expected beam, point-mass or eigenmodes"
            )),
        }
    }
}
