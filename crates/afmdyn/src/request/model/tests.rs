use super::*;

/// Every field of [`ModelSpec`] is a row of the table and every row a field: a spec with
/// every value set serialises to exactly the table's names.
#[test]
fn the_table_names_every_field_of_the_spec() {
    let full = ModelSpec {
        modes: Some(1),
        tip_mass_ratio: Some(0.0),
        drive_amplitude: Some(0.0),
        beam_damping: Some(0.0),
        contact_stiffness: Some(0.0),
        gap: Some(0.0),
        contact_damping: Some(0.0),
        omega: Some(1.0),
        contact_law: Some(LawKind::Linear),
        excitation: Some(Excitation::Tip),
        // every group of the registry
        groups: GROUPS
            .iter()
            .fold(LawGroups::default(), |g, p| g.with(p.name, 1.0)),
        z_c: Some(0.0),
        drive_frequency: Some(1.0),
    };
    let v = serde_json::to_value(full).unwrap();
    let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    let mut names: Vec<&str> = MODEL_PARAMETERS.iter().map(|p| p.name).collect();
    let mut keys_sorted = keys.clone();
    keys_sorted.sort_unstable();
    names.sort_unstable();
    assert_eq!(keys_sorted, names);
    // and the aliases are accepted as keys
    for p in MODEL_PARAMETERS.iter() {
        if let Some(alias) = p.alias {
            let spec = ModelSpec::from_toml(&format!("{alias} = 0.5")).unwrap();
            let direct = ModelSpec::from_toml(&format!("{} = 0.5", p.name)).unwrap();
            assert_eq!(spec, direct, "{alias}");
        }
    }
}

/// The precedence: defaults ← probe ← values ← z_c; z_c without a probe is refused naming
/// it; z_c and gap together are refused (both set α5).
#[test]
fn precedence_and_the_si_overrides() {
    let spec = ModelSpec {
        omega: Some(3.0),
        ..ModelSpec::default()
    };
    let p = spec.resolve(Params::default(), None).unwrap();
    assert_eq!(
        p,
        Params {
            omega: 3.0,
            ..Params::default()
        }
    );
    let e = ModelSpec {
        z_c: Some(1e-9),
        ..ModelSpec::default()
    }
    .resolve(Params::default(), None)
    .unwrap_err();
    assert!(
        e.to_string().starts_with("z_c = 1e-9: needs a probe"),
        "{e}"
    );
    let probe = Probe::parse(
        include_str!("../../../../../examples/probe-point-mass-dmt.toml"),
        "probe-point-mass-dmt.toml",
    )
    .unwrap();
    // the probe's own set when nothing is given
    assert_eq!(
        ModelSpec::default()
            .resolve(Params::default(), Some(&probe))
            .unwrap(),
        probe.params
    );
    // z_c sets α5 through the probe's length scale (z_c = the probe's own gives its α5)
    let at = ModelSpec {
        z_c: Some(probe.z_c),
        ..ModelSpec::default()
    }
    .resolve(Params::default(), Some(&probe))
    .unwrap();
    assert!((at.alpha5 - probe.params.alpha5).abs() <= 1e-12 * probe.params.alpha5.abs());
    // the drive frequency sets Ω through the probe's time scale
    let f = ModelSpec {
        drive_frequency: Some(probe.drive_frequency),
        ..ModelSpec::default()
    }
    .resolve(Params::default(), Some(&probe))
    .unwrap();
    assert!((f.omega - probe.params.omega).abs() <= 1e-12 * probe.params.omega);
    let both = ModelSpec {
        z_c: Some(1e-9),
        gap: Some(0.1),
        ..ModelSpec::default()
    }
    .resolve(Params::default(), Some(&probe))
    .unwrap_err();
    assert!(
        both.to_string()
            .starts_with("gap = 0.1: is the dimensionless α5"),
        "{both}"
    );
}

/// Under a probe every dimensionless value the probe sets is refused, named, with the SI
/// key or flag to use (issue 42: `--hamaker 6.6e-20` was taken as H̃ and moved the peak
/// force; `--drive-amplitude 20e-9` ran with no drive); without a probe they are taken.
#[test]
fn a_probe_refuses_the_values_it_sets() {
    let probe = Probe::parse(
        include_str!("../../../../../examples/probe-point-mass-dmt.toml"),
        "probe-point-mass-dmt.toml",
    )
    .unwrap();
    let cases: [(ModelSpec, &str); 10] = [
        (
            ModelSpec {
                tip_mass_ratio: Some(0.1),
                ..ModelSpec::default()
            },
            "[cantilever] tip_mass_ratio",
        ),
        (
            ModelSpec {
                drive_amplitude: Some(20e-9),
                ..ModelSpec::default()
            },
            "[drive] free_amplitude (m)",
        ),
        (
            ModelSpec {
                beam_damping: Some(0.1),
                ..ModelSpec::default()
            },
            "[cantilever] quality_factor",
        ),
        (
            ModelSpec {
                contact_stiffness: Some(20.0),
                ..ModelSpec::default()
            },
            "[sample] youngs_modulus (Pa",
        ),
        (
            ModelSpec {
                gap: Some(1.0),
                ..ModelSpec::default()
            },
            "z_c in m",
        ),
        (
            ModelSpec {
                contact_damping: Some(0.2),
                ..ModelSpec::default()
            },
            "[sample] viscosity",
        ),
        (
            ModelSpec {
                omega: Some(1.0),
                ..ModelSpec::default()
            },
            "drive frequency in Hz",
        ),
        (
            ModelSpec {
                contact_law: Some(LawKind::Hertz),
                ..ModelSpec::default()
            },
            "[sample] law",
        ),
        (
            ModelSpec {
                groups: LawGroups::default().with("hamaker", 6.6e-20),
                ..ModelSpec::default()
            },
            "[sample] hamaker (J)",
        ),
        (
            ModelSpec {
                groups: LawGroups::default().with("intermolecular_distance", 0.01),
                ..ModelSpec::default()
            },
            "[sample] intermolecular_distance (m)",
        ),
    ];
    for (spec, hint) in cases {
        let e = spec.resolve(Params::default(), Some(&probe)).unwrap_err();
        assert!(matches!(e, SimError::OutOfRange { .. }), "{e:?}");
        assert!(e.to_string().contains(hint), "{e}");
        // taken as the dimensionless value without a probe (the law groups need their law)
        if spec.groups.given().next().is_none() {
            spec.resolve(Params::default(), None).unwrap();
        }
    }
    let e = ModelSpec {
        groups: LawGroups::default().with("hamaker", 6.6e-20),
        ..ModelSpec::default()
    }
    .resolve(Params::default(), Some(&probe))
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "hamaker = 6.6e-20: is the dimensionless H̃ and a probe sets it: give the Hamaker \
         constant in the probe file's [sample] hamaker (J)"
    );
    // what a probe takes: N, r (its own law's), z_c in m and f in Hz
    let ok = ModelSpec {
        z_c: Some(12e-9),
        drive_frequency: Some(299e3),
        ..ModelSpec::default()
    }
    .resolve(Params::default(), Some(&probe))
    .unwrap();
    assert_eq!(ok.alpha3, probe.params.alpha3);
}

/// A z_c beyond the model's α5 range is refused naming z_c in m and the probe's range in
/// m, not α5 (issue 42: `--z-c 50um` on a 10 pm probe named `alpha5 = 4.999983500000001e6`).
#[test]
fn z_c_out_of_the_models_range_is_named_in_metres() {
    let text = include_str!("../../../../../examples/probe-point-mass-dmt.toml")
        .replace("free_amplitude = 10e-9", "free_amplitude = 10e-12")
        .replace("z_c = 8e-9", "z_c = 8e-12");
    let probe = Probe::parse(&text, "small.toml").unwrap();
    assert_eq!(probe.scales.length_m, 10e-12);
    let e = ModelSpec {
        z_c: Some(50e-6),
        ..ModelSpec::default()
    }
    .resolve(Params::default(), Some(&probe))
    .unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.starts_with("z_c = 5e-5 m (this probe allows [-"),
        "{msg}"
    );
    assert!(!msg.contains("alpha5") && msg.contains("e-5] m"), "{msg}");
    // just inside the range is taken
    let edge = probe.z_c_of(&Params {
        alpha5: 0.999_999 * crate::params::DISPLACEMENT_MAX,
        ..probe.params
    });
    ModelSpec {
        z_c: Some(edge),
        ..ModelSpec::default()
    }
    .resolve(Params::default(), Some(&probe))
    .unwrap();
}
