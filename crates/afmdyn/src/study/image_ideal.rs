//! The ideal-feedback image of `image` (issue 46) and its setpoint study, computed from the
//! request (`crate::request::image`: the sample map, the request, their checks and cost): each
//! material's approach curve (`material_curves`), then the image line by line ([`image`]).
//!
//! **Ideal feedback.** A feedback loop infinitely faster than the scan holds the amplitude at
//! the setpoint A_sp = r A₀ at every pixel, so a pixel's operating point is a point of its
//! material's approach curve where A(z_c) = A_sp ([`crate::analysis::setpoint`]), and the z
//! piezo records the true height plus the rest distance z_c there. Which of the material's
//! operating points (in the bistable range one attractive, one repulsive: García & San Paulo,
//! *Phys. Rev. B* 61 (2000) R13381) is the history's: each line is engaged from far, as an
//! instrument engages, on the operating point the approach sweep meets first (its largest z_c);
//! along the line the regime (attractive or repulsive) is kept from pixel to pixel while the new
//! material has an operating point in it, and otherwise the nearest z_c of the other regime is
//! taken and the switch reported. The apparent height is h + z_c − z_c,ref, z_c,ref the engaged
//! rest distance on the background, so a soft domain of the background's true height shows its
//! difference in z_c (García & San Paulo 2000; the height artefacts of Kühle, Sørensen & Bohr,
//! *J. Appl. Phys.* 81 (1997) 6562). The operating points of each material are computed once
//! (an approach curve per material, [`crate::analysis::approach::approach_retract`]), so the
//! image costs one approach curve per material however many pixels it has, and the
//! [`setpoint_study`] (every domain's contrast against the setpoint) as many however many
//! setpoints.

use crate::analysis::approach::approach_retract;
use crate::analysis::setpoint::operating_points;
use crate::analysis::stepped::SteppedSpec;
use crate::error::SimError;
use crate::layout::{Layout, Values, Variable};
use crate::params::Params;
use crate::report::image::DomainContrast;
use crate::report::CurveUnits;
use crate::request::costs::check_cost;
use crate::request::curves::{approach_request, CurveRequest};
use crate::request::image::{
    background_probe, curves_cost, material_models, pixel_grid, Image, ImageRequest, Material,
    OperatingPoint, Pixel, Regime, SampleMap, SetpointStudy, MAX_STUDY_RATIOS,
};
use crate::request::limits::Cost;
use crate::study::named::Outcome;
use serde_json::Value;

/// One material's approach curve: the background or a domain's sample under the probe's lever
/// and drive.
pub(crate) struct MaterialCurve {
    pub(crate) name: String,
    pub(crate) params: Params,
    pub(crate) curve: crate::analysis::stepped::SteppedCurve,
    /// The curve's spec (its operating points are refined with it).
    pub(crate) spec: SteppedSpec,
    /// Its probe's own warnings ([`Probe::warnings`]: a sample outside its law's regime, a
    /// value outside its typical range), named by the material.
    pub(crate) probe_warnings: Vec<String>,
}

/// The approach curve of `params` (`curve_points` z_c values each way over the probe's default
/// range, no branches), and its spec.
fn approach_curve(
    params: Params,
    units: &CurveUnits,
    curve_points: usize,
) -> Result<(SteppedSpec, crate::analysis::stepped::SteppedCurve), SimError> {
    let curve_req = CurveRequest {
        points: Some(curve_points),
        branches: false,
        ..CurveRequest::default()
    };
    let spec = approach_request(params, &curve_req, units.length, false)?;
    let curve = approach_retract(&spec)?;
    Ok((spec, curve))
}

/// The materials of `map` under the probe `probe_table`: the background, then one per domain
/// with its own sample, each with its approach curve; the material of each domain; the SI
/// units.
///
/// `extra` is what the caller adds to the curves' cost (the pixels' memory, a scan's drive
/// periods): the whole is held against the budgets of a request ([`check_cost`], named
/// `image`) before the first curve.
pub(crate) fn material_curves(
    probe_table: &toml::Table,
    map: &SampleMap,
    curve_points: usize,
    extra: Cost,
) -> Result<(Vec<MaterialCurve>, Vec<usize>, CurveUnits), SimError> {
    let background = background_probe(probe_table)?;
    let units = CurveUnits::from_scales(&background.scales, false);
    check_cost("image", curves_cost(&background, map, curve_points, extra)?)?;
    let (models, of_domain, warnings) = material_models(probe_table, map, &background)?;
    let materials = models
        .into_iter()
        .zip(warnings)
        .map(|((name, params), probe_warnings)| {
            let (spec, curve) = approach_curve(params, &units, curve_points)?;
            Ok(MaterialCurve {
                name,
                params,
                curve,
                spec,
                probe_warnings,
            })
        })
        .collect::<Result<Vec<_>, SimError>>()?;
    Ok((materials, of_domain, units))
}

/// The warnings of the materials' approach curves, each named by its material.
fn curve_warnings(curves: &[MaterialCurve]) -> Vec<String> {
    curves
        .iter()
        .flat_map(|m| {
            m.curve
                .warnings
                .iter()
                .map(move |w| format!("{} (its approach curve): {w}", m.name))
        })
        .collect()
}

/// The operating points of a material's curve at the setpoint `ratio`, in SI (`units`;
/// [`crate::report::setpoint`]).
fn points_at(
    m: &MaterialCurve,
    ratio: f64,
    units: &CurveUnits,
) -> Result<Vec<OperatingPoint>, SimError> {
    let (points, dropped) = operating_points(&m.spec, &m.curve, ratio)?;
    let doc = crate::report::setpoint(&m.params, &m.curve, (&points, &dropped), ratio, units);
    let num = |p: &Value, k: &str| p[k].as_f64().unwrap_or(f64::NAN);
    Ok(doc["points"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|p| OperatingPoint {
                    source: p["source"].as_str().unwrap_or("").to_string(),
                    z_c: num(p, "z_c"),
                    regime: if p["regime"] == "attractive" {
                        Regime::Attractive
                    } else {
                        Regime::Repulsive
                    },
                    amplitude: num(p, "amplitude"),
                    phase_deg: num(p, "phase_deg"),
                    energy_dissipated: num(p, "energy_dissipated"),
                    virial: num(p, "virial"),
                    peak_force: num(p, "peak_force"),
                    indentation: num(p, "indentation"),
                })
                .collect()
        })
        .unwrap_or_default())
}

/// The operating point a line engages on: the approach sweep's first (largest z_c), else the
/// largest z_c of any.
fn engage(points: &[OperatingPoint]) -> Option<usize> {
    let best = |approach_only: bool| {
        (0..points.len())
            .filter(|&i| !approach_only || points[i].source == "approach")
            .max_by(|&a, &b| points[a].z_c.total_cmp(&points[b].z_c))
    };
    best(true).or_else(|| best(false))
}

/// The operating point of a material continued from the previous pixel's (regime, z_c): the
/// same regime, nearest z_c; else the nearest z_c of the other regime (switched = true).
fn continue_from(points: &[OperatingPoint], regime: Regime, z_c: f64) -> Option<(usize, bool)> {
    let nearest = |same: bool| {
        (0..points.len())
            .filter(|&i| (points[i].regime == regime) == same)
            .min_by(|&a, &b| {
                (points[a].z_c - z_c)
                    .abs()
                    .total_cmp(&(points[b].z_c - z_c).abs())
            })
    };
    nearest(true)
        .map(|i| (i, false))
        .or_else(|| nearest(false).map(|i| (i, true)))
}

/// The ideal-feedback image of `map` under `probe` (module docs): the operating points of each
/// material, then the scan line by line.
///
/// # Errors
/// As [`ImageRequest::validate`]; [`SimError::Probe`] for a domain's sample the probe format
/// refuses (named by the domain); as the approach curves.
pub fn image(
    probe_table: &toml::Table,
    map: &SampleMap,
    req: &ImageRequest,
) -> Result<Image, SimError> {
    req.validate(map)?;
    let extra = Cost {
        bytes: req.pixel_bytes(map),
        work: 0.0,
    };
    let (curves, of_domain, units) = material_curves(probe_table, map, req.curve_points, extra)?;
    image_of(&curves, &of_domain, &units, map, req)
}

/// [`image`] from the materials' curves ([`material_curves`]).
pub(crate) fn image_of(
    curves: &[MaterialCurve],
    of_domain: &[usize],
    units: &CurveUnits,
    map: &SampleMap,
    req: &ImageRequest,
) -> Result<Image, SimError> {
    let materials: Vec<Material> = curves
        .iter()
        .map(|m| {
            Ok(Material {
                name: m.name.clone(),
                points: points_at(m, req.setpoint, units)?,
                warnings: m.curve.warnings.clone(),
            })
        })
        .collect::<Result<_, SimError>>()?;
    let (x, y) = pixel_grid(map, req);
    // the materials' probe warnings (issue 77: the AM image lacked them), then their approach
    // curves' own (an unsettled point, a failed one), named by material
    let mut warnings: Vec<String> = curves
        .iter()
        .flat_map(|m| m.probe_warnings.clone())
        .collect();
    warnings.extend(curve_warnings(curves));
    for m in &materials {
        if m.points.is_empty() {
            warnings.push(warning!(
                "image.setpoint-unreached",
                "Give a setpoint that every material's approach curve reaches, or a \
                 longer range of its curves.",
                "{}: the setpoint A/A0 = {} is not reached on its approach curve: its pixels \
                 are empty (NaN)",
                m.name,
                req.setpoint
            ));
        }
    }
    let reference = engage(&materials[0].points)
        .map(|i| materials[0].points[i].z_c)
        .unwrap_or(f64::NAN);
    let mut pixels = Vec::with_capacity(y.len());
    let mut switches = 0usize;
    for &yj in &y {
        let mut line = Vec::with_capacity(req.pixels);
        let mut prev: Option<(Regime, f64)> = None;
        for &xi in &x {
            let d = map.domain_at(xi, yj);
            let material = d.map_or(0, |k| of_domain[k]);
            let height = map.height_at(xi, yj);
            let pts = &materials[material].points;
            let (point, switched) = match prev {
                None => (engage(pts), false),
                Some((regime, z)) => match continue_from(pts, regime, z) {
                    Some((i, s)) => (Some(i), s),
                    None => (None, false),
                },
            };
            if let Some(i) = point {
                prev = Some((pts[i].regime, pts[i].z_c));
            }
            switches += usize::from(switched);
            line.push(Pixel {
                domain: d,
                material,
                height,
                point,
                switched,
            });
        }
        pixels.push(line);
    }
    if switches > 0 {
        warnings.push(warning!(
            "image.regime-switch",
            "For one regime over the whole image, give a setpoint at which every material \
             has an operating point in it.",
            "{switches} pixel(s) switch regime (attractive ↔ repulsive) where a material has no \
             operating point in the previous one's: the image's contrast changes there"
        ));
    }
    Ok(Image {
        x,
        y,
        materials,
        pixels,
        reference,
        domain_names: map.domains.iter().map(|d| d.name.clone()).collect(),
        warnings,
    })
}

/// The variables of a setpoint study's layout over (`domain`, `setpoint`)
/// ([`SetpointStudy::layout`]): name, unit (SI) and long name.
const STUDY_VARIABLES: [(&str, &str, &str); 3] = [
    (
        "apparent_height",
        "m",
        "apparent height h + z_c − z_c,ref of the domain (NaN: no operating point)",
    ),
    (
        "phase_deg",
        "degree",
        "phase lag of the first harmonic behind the drive",
    ),
    (
        "energy_dissipated",
        "J",
        "energy dissipated in the sample per drive period",
    ),
];

impl SetpointStudy {
    /// The study's layout (what Python's `afmdyn.setpoint_study` returns): over `domain` (its
    /// name, the background first; a coordinate of words) and `setpoint` (the ratio
    /// A_sp/A₀; its coordinate) the `apparent_height` (m), `phase_deg` (degree) and
    /// `energy_dissipated` (J), NaN where a material has no operating point, and `regime`
    /// (`attractive`, `repulsive`, or empty there).
    pub fn layout(&self) -> Layout {
        let (dd, rr) = (self.domains.len(), self.ratio.len());
        let both = ["domain", "setpoint"];
        let names = self.domains.iter().map(|d| d.name.clone()).collect();
        let mut variables = vec![
            Variable::new(
                "domain",
                &["domain"],
                "",
                "domain of the sample map (the background first)",
                Values::Text(names),
            ),
            Variable::f64(
                "setpoint",
                &["setpoint"],
                "1",
                "setpoint ratio A_sp/A0",
                &self.ratio,
            ),
        ];
        for (name, unit, long_name) in STUDY_VARIABLES {
            let series = |d: &DomainContrast| match name {
                "apparent_height" => d.apparent_height.clone(),
                "phase_deg" => d.phase_deg.clone(),
                _ => d.energy_dissipated.clone(),
            };
            let values: Vec<f64> = self.domains.iter().flat_map(series).collect();
            variables.push(Variable::f64(name, &both, unit, long_name, &values));
        }
        let word = |r: &Option<Regime>| match r {
            Some(Regime::Attractive) => "attractive".to_string(),
            Some(Regime::Repulsive) => "repulsive".to_string(),
            None => String::new(),
        };
        let regimes = self.domains.iter().flat_map(|d| d.regime.iter().map(word));
        variables.push(Variable::new(
            "regime",
            &both,
            "",
            "regime of the operating point (mean tip–sample force attractive or repulsive; \
             empty: none)",
            Values::Text(regimes.collect()),
        ));
        Layout::new(
            "setpoint study",
            &[("domain", dd), ("setpoint", rr)],
            variables,
        )
    }

    /// The outcome a front end shows: the study's JSON (`ratio`, `domains`, `warnings`: the
    /// command line's `setpoint_study` of `image.json`) and its layout `setpoint_study`
    /// ([`SetpointStudy::layout`]).
    pub fn outcome(&self) -> Outcome {
        Outcome {
            document: serde_json::to_value(self).unwrap_or_default(),
            datasets: vec![("setpoint_study".into(), self.layout())],
            facts: serde_json::Map::new(),
        }
    }
}

/// The setpoint study of `map` under the probe at the `ratios` ([`SetpointStudy`]).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `setpoint_study` for a ratio outside (0, 1) or no ratios;
/// as [`image`]'s materials.
pub fn setpoint_study(
    probe_table: &toml::Table,
    map: &SampleMap,
    ratios: &[f64],
    curve_points: usize,
) -> Result<SetpointStudy, SimError> {
    if ratios.len() > MAX_STUDY_RATIOS {
        return Err(SimError::out_of_range(
            "setpoint_study",
            format!("{} ratios", ratios.len()),
            "must be at most 1000 ratios (MAX_STUDY_RATIOS), as the command line's FROM:TO:N",
        ));
    }
    if ratios.is_empty() || ratios.iter().any(|&r| !(r > 0.0 && r < 1.0)) {
        return Err(SimError::out_of_range(
            "setpoint_study",
            format!("{ratios:?}"),
            "must be one or more ratios A_sp/A0 in (0, 1)",
        ));
    }
    ImageRequest {
        curve_points,
        ..ImageRequest::at(ratios[0])
    }
    .validate(map)?;
    let extra = crate::request::limits::Cost {
        bytes: 0.0,
        work: 0.0,
    };
    let (curves, of_domain, units) = material_curves(probe_table, map, curve_points, extra)?;
    let names = std::iter::once(("background".to_string(), 0, 0.0)).chain(
        map.domains
            .iter()
            .zip(&of_domain)
            .map(|(d, &m)| (d.name.clone(), m, d.height)),
    );
    let mut domains: Vec<DomainContrast> = names
        .clone()
        .map(|(name, _, _)| DomainContrast {
            name,
            apparent_height: Vec::with_capacity(ratios.len()),
            phase_deg: Vec::with_capacity(ratios.len()),
            energy_dissipated: Vec::with_capacity(ratios.len()),
            regime: Vec::with_capacity(ratios.len()),
        })
        .collect();
    for &r in ratios {
        let points: Vec<Vec<OperatingPoint>> = curves
            .iter()
            .map(|m| points_at(m, r, &units))
            .collect::<Result<_, SimError>>()?;
        let engaged = engage(&points[0]).map(|i| &points[0][i]);
        for ((_, material, height), series) in names.clone().zip(domains.iter_mut()) {
            let pts = &points[material];
            let point = engaged.and_then(|e| {
                if material == 0 {
                    Some(e)
                } else {
                    continue_from(pts, e.regime, e.z_c).map(|(i, _)| &pts[i])
                }
            });
            let reference = engaged.map_or(f64::NAN, |e| e.z_c);
            series
                .apparent_height
                .push(point.map_or(f64::NAN, |o| height + o.z_c - reference));
            series
                .phase_deg
                .push(point.map_or(f64::NAN, |o| o.phase_deg));
            series
                .energy_dissipated
                .push(point.map_or(f64::NAN, |o| o.energy_dissipated));
            series.regime.push(point.map(|o| o.regime));
        }
    }
    Ok(SetpointStudy {
        ratio: ratios.to_vec(),
        domains,
        warnings: curve_warnings(&curves),
    })
}
