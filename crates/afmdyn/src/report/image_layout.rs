//! The layouts of an image, declared beside the image's types as a chart's beside the chart
//! (a layout module knows no request): `image.nc` of `afmdyn image --out DIR` ([`crate::layout::netcdf::write`])
//! and the variables' units and long names of Python's `afmdyn.image` Dataset — the
//! ideal-feedback image ([`crate::report::image::Image`], [`layout`]) and the PI scan
//! ([`crate::report::image::PiImage`], [`scan_layout`]).

use super::image::SCAN_FIELDS;
use super::image::{scan_cells, Image, PeakForceImage, PiImage, Regime, FIELDS};
use crate::layout::columns::{self, UnitNames};
use crate::layout::{Attr, Layout, Values, Variable};

/// The names of the images' units: SI.
const SI: UnitNames = UnitNames::si_or_model(true);

/// The codes of `regime`: 0 where the setpoint is not reached, 1 attractive, 2 repulsive (CF
/// `flag_values` and `flag_meanings`).
pub(crate) const REGIME_FLAGS: [(i32, &str); 3] =
    [(0, "not_reached"), (1, "attractive"), (2, "repulsive")];

/// A name as one word of a CF `flag_meanings` list (blanks become `_`).
fn word(name: &str) -> String {
    name.split_whitespace().collect::<Vec<_>>().join("_")
}

/// `v` with the CF `flag_values` 0, 1, … and `flag_meanings` `names`.
fn flags(v: Variable, names: Vec<String>) -> Variable {
    let codes = (0..names.len() as i32).collect();
    v.with("flag_values", Attr::I32(codes))
        .with("flag_meanings", Attr::Text(names.join(" ")))
}

/// The regime codes [`REGIME_FLAGS`] over (y, x).
fn regime_variable(name: &str, codes: &[i32]) -> Variable {
    flags(
        Variable::i32(
            name,
            &["y", "x"],
            "1",
            "regime of the operating point (mean tip–sample force attractive or repulsive)",
            codes,
        ),
        REGIME_FLAGS.iter().map(|(_, n)| n.to_string()).collect(),
    )
}

/// The material codes (indices into the image's materials, 0 the background) over (y, x).
fn material_variable(img: &Image, name: &str, codes: &[i32]) -> Variable {
    flags(
        Variable::i32(name, &["y", "x"], "1", "material of the pixel", codes),
        img.materials.iter().map(|m| word(&m.name)).collect(),
    )
}

/// The domain codes over (y, x): 0 the background, k the map's k-th domain.
fn domain_variable(img: &Image) -> Variable {
    let (nx, ny) = (img.x.len(), img.y.len());
    let domain: Vec<i32> = (0..ny)
        .flat_map(|j| (0..nx).map(move |i| (j, i)))
        .map(|(j, i)| img.pixels[j][i].domain.map_or(0, |k| k as i32 + 1))
        .collect();
    domain_codes(&domain, &img.domain_names)
}

/// The domain codes `domain` over (y, x) with the map's domain names `names` as their meanings.
fn domain_codes(domain: &[i32], names: &[String]) -> Variable {
    flags(
        Variable::i32(
            "domain",
            &["y", "x"],
            "1",
            "domain of the sample map on top at the pixel",
            domain,
        ),
        std::iter::once("background".to_string())
            .chain(names.iter().map(|n| word(n)))
            .collect(),
    )
}

/// The image's layout: coordinates `x`, `y` (m: pixel centres and line positions); over
/// (y, x) the `FIELDS` as 64-bit floats in SI (NaN where the setpoint is not reached),
/// `regime` (codes [`REGIME_FLAGS`]), `material` (index into the image's materials, 0 the
/// background) and `domain` (0 the background, k the map's k-th domain), each 32-bit integer
/// codes with their CF `flag_values` and `flag_meanings`; the scalars `setpoint` (A_sp/A₀, as
/// given) and `reference_z_c` (m).
pub(crate) fn layout(img: &Image, setpoint: f64) -> Layout {
    let (nx, ny) = (img.x.len(), img.y.len());
    let cells = || (0..ny).flat_map(move |j| (0..nx).map(move |i| (j, i)));
    let mut variables = vec![
        Variable::f64("x", &["x"], "m", "pixel centre x", &img.x),
        Variable::f64("y", &["y"], "m", "line position y", &img.y),
    ];
    let fields = &columns::cells((ny, nx));
    variables.extend(columns::variables(&FIELDS, img, fields, &["y", "x"], &SI));
    let regime: Vec<i32> = cells()
        .map(|(j, i)| match img.point(j, i).map(|o| o.regime) {
            None => REGIME_FLAGS[0].0,
            Some(Regime::Attractive) => REGIME_FLAGS[1].0,
            Some(Regime::Repulsive) => REGIME_FLAGS[2].0,
        })
        .collect();
    variables.push(regime_variable("regime", &regime));
    let material: Vec<i32> = cells()
        .map(|(j, i)| img.pixels[j][i].material as i32)
        .collect();
    variables.push(material_variable(img, "material", &material));
    variables.push(domain_variable(img));
    variables.push(Variable::f64(
        "setpoint",
        &[],
        "1",
        "amplitude setpoint A_sp/A0",
        &[setpoint],
    ));
    variables.push(Variable::f64(
        "reference_z_c",
        &[],
        "m",
        "rest distance z_c,ref engaged on the background (the zero of the apparent height)",
        &[img.reference],
    ));
    Layout::new(
        format!("afmdyn ideal-feedback AM-AFM image at the setpoint A/A0 = {setpoint}"),
        &[("y", ny), ("x", nx)],
        variables,
    )
}

/// The PI scan's layout: coordinates `x`, `y` (m); over (y, x) the `SCAN_FIELDS` of the
/// trace and, suffixed `_retrace`, of the retrace (64-bit floats in SI), `lost_contact` and
/// `lost_contact_retrace` (flags), `regime` and `material` of each direction (codes as in
/// [`layout`]), `ideal_height` (m, the ideal image's apparent height), `true_height` (m) and
/// `domain`; the scalars `setpoint`, `reference_z_c` (m), `scan_rate` (Hz),
/// `proportional_gain` (1), `integral_gain` (1/s) and `time_constant` (s).
pub(crate) fn scan_layout(img: &PiImage, setpoint: f64) -> Layout {
    let g = &img.ideal;
    let (nx, ny) = (g.x.len(), g.y.len());
    let cells = || (0..ny).flat_map(move |j| (0..nx).map(move |i| (j, i)));
    let grid: &[&str] = &["y", "x"];
    let mut variables = vec![
        Variable::f64("x", &["x"], "m", "pixel centre x", &g.x),
        Variable::f64("y", &["y"], "m", "line position y", &g.y),
    ];
    for (d, suffix) in [(0, ""), (1, "_retrace")] {
        variables.extend(direction_variables(img, d, suffix));
    }
    let ideal: Vec<f64> = cells().map(|(j, i)| g.apparent_height(j, i)).collect();
    variables.push(Variable::f64(
        "ideal_height",
        grid,
        "m",
        "apparent height under the ideal feedback h + z_c − z_c,ref",
        &ideal,
    ));
    let truth: Vec<f64> = cells().map(|(j, i)| g.pixels[j][i].height).collect();
    variables.push(Variable::f64(
        "true_height",
        grid,
        "m",
        "true height of the sample map",
        &truth,
    ));
    variables.push(domain_variable(g));
    let s = &img.settings;
    for (name, units, long_name, v) in [
        ("setpoint", "1", "amplitude setpoint A_sp/A0", setpoint),
        (
            "reference_z_c",
            "m",
            "rest distance z_c,ref engaged on the background under the ideal feedback (the \
             zero of the heights)",
            g.reference,
        ),
        (
            "scan_rate",
            "Hz",
            "lines (trace and retrace) per second",
            s.scan_rate,
        ),
        (
            "proportional_gain",
            "1",
            "K_P of the z controller",
            s.proportional_gain,
        ),
        (
            "integral_gain",
            "1/s",
            "K_I of the z controller",
            s.integral_gain,
        ),
        (
            "time_constant",
            "s",
            "time constant of the lock-in's low-pass",
            s.time_constant,
        ),
    ] {
        variables.push(Variable::f64(name, &[], units, long_name, &[v]));
    }
    Layout::new(
        format!("afmdyn PI-feedback AM-AFM scan at the setpoint A/A0 = {setpoint}"),
        &[("y", ny), ("x", nx)],
        variables,
    )
}

/// The maps of the PI scan's direction `d` (0 the trace, 1 the retrace, its names suffixed
/// `suffix`) over (y, x): the [`SCAN_FIELDS`], `lost_contact`, `regime` and `material`.
fn direction_variables(img: &PiImage, d: usize, suffix: &str) -> Vec<Variable> {
    let g = &img.ideal;
    let (nx, ny) = (g.x.len(), g.y.len());
    let cells = || (0..ny).flat_map(move |j| (0..nx).map(move |i| (j, i)));
    let grid: &[&str] = &["y", "x"];
    let pixel = |j: usize, i: usize| {
        if d == 0 {
            &img.lines[j].trace[i]
        } else {
            &img.lines[j].retrace[i]
        }
    };
    let fields = &scan_cells(d, (ny, nx));
    let mut variables = columns::variables(&SCAN_FIELDS, img, fields, grid, &SI);
    for v in &mut variables {
        v.name.push_str(suffix);
    }
    let regime: Vec<i32> = cells()
        .map(|(j, i)| {
            if crate::report::regime(pixel(j, i).mean_deflection) == "attractive" {
                REGIME_FLAGS[1].0
            } else {
                REGIME_FLAGS[2].0
            }
        })
        .collect();
    variables.push(regime_variable(&format!("regime{suffix}"), &regime));
    let material: Vec<i32> = cells().map(|(j, i)| pixel(j, i).material as i32).collect();
    variables.push(material_variable(
        g,
        &format!("material{suffix}"),
        &material,
    ));
    variables
}

/// A PeakForce image's layout (`image.nc` of `afmdyn image --mode peakforce`): coordinates
/// `x`, `y` (m); over (y, x) the maps ([`PeakForceImage::fields`]) as 64-bit floats in SI (NaN where the setpoint
/// is not reached), `evaluations` (steady taps computed per pixel), `material` and `domain`
/// (32-bit codes with their CF `flag_values` and `flag_meanings`, as in [`layout`]); the scalars
/// `setpoint` (N) and `reference_z_c` (m).
pub(crate) fn peakforce_layout(img: &PeakForceImage) -> Layout {
    let (nx, ny) = (img.x.len(), img.y.len());
    let cells = || (0..ny).flat_map(move |j| (0..nx).map(move |i| (j, i)));
    let grid: &[&str] = &["y", "x"];
    let mut variables = vec![
        Variable::f64("x", &["x"], "m", "pixel centre x", &img.x),
        Variable::f64("y", &["y"], "m", "line position y", &img.y),
    ];
    let fields = &columns::cells((ny, nx));
    variables.extend(columns::variables(img.fields(), img, fields, grid, &SI));
    let evaluations: Vec<i32> = cells()
        .map(|(j, i)| img.pixels[j][i].evaluations as i32)
        .collect();
    variables.push(Variable::i32(
        "evaluations",
        grid,
        "1",
        "steady taps computed for the pixel (0: the previous pixel's orbit or the engage kept)",
        &evaluations,
    ));
    let material: Vec<i32> = cells().map(|(j, i)| img.material[j][i] as i32).collect();
    variables.push(flags(
        Variable::i32("material", grid, "1", "material of the pixel", &material),
        img.materials.iter().map(|m| word(&m.name)).collect(),
    ));
    let domain: Vec<i32> = cells()
        .map(|(j, i)| img.domain[j][i].map_or(0, |k| k as i32 + 1))
        .collect();
    variables.push(domain_codes(&domain, &img.domain_names));
    variables.push(Variable::f64(
        "setpoint",
        &[],
        "N",
        "peak-force setpoint",
        &[img.setpoint],
    ));
    variables.push(Variable::f64(
        "reference_z_c",
        &[],
        "m",
        "mean rest separation z_c,ref engaged on the background (the zero of the apparent \
         height)",
        &[img.reference],
    ));
    Layout::new(
        format!(
            "afmdyn ideal-feedback PeakForce image at the peak force {} N",
            img.setpoint
        ),
        &[("y", ny), ("x", nx)],
        variables,
    )
}

/// A number map's summary in an image's JSON document: `units`, the `min`, `max` and `mean`
/// of the finite ones of `values` (null where there is none) and `finite` (their number).
pub(crate) fn number_summary(units: &str, values: impl Iterator<Item = f64>) -> serde_json::Value {
    use serde_json::{json, Value};
    let num = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
    let finite: Vec<f64> = values.filter(|x| x.is_finite()).collect();
    let n = finite.len();
    let min = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let max = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mean = finite.iter().sum::<f64>() / n as f64;
    json!({"units": units, "min": num(min), "max": num(max), "mean": num(mean), "finite": n})
}

/// The maps of an image's layout ([`layout`], [`scan_layout`]) summarised for its JSON document
/// (the maps themselves are the dataset's, `image.nc`): `pixels` and `lines`, `x` and `y` (m,
/// the first and last pixel centre and line position), and under `maps` every variable over
/// (y, x): a float map's `units`, `min`, `max` and `mean` over its finite values (null where it
/// has none) and `finite` (their number); a flag or code map's count of pixels per meaning
/// (`counts`).
pub(crate) fn summary(layout: &Layout) -> serde_json::Value {
    use serde_json::{json, Map, Value};
    let num = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
    let ends = |name: &str| -> Value {
        let values = layout.variables.iter().find(|v| v.name == name);
        match values.map(|v| &v.values) {
            Some(Values::F64(c)) => json!([
                num(c.first().copied().unwrap_or(f64::NAN)),
                num(c.last().copied().unwrap_or(f64::NAN))
            ]),
            _ => Value::Null,
        }
    };
    let length = |name: &str| {
        layout
            .dims
            .iter()
            .find(|(n, _)| n == name)
            .map_or(0, |(_, l)| *l)
    };
    let mut maps = Map::new();
    for v in layout.variables.iter().filter(|v| v.dims == ["y", "x"]) {
        let entry = match &v.values {
            Values::F64(values) => number_summary(&v.units, values.iter().copied()),
            Values::I32(codes) => {
                let meanings = v.attrs.iter().find_map(|(k, a)| match (k.as_str(), a) {
                    ("flag_meanings", Attr::Text(t)) => Some(t.clone()),
                    _ => None,
                });
                let words: Vec<String> = meanings
                    .unwrap_or_default()
                    .split_whitespace()
                    .map(str::to_string)
                    .collect();
                let mut counts = Map::new();
                for &c in codes {
                    let word = usize::try_from(c)
                        .ok()
                        .and_then(|k| words.get(k).cloned())
                        .unwrap_or_else(|| c.to_string());
                    let n = counts.entry(word).or_insert(json!(0));
                    *n = json!(n.as_u64().unwrap_or(0) + 1);
                }
                json!({"counts": counts})
            }
            Values::Bool(flags) => {
                let set = flags.iter().filter(|&&b| b).count();
                json!({"counts": {"true": set, "false": flags.len() - set}})
            }
            _ => continue,
        };
        maps.insert(v.name.clone(), entry);
    }
    json!({
        "pixels": length("x"),
        "lines": length("y"),
        "x": ends("x"),
        "y": ends("y"),
        "maps": maps,
    })
}
