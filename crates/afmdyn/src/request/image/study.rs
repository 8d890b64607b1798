//! The setpoint study of an image ([`super::setpoint_study`]): the domain contrast of
//! height, phase and dissipation over a range of amplitude ratios.

use super::*;
use crate::layout::{Layout, Values, Variable};
use crate::study::named::Outcome;

/// The most setpoints of a setpoint study, on every front end: each is a line engaged on
/// the background that crosses every domain.
pub const MAX_STUDY_RATIOS: usize = 1000;

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

/// Parse a setpoint study's ratios `FROM:TO:N` (N evenly spaced ratios in (0, 1), ends
/// included).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `setpoint_study` for another form, ratios outside (0, 1)
/// or N outside 2..=1000.
pub fn study_ratios(spec: &str) -> Result<Vec<f64>, SimError> {
    let bad = || {
        SimError::out_of_range(
            "setpoint_study",
            spec.to_string(),
            "must be FROM:TO:N, ratios A_sp/A0 in (0, 1) and N in 2..=1000 (MAX_STUDY_RATIOS; \
             e.g. 0.2:0.95:16)",
        )
    };
    let parts: Vec<&str> = spec.split(':').collect();
    let [from, to, n] = parts[..] else {
        return Err(bad());
    };
    let (from, to): (f64, f64) = (
        from.trim().parse().map_err(|_| bad())?,
        to.trim().parse().map_err(|_| bad())?,
    );
    let n: usize = n.trim().parse().map_err(|_| bad())?;
    let inside = |r: f64| r > 0.0 && r < 1.0;
    if !(inside(from) && inside(to) && (2..=MAX_STUDY_RATIOS).contains(&n)) {
        return Err(bad());
    }
    // (1 − t)·from + t·to: both ends exactly
    Ok((0..n)
        .map(|k| {
            let t = k as f64 / (n - 1) as f64;
            (1.0 - t) * from + t * to
        })
        .collect())
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
