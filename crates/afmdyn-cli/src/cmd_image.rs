//! `afmdyn image`: the AM-AFM image of a heterogeneous sample under an ideal amplitude feedback,
//! or scanned in the time domain under a lock-in and a PI z controller (`--feedback pi`).
//! The sample map, the operating points and the scan are the library's
//! ([`afmdyn::request::image`], [`afmdyn::request::image_scan`]); this front end reads the two
//! files, maps the flags, and writes `image.json`, `image.nc` (the library's layouts,
//! [`afmdyn::request::image_layout`]), the maps (height, phase, E_dis; the error image of a PI
//! scan) and the line profile.

use crate::error::CliError;
use crate::output::{si_value, write_document, write_layout, OutDir};
use crate::plot::{save, save_image, AfmImage, Figure, Series, Style};
use afmdyn::request::image::{
    image, setpoint_study, study_ratios, Image, ImageRequest, SampleMap, SetpointStudy,
};
use afmdyn::request::image_scan::{PiImage, PiScan, ScanStudy};
use clap::Args;
use std::path::PathBuf;

/// `afmdyn image` flags.
#[derive(Debug, Args)]
pub struct ImageArgs {
    /// The probe file (SI): the lever, tip, drive and the background sample
    #[arg(long, value_name = "PROBE.toml")]
    probe: PathBuf,
    /// A cantilever of the library (`afmdyn cantilevers` lists them) for the probe file, as for
    /// every command taking --probe
    #[arg(long, value_name = "NAME")]
    cantilever: Option<String>,
    /// The fluid around the lever, over the probe file's [medium]: water, air or none, as for
    /// every command taking --probe
    #[allow(rustdoc::broken_intra_doc_links)]
    #[arg(long, value_name = "NAME")]
    medium: Option<String>,
    /// The sample map: size = [Lx, Ly] (m) and [[domain]] entries (name, x, y, height,
    /// [domain.sample])
    #[arg(long, value_name = "S.toml")]
    sample: PathBuf,
    /// Amplitude setpoint A_sp/A0 in (0, 1)
    #[arg(long)]
    setpoint: f64,
    /// Feedback: ideal (an operating point of the local material at every pixel) or pi (a
    /// time-domain scan, trace and retrace, under a lock-in and a PI z controller)
    #[arg(long, default_value = "ideal")]
    feedback: String,
    /// PI scan: lines (trace and retrace) per second, Hz (default: a pixel lasts 5 loop time
    /// constants 1/K_I)
    #[arg(long, value_name = "HZ")]
    scan_rate: Option<f64>,
    /// PI scan: the gains K_P (m/m) and K_I (1/s) (default: K_P = 0, K_I = 1/(4(τ_c + τ_L)),
    /// τ_c = 2Q/ω0)
    #[arg(
        long,
        value_name = "P,I",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    gains: Option<Vec<f64>>,
    /// PI scan: the lock-in's low-pass time constant, s (default: τ_c/4)
    #[arg(long, value_name = "S")]
    time_constant: Option<f64>,
    /// PI scan: worker threads, one line per task (default: all cores)
    #[arg(long)]
    threads: Option<usize>,
    /// PI scan: continue an interrupted scan; refused unless the other arguments are those of
    /// the interrupted run (recorded in OUT/.image.run.json)
    #[arg(long)]
    resume: bool,
    /// Testing: abort the process, as if killed, after this many lines are stored
    #[arg(long, hide = true)]
    abort_after: Option<usize>,
    /// Pixels per line [default: 64]
    #[arg(long)]
    pixels: Option<usize>,
    /// Lines (default: as many as pixels, 1 for a line map with Ly = 0)
    #[arg(long)]
    lines: Option<usize>,
    /// Points of each material's approach curve (the probe's default z_c range) [default: 120]
    #[arg(long)]
    curve_points: Option<usize>,
    /// Also the setpoint study FROM:TO:N (e.g. 0.2:0.95:16): every domain's apparent height,
    /// phase and E_dis at N setpoints, as a line engaged on the background meets it (the
    /// contrast inversion); "setpoint_study" in the document and two plots
    #[arg(long, value_name = "FROM:TO:N")]
    setpoint_study: Option<String>,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/image")]
    out: PathBuf,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// The map of one field over the image as AFM software draws it (dark = low, a colour bar in
/// `unit`, the scan's aspect ratio: [`crate::plot::AfmImage`]).
fn map_of(
    out: &OutDir,
    img: &Image,
    stem: &str,
    title: &str,
    unit: &str,
    value: &dyn Fn(usize, usize) -> f64,
) -> Result<(), CliError> {
    let (nx, ny) = (img.x.len(), img.y.len());
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
    save_image(
        out.path(),
        stem,
        &AfmImage {
            title: title.to_string(),
            x: img.x.clone(),
            y: img.y.clone(),
            values,
            label: format!("{quantity} ({unit})"),
        },
    )?;
    Ok(())
}

/// The setpoint study's plots: each domain's apparent height and phase lag against A/A0.
fn study_plots(out: &OutDir, s: &SetpointStudy) -> Result<(), CliError> {
    for (stem, title, label, get) in [
        (
            "image-setpoint-height",
            "Apparent height of each domain against the setpoint (ideal feedback)",
            "apparent height (m)",
            (|d: &afmdyn::request::image::DomainContrast| d.apparent_height.clone())
                as fn(&afmdyn::request::image::DomainContrast) -> Vec<f64>,
        ),
        (
            "image-setpoint-phase",
            "Phase lag of each domain against the setpoint (ideal feedback)",
            "phase lag (°)",
            |d| d.phase_deg.clone(),
        ),
    ] {
        save(
            out.path(),
            stem,
            &Figure {
                title: title.into(),
                x_label: "setpoint A/A0".into(),
                y_label: label.into(),
                series: s
                    .domains
                    .iter()
                    .enumerate()
                    .map(|(k, d)| Series {
                        label: d.name.clone(),
                        points: s
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
            },
        )?;
    }
    Ok(())
}

/// Run `afmdyn image`.
pub fn image_cmd(a: &ImageArgs) -> Result<(), CliError> {
    let pi = match a.feedback.as_str() {
        "ideal" => {
            for (set, flag) in [
                (a.scan_rate.is_some(), "--scan-rate"),
                (a.gains.is_some(), "--gains"),
                (a.time_constant.is_some(), "--time-constant"),
                (a.threads.is_some(), "--threads"),
                (a.resume, "--resume"),
            ] {
                if set {
                    return Err(CliError::Input(format!(
                        "{flag}: only with --feedback pi (the ideal feedback has no loop)"
                    )));
                }
            }
            None
        }
        "pi" => {
            if a.setpoint_study.is_some() {
                return Err(CliError::Input(
                    "--setpoint-study: only with --feedback ideal (a study of exact operating \
                     points)"
                        .into(),
                ));
            }
            Some(PiScan {
                scan_rate: a.scan_rate,
                gains: match a.gains.as_deref() {
                    None => None,
                    Some([p, i]) => Some((*p, *i)),
                    Some(g) => {
                        return Err(CliError::Input(format!(
                            "--gains {g:?}: must be two numbers P,I (K_P in m/m, K_I in 1/s)"
                        )))
                    }
                },
                time_constant: a.time_constant,
            })
        }
        other => {
            return Err(CliError::Input(format!(
                "feedback = {other}: must be ideal or pi"
            )))
        }
    };
    let text = crate::args::probe_text(&a.probe, a.cantilever.as_deref(), a.medium.as_deref())?;
    let table = afmdyn::probe::Probe::table(&text, &a.probe.display().to_string())?;
    // a sample map's refusals (its file, its height map's) name the option
    let map = SampleMap::load(&a.sample).map_err(|e| match e {
        afmdyn::SimError::Probe(m) => CliError::Input(format!("--sample {m}")),
        e => e.into(),
    })?;
    let req = ImageRequest::with(a.setpoint, a.pixels, a.lines, a.curve_points);
    req.validate(&map)?;
    let ratios = a.setpoint_study.as_deref().map(study_ratios).transpose()?;
    if let Some(scan) = pi {
        return pi_cmd(a, &table, &map, &req, &scan);
    }
    let out = OutDir::lock(&a.out)?;
    let img = image(&table, &map, &req)?;
    let mut json = img.document(a.setpoint);
    let study = match &ratios {
        Some(r) => Some(setpoint_study(&table, &map, r, req.curve_points)?),
        None => None,
    };
    if let Some(s) = &study {
        json["setpoint_study"] = serde_json::to_value(s).expect("a study serialises");
        study_plots(&out, s)?;
    }
    write_document(&out, "image.json", &json)?;
    write_layout(
        &out.join("image.nc"),
        &afmdyn::request::image_layout::layout(&img, a.setpoint),
    )?;
    let img = &img;
    let field = |get: fn(&afmdyn::request::image::OperatingPoint) -> f64| {
        move |j: usize, i: usize| img.point(j, i).map_or(f64::NAN, get)
    };
    map_of(
        &out,
        img,
        "image-height",
        "Apparent height (ideal feedback)",
        "m",
        &|j, i| img.apparent_height(j, i),
    )?;
    map_of(
        &out,
        img,
        "image-phase",
        "Phase lag",
        "°",
        &field(|o| o.phase_deg),
    )?;
    map_of(
        &out,
        img,
        "image-dissipation",
        "Energy dissipated per period",
        "J",
        &field(|o| o.energy_dissipated),
    )?;
    // the first line's profile: apparent and true height
    let profile = |f: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        (0..img.x.len())
            .map(|i| (img.x[i], f(i)))
            .filter(|p| p.1.is_finite())
            .collect()
    };
    save(
        out.path(),
        "image-profile",
        &Figure {
            title: format!(
                "Line profile at y = {} (setpoint A/A0 = {})",
                si_value(img.y[0], "m"),
                a.setpoint
            ),
            x_label: "x (m)".into(),
            y_label: "height (m)".into(),
            series: vec![
                Series {
                    label: "apparent height".into(),
                    points: profile(&|i| img.apparent_height(0, i)),
                    style: Style::Line,
                    color: 0,
                },
                Series {
                    label: "true height".into(),
                    points: profile(&|i| img.pixels[0][i].height),
                    style: Style::Dashed,
                    color: 1,
                },
            ],
            shade: Vec::new(),
            y_min_span: 1e-12,
        },
    )?;
    if a.json {
        outln!("{json}");
        return Ok(());
    }
    outln!(
        "ideal-feedback image, {} × {} pixels, setpoint A/A0 = {}; z_c,ref = {} on the background",
        img.x.len(),
        img.y.len(),
        a.setpoint,
        si_value(img.reference, "m")
    );
    let names: Vec<(Option<usize>, &str)> = std::iter::once((None, "background"))
        .chain(
            img.domain_names
                .iter()
                .enumerate()
                .map(|(k, n)| (Some(k), n.as_str())),
        )
        .collect();
    for (d, name) in names {
        // where this domain is first met in the image, its operating point there
        let first = img.pixels.iter().enumerate().find_map(|(j, line)| {
            line.iter()
                .position(|p| p.domain == d && p.point.is_some())
                .map(|i| (j, i))
        });
        match first {
            Some((j, i)) => {
                let o = img.point(j, i).expect("a point");
                outln!(
                    "  {}: z_c {} ({:?}), apparent height {} over true {}, phase {:.2}°, E_dis {}, peak force {}",
                    name,
                    si_value(o.z_c, "m"),
                    o.regime,
                    si_value(img.apparent_height(j, i), "m"),
                    si_value(img.pixels[j][i].height, "m"),
                    o.phase_deg,
                    si_value(o.energy_dissipated, "J"),
                    si_value(o.peak_force, "N")
                );
            }
            None => outln!("  {name}: not imaged (no operating point, or not in the map)"),
        }
    }
    if let Some(s) = &study {
        outln!("setpoint study (apparent height, phase; a line engaged on the background):");
        for (k, r) in s.ratio.iter().enumerate() {
            let cells: Vec<String> = s
                .domains
                .iter()
                .map(|d| {
                    format!(
                        "{} {}, {:.1}°",
                        d.name,
                        si_value(d.apparent_height[k], "m"),
                        d.phase_deg[k]
                    )
                })
                .collect();
            outln!("  A/A0 = {r:.3}: {}", cells.join("; "));
        }
    }
    outln!("outputs in {}", out.path().display());
    Ok(())
}

/// `afmdyn image --feedback pi`: the scan's lines as a study on the worker threads, then the
/// document, the maps (recorded height, error image, phase, E_dis) and the first line's profile
/// (trace, retrace, ideal and true height).
fn pi_cmd(
    a: &ImageArgs,
    table: &toml::Table,
    map: &SampleMap,
    req: &ImageRequest,
    scan: &PiScan,
) -> Result<(), CliError> {
    let study = ScanStudy::new(table, map, req, scan)?;
    let out = OutDir::lock(&a.out)?;
    let mut store = afmdyn::study::scan_store::scan_store(out.dir_lock());
    crate::progress::study(
        &study,
        &mut store,
        a.resume,
        a.threads,
        "lines",
        a.abort_after,
    )
    .map_err(|e| crate::error::study_error(e, "image"))?;
    let records = store
        .records()
        .map_err(|e| crate::error::store_error(e, "image"))?;
    let img = study.assemble(records)?;
    let json = img.document(a.setpoint);
    write_document(&out, "image.json", &json)?;
    write_layout(
        &out.join("image.nc"),
        &afmdyn::request::image_layout::scan_layout(&img, a.setpoint),
    )?;
    let grid = &img.ideal;
    let pixel = |j: usize, i: usize| &img.lines[j].trace[i];
    map_of(
        &out,
        grid,
        "image-height",
        "Recorded height (PI feedback, trace)",
        "m",
        &|j, i| img.height(0, j, i),
    )?;
    map_of(
        &out,
        grid,
        "image-error",
        "Amplitude error A_sp - A (PI feedback, trace)",
        "m",
        &|j, i| pixel(j, i).tracking_error * img.length(),
    )?;
    map_of(
        &out,
        grid,
        "image-phase",
        "Phase lag (PI feedback, trace)",
        "°",
        &|j, i| pixel(j, i).phase.to_degrees(),
    )?;
    map_of(
        &out,
        grid,
        "image-dissipation",
        "Energy dissipated per period (PI feedback, trace)",
        "J",
        &|j, i| pixel(j, i).energy_dissipated * img.energy(),
    )?;
    pi_profile(&out, &img, a.setpoint)?;
    if a.json {
        outln!("{json}");
        return Ok(());
    }
    let s = img.settings;
    outln!(
        "PI-feedback image, {} × {} pixels, setpoint A/A0 = {}: scan rate {}, K_P {}, K_I {}, \
         lock-in time constant {}; {} drive periods per pixel ({}), {} to engage each line",
        grid.x.len(),
        grid.y.len(),
        a.setpoint,
        si_value(s.scan_rate, "Hz"),
        s.proportional_gain,
        si_value(s.integral_gain, "1/s"),
        si_value(s.time_constant, "s"),
        s.periods_per_pixel,
        si_value(s.pixel_time, "s"),
        s.engage_periods
    );
    for (name, art) in ["trace", "retrace"].iter().zip(img.artefacts) {
        outln!(
            "  {name}: height error against the ideal image RMS {}, largest {}; overshoot {}; \
             error image RMS {}; {} pixel(s) lost contact; {} period(s) at the output limit",
            si_value(art.height_rms_error, "m"),
            si_value(art.height_max_error, "m"),
            si_value(art.overshoot, "m"),
            si_value(art.tracking_error_rms, "m"),
            art.lost_contact_pixels,
            art.saturated_periods
        );
    }
    outln!("outputs in {}", out.path().display());
    Ok(())
}

/// The first line of a PI scan: trace, retrace, the ideal image's apparent height and the true
/// height.
fn pi_profile(out: &OutDir, img: &PiImage, setpoint: f64) -> Result<(), CliError> {
    let g = &img.ideal;
    let profile = |f: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        (0..g.x.len())
            .map(|i| (g.x[i], f(i)))
            .filter(|p| p.1.is_finite())
            .collect()
    };
    let series = [
        (
            "trace",
            Style::Line,
            &(|i| img.height(0, 0, i)) as &dyn Fn(usize) -> f64,
        ),
        ("retrace", Style::Line, &|i| img.height(1, 0, i)),
        ("ideal feedback", Style::Dashed, &|i| {
            g.apparent_height(0, i)
        }),
        ("true height", Style::Dashed, &|i| g.pixels[0][i].height),
    ];
    save(
        out.path(),
        "image-profile",
        &Figure {
            title: format!(
                "Line profile at y = {} (PI feedback, setpoint A/A0 = {setpoint})",
                si_value(g.y[0], "m"),
            ),
            x_label: "x (m)".into(),
            y_label: "height (m)".into(),
            series: series
                .iter()
                .enumerate()
                .map(|(k, (label, style, f))| Series {
                    label: (*label).into(),
                    points: profile(f),
                    style: *style,
                    color: k,
                })
                .collect(),
            shade: Vec::new(),
            y_min_span: 1e-12,
        },
    )?;
    Ok(())
}
