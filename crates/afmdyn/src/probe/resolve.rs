//! From the probe file's SI values to the dimensionless parameter set: scales, the mode model, the sample's law and groups, the drive.

use super::*;

impl Probe {
    /// The mapping of the module docs: the structure's first mode and the calibration, the
    /// lever in vacuum (with `[medium]`), the scales, the damping, the sample's groups, the
    /// fluid's loading and the drive.
    pub(super) fn resolve(
        structure: Structure,
        modes: usize,
        cantilever: Cantilever,
        sample: Sample,
        drive: Drive,
        medium: Option<medium::MediumSpec>,
    ) -> Result<Probe, String> {
        let g0 = drive.free_amplitude;
        let bare = cantilever.bare(structure, modes, drive.excitation);
        let (w1, x1, k1) = first_mode(&bare).map_err(|e| e.to_string())?;
        let calibration = cantilever.calibration(&bare, k1)?;
        // [medium]: the lever's f₀ and Q in vacuum (medium.rs), which the model takes
        let vacuum = match &medium {
            None => None,
            Some(spec) => Some(cantilever.to_vacuum(spec, &calibration, &bare, w1 * w1 / k1)?),
        };
        let (f0_model, q1, qs) = vacuum.as_ref().map_or(
            (
                calibration.resonance_frequency,
                calibration.quality_factor,
                &calibration.quality_factors,
            ),
            |v| (v.f0, v.q1, &v.qs),
        );
        let time_s = w1 / (TAU * f0_model);
        let scales = Scales {
            length_m: g0,
            time_s,
            force_n: calibration.spring_constant * g0 / k1,
        };
        // the eigenmode model's frequency ratios in vacuum
        let eigenmodes = bare
            .eigenmodes
            .map(|e| vacuum.as_ref().map_or(e, |v| v.ratios(e)));
        let profile = damping_profile(structure, eigenmodes, q1, qs.as_deref());
        let (law, alpha4, alpha6) = sample.groups(&scales)?;
        let mut params = Params {
            alpha3: crate::eigen::beam_damping_for_q(w1, &x1, q1, profile.as_ref().map(|s| &s[..])),
            alpha4,
            alpha6,
            contact_law: law,
            alpha2: 1.0,
            damping_profile: profile,
            eigenmodes,
            ..bare
        };
        // the fluid's loading of every mode; the drive then defaults to the first mode's
        // natural frequency in the fluid (f₀ without one)
        // laws of a gas: a meniscus does not form under a liquid, and the electrostatic law is
        // the force across vacuum (ε₀), not across a polar, screening liquid
        let liquid = medium.as_ref().is_some_and(|m| m.is_liquid());
        if let Some(why) = law.not_in_liquid().filter(|_| liquid) {
            return Err(format!(
                "[sample].law = \"{}\" in a liquid [medium]: {why} (use it in air, or another \
                 law)",
                law.name()
            ));
        }
        let medium_report = match (&medium, &vacuum) {
            (Some(spec), Some(v)) => Some(medium::load(spec, v, &mut params, time_s)?),
            _ => None,
        };
        let drive_hz = drive.frequency.unwrap_or(
            medium_report
                .as_ref()
                .map_or(calibration.resonance_frequency, |m| m.resonance_frequency),
        );
        params.omega = scales.omega(drive_hz);
        let z_c = sample.z_c.unwrap_or(g0);
        params.alpha5 = params.alpha5_for_rest_distance(z_c / g0);
        params.alpha2 = drive.alpha2(&params)?;
        let components =
            Self::resolve_components(&mut params, &drive.components, drive_hz, &scales)?;
        params
            .validate_fields()
            .map_err(|e| derived(e.to_string()))?;
        Ok(Probe {
            params,
            scales,
            calibration,
            free_amplitude: g0,
            drive_frequency: drive_hz,
            components,
            z_c,
            z_c_in_file: sample.z_c.is_some(),
            medium: medium_report,
            tabor_parameter: sample.tabor_parameter(),
            input_warnings: vacuum.map_or(Vec::new(), |v| v.warnings),
            tip_radius: sample.tip_radius(),
            off_resonance: drive.off_resonance,
            sample_inputs: sample.inputs(),
            assumed: Vec::new(),
            plan: cantilever.beam.plan(),
        })
    }

    /// The further components of a multifrequency drive ([`Params::drive_components`]): each
    /// at the frequency given, or at its mode's free resonance (mode i + 1 for component i,
    /// the undamped natural frequency of the free structure), its ratio to the first
    /// component's frequency the rational p/q ([`rational_ratio`]), its force F̃ᵢ = A₀ᵢ/|Hᵢ|
    /// from the free amplitude through the free response Hᵢ to a tip force at that frequency
    /// ([`CantileverModel::free_force_response`]), phase θ = 0.
    pub(super) fn resolve_components(
        params: &mut Params,
        given: &[(f64, f64)],
        drive_hz: f64,
        scales: &Scales,
    ) -> Result<Vec<DriveComponentSi>, String> {
        if given.is_empty() {
            return Ok(Vec::new());
        }
        let model = CantileverModel::new(params).map_err(|e| derived(e.to_string()))?;
        let natural = crate::eigen::natural_modes(model.galerkin().region(Region::Free));
        let mut out = Vec::new();
        for (i, &(amp, f)) in given.iter().enumerate() {
            let f = if f.is_nan() {
                let k = i + 1;
                let w = *natural.omega.get(k).ok_or_else(|| {
                    format!(
                        "[drive].frequency: component {} has no mode {} to default to (modes = \
                         {}): give the frequencies",
                        k + 1,
                        k + 1,
                        params.modes
                    )
                })?;
                scales.frequency_hz(w)
            } else {
                f
            };
            let r = f / drive_hz;
            let (p, q) = rational_ratio(r).or_else(|| convergent(r)).ok_or_else(|| {
                format!(
                    "[drive].frequency[{}] = {} Hz: its ratio to the first component's \
                     {} Hz, {}, must be in (0, 1e6)",
                    i + 1,
                    crate::error::number(f),
                    crate::error::number(drive_hz),
                    crate::error::number(r),
                )
            })?;
            // a lock-in at one frequency measures the sum of every component there: two
            // components at one frequency would each be reported with their total amplitude
            let same = (p, q) == (1, 1)
                || out.iter().any(|c: &DriveComponentSi| {
                    u64::from(c.ratio[0]) * u64::from(q) == u64::from(p) * u64::from(c.ratio[1])
                });
            if same {
                return Err(format!(
                    "[drive].frequency[{}] = {} Hz: another component is at this frequency; \
                     a lock-in cannot tell components at one frequency apart, so give them as \
                     one component (their amplitudes added)",
                    i + 1,
                    crate::error::number(f),
                ));
            }
            let ratio = f64::from(p) / f64::from(q);
            let h = model
                .free_force_response(ratio * params.omega)
                .map_err(|e| derived(e.to_string()))?;
            let force = amp / scales.length_m / h.norm();
            params.drive_components[i] = Some(DriveComponent {
                force,
                ratio: [p, q],
                phase: 0.0,
            });
            out.push(DriveComponentSi {
                free_amplitude: amp,
                frequency: drive_hz * ratio,
                ratio: [p, q],
            });
        }
        if out.len() > MAX_DRIVE_COMPONENTS {
            return Err(format!(
                "[drive]: at most {} components",
                1 + MAX_DRIVE_COMPONENTS
            ));
        }
        Ok(out)
    }
}

impl Cantilever {
    /// The undamped structure without drive or sample, whose first mode's ω̃₁ and k̃₁ set the
    /// scales (module docs): the beam's tip-mass ratio, the eigenmode model's modes relative to
    /// mode 1.
    fn bare(&self, structure: Structure, modes: usize, excitation: Excitation) -> Params {
        let alpha1 = match structure {
            Structure::Beam => self.beam.tip_mass_ratio(),
            Structure::PointMass | Structure::Eigenmodes => 0.0,
        };
        let eigenmodes = self.eigen.as_ref().map(|(k, f)| {
            let mut e = crate::params::Eigenmodes {
                stiffness: [1.0; MAX_MODES],
                frequency: [1.0; MAX_MODES],
            };
            for j in 0..k.len() {
                e.stiffness[j] = k[j] / k[0];
                e.frequency[j] = f[j] / f[0];
            }
            e
        });
        Params {
            modes,
            alpha1,
            alpha2: 0.0,
            alpha3: 0.0,
            alpha4: 0.0,
            alpha5: 1.0,
            alpha6: 0.0,
            omega: 1.0,
            structure,
            eigenmodes,
            excitation,
            ..Params::default()
        }
    }

    /// The first-mode calibration of the `bare` structure (k̃₁ its modal stiffness): k and f₀
    /// given, or from the geometry (the first mode of the beam with its tip mass; the point
    /// mass takes the first mode of a 6-mode beam), and the static stiffness.
    fn calibration(&self, bare: &Params, k1: f64) -> Result<Calibration, String> {
        let (k, f0, static_k) = match self.beam {
            Beam::Calibrated { k, f0, .. } => (k, f0, None),
            Beam::Geometry { si, .. } => {
                let (bw1, _, bk1) = first_mode(&Params {
                    structure: Structure::Beam,
                    modes: if bare.structure == Structure::Beam {
                        bare.modes
                    } else {
                        6
                    },
                    alpha1: si.tip_mass_ratio(),
                    ..*bare
                })
                .map_err(|e| e.to_string())?;
                let unit = si.stiffness_unit();
                (bk1 * unit, bw1 / (TAU * si.time_scale()), Some(3.0 * unit))
            }
        };
        // the static stiffness: the point mass's is its spring k; the beam's 3EI/L³, from the
        // geometry or from a calibrated k through the modal stiffness k = k̃₁ EI/L³ (issue 42:
        // it was reported as 0 whenever k was given)
        let static_k = match bare.structure {
            Structure::PointMass => k,
            // the modes' springs in series at the tip (each takes the static force)
            Structure::Eigenmodes => {
                let compliance: f64 = bare
                    .eigenmodes
                    .map_or(1.0, |e| (0..bare.modes).map(|j| 1.0 / e.stiffness[j]).sum());
                k / compliance
            }
            Structure::Beam => static_k.unwrap_or(3.0 * k / k1),
        };
        Ok(Calibration {
            spring_constant: k,
            resonance_frequency: f0,
            quality_factor: self.q1,
            quality_factors: self.qs.clone(),
            tip_mass_ratio: bare.alpha1,
            static_spring_constant: static_k,
        })
    }

    /// The lever's calibration brought to vacuum in the fluid `spec` ([`medium::to_vacuum`]);
    /// `w1_k1` is ω̃₁²/k̃₁ of the `bare` structure's first mode.
    fn to_vacuum(
        &self,
        spec: &medium::MediumSpec,
        calibration: &Calibration,
        bare: &Params,
        w1_k1: f64,
    ) -> Result<medium::Vacuum, String> {
        // the beam's modes' frequencies per unit f₀; the lumped models take the uniform
        // beam's ω̃₁²/k̃₁ = 4
        let (w1_k1, ratios) = if bare.structure == Structure::Beam {
            let g = Galerkin::new(bare).map_err(|e| e.to_string())?;
            let om = crate::eigen::natural_modes(g.region(Region::Free)).omega;
            (w1_k1, om.iter().map(|w| w / om[0]).collect())
        } else {
            (4.0, vec![1.0])
        };
        let eigen_f = self.eigen.as_ref().map(|(_, f)| f.as_slice());
        medium::to_vacuum(spec, &self.beam, calibration, eigen_f, w1_k1, &ratios)
    }
}

/// The damping profile s_j from per-mode quality factors `qs` (module docs; `None` without
/// them): C_jj = m_j ω_j / Q_j = α3 s_j with α3 = 1/Q₁ (mode 1's m and ω are 1) for the
/// eigenmode model, s_j = (β_j²/β₁²)(Q₁/Q_j) for the beam.
fn damping_profile(
    structure: Structure,
    eigenmodes: Option<crate::params::Eigenmodes>,
    q1: f64,
    qs: Option<&[f64]>,
) -> Option<[f64; MAX_MODES]> {
    match (qs, structure) {
        (Some(q), Structure::Eigenmodes) => eigenmodes.map(|e| {
            let mut s = [1.0; MAX_MODES];
            for (j, qj) in q.iter().enumerate() {
                s[j] = e.mass(j) * e.frequency[j] * q1 / qj;
            }
            s
        }),
        (Some(q), Structure::Beam) => {
            let mut s = [1.0; MAX_MODES];
            for (j, qj) in q.iter().enumerate() {
                let bj = crate::beam::beta_root(j + 1).powi(2);
                let b1 = crate::beam::beta_root(1).powi(2);
                s[j] = (bj / b1) * (q1 / qj);
            }
            Some(s)
        }
        _ => None,
    }
}

impl Sample {
    /// The law and its groups, α4 and α6 under the probe's `scales` ([`crate::contact::Law::from_si`]).
    fn groups(&self, scales: &Scales) -> Result<(ContactLaw, f64, f64), String> {
        let kind: crate::contact::LawKind = self.law.parse()?;
        kind.from_si(&crate::contact::SampleSi {
            g0: scales.length_m,
            force: scales.force_n,
            time: scales.time_s,
            ..self.si
        })
    }

    /// The Tabor parameter of a JKR sample, or of a DMT or electrostatic one with a Hamaker
    /// constant (W = H/(12πa₀²)); `None` for the other laws.
    fn tabor_parameter(&self) -> Option<f64> {
        let si = &self.si;
        let work = match (self.law.as_str(), si.adhesion_energy, si.hamaker) {
            ("jkr", Some(w), _) => Some(w),
            ("dmt" | "electrostatic", _, Some(h)) if h > 0.0 => {
                Some(work_of_adhesion(h, si.a0.unwrap_or(f64::NAN)))
            }
            _ => None,
        };
        work.filter(|_| self.shape.has_radius()).map(|w| {
            tabor_parameter(
                si.radius.unwrap_or(0.0),
                si.e_star.unwrap_or(f64::NAN),
                w,
                si.a0.unwrap_or(DEFAULT_INTERMOLECULAR_DISTANCE),
            )
        })
    }

    /// The tip radius of a law whose contact is Hertz's sphere ([`crate::contact::Law::TIP_RADIUS`],
    /// [`Probe::tip_radius`]).
    fn tip_radius(&self) -> Option<f64> {
        let hertz = self.law.parse::<crate::contact::LawKind>();
        self.si
            .radius
            .filter(|_| hertz.is_ok_and(|k| k.info().tip_radius))
            .filter(|_| self.shape == crate::contact::indenter::TipShape::Paraboloid)
    }

    /// The inputs by their probe keys ([`SampleInputs`]).
    fn inputs(&self) -> SampleInputs {
        let si = &self.si;
        SampleInputs {
            youngs_modulus: self.elastic.map(|e| e[0]),
            poisson_ratio: self.elastic.map(|e| e[1]),
            tip_youngs_modulus: self.elastic.map(|e| e[2]),
            tip_poisson_ratio: self.elastic.map(|e| e[3]),
            radius: si.radius.filter(|_| self.shape.has_radius()),
            adhesion_energy: si.adhesion_energy,
            hamaker: si.hamaker,
            intermolecular_distance: si.a0,
            stiffness: si.stiffness,
            maxwell_stiffness: si.maxwell.map(|m| m.0),
            relaxation_time: si.maxwell.map(|m| m.1),
            tip_shape: self.shape,
        }
    }
}

impl Drive {
    /// α2 of the drive: the free tip amplitude A₀ (= 1 in units of g₀) at Ω of `params`,
    /// α2 = 1/|H(Ω)|; off resonance the modulation amplitude A_m = g₀ itself, α2 = 1.
    fn alpha2(&self, params: &Params) -> Result<f64, String> {
        if self.off_resonance {
            return Ok(1.0);
        }
        let unit_response = CantileverModel::new(params)
            .map_err(|e| derived(e.to_string()))?
            .free_tip_response()
            .map_err(|e| derived(e.to_string()))?
            .norm();
        Ok(1.0 / unit_response)
    }
}
