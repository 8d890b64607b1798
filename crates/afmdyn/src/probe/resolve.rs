//! From the probe file's SI values to the dimensionless parameter set: scales, the mode model, the sample's law and groups, the drive.

use super::*;

impl Probe {
    /// The mapping of the module docs.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn resolve(
        structure: Structure,
        modes: usize,
        beam: Beam,
        q1: f64,
        qs: Option<Vec<f64>>,
        eigen: Option<(Vec<f64>, Vec<f64>)>,
        sample: Sample,
        drive: Drive,
        medium: Option<medium::MediumSpec>,
    ) -> Result<Probe, String> {
        let (a0, freq) = (drive.free_amplitude, drive.frequency);
        let q1_file = q1;
        let g0 = a0;
        // tip-mass ratio α1 of the beam, and for the geometry the time scale and the stiffness
        // unit EI/L³ (with the static stiffness 3EI/L³)
        let (beam_alpha1, geometry) = match beam {
            Beam::Calibrated { alpha1, k, f0, .. } => (alpha1, Err((k, f0))),
            Beam::Geometry { si, .. } => (
                si.tip_mass_ratio(),
                Ok((si.time_scale(), si.stiffness_unit())),
            ),
        };
        let alpha1 = match structure {
            Structure::Beam => beam_alpha1,
            Structure::PointMass | Structure::Eigenmodes => 0.0,
        };
        // the eigenmode model's modes relative to mode 1
        let eigenmodes = eigen.as_ref().map(|(k, f)| {
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
        // undamped structure without drive or sample: ω̃₁ and k̃₁
        let bare = Params {
            modes,
            alpha1,
            alpha2: 0.0,
            alpha3: 0.0,
            alpha4: 0.0,
            alpha5: 1.0,
            alpha6: 0.0,
            omega: 1.0,
            contact_law: ContactLaw::Linear,
            structure,
            damping_profile: None,
            eigenmodes,
            drive_components: [None; MAX_DRIVE_COMPONENTS],
            excitation: drive.excitation,
            hydrodynamic: None,
        };
        let (w1, x1, k1) = first_mode(&bare).map_err(|e| e.to_string())?;
        // k and f0, given or from the geometry (first mode of the beam with its tip mass; the
        // point mass takes the first mode of a 6-mode beam)
        let (k, f0, static_k) = match geometry {
            Err((k, f0)) => (k, f0, 0.0),
            Ok((ts, unit)) => {
                let (bw1, _, bk1) = first_mode(&Params {
                    structure: Structure::Beam,
                    modes: if structure == Structure::Beam {
                        modes
                    } else {
                        6
                    },
                    alpha1: beam_alpha1,
                    ..bare
                })
                .map_err(|e| e.to_string())?;
                (bk1 * unit, bw1 / (TAU * ts), 3.0 * unit)
            }
        };
        // the static stiffness: the point mass's is its spring k; the beam's 3EI/L³, from the
        // geometry or from a calibrated k through the modal stiffness k = k̃₁ EI/L³ (issue 42:
        // it was reported as 0 whenever k was given)
        let static_k = match structure {
            Structure::PointMass => k,
            // the modes' springs in series at the tip (each takes the static force)
            Structure::Eigenmodes => {
                let compliance: f64 =
                    eigenmodes.map_or(1.0, |e| (0..modes).map(|j| 1.0 / e.stiffness[j]).sum());
                k / compliance
            }
            Structure::Beam if geometry.is_ok() => static_k,
            Structure::Beam => 3.0 * k / k1,
        };
        // [medium]: the lever's f₀ and Q in vacuum (medium.rs); the eigenmode model's
        // frequency ratios with them
        let (f0_model, q1_model, qs_model, eigenmodes, vacuum) = match &medium {
            None => (f0, q1, qs.clone(), eigenmodes, None),
            Some(spec) => {
                let (w1_k1, ratios) = if structure == Structure::Beam {
                    let g = Galerkin::new(&bare).map_err(|e| e.to_string())?;
                    let om = crate::eigen::natural_modes(g.region(Region::Free)).omega;
                    (w1 * w1 / k1, om.iter().map(|w| w / om[0]).collect())
                } else {
                    (4.0, vec![1.0])
                };
                let eigen_f = eigen.as_ref().map(|(_, f)| f.as_slice());
                let v = medium::to_vacuum(
                    spec,
                    &beam,
                    k,
                    f0,
                    q1,
                    qs.as_deref(),
                    eigen_f,
                    w1_k1,
                    &ratios,
                )?;
                let eigenmodes = eigenmodes.map(|mut e| {
                    if let Some(fv) = &v.eigen_frequencies {
                        for (j, f) in fv.iter().enumerate() {
                            e.frequency[j] = f / fv[0];
                        }
                    }
                    e
                });
                (v.f0, v.q1, v.qs.clone(), eigenmodes, Some(v))
            }
        };
        let time_s = w1 / (TAU * f0_model);
        let force_n = k * g0 / k1;
        let scales = Scales {
            length_m: g0,
            time_s,
            force_n,
        };
        // damping: profile from per-mode Q, then α3 from Q1
        let (q1, qs_given) = (q1_model, qs);
        let profile = match (&qs_model, structure) {
            // C_jj = m_j ω_j / Q_j = α3 s_j with α3 = 1/Q₁ (mode 1's m and ω are 1)
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
        };
        let with_profile = Params {
            damping_profile: profile,
            eigenmodes,
            ..bare
        };
        let alpha3 =
            crate::eigen::beam_damping_for_q(w1, &x1, q1, profile.as_ref().map(|s| &s[..]));
        // sample groups
        // the law's groups and α4, α6 from the sample's SI values ([`Law::from_si`])
        let kind: crate::contact::LawKind = sample.law.parse()?;
        let si = crate::contact::SampleSi {
            g0,
            force: force_n,
            time: time_s,
            e_star: sample.e_star,
            radius: sample.radius,
            hamaker: sample.hamaker,
            a0: sample.a0,
            viscosity: sample.viscosity,
            stiffness: sample.stiffness,
            damping: sample.damping,
            restitution: sample.restitution,
            voltage: sample.voltage,
            adhesion_energy: sample.adhesion_energy,
            meniscus: sample.meniscus,
            maxwell: sample.maxwell,
        };
        let (law, alpha4, alpha6) = kind.from_si(&si)?;
        let work = match (sample.law.as_str(), sample.adhesion_energy, sample.hamaker) {
            ("jkr", Some(w), _) => Some(w),
            ("dmt" | "electrostatic", _, Some(h)) if h > 0.0 => {
                Some(work_of_adhesion(h, sample.a0.unwrap_or(f64::NAN)))
            }
            _ => None,
        };
        let tabor_parameter = work.map(|w| {
            tabor_parameter(
                sample.radius.unwrap_or(0.0),
                sample.e_star.unwrap_or(f64::NAN),
                w,
                sample.a0.unwrap_or(DEFAULT_INTERMOLECULAR_DISTANCE),
            )
        });
        let z_c_in_file = sample.z_c.is_some();
        let z_c = sample.z_c.unwrap_or(a0);
        let mut params = Params {
            alpha3,
            alpha4,
            alpha6,
            contact_law: law,
            alpha2: 1.0,
            ..with_profile
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
        let drive_hz = freq.unwrap_or(medium_report.as_ref().map_or(f0, |m| m.resonance_frequency));
        params.omega = scales.omega(drive_hz);
        params.alpha5 = params.alpha5_for_rest_distance(z_c / g0);
        // drive amplitude: free tip amplitude A0 (= 1 in units of g0) at Ω; off resonance the
        // modulation amplitude A_m = g0 itself
        params.alpha2 = if drive.off_resonance {
            1.0
        } else {
            let unit_response = CantileverModel::new(&params)
                .map_err(|e| derived(e.to_string()))?
                .free_tip_response()
                .map_err(|e| derived(e.to_string()))?
                .norm();
            1.0 / unit_response
        };
        let components =
            Self::resolve_components(&mut params, &drive.components, drive_hz, &scales)?;
        params
            .validate_fields()
            .map_err(|e| derived(e.to_string()))?;
        Ok(Probe {
            params,
            scales,
            calibration: Calibration {
                spring_constant: k,
                resonance_frequency: f0,
                quality_factor: q1_file,
                quality_factors: qs_given,
                tip_mass_ratio: alpha1,
                static_spring_constant: static_k,
            },
            free_amplitude: a0,
            drive_frequency: drive_hz,
            components,
            z_c,
            z_c_in_file,
            medium: medium_report,
            tabor_parameter,
            input_warnings: vacuum.as_ref().map_or(Vec::new(), |v| v.warnings.clone()),
            tip_radius: sample.radius.filter(|_| {
                matches!(
                    sample.law.as_str(),
                    "hertz" | "dmt" | "electrostatic" | "jkr" | "capillary"
                )
            }),
            off_resonance: drive.off_resonance,
            sample_inputs: SampleInputs {
                youngs_modulus: sample.elastic.map(|e| e[0]),
                poisson_ratio: sample.elastic.map(|e| e[1]),
                tip_youngs_modulus: sample.elastic.map(|e| e[2]),
                tip_poisson_ratio: sample.elastic.map(|e| e[3]),
                radius: sample.radius,
                adhesion_energy: sample.adhesion_energy,
                hamaker: sample.hamaker,
                intermolecular_distance: sample.a0,
                stiffness: sample.stiffness,
                maxwell_stiffness: sample.maxwell.map(|m| m.0),
                relaxation_time: sample.maxwell.map(|m| m.1),
            },
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
