//! `image`: the document (`image.json`), the dataset (`image.nc`), the maps as AFM software
//! draws them (height, phase, E_dis; the error image of a PI scan), the first line's profile,
//! the setpoint study's plots and the text summary, for the ideal feedback and the PI scan.

use crate::error::number;
use crate::layout::columns::UnitNames;
use crate::layout::figure::{AfmImage, Figure, Plot, Series, Style};
use crate::report::image::{DomainContrast, Image, OperatingPoint, PeakForceImage, PeakForceTap};
use crate::report::image::{PiImage, SetpointStudy};
use crate::report::image_layout::{layout, number_summary, peakforce_layout, scan_layout, summary};
use crate::report::{Presentation, TextUnits};
use serde_json::{json, Value};

/// A profile's series: its label, style and value at pixel i of the first line.
type ProfileSeries<'a> = (&'a str, Style, &'a dyn Fn(usize) -> f64);

/// A map's stem, title, unit and value at (line j, pixel i).
type MapField<'a> = (&'a str, &'a str, &'a str, &'a dyn Fn(usize, usize) -> f64);

/// The map `stem` of one field over the image's grid `img` (dark = low, a colour bar in `unit`,
/// the scan's aspect ratio).
fn map_of(
    s: &mut Presentation,
    img: &Image,
    stem: &str,
    title: &str,
    unit: &str,
    value: &dyn Fn(usize, usize) -> f64,
) {
    map_on(s, (&img.x, &img.y), stem, title, unit, value);
}

/// The map `stem` of one field over the pixel centres x and line positions y ([`map_of`]).
fn map_on(
    s: &mut Presentation,
    (x, y): (&[f64], &[f64]),
    stem: &str,
    title: &str,
    unit: &str,
    value: &dyn Fn(usize, usize) -> f64,
) {
    let (nx, ny) = (x.len(), y.len());
    let values: Vec<f64> = (0..ny)
        .flat_map(|j| (0..nx).map(move |i| (j, i)))
        .map(|(j, i)| value(j, i))
        .collect();
    // the bar's description: the title's quantity (before any parenthesis) and the unit
    let quantity = title.split(" (").next().unwrap_or(title);
    let mut chars = quantity.chars();
    let quantity: String = chars
        .next()
        .map(|c| c.to_lowercase().chain(chars).collect())
        .unwrap_or_default();
    s.figure(
        stem,
        Plot::Image(AfmImage {
            title: title.to_string(),
            x: x.to_vec(),
            y: y.to_vec(),
            values,
            label: format!("{quantity} ({unit})"),
        }),
    );
}

/// The first line's profile: each series' (x, value) pairs where finite.
fn profile(s: &mut Presentation, img: &Image, title: String, series: &[ProfileSeries<'_>]) {
    let points = |f: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        (0..img.x.len())
            .map(|i| (img.x[i], f(i)))
            .filter(|p| p.1.is_finite())
            .collect()
    };
    let fig = Figure {
        title,
        x_label: "x (m)".into(),
        y_label: "height (m)".into(),
        series: series
            .iter()
            .enumerate()
            .map(|(k, (label, style, f))| Series {
                label: (*label).into(),
                points: points(*f),
                style: *style,
                color: k,
            })
            .collect(),
        shade: Vec::new(),
        y_min_span: 1e-12,
    };
    s.figure("image-profile", Plot::Lines(fig));
}

/// The setpoint study's plots: each domain's apparent height and phase lag against A/A0.
fn study_plots(s: &mut Presentation, study: &SetpointStudy) {
    type Get = fn(&DomainContrast) -> Vec<f64>;
    for (stem, title, label, get) in [
        (
            "image-setpoint-height",
            "Apparent height of each domain against the setpoint (ideal feedback)",
            "apparent height (m)",
            (|d: &DomainContrast| d.apparent_height.clone()) as Get,
        ),
        (
            "image-setpoint-phase",
            "Phase lag of each domain against the setpoint (ideal feedback)",
            "phase lag (°)",
            |d| d.phase_deg.clone(),
        ),
    ] {
        let fig = Figure {
            title: title.into(),
            x_label: "setpoint A/A0".into(),
            y_label: label.into(),
            series: study
                .domains
                .iter()
                .enumerate()
                .map(|(k, d)| Series {
                    label: d.name.clone(),
                    points: study
                        .ratio
                        .iter()
                        .copied()
                        .zip(get(d))
                        .filter(|p| p.1.is_finite())
                        .collect(),
                    style: Style::Line,
                    color: k,
                })
                .collect(),
            shade: Vec::new(),
            y_min_span: 0.0,
        };
        s.figure(stem, Plot::Lines(fig));
    }
}

/// The summary document of an ideal-feedback image at `setpoint` (`afmdyn image --json`,
/// `image.json`; the maps are `image.nc`'s): `image`, its maps summarised
/// (`crate::report::image_layout::summary`: per map `min`, `max`, `mean`; per code map the
/// pixels of each meaning); `feedback`, `setpoint`, `reference_z_c` (m), `materials` with their
/// operating points, `warnings`, and the setpoint study (`"setpoint_study"`) when one was
/// asked for. `ideal_document` is the document with every pixel.
pub fn ideal_summary(img: &Image, setpoint: f64, study: Option<&SetpointStudy>) -> Value {
    let num = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
    let mut json = json!({
        "image": summary(&layout(img, setpoint)),
        "feedback": "ideal",
        "setpoint": setpoint,
        "reference_z_c": num(img.reference),
        "materials": img.materials,
        "warnings": img.warnings,
    });
    if let Some(s) = study {
        json["setpoint_study"] = serde_json::to_value(s).expect("a study serialises");
    }
    json
}

/// The summary document of a PI-scanned image at `setpoint` (`afmdyn image --feedback pi
/// --json`, `image.json`; the maps are `image.nc`'s): `image`, the maps of trace, retrace and
/// ideal image summarised (`crate::report::image_layout::summary`); `feedback`, `scan` (the
/// settings), `artefacts` of `trace` and `retrace`, `setpoint`, `reference_z_c` (m),
/// `materials`, `warnings`. [`PiImage::document`] is the document with every pixel.
pub fn pi_summary(img: &PiImage, setpoint: f64) -> Value {
    let num = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
    json!({
        "image": summary(&scan_layout(img, setpoint)),
        "feedback": "pi",
        "scan": img.settings,
        "artefacts": {"trace": img.artefacts[0], "retrace": img.artefacts[1]},
        "setpoint": setpoint,
        "reference_z_c": num(img.ideal.reference),
        "materials": img.ideal.materials,
        "warnings": img.warnings,
    })
}

/// An ideal-feedback image at `setpoint` (and its setpoint study): the study's plots,
/// `image.json` (`document`: [`ideal_summary`], or [`ideal_document`]), `image.nc`, the maps `image-height`,
/// `image-phase`, `image-dissipation`, the profile `image-profile`, and the summary: every
/// material's operating point where it is first met, the study's table.
pub(crate) fn ideal(
    img: &Image,
    setpoint: f64,
    study: Option<&SetpointStudy>,
    document: &Value,
    u: TextUnits,
) -> Presentation {
    let mut s = Presentation::default();
    if let Some(st) = study {
        study_plots(&mut s, st);
    }
    s.json("image.json", document.clone());
    s.dataset("image.nc", layout(img, setpoint));
    let field = |get: fn(&OperatingPoint) -> f64| {
        move |j: usize, i: usize| img.point(j, i).map_or(f64::NAN, get)
    };
    let height = |j, i| img.apparent_height(j, i);
    let title = "Apparent height (ideal feedback)";
    map_of(&mut s, img, "image-height", title, "m", &height);
    let phase = field(|o| o.phase_deg);
    map_of(&mut s, img, "image-phase", "Phase lag", "°", &phase);
    let title = "Energy dissipated per period";
    let dissipation = field(|o| o.energy_dissipated);
    map_of(&mut s, img, "image-dissipation", title, "J", &dissipation);
    // the first line's profile: apparent and true height
    let title = format!(
        "Line profile at y = {} (setpoint A/A0 = {})",
        u.value(img.y[0], "m"),
        setpoint
    );
    let series: [ProfileSeries<'_>; 2] = [
        ("apparent height", Style::Line, &|i| {
            img.apparent_height(0, i)
        }),
        ("true height", Style::Dashed, &|i| img.pixels[0][i].height),
    ];
    profile(&mut s, img, title, &series);
    s.line(format!(
        "ideal-feedback image, {} × {} pixels, setpoint A/A0 = {}; z_c,ref = {} on the background",
        img.x.len(),
        img.y.len(),
        number(setpoint),
        u.value(img.reference, "m")
    ));
    let names = std::iter::once((None, "background")).chain(
        img.domain_names
            .iter()
            .enumerate()
            .map(|(k, n)| (Some(k), n.as_str())),
    );
    for (d, name) in names {
        // where this domain is first met in the image, its operating point there
        let first = img.pixels.iter().enumerate().find_map(|(j, line)| {
            line.iter()
                .position(|p| p.domain == d && p.point.is_some())
                .map(|i| (j, i))
        });
        let Some((j, i)) = first else {
            s.line(format!(
                "  {name}: not imaged (no operating point, or not in the map)"
            ));
            continue;
        };
        let o = img.point(j, i).expect("a point");
        s.line(format!(
            "  {}: z_c {} ({:?}), apparent height {} over true {}, phase {:.2}°, E_dis {}, peak force {}",
            name,
            u.value(o.z_c, "m"),
            o.regime,
            u.value(img.apparent_height(j, i), "m"),
            u.value(img.pixels[j][i].height, "m"),
            o.phase_deg,
            u.value(o.energy_dissipated, "J"),
            u.value(o.peak_force, "N")
        ));
    }
    if let Some(st) = study {
        s.line("setpoint study (apparent height, phase; a line engaged on the background):");
        for (k, r) in st.ratio.iter().enumerate() {
            let cells: Vec<String> = st
                .domains
                .iter()
                .map(|d| {
                    format!(
                        "{} {}, {:.1}°",
                        d.name,
                        u.value(d.apparent_height[k], "m"),
                        d.phase_deg[k]
                    )
                })
                .collect();
            s.line(format!("  A/A0 = {r:.3}: {}", cells.join("; ")));
        }
    }
    s
}

/// A PI-scanned image at `setpoint`: `image.json` (`document`: [`pi_summary`], or
/// [`PiImage::document`]),
/// `image.nc`, the trace's maps (recorded height, error image, phase, E_dis), the first line's
/// profile (trace, retrace, ideal and true height), and the summary: the settings and each
/// direction's artefacts.
pub(crate) fn pi(img: &PiImage, setpoint: f64, document: &Value, u: TextUnits) -> Presentation {
    let mut s = Presentation::default();
    s.json("image.json", document.clone());
    s.dataset("image.nc", scan_layout(img, setpoint));
    let grid = &img.ideal;
    let pixel = |j: usize, i: usize| &img.lines[j].trace[i];
    let maps: [MapField<'_>; 4] = [
        (
            "image-height",
            "Recorded height (PI feedback, trace)",
            "m",
            &|j, i| img.height(0, j, i),
        ),
        (
            "image-error",
            "Amplitude error A_sp - A (PI feedback, trace)",
            "m",
            &|j, i| pixel(j, i).tracking_error * img.length(),
        ),
        (
            "image-phase",
            "Phase lag (PI feedback, trace)",
            "°",
            &|j, i| pixel(j, i).phase.to_degrees(),
        ),
        (
            "image-dissipation",
            "Energy dissipated per period (PI feedback, trace)",
            "J",
            &|j, i| pixel(j, i).energy_dissipated * img.energy(),
        ),
    ];
    for (stem, title, unit, value) in maps {
        map_of(&mut s, grid, stem, title, unit, value);
    }
    let title = format!(
        "Line profile at y = {} (PI feedback, setpoint A/A0 = {setpoint})",
        u.value(grid.y[0], "m"),
    );
    let series: [ProfileSeries<'_>; 4] = [
        ("trace", Style::Line, &|i| img.height(0, 0, i)),
        ("retrace", Style::Line, &|i| img.height(1, 0, i)),
        ("ideal feedback", Style::Dashed, &|i| {
            grid.apparent_height(0, i)
        }),
        ("true height", Style::Dashed, &|i| grid.pixels[0][i].height),
    ];
    profile(&mut s, grid, title, &series);
    let st = img.settings;
    s.line(format!(
        "PI-feedback image, {} × {} pixels, setpoint A/A0 = {}: scan rate {}, K_P {}, K_I {}, \
         lock-in time constant {}; {} drive periods per pixel ({}), {} to engage each line",
        grid.x.len(),
        grid.y.len(),
        number(setpoint),
        u.value(st.scan_rate, "Hz"),
        number(st.proportional_gain),
        u.value(st.integral_gain, "1/s"),
        u.value(st.time_constant, "s"),
        st.periods_per_pixel,
        u.value(st.pixel_time, "s"),
        st.engage_periods
    ));
    if let (Some(t), Some(seed)) = (st.temperature, st.seed) {
        s.line(format!(
            "  thermal noise at {} K (seed {seed}): the lever's thermal force on every line",
            number(t)
        ));
    }
    for (name, art) in ["trace", "retrace"].iter().zip(img.artefacts) {
        s.line(format!(
            "  {name}: height error against the ideal image RMS {}, largest {}; overshoot {}; \
             error image RMS {}; {} pixel(s) lost contact; {} period(s) at the output limit",
            u.value(art.height_rms_error, "m"),
            u.value(art.height_max_error, "m"),
            u.value(art.overshoot, "m"),
            u.value(art.tracking_error_rms, "m"),
            art.lost_contact_pixels,
            art.saturated_periods
        ));
    }
    s
}

/// The summary document of a PeakForce image (`afmdyn image --mode peakforce --json`,
/// `image.json`; the maps are `image.nc`'s): `image`, its maps summarised
/// ([`crate::report::image_layout::summary`]); `mode`, `feedback`, `setpoint` (N),
/// `reference_z_c` (m), `materials` (each with its true modulus and engaged operating point,
/// as [`PeakForceImage::document_head`], and its pixels: `pixels`, `taps` the steady taps of
/// the continuations into them, `reengaged`, and `maps`, each of `PF_FIELDS` summarised
/// over them as [`number_summary`]), `taps`, `warnings`. [`PeakForceImage::document`] is the
/// document with every pixel.
pub(crate) fn peakforce_summary(img: &PeakForceImage) -> Value {
    let mut doc = img.document_head();
    doc["image"] = summary(&peakforce_layout(img));
    let cells: Vec<(usize, usize)> = (0..img.y.len())
        .flat_map(|j| (0..img.x.len()).map(move |i| (j, i)))
        .collect();
    for (m, entry) in doc["materials"]
        .as_array_mut()
        .expect("the materials' list")
        .iter_mut()
        .enumerate()
    {
        let mine: Vec<(usize, usize)> = cells
            .iter()
            .copied()
            .filter(|&(j, i)| img.material[j][i] == m)
            .collect();
        let pixels = || mine.iter().map(|&(j, i)| &img.pixels[j][i]);
        let mut maps = serde_json::Map::new();
        for c in img.fields() {
            let values = mine.iter().map(|cell| c.number(img, cell));
            let units = c.unit.name(&UnitNames::si_or_model(true));
            maps.insert(c.name.into(), number_summary(units, values));
        }
        entry["pixels"] = json!(mine.len());
        entry["taps"] = json!(pixels().map(|p| p.evaluations).sum::<usize>());
        entry["reengaged"] = json!(pixels().filter(|p| p.reengaged).count());
        entry["maps"] = Value::Object(maps);
    }
    doc
}

/// A material's engaged dissipation per cycle for the summary: 0 where it is round-off, within
/// 1e-9 of the contact's work scale (peak force × deformation: an elastic sample's orbit
/// closes its energy to ~1e-12 of it), as a single tap's says within its energy balance's
/// residual (issue 77: "dissipation -3.36e-12 aJ" was printed on an elastic sample).
fn dissipation(t: &PeakForceTap, u: &TextUnits) -> String {
    let scale = (t.peak_force * t.deformation).abs();
    if t.dissipation.abs() <= 1e-9 * scale {
        format!(
            "0 (round-off: below 1e-9 of peak force × deformation, {})",
            u.value(scale, "J")
        )
    } else {
        u.value(t.dissipation, "J")
    }
}

/// A PeakForce image: `image.json` (`document`: `peakforce_summary`, or
/// [`PeakForceImage::document`]), `image.nc`, the maps `image-height`, `image-modulus`,
/// `image-adhesion`, `image-deformation`, `image-dissipation` (and with a temperature
/// `image-peak-force-noise`), and the summary: every material's engaged operating point beside
/// its true modulus (and its noise).
pub(crate) fn peakforce(img: &PeakForceImage, document: &Value, u: TextUnits) -> Presentation {
    let mut s = Presentation::default();
    s.json("image.json", document.clone());
    s.dataset("image.nc", peakforce_layout(img));
    for (stem, field, title, unit) in [
        (
            "image-height",
            "height",
            "Apparent height (ideal peak-force feedback)",
            "m",
        ),
        (
            "image-modulus",
            "modulus_dmt",
            "Modulus (DMT fit, PF-QNM)",
            "Pa",
        ),
        ("image-adhesion", "adhesion", "Adhesion", "N"),
        ("image-deformation", "deformation", "Deformation", "m"),
        (
            "image-dissipation",
            "dissipation",
            "Dissipation per cycle",
            "J",
        ),
    ]
    .into_iter()
    .chain(img.temperature.map(|_| {
        let title = "Peak-force noise σ per cycle (thermal)";
        ("image-peak-force-noise", "peak_force_noise", title, "N")
    })) {
        let value = |j: usize, i: usize| img.value(field, j, i);
        map_on(&mut s, (&img.x, &img.y), stem, title, unit, &value);
    }
    s.line(format!(
        "PeakForce image (ideal feedback), {} × {} pixels, peak-force setpoint {}; z_c,ref = {} \
         on the background; {} steady taps",
        img.x.len(),
        img.y.len(),
        u.value(img.setpoint, "N"),
        u.value(img.reference, "m"),
        img.taps()
    ));
    for m in &img.materials {
        match &m.engaged {
            Some(t) => s.line(format!(
                "  {}: z_c {}, modulus_dmt {} (true E* {}), adhesion {}, deformation {}, \
                 dissipation {}",
                m.name,
                u.value(t.z_c, "m"),
                u.value(t.modulus_dmt, "Pa"),
                u.value(m.true_modulus, "Pa"),
                u.value(t.adhesion, "N"),
                u.value(t.deformation, "m"),
                dissipation(t, &u)
            )),
            None => s.line(format!(
                "  {}: not imaged ({})",
                m.name,
                m.message.as_deref().unwrap_or("no operating point")
            )),
        }
        if let (Some(n), Some(t)) = (m.engaged.and_then(|e| e.noise), img.temperature) {
            s.line(format!(
                "  {}: thermal noise at {} K, per cycle: σ(peak force) = {}, σ(deformation) = {}",
                m.name,
                number(t),
                u.value(n.peak_force, "N"),
                u.value(n.deformation, "m")
            ));
        }
    }
    s
}
