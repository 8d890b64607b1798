//! Reading a probe file's tables ([cantilever], [tip], [sample], [drive], [medium], the plan) into a [`Probe`]'s inputs.

use super::*;

impl Probe {
    /// The probe of a file's table: every section read, every problem collected in `problems`
    /// (in the file's order), then resolved ([`Probe::resolve`]).
    pub(super) fn read(root: &toml::Table, problems: &mut Vec<String>) -> Option<Probe> {
        let mut r = Reader {
            problems,
            warnings: Vec::new(),
        };
        r.unknown(
            root,
            "",
            &[
                "model",
                "modes",
                "cantilever",
                "tip",
                "sample",
                "drive",
                "medium",
            ],
        );
        let structure = Self::read_structure(&mut r, root);
        let modes = Self::read_modes(&mut r, root, structure);
        // [cantilever]
        let cant = r.table(root, "cantilever", true);
        let mut eigen = None;
        let (beam, q1, qs) = match (cant, structure) {
            (Some(c), Some(Structure::Eigenmodes)) => match Self::read_eigenmodes(&mut r, c) {
                Some((k, f, q)) => {
                    let beam = Beam::Calibrated {
                        k: k[0],
                        f0: f[0],
                        alpha1: 0.0,
                        plan: Self::read_plan(&mut r, c),
                    };
                    let q1 = q[0];
                    eigen = Some((k, f));
                    (Some(beam), Some(q1), Some(q))
                }
                None => (None, None, None),
            },
            (Some(c), _) => Self::read_cantilever(&mut r, c),
            (None, _) => (None, None, None),
        };
        // [tip]: a silicon tip where the section omits its elastic constants (the one
        // materials table, crate::units::SILICON_TIP)
        let tip = r.table(root, "tip", false);
        let (radius, shape, tip_e, tip_nu) = tip
            .map_or((None, TipShape::Paraboloid, None, None), |t| {
                Self::read_tip(&mut r, t)
            });
        // [sample]
        let sample = r
            .table(root, "sample", true)
            .and_then(|s| Self::read_sample(&mut r, s, tip, radius, tip_e, tip_nu))
            .map(|s| Sample { shape, ..s });
        let drive = Self::read_drive(&mut r, root, structure);
        // [medium]
        let medium = r
            .table(root, "medium", false)
            .and_then(|t| medium::read(&mut r, t));
        let medium_given = root.contains_key("medium");
        // [cantilever] quality_factors against the model: the point mass has one mode, the
        // others one value per mode (counted as written: an entry refused is still one value)
        if let (Some(Structure::PointMass), Some(_)) = (structure, &qs) {
            r.problems.push(
                "[cantilever].quality_factors: the point-mass model has one mode (use quality_factor)"
                    .into(),
            );
        }
        let written = match cant.and_then(|c| c.get("quality_factors")) {
            Some(toml::Value::Array(a)) => Some(a.len()),
            _ => None,
        };
        if let (Some(n), Some(len)) = (modes, written) {
            if len != n {
                r.problems.push(format!(
                    "[cantilever].quality_factors has {len} values: give one per mode (modes = {n})"
                ));
            }
        }
        if !r.problems.is_empty() || (medium_given && medium.is_none()) {
            return None;
        }
        let cantilever = Cantilever {
            beam: beam?,
            q1: q1?,
            qs,
            eigen,
        };
        match Self::resolve(structure?, modes?, cantilever, sample?, drive?, medium) {
            Ok(p) => Some(Probe {
                input_warnings: [std::mem::take(&mut r.warnings), p.input_warnings.clone()]
                    .concat(),
                ..p
            }),
            Err(e) => {
                r.problems.push(e);
                None
            }
        }
    }

    /// `[tip]`: its radius (m), shape, and elastic constants (Pa, 1), silicon's where the
    /// section omits them (the one materials table, `crate::cantilevers`); a shape without a
    /// radius takes a stand-in radius for the dimensionless groups (warned of where given).
    fn read_tip(
        r: &mut Reader<'_>,
        t: &toml::Table,
    ) -> (Option<f64>, TipShape, Option<f64>, Option<f64>) {
        let keys = [
            "radius",
            "youngs_modulus",
            "poisson_ratio",
            "shape",
            "half_angle",
            "face_angle",
        ];
        r.unknown(t, "tip", &keys);
        let mut radius = r.optional(t, "tip", "radius", "m", POSITIVE);
        let shape = Self::read_shape(r, t);
        if !shape.has_radius() {
            if radius.is_some() {
                r.warnings.push(warning!(
                    "probe.radius-unused",
                    "Remove [tip].radius, or give a shape with a radius.",
                    "[tip].radius is not used by the {} shape (the sharp indenter's force \
                     has no radius)",
                    shape.name()
                ));
            }
            // the dimensionless groups' radius, which no analysis that takes this shape
            // reads (the dynamic ones refuse it: Probe::from_table_for)
            radius = radius.or(Some(SHAPE_STAND_IN_RADIUS));
        }
        let mut tip_e = r.optional(t, "tip", "youngs_modulus", "Pa", POSITIVE);
        let mut tip_nu = r.optional(t, "tip", "poisson_ratio", "1", POISSON);
        if !t.contains_key("youngs_modulus") {
            tip_e = Some(crate::cantilevers::SILICON_YOUNGS_MODULUS);
        }
        if !t.contains_key("poisson_ratio") {
            tip_nu = Some(crate::cantilevers::SILICON_POISSON_RATIO);
        }
        (radius, shape, tip_e, tip_nu)
    }

    /// `[tip] shape` (default the paraboloid) with its angle (degrees): `half_angle` of the
    /// cone and the four-sided pyramid, `face_angle` of the three-sided one
    /// ([`TipShape::angle_key`]); an angle of another shape is a problem.
    fn read_shape(r: &mut Reader<'_>, t: &toml::Table) -> TipShape {
        const S: &str = "tip";
        let angles =
            ["half_angle", "face_angle"].map(|k| (k, r.optional(t, S, k, "degree", ANGLE)));
        let name = match r.string(t, S, "shape") {
            None => "paraboloid".to_string(),
            Some(s) => s.trim().to_ascii_lowercase(),
        };
        let key = TipShape::angle_key(&name);
        let Some(shape) = TipShape::of(&name, f64::NAN) else {
            r.problems.push(format!(
                "[tip].shape = '{name}': expected {}",
                crate::contact::indenter::SHAPES
            ));
            return TipShape::Paraboloid;
        };
        for (k, _) in angles {
            if t.contains_key(k) && key != Some(k) {
                r.problems.push(format!(
                    "[tip].{k}: the {name} shape takes {}",
                    key.map_or("[tip].radius (m)".to_string(), |a| format!(
                        "[tip].{a} (degrees)"
                    ))
                ));
            }
        }
        match key {
            None => shape,
            Some(k) if !t.contains_key(k) => {
                r.problems.push(format!(
                    "missing key [tip].{k} (degrees, needed by the {name} shape)"
                ));
                shape
            }
            Some(k) => {
                let angle = angles.iter().find(|(a, _)| *a == k).and_then(|(_, v)| *v);
                TipShape::of(&name, angle.unwrap_or(f64::NAN)).unwrap_or(shape)
            }
        }
    }

    /// The root's `model`: the structure.
    fn read_structure(r: &mut Reader<'_>, root: &toml::Table) -> Option<Structure> {
        match r.string(root, "", "model") {
            None if !root.contains_key("model") => {
                r.problems
                    .push("missing key model (\"beam\", \"point-mass\" or \"eigenmodes\")".into());
                None
            }
            None => None,
            Some(s) => match s.parse::<Structure>() {
                Ok(x) => Some(x),
                Err(e) => {
                    r.problems.push(e);
                    None
                }
            },
        }
    }

    /// The root's `modes`, N: the beam's as given, the point mass's 1, the eigenmode model's one
    /// per entry of the cantilever's arrays.
    fn read_modes(
        r: &mut Reader<'_>,
        root: &toml::Table,
        structure: Option<Structure>,
    ) -> Option<usize> {
        let modes = match root.get("modes") {
            None => None,
            Some(toml::Value::Integer(i)) if (1..=MAX_MODES as i64).contains(i) => {
                Some(*i as usize)
            }
            Some(v) => {
                r.problems
                    .push(format!("modes = {v}: must be an integer in 1..=20"));
                None
            }
        };
        match (structure, modes) {
            (Some(Structure::PointMass), Some(n)) if n != 1 => {
                r.problems.push(format!(
                    "modes = {n}: the point-mass model has one mode (omit modes)"
                ));
                None
            }
            (Some(Structure::PointMass), _) => Some(1),
            (Some(Structure::Eigenmodes), n) => {
                let len = root
                    .get("cantilever")
                    .and_then(|c| c.get("spring_constant"))
                    .and_then(toml::Value::as_array)
                    .map(Vec::len);
                match (n, len) {
                    (Some(n), Some(len)) if n != len => {
                        r.problems.push(format!(
                            "modes = {n}: the eigenmode model has one mode per entry of \
                             [cantilever].spring_constant ({len}; omit modes)"
                        ));
                        None
                    }
                    (_, Some(len)) if (1..=MAX_MODES).contains(&len) => Some(len),
                    (_, Some(len)) => {
                        r.problems.push(format!(
                            "[cantilever].spring_constant has {len} values: give 1..=20"
                        ));
                        None
                    }
                    (_, None) => None,
                }
            }
            // (a modes key that is present but invalid was reported above)
            (Some(Structure::Beam), None) if !root.contains_key("modes") => {
                r.problems
                    .push("missing key modes (number of Galerkin modes, 1..=20)".into());
                None
            }
            (_, n) => n,
        }
    }

    /// `[drive]`: tapping near resonance (free amplitude and frequency, the excitation), or
    /// off-resonance modulation; `None` when a required value is missing or refused.
    fn read_drive(
        r: &mut Reader<'_>,
        root: &toml::Table,
        structure: Option<Structure>,
    ) -> Option<Drive> {
        let drive = r.table(root, "drive", true);
        let mut excitation = Excitation::Base;
        let off_resonance = drive
            .and_then(|d| d.get("mode"))
            .and_then(toml::Value::as_str)
            .is_some_and(|m| m == "off-resonance");
        let (a0, frequency, components) = match drive {
            Some(d) if off_resonance => {
                r.unknown(
                    d,
                    "drive",
                    &[
                        "mode",
                        "modulation_frequency",
                        "modulation_amplitude",
                        "modulated",
                    ],
                );
                excitation = Excitation::Sample;
                match r.string(d, "drive", "modulated") {
                    None | Some("sample") => {}
                    Some("base") if structure.is_some_and(Structure::is_lumped) => r.problems.push(
                        "[drive].modulated = \"base\": the base's inertial term is modelled \
                             for the beam only; the point-mass and eigenmode models take \
                             modulated = \"sample\" (at f_m ≪ f₀ the two differ by (f_m/f₀)² \
                             of the drive)"
                            .into(),
                    ),
                    Some("base") => excitation = Excitation::Base,
                    Some(m) => r.problems.push(format!(
                        "[drive].modulated = \"{m}\": expected sample (the sample moves, the \
                         default) or base (the lever's base moves)"
                    )),
                }
                (
                    r.required(d, "drive", "modulation_amplitude", "m", POSITIVE),
                    r.required(d, "drive", "modulation_frequency", "Hz", POSITIVE),
                    Vec::new(),
                )
            }
            Some(d) => {
                if let Some(m) = r.string(d, "drive", "mode") {
                    if m != "tapping" {
                        r.problems.push(format!(
                            "[drive].mode = \"{m}\": expected tapping (the default: a drive \
                             near resonance) or off-resonance (PeakForce tapping)"
                        ));
                    }
                }
                r.unknown(
                    d,
                    "drive",
                    &["mode", "free_amplitude", "frequency", "excitation"],
                );
                if let Some(e) = r.string(d, "drive", "excitation") {
                    match e.parse::<Excitation>() {
                        Ok(x) => excitation = x,
                        Err(m) => r.problems.push(format!("[drive].{m}")),
                    }
                }
                Self::read_components(r, d)
            }
            None => (None, None, Vec::new()),
        };
        if excitation == Excitation::Tip && structure.is_some_and(Structure::is_lumped) {
            r.problems.push(
                "[drive].excitation = \"tip\": the point-mass and eigenmode models are always \
                 driven by a force at the tip (omit excitation)"
                    .into(),
            );
        }
        Some(Drive {
            free_amplitude: a0?,
            frequency,
            components,
            excitation,
            off_resonance,
        })
    }

    /// `[drive]`'s components: `free_amplitude` (m) and `frequency` (Hz) as numbers (one component), or as
    /// arrays of equal length (a multifrequency drive, at most 1 + [`MAX_DRIVE_COMPONENTS`]
    /// components; `frequency` may be omitted, each component then at its mode's free
    /// resonance). Returns A₀ and f of the first component and (A₀ᵢ, fᵢ) of the others (fᵢ NaN
    /// where omitted).
    #[allow(clippy::type_complexity)]
    fn read_components(
        r: &mut Reader<'_>,
        d: &toml::Table,
    ) -> (Option<f64>, Option<f64>, Vec<(f64, f64)>) {
        const S: &str = "drive";
        let arrays = matches!(d.get("free_amplitude"), Some(toml::Value::Array(_)))
            || matches!(d.get("frequency"), Some(toml::Value::Array(_)));
        if !arrays {
            return (
                r.required(d, S, "free_amplitude", "m", POSITIVE),
                r.optional(d, S, "frequency", "Hz", POSITIVE),
                Vec::new(),
            );
        }
        let mut array = |key: &str, unit: &str| -> Option<Vec<f64>> {
            let a = match d.get(key) {
                Some(toml::Value::Array(a)) => a,
                _ => {
                    r.problems.push(format!(
                        "[drive].{key} must be an array ({unit}), one value per component, \
                         when the other key is"
                    ));
                    return None;
                }
            };
            if a.is_empty() || a.len() > 1 + MAX_DRIVE_COMPONENTS {
                r.problems.push(format!(
                    "[drive].{key} has {} values: give 1 to {} components",
                    a.len(),
                    1 + MAX_DRIVE_COMPONENTS
                ));
                return None;
            }
            let mut v = Vec::with_capacity(a.len());
            for (i, x) in a.iter().enumerate() {
                match x.as_float().or(x.as_integer().map(|i| i as f64)) {
                    Some(y) if y.is_finite() && y > 0.0 => {
                        let key_i = format!("{key}[{i}]");
                        if let Some(hint) = scale_hint(S, key, y) {
                            r.problems
                                .push(format!("[drive].{key_i} = {y} ({unit}): {hint}"));
                        } else {
                            v.push(y);
                        }
                    }
                    _ => r.problems.push(format!(
                        "[drive].{key}[{i}] = {x} ({unit}): must be finite and > 0"
                    )),
                }
            }
            (v.len() == a.len()).then_some(v)
        };
        let amplitudes = array("free_amplitude", "m");
        let frequencies = if d.contains_key("frequency") {
            array("frequency", "Hz").map(Some)
        } else {
            Some(None)
        };
        let (Some(amplitudes), Some(frequencies)) = (amplitudes, frequencies) else {
            return (None, None, Vec::new());
        };
        if let Some(f) = &frequencies {
            if f.len() != amplitudes.len() {
                r.problems.push(format!(
                    "[drive]: free_amplitude and frequency have {} and {} values: give one of \
                     each per component",
                    amplitudes.len(),
                    f.len()
                ));
                return (None, None, Vec::new());
            }
        }
        let f = |i: usize| frequencies.as_ref().map_or(f64::NAN, |f| f[i]);
        let extra = (1..amplitudes.len())
            .map(|i| (amplitudes[i], f(i)))
            .collect();
        (
            Some(amplitudes[0]),
            frequencies.as_ref().map(|f| f[0]),
            extra,
        )
    }

    /// The eigenmode model's `[cantilever]`: `spring_constant`, `resonance_frequency` and
    /// `quality_factor` as arrays of equal length, one entry per mode (N/m, Hz, 1), the
    /// frequencies increasing.
    #[allow(clippy::type_complexity)]
    pub(super) fn read_eigenmodes(
        r: &mut Reader<'_>,
        c: &toml::Table,
    ) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        const S: &str = "cantilever";
        r.unknown(
            c,
            S,
            &[
                "spring_constant",
                "resonance_frequency",
                "quality_factor",
                "length",
                "width",
            ],
        );
        let mut array = |key: &str, max: f64| -> Option<Vec<f64>> {
            let Some(toml::Value::Array(a)) = c.get(key) else {
                r.problems.push(format!(
                    "[cantilever].{key} must be an array, one value per mode (the eigenmode \
                     model)"
                ));
                return None;
            };
            let mut v = Vec::with_capacity(a.len());
            for (i, x) in a.iter().enumerate() {
                match x.as_float().or(x.as_integer().map(|i| i as f64)) {
                    Some(y) if y.is_finite() && y > 0.0 && y <= max => v.push(y),
                    _ => r.problems.push(format!(
                        "[cantilever].{key}[{i}] = {x}: must be a number in (0, {max:e}]"
                    )),
                }
            }
            (v.len() == a.len()).then_some(v)
        };
        let k = array("spring_constant", 1e6);
        let f = array("resonance_frequency", 1e10);
        let q = array("quality_factor", MAX_QUALITY_FACTOR);
        let (k, f, q) = (k?, f?, q?);
        if k.len() != f.len() || k.len() != q.len() {
            r.problems.push(format!(
                "[cantilever]: spring_constant, resonance_frequency and quality_factor have \
                 {}, {} and {} values: give one of each per mode",
                k.len(),
                f.len(),
                q.len()
            ));
            return None;
        }
        if k.is_empty() {
            r.problems
                .push("[cantilever].spring_constant is empty: give one value per mode".into());
            return None;
        }
        if f.windows(2).any(|w| w[1] <= w[0]) {
            r.problems
                .push("[cantilever].resonance_frequency must increase from mode to mode".into());
            return None;
        }
        Some((k, f, q))
    }

    /// A calibrated lever's plan, `[cantilever] length` and `width` (m), both or neither: what
    /// `[medium]` needs.
    pub(super) fn read_plan(r: &mut Reader<'_>, c: &toml::Table) -> Option<(f64, f64)> {
        const S: &str = "cantilever";
        let length = r.optional(c, S, "length", "m", POSITIVE);
        let width = r.optional(c, S, "width", "m", POSITIVE);
        if c.contains_key("length") != c.contains_key("width") {
            r.problems.push(
                "[cantilever]: give both length and width (m, the lever's plan) or neither".into(),
            );
        }
        length.zip(width)
    }

    #[allow(clippy::type_complexity)]
    pub(super) fn read_cantilever(
        r: &mut Reader<'_>,
        c: &toml::Table,
    ) -> (Option<Beam>, Option<f64>, Option<Vec<f64>>) {
        const S: &str = "cantilever";
        const CAL: [&str; 3] = ["spring_constant", "resonance_frequency", "tip_mass_ratio"];
        const GEO: [&str; 6] = [
            "length",
            "width",
            "thickness",
            "youngs_modulus",
            "density",
            "tip_mass",
        ];
        let mut known: Vec<&str> = CAL.iter().chain(GEO.iter()).copied().collect();
        known.extend(["quality_factor", "quality_factors"]);
        r.unknown(c, S, &known);
        let has_cal = CAL[..2].iter().any(|k| c.contains_key(*k));
        // length and width may come with calibrated values: the plan `[medium]` needs
        let has_geo = GEO
            .iter()
            .any(|k| c.contains_key(*k) && !(has_cal && matches!(*k, "length" | "width")));
        let beam = match (has_cal, has_geo) {
            (true, true) => {
                r.problems.push(
                    "[cantilever]: give either calibrated values (spring_constant, \
                     resonance_frequency) or the geometry (length, width, thickness, \
                     youngs_modulus, density, tip_mass), not both"
                        .into(),
                );
                None
            }
            (false, true) => {
                let length = r.required(c, S, "length", "m", POSITIVE);
                let width = r.required(c, S, "width", "m", POSITIVE);
                let thickness = r.required(c, S, "thickness", "m", POSITIVE);
                let e = r.required(c, S, "youngs_modulus", "Pa", POSITIVE);
                let rho = r.required(c, S, "density", "kg/m^3", POSITIVE);
                let tip_mass = r.optional(c, S, "tip_mass", "kg", NON_NEGATIVE);
                match (length, width, thickness, e, rho) {
                    (Some(l), Some(b), Some(h), Some(e), Some(rho)) => Some(Beam::Geometry {
                        width: b,
                        si: crate::units::BeamSi {
                            length: l,
                            bending_stiffness: e * b * h.powi(3) / 12.0,
                            mass_per_length: rho * b * h,
                            tip_mass: tip_mass.unwrap_or(0.0),
                        },
                    }),
                    _ => None,
                }
            }
            _ => {
                let k = r.required(c, S, "spring_constant", "N/m", POSITIVE);
                let f0 = r.required(c, S, "resonance_frequency", "Hz", POSITIVE);
                let alpha1 = r
                    .optional(c, S, "tip_mass_ratio", "1", NON_NEGATIVE)
                    .unwrap_or(0.0);
                let plan = Self::read_plan(r, c);
                match (k, f0) {
                    (Some(k), Some(f0)) => Some(Beam::Calibrated {
                        k,
                        f0,
                        alpha1,
                        plan,
                    }),
                    _ => None,
                }
            }
        };
        let qs = match c.get("quality_factors") {
            None => None,
            Some(toml::Value::Array(a)) => {
                let mut v = Vec::with_capacity(a.len());
                for (i, x) in a.iter().enumerate() {
                    match x.as_float().or(x.as_integer().map(|i| i as f64)) {
                        Some(q) if q.is_finite() && q > 0.0 && q <= MAX_QUALITY_FACTOR => v.push(q),
                        _ => r.problems.push(format!(
                            "[cantilever].quality_factors[{i}] = {}: must be a number in (0, 1e7]",
                            x.as_float().map_or(x.to_string(), crate::error::number)
                        )),
                    }
                }
                Some(v)
            }
            Some(_) => {
                r.problems
                    .push("[cantilever].quality_factors must be an array of numbers".into());
                None
            }
        };
        let q1 = match (c.contains_key("quality_factor"), &qs) {
            (true, _) => r.required(c, S, "quality_factor", "1", QUALITY),
            (false, Some(q)) => q.first().copied(),
            (false, None) => {
                r.problems
                    .push("missing key [cantilever].quality_factor (Q of mode 1)".into());
                None
            }
        };
        if let (Some(q1), Some(q)) = (q1, &qs) {
            if q.first().is_some_and(|&f| f != q1) {
                r.problems.push(format!(
                    "[cantilever].quality_factor = {} differs from quality_factors[0] = {}",
                    crate::error::number(q1),
                    q[0]
                ));
            }
        }
        (beam, q1, qs)
    }

    /// `[sample]`: the law and the keys it takes ([`crate::contact::Law::SAMPLE_KEYS`]), with
    /// the `[tip]`'s radius and elastic constants as read.
    pub(super) fn read_sample(
        r: &mut Reader<'_>,
        s: &toml::Table,
        tip: Option<&toml::Table>,
        radius: Option<f64>,
        tip_e: Option<f64>,
        tip_nu: Option<f64>,
    ) -> Option<Sample> {
        const S: &str = "sample";
        let law = Self::read_law(r, s)?;
        let keys = law
            .parse::<crate::contact::LawKind>()
            .map_or(&[][..], |kind| kind.info().sample_keys);
        r.unknown(s, S, keys);
        let z_c = r.optional(s, S, "z_c", "m", ANY);
        let mut out = Sample {
            law,
            si: crate::contact::SampleSi {
                radius,
                ..Default::default()
            },
            z_c,
            elastic: None,
            shape: TipShape::Paraboloid,
        };
        let si = &mut out.si;
        match out.law.as_str() {
            "linear" => {
                si.stiffness = r.required(s, S, "stiffness", "N/m", NON_NEGATIVE);
                si.damping = r.optional(s, S, "damping", "N s/m", NON_NEGATIVE);
                si.stiffness.map(|_| out)
            }
            "sls" => {
                si.stiffness = r.required(s, S, "stiffness", "N/m", POSITIVE);
                let k2 = r.required(s, S, "maxwell_stiffness", "N/m", POSITIVE);
                let tau = r.required(s, S, "relaxation_time", "s", POSITIVE);
                si.maxwell = k2.zip(tau);
                si.stiffness.and(si.maxwell).map(|_| out)
            }
            "impact" => {
                si.restitution = r.required(s, S, "restitution", "1", UNIT_INTERVAL);
                si.restitution.map(|_| out)
            }
            _ => Self::read_contact(r, s, out, tip, tip_e, tip_nu),
        }
    }

    /// `[sample] law`: a registered law's name ([`crate::contact::LAWS`]) in any case ("DMT" as
    /// the literature writes it).
    fn read_law(r: &mut Reader<'_>, s: &toml::Table) -> Option<String> {
        match r
            .string(s, "sample", "law")
            .map(|l| (l, l.trim().to_ascii_lowercase()))
        {
            Some((_, l)) if crate::contact::LAWS.iter().any(|law| law.name == l) => Some(l),
            Some((l, _)) => {
                r.problems.push(format!(
                    "[sample].law = '{l}': expected {}",
                    crate::contact::LawKind::EXPECTED
                ));
                None
            }
            None => {
                if !s.contains_key("law") {
                    r.problems.push(format!(
                        "missing key [sample].law ({})",
                        crate::contact::LawKind::EXPECTED
                    ));
                }
                None
            }
        }
    }

    /// The `[sample]` of a law of Hertz's contact (hertz, dmt, electrostatic, jkr, capillary):
    /// the tip's radius, E* of tip and sample, and the law's own keys.
    fn read_contact(
        r: &mut Reader<'_>,
        s: &toml::Table,
        mut out: Sample,
        tip: Option<&toml::Table>,
        tip_e: Option<f64>,
        tip_nu: Option<f64>,
    ) -> Option<Sample> {
        const S: &str = "sample";
        let (law, si) = (out.law.as_str(), &mut out.si);
        // the tip (its radius; E and ν default to silicon's)
        if tip.is_none() {
            r.problems.push(format!(
                "missing table [tip] (the {law} law needs the tip radius; youngs_modulus and \
                 poisson_ratio default to silicon's)"
            ));
        } else if si.radius.is_none() && !tip.is_some_and(|t| t.contains_key("radius")) {
            r.problems.push(format!(
                "missing key [tip].radius (m, needed by the {law} law)"
            ));
        }
        let e_s = r.required(s, S, "youngs_modulus", "Pa", POSITIVE);
        let nu_s = r.required(s, S, "poisson_ratio", "1", POISSON);
        if let (Some(et), Some(nt), Some(es), Some(ns)) = (tip_e, tip_nu, e_s, nu_s) {
            si.e_star = Some(crate::contact::reduced_modulus(et, nt, es, ns));
            out.elastic = Some([es, ns, et, nt]);
        }
        if law == "hertz" {
            si.damping = r.optional(s, S, "damping", "N s/m", NON_NEGATIVE);
        } else if law == "capillary" {
            let volume = r.required(s, S, "meniscus_volume", "m^3", POSITIVE);
            let gamma = r
                .optional(s, S, "surface_tension", "N/m", POSITIVE)
                .or(Some(WATER_SURFACE_TENSION));
            let theta = r
                .optional(s, S, "contact_angle", "degree", WETTING_ANGLE)
                .or(Some(0.0));
            si.viscosity = r.optional(s, S, "viscosity", "Pa s", NON_NEGATIVE);
            if let (Some(v), Some(g), Some(t)) = (volume, gamma, theta) {
                si.meniscus = Some((v, g, t.to_radians()));
            }
            si.meniscus?;
        } else {
            // JKR: the work of adhesion W, or H/(12πa₀²) from the Hamaker constant
            si.hamaker = if law == "jkr" {
                si.adhesion_energy = r.optional(s, S, "adhesion_energy", "J/m^2", POSITIVE);
                // (a given but invalid adhesion_energy is reported by its own check, not
                // as missing)
                match (s.contains_key("adhesion_energy"), s.contains_key("hamaker")) {
                    (_, true) => r.optional(s, S, "hamaker", "J", POSITIVE),
                    (true, false) => None,
                    (false, false) => {
                        r.problems.push(
                            "missing key [sample].adhesion_energy (W, J/m², the jkr law's work \
                             of adhesion; or hamaker, J, for W = H/(12πa₀²))"
                                .into(),
                        );
                        None
                    }
                }
            } else {
                r.required(s, S, "hamaker", "J", NON_NEGATIVE)
            };
            // a₀ = 0.165 nm when omitted (Israelachvili, Intermolecular and Surface Forces,
            // 3rd ed., Academic Press 2011, §13.6: the contact separation D₀ that gives
            // surface energies from Hamaker constants; García & San Paulo 1999 use it)
            si.a0 = if s.contains_key("intermolecular_distance") {
                r.optional(s, S, "intermolecular_distance", "m", POSITIVE)
            } else {
                Some(DEFAULT_INTERMOLECULAR_DISTANCE)
            };
            si.viscosity = r.optional(s, S, "viscosity", "Pa s", NON_NEGATIVE);
        }
        if law == "electrostatic" {
            // the voltage across the gap: the bias less the contact potential difference
            let bias = r.required(s, S, "bias_voltage", "V", ANY);
            let cpd = r
                .optional(s, S, "contact_potential", "V", ANY)
                .unwrap_or(0.0);
            si.voltage = bias.map(|b| b - cpd);
            si.voltage?;
        }
        if law == "jkr" {
            if si.adhesion_energy.is_some() && si.hamaker.is_some() {
                r.problems.push(
                    "[sample] gives both adhesion_energy and hamaker: the jkr law takes one work \
                     of adhesion (W, or H/(12πa₀²))"
                        .into(),
                );
                return None;
            }
            if let (None, Some(h), Some(a0)) = (si.adhesion_energy, si.hamaker, si.a0) {
                si.adhesion_energy = Some(work_of_adhesion(h, a0));
            }
            si.adhesion_energy?;
        }
        si.e_star.and(si.radius).map(|_| out)
    }
}
