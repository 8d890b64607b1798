//! The layout of an ideal-feedback image ([`crate::request::image::Image`]): `image.nc` of
//! `afmdyn image --out DIR` ([`super::netcdf::write`]) and the variables' units and long
//! names of Python's `afmdyn.image` Dataset.

use super::{Attr, Layout, Variable};
use crate::request::image::{Image, OperatingPoint, Regime};

/// The numeric maps of an image over (y, x): name, units, long name, as the JSON document's
/// `image` block names them ([`Image::document`]).
pub const FIELDS: [(&str, &str, &str); 9] = [
    (
        "height",
        "m",
        "apparent height h + z_c − z_c,ref (ideal feedback)",
    ),
    ("true_height", "m", "true height of the sample map"),
    ("z_c", "m", "rest distance z_c the feedback holds"),
    ("amplitude", "m", "amplitude (the setpoint where reached)"),
    ("phase_deg", "degree", "phase lag behind the drive"),
    (
        "energy_dissipated",
        "J",
        "energy dissipated per drive period",
    ),
    ("virial", "J", "virial of the tip–sample force"),
    ("peak_force", "N", "largest tip–sample force"),
    ("indentation", "m", "largest indentation"),
];

/// The codes of `regime`: 0 where the setpoint is not reached, 1 attractive, 2 repulsive (CF
/// `flag_values` and `flag_meanings`).
pub const REGIME_FLAGS: [(i32, &str); 3] =
    [(0, "not_reached"), (1, "attractive"), (2, "repulsive")];

/// A name as one word of a CF `flag_meanings` list (blanks become `_`).
fn word(name: &str) -> String {
    name.split_whitespace().collect::<Vec<_>>().join("_")
}

/// The image's layout: coordinates `x`, `y` (m: pixel centres and line positions); over
/// (y, x) the [`FIELDS`] as 64-bit floats in SI (NaN where the setpoint is not reached),
/// `regime` (codes [`REGIME_FLAGS`]), `material` (index into the image's materials, 0 the
/// background) and `domain` (0 the background, k the map's k-th domain), each 32-bit integer
/// codes with their CF `flag_values` and `flag_meanings`; the scalars `setpoint` (A_sp/A₀, as
/// given) and `reference_z_c` (m).
pub fn layout(img: &Image, setpoint: f64) -> Layout {
    let (nx, ny) = (img.x.len(), img.y.len());
    let cells = || (0..ny).flat_map(move |j| (0..nx).map(move |i| (j, i)));
    let point = |get: fn(&OperatingPoint) -> f64| -> Vec<f64> {
        cells()
            .map(|(j, i)| img.point(j, i).map_or(f64::NAN, get))
            .collect()
    };
    let grid: &[&str] = &["y", "x"];
    let mut variables = vec![
        Variable::f64("x", &["x"], "m", "pixel centre x", &img.x),
        Variable::f64("y", &["y"], "m", "line position y", &img.y),
    ];
    for (name, units, long_name) in FIELDS {
        let values = match name {
            "height" => cells().map(|(j, i)| img.apparent_height(j, i)).collect(),
            "true_height" => cells().map(|(j, i)| img.pixels[j][i].height).collect(),
            "z_c" => point(|o| o.z_c),
            "amplitude" => point(|o| o.amplitude),
            "phase_deg" => point(|o| o.phase_deg),
            "energy_dissipated" => point(|o| o.energy_dissipated),
            "virial" => point(|o| o.virial),
            "peak_force" => point(|o| o.peak_force),
            _ => point(|o| o.indentation),
        };
        variables.push(Variable::f64(name, grid, units, long_name, &values));
    }
    let flags = |v: Variable, names: Vec<String>| {
        let codes = (0..names.len() as i32).collect();
        v.with("flag_values", Attr::I32(codes))
            .with("flag_meanings", Attr::Text(names.join(" ")))
    };
    let regime: Vec<i32> = cells()
        .map(|(j, i)| match img.point(j, i).map(|o| o.regime) {
            None => REGIME_FLAGS[0].0,
            Some(Regime::Attractive) => REGIME_FLAGS[1].0,
            Some(Regime::Repulsive) => REGIME_FLAGS[2].0,
        })
        .collect();
    variables.push(flags(
        Variable::i32(
            "regime",
            grid,
            "1",
            "regime of the operating point (mean tip–sample force attractive or repulsive)",
            &regime,
        ),
        REGIME_FLAGS.iter().map(|(_, n)| n.to_string()).collect(),
    ));
    let material: Vec<i32> = cells()
        .map(|(j, i)| img.pixels[j][i].material as i32)
        .collect();
    variables.push(flags(
        Variable::i32("material", grid, "1", "material of the pixel", &material),
        img.materials.iter().map(|m| word(&m.name)).collect(),
    ));
    let domain: Vec<i32> = cells()
        .map(|(j, i)| img.pixels[j][i].domain.map_or(0, |k| k as i32 + 1))
        .collect();
    variables.push(flags(
        Variable::i32(
            "domain",
            grid,
            "1",
            "domain of the sample map on top at the pixel",
            &domain,
        ),
        std::iter::once("background".to_string())
            .chain(img.domain_names.iter().map(|n| word(n)))
            .collect(),
    ));
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
