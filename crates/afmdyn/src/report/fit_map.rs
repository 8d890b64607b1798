//! A fitted force map's document and layout (`afmdyn fit-map --json`, `fit_map.nc`, Python's
//! Dataset): the curves' estimates and flags over the map's grid ([`FitMap`]).

use crate::analysis::fit::force_curve::{BASELINE, CONTACT_POINT, YOUNGS_MODULUS};
use crate::analysis::fit::map::{median_spread, CurveFit, CurveFlag, FitMap};
use crate::layout::{Attr, Layout, Variable};
use serde_json::{json, Value};

/// The short name of a probe key in the dataset: `youngs_modulus`, `tip_radius`,
/// `contact_point`, `baseline`, `hamaker`, `adhesion_energy`.
pub fn short_name(key: &str) -> String {
    key.strip_prefix("sample.")
        .map_or_else(|| key.replace('.', "_"), str::to_string)
}

/// The unit of a fitted parameter.
pub fn unit_of(key: &str) -> &'static str {
    match key {
        YOUNGS_MODULUS => "Pa",
        CONTACT_POINT | "tip.radius" => "m",
        BASELINE => "N",
        "sample.hamaker" => "J",
        "sample.adhesion_energy" => "J/m^2",
        "sample.stiffness" | "sample.maxwell_stiffness" => "N/m",
        "sample.relaxation_time" => "s",
        _ => "1",
    }
}

/// The document of a fitted map (`afmdyn fit-map --json`, Python's `summary`): `law`,
/// `grid` (x and y positions, m), `fitted` (the probe keys), `counts` (curves per flag),
/// per parameter its `median` and 16th–84th percentiles over the curves flagged `fitted`
/// (`summary`),
/// `curves` (each curve's `x`, `y`, `ix`, `iy`, `estimates` keyed as `fit`'s with `value`,
/// `standard_error` and `interval`, `chi2_dof`, `contact_rows`, `contact_height`, `flag`,
/// `reason`, `spring_constant` (N/m, the file's for the curve, else the probe's), and
/// `thickness` where the bottom effect is corrected), `units`, `preprocessing`
/// (nanite's steps, how the contact point is found, the segment, `range_x` and
/// `bottom_effect`: how the sample's thickness was given), `method` and `warnings`.
pub fn document(m: &FitMap) -> Value {
    let counts: serde_json::Map<String, Value> = (m.counts().into_iter())
        .map(|(name, n)| (name.to_string(), json!(n)))
        .collect();
    let usable = |c: &&CurveFit| c.flag == CurveFlag::Fitted;
    let mut summary = serde_json::Map::new();
    for (k, name) in m.names.iter().enumerate() {
        let v: Vec<f64> = m
            .curves
            .iter()
            .filter(usable)
            .filter_map(|c| c.values[k])
            .collect();
        if let Some([median, p16, p84]) = median_spread(&v) {
            summary.insert(
                name.clone(),
                json!({"median": median, "p16": p16, "p84": p84, "curves": v.len()}),
            );
        }
    }
    let curves: Vec<Value> = m.curves.iter().map(|c| curve_entry(m, c)).collect();
    let mut units = serde_json::Map::new();
    for n in &m.names {
        units.insert(n.clone(), json!(unit_of(n)));
    }
    units.insert("x".into(), json!("m"));
    units.insert("contact_height".into(), json!("m"));
    units.insert("thickness".into(), json!("m"));
    units.insert("spring_constant".into(), json!("N/m"));
    units.insert("chi2_dof".into(), json!("N^2"));
    json!({
        "law": m.law.name(),
        "grid": {"x": m.xs, "y": m.ys},
        "fitted": m.names,
        "counts": counts,
        "summary": summary,
        "curves": curves,
        "units": units,
        "preprocessing": {
            // nanite's steps and names (Müller et al. 2019; nanite 4.2 preproc.py, poc.py)
            "steps": ["compute_tip_position", "correct_force_offset", "correct_tip_offset"],
            "contact_point": if m.names.iter().any(|n| n == CONTACT_POINT) {
                "fitted, from deviation_from_baseline's estimate"
            } else {
                "deviation_from_baseline (held)"
            },
            "segment": m.segment,
            "range_x": m.range,
            "range_type": "relative to deviation_from_baseline's contact point (tip positions after correct_tip_offset)",
            "bottom_effect": m.layer,
        },
        "method": "every curve fitted as fit fits one (nanite's preprocessing; Levenberg–Marquardt; \
                   no σ: the noise estimated from the residuals), its intervals Wald's (±1.96 \
                   standard errors); a curve at a bound of a parameter's physical range, not \
                   constrained, or with fewer than 8 rows indented is flagged \
                   (docs/tutorials/mapping-a-cell.md)",
        "warnings": warnings(m, &counts),
    })
}

/// One curve's entry in the document.
fn curve_entry(m: &FitMap, c: &CurveFit) -> Value {
    let mut estimates = serde_json::Map::new();
    for (k, name) in m.names.iter().enumerate() {
        estimates.insert(
            name.clone(),
            json!({"value": c.values[k], "standard_error": c.standard_errors[k], "interval": c.intervals[k]}),
        );
    }
    json!({
        "x": c.x, "y": c.y, "ix": c.ix, "iy": c.iy,
        "estimates": estimates,
        "chi2_dof": c.chi2_dof,
        "contact_rows": c.contact_rows,
        "contact_height": c.contact_height,
        "spring_constant": c.spring_constant,
        "thickness": c.thickness,
        "flag": c.flag,
        "reason": c.reason,
    })
}

/// The caveats of a fitted map: the curves flagged, with the first reason of each flag, and
/// the curves whose data look off against the probe (`fit`'s data warnings), with the first.
fn warnings(m: &FitMap, counts: &serde_json::Map<String, Value>) -> Vec<String> {
    let total = m.curves.len();
    let mut w = Vec::new();
    for flag in [
        CurveFlag::AtBound,
        CurveFlag::NotConstrained,
        CurveFlag::TooFewContactRows,
        CurveFlag::Failed,
    ] {
        let name = CurveFlag::NAMES[flag.code() as usize];
        let n = counts.get(name).and_then(Value::as_u64).unwrap_or(0);
        if let Some(first) = m.curves.iter().find(|c| c.flag == flag) {
            w.push(warning!(
                "fit-map.flagged",
                "Look at the flagged curves (the map's flag) and refit them alone, with \
                 other bounds, start values or range.",
                "{n} of {total} curves {}: the first at x = {:.4e} m, y = {:.4e} m: {}",
                name.replace('_', " "),
                first.x,
                first.y,
                first.reason.as_deref().unwrap_or("")
            ));
        }
    }
    let slips: Vec<&CurveFit> = m
        .curves
        .iter()
        .filter(|c| c.data_warning.is_some())
        .collect();
    if let Some(first) = slips.first() {
        w.push(warning!(
            "fit-map.data",
            "Check the map's units and the probe's spring constant: the first curve's \
             message names the column.",
            "{} of {total} curves' data look off against the probe: the first at x = {:.4e} m, \
             y = {:.4e} m: {}",
            slips.len(),
            first.x,
            first.y,
            first.data_warning.as_deref().unwrap_or("")
        ));
    }
    w
}

/// The map's layout over (y, x): the coordinates `x`, `y` (m); per fitted parameter its
/// value, `_standard_error`, `_lower` and `_upper` (the 95 % interval) named by
/// [`short_name`]; `chi2_dof` (N²), `contact_rows`, `topography` (the contact point's
/// piezo height, m), `spring_constant` (N/m), `thickness` (m, where the bottom effect is corrected) and `flag` (CF `flag_values`/`flag_meanings`: [`CurveFlag::NAMES`]).
pub fn layout(m: &FitMap) -> Layout {
    let (nx, ny) = (m.xs.len(), m.ys.len());
    let at = |c: &CurveFit| c.iy * nx + c.ix;
    let grid = |f: &dyn Fn(&CurveFit) -> Option<f64>| {
        let mut v = vec![f64::NAN; nx * ny];
        for c in &m.curves {
            v[at(c)] = f(c).unwrap_or(f64::NAN);
        }
        v
    };
    let d = &["y", "x"];
    let mut vars = vec![
        Variable::f64("x", &["x"], "m", "position x", &m.xs),
        Variable::f64("y", &["y"], "m", "position y", &m.ys),
    ];
    for (k, name) in m.names.iter().enumerate() {
        let (s, u) = (short_name(name), unit_of(name));
        vars.push(Variable::f64(
            &s,
            d,
            u,
            name.as_str(),
            &grid(&|c| c.values[k]),
        ));
        let se = grid(&|c| c.standard_errors[k]);
        vars.push(Variable::f64(
            &format!("{s}_standard_error"),
            d,
            u,
            "standard error",
            &se,
        ));
        let lo = grid(&|c| c.intervals[k][0]);
        vars.push(Variable::f64(
            &format!("{s}_lower"),
            d,
            u,
            "95 % interval, lower end (Wald)",
            &lo,
        ));
        let hi = grid(&|c| c.intervals[k][1]);
        vars.push(Variable::f64(
            &format!("{s}_upper"),
            d,
            u,
            "95 % interval, upper end (Wald)",
            &hi,
        ));
    }
    vars.push(Variable::f64(
        "chi2_dof",
        d,
        "N^2",
        "χ²/dof (the force noise variance)",
        &grid(&|c| c.chi2_dof),
    ));
    let mut rows = vec![0; nx * ny];
    let mut flags = vec![5; nx * ny];
    for c in &m.curves {
        rows[at(c)] = i32::try_from(c.contact_rows).unwrap_or(i32::MAX);
        flags[at(c)] = c.flag.code();
    }
    vars.push(Variable::i32(
        "contact_rows",
        d,
        "1",
        "rows indented beyond the contact point",
        &rows,
    ));
    vars.push(Variable::f64(
        "topography",
        d,
        "m",
        "the contact point's piezo height",
        &grid(&|c| c.contact_height),
    ));
    vars.push(Variable::f64(
        "spring_constant",
        d,
        "N/m",
        "the lever's spring constant the curve was fitted with (the file's, else the probe's)",
        &grid(&|c| c.spring_constant),
    ));
    if m.layer.is_some() {
        vars.push(Variable::f64(
            "thickness",
            d,
            "m",
            "the sample's thickness of the bottom-effect correction",
            &grid(&|c| c.thickness),
        ));
    }
    vars.push(
        Variable::i32("flag", d, "1", "how the curve's fit ended", &flags)
            .with("flag_values", Attr::I32((0..6).collect()))
            .with("flag_meanings", Attr::Text(CurveFlag::NAMES.join(" "))),
    );
    Layout::new("fit map", &[("y", ny), ("x", nx)], vars)
}
