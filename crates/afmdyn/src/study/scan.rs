//! The PI scan of an image (issue 46, `afmdyn image --feedback pi`) as a study
//! (`ScanStudy::tasks`: one task per line) and its local run ([`pi_image`]); the scan's request,
//! its units and settings are `crate::request::image_scan`'s.
//!
//! **An image is a study** ([`ScanStudy`], [`super::Study`]): its tasks are its lines,
//! each engaged from far on its first pixel's material (the steady state of the approach curve's
//! farthest point; the controller brings the tip down to the setpoint for
//! `ENGAGE_LOOP_TIMES` loop time constants 1/K_I), then scanned from x = 0 to Lx (trace) and
//! back (retrace) at the scan rate. Every line depends only on the request and its number, so
//! the image does not depend on the thread count or on the executor (the rayon pool, Dask).
//!
//! **Records.** Per pixel and direction ([`crate::analysis::am_loop::ScanPixel`]): the mean piezo
//! position over the pixel's drive periods (the height image: the piezo position less the
//! ideal image's reference z_c,ref, so that a perfect controller records the ideal image's
//! apparent height), the mean lock-in amplitude and phase, the mean error A_sp − A (the error
//! image), and E_dis, virial, peak force and indentation over the pixel's last drive period
//! (`crate::analysis::observables::observe`).
//!
//! **Artefacts** ([`Artefacts`], per direction): the RMS and largest difference of the recorded
//! height from the ideal image's apparent height; the overshoot, how far a recorded height goes
//! beyond the ideal heights of its pixel and its two neighbours (a lag stays between them; an
//! overshoot does not; pixels beside one without an ideal height are left out); the pixels that
//! lost contact; the periods at the controller's output limit (an unstable loop); the largest
//! energy-balance residual of a pixel's last period.

use super::image_ideal::{image_of, material_curves};
use super::Tasks;
use crate::analysis::am_loop::{
    engage_position, scan_line, Engage, LineSpec, ScanLine, LOCK_IN_SAMPLES,
};
use crate::analysis::approach::rest_distance;
use crate::error::SimError;
use crate::integrate::IntegratorOptions;
use crate::probe::Probe;
use crate::report::CurveUnits;
use crate::request::image::{Image, ImageRequest, SampleMap};
use crate::request::image_scan::{resolve, PiScan, ScanRecipe, ScanSettings};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use std::sync::atomic::AtomicBool;

pub(crate) use crate::report::image::{Artefacts, PiImage};

impl ScanStudy {
    /// The scan as a `Tasks` study: one task per line (its trace and retrace).
    pub(crate) fn tasks(&self) -> Tasks<'_, ScanLine> {
        Tasks::new(&self.fingerprint, self.lines(), |t, cancel| {
            self.line(t, cancel).map(Some)
        })
    }
}

/// The PI-scanned image of `map` under `probe_table` ([`crate::request::image_scan`]), its lines on
/// `threads` worker threads (`None`: all cores) with progress and cancellation in `observer`.
///
/// # Errors
/// As `ScanStudy::new` and the lines; [`SimError::Cancelled`].
pub fn pi_image(
    probe_table: &toml::Table,
    map: &SampleMap,
    req: &ImageRequest,
    scan: &PiScan,
    threads: Option<usize>,
    observer: &dyn super::Observer,
) -> Result<PiImage, SimError> {
    let study = ScanStudy::new(probe_table, map, req, scan)?;
    let records = super::execute_in_memory(&study.tasks(), threads, observer)?;
    study.assemble(records)
}

/// The study of a PI scan: one task per line ([module docs](self)).
pub struct ScanStudy {
    pub(crate) fingerprint: Value,
    recipe: ScanRecipe,
    ideal: Image,
    /// What a line needs (the start of a distributed scan's stage, [`ScanStudy::line_job`]).
    job: LineJob,
    units: CurveUnits,
    settings: ScanSettings,
}

/// What scanning one line of a PI image needs ([`ScanStudy::line_job`]): the line's
/// settings, each material's engage, the sample map and the lines' y positions (model units
/// as [`LineSpec`]; `length` is g₀ in m). Its lines are those of the study it came from, bit
/// for bit, wherever it is sent (serde: every number as its bits).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct LineJob {
    spec: LineSpec,
    /// Per material: where a line starting on it engages.
    engage: Vec<Engage>,
    map: SampleMap,
    /// The material of each of the map's domains.
    of_domain: Vec<usize>,
    /// The lines' y positions (m), shape `[lines]`.
    y: Vec<f64>,
    /// g₀ (m).
    length: f64,
    pixels: usize,
}

impl LineJob {
    /// The number of lines.
    pub fn lines(&self) -> usize {
        self.y.len()
    }

    /// Scan line `t` (trace and retrace).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `line` beyond the image; as
    /// [`crate::analysis::am_loop::scan_line`].
    pub fn line(&self, t: usize, cancel: &AtomicBool) -> Result<ScanLine, SimError> {
        if t >= self.lines() {
            return Err(SimError::out_of_range(
                "line",
                format!("{t} (of {} lines)", self.lines()),
                "must be a line of the image",
            ));
        }
        let y = self.y[t];
        let map = &self.map;
        let (lx, g0) = (map.size.0, self.length);
        let dx = lx / self.pixels as f64;
        let under_tip = |s: f64| {
            // a position on an edge belongs to the pixel it begins
            let x = (s * dx).clamp(0.0, lx);
            let m = map.domain_at(x, y).map_or(0, |k| self.of_domain[k]);
            (m, map.height_at(x, y) / g0)
        };
        let first = under_tip(engage_position(&self.spec)).0;
        scan_line(&self.spec, &self.engage[first], &under_tip, t, cancel)
    }
}

impl ScanStudy {
    /// The study of `req` and `scan` over `map` under the probe `probe_table` (SI in): the
    /// materials' approach curves, the ideal image, the settings.
    ///
    /// # Errors
    /// As [`super::image::image`]; [`SimError::OutOfRange`] naming `scan_rate` (> 0, at most
    /// the drive frequency over 2 × pixels: a pixel needs a drive period; and at most
    /// [`MAX_SCAN_PERIODS`] periods in all), `gains` (K_P ≥ 0, K_I > 0, finite) or
    /// `time_constant` (≥ 0, finite, at most 1 000 s).
    pub(crate) fn new(
        probe_table: &toml::Table,
        map: &SampleMap,
        req: &ImageRequest,
        scan: &PiScan,
    ) -> Result<ScanStudy, SimError> {
        req.validate(map)?;
        let probe =
            Probe::from_table(probe_table, "probe").map_err(|e| SimError::Probe(e.to_string()))?;
        let (settings, gains, total) = resolve(&probe, map, req, scan)?;
        let thermal = scan.thermal(&probe)?;
        let pixels = req.pixels;
        // the lines' drive periods (× modes) and the pixels' memory, with the curves' cost
        let extra = crate::request::limits::Cost {
            bytes: req.pixel_bytes(map),
            work: total,
        };
        let (curves, of_domain, units) =
            material_curves(probe_table, map, req.curve_points, extra)?;
        let ideal = image_of(&curves, &of_domain, &units, map, req)?;
        let engage = curves
            .iter()
            .map(|m| {
                let far = &m.curve.first[0];
                Engage {
                    state: far.state.clone(),
                    z_c: rest_distance(&m.params, far.value),
                    amplitude: far.observables.amplitude,
                    phase: far.observables.phase,
                }
            })
            .collect::<Vec<_>>();
        // the controller's range above the local surface: the approach curves' z_c range
        let (lo, hi) = curves
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |r, m| {
                m.curve.first.iter().fold(r, |(lo, hi), p| {
                    let z = rest_distance(&m.params, p.value);
                    (lo.min(z), hi.max(z))
                })
            });
        let free_amplitude = probe.free_amplitude / units.length;
        let spec = LineSpec {
            materials: curves.iter().map(|m| m.params).collect(),
            setpoint: req.setpoint * free_amplitude,
            free_amplitude,
            gains,
            samples: LOCK_IN_SAMPLES,
            pixels,
            periods_per_pixel: settings.periods_per_pixel,
            engage_periods: settings.engage_periods,
            range: (lo, hi),
            integrator: IntegratorOptions::default(),
            thermal,
        };
        // what a resumed scan must match: everything its lines depend on (the settings as
        // given under "feedback", named first when a resume differs; then as resolved)
        let fingerprint = json!({
            "feedback": scan,
            "probe": probe_table,
            "map": map,
            "request": req,
            "scan": settings,
        });
        let job = LineJob {
            spec,
            engage,
            map: map.clone(),
            of_domain,
            y: ideal.y.clone(),
            length: units.length,
            pixels,
        };
        Ok(ScanStudy {
            fingerprint,
            recipe: ScanRecipe {
                probe: probe_table.clone(),
                map: map.clone(),
                request: *req,
                scan: *scan,
            },
            ideal,
            job,
            units,
            settings,
        })
    }

    /// The study of a recipe ([`ScanStudy::recipe`]).
    ///
    /// # Errors
    /// As [`ScanStudy::new`].
    #[cfg(feature = "files")]
    pub(crate) fn from_recipe(r: &ScanRecipe) -> Result<ScanStudy, SimError> {
        ScanStudy::new(&r.probe, &r.map, &r.request, &r.scan)
    }

    /// What rebuilds this study elsewhere.
    pub fn recipe(&self) -> &ScanRecipe {
        &self.recipe
    }

    /// The number of lines.
    pub fn lines(&self) -> usize {
        self.ideal.y.len()
    }

    /// Scan line `t` (trace and retrace): `LineJob::line` of `ScanStudy::line_job`.
    ///
    /// # Errors
    /// As `LineJob::line`.
    pub fn line(&self, t: usize, cancel: &AtomicBool) -> Result<ScanLine, SimError> {
        self.job.line(t, cancel)
    }

    /// What scanning a line needs, without the materials' approach curves that
    /// [`ScanStudy::new`] computes: a distributed scan sends it to its workers once (the
    /// stage's start, [`crate::study::plan`]), so that a worker does not build the study.
    #[cfg(feature = "files")]
    pub(crate) fn line_job(&self) -> &LineJob {
        &self.job
    }

    /// The image of the finished lines `records` (in any order, every line once).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `lines` when a line is missing or repeated.
    pub fn assemble(&self, records: Vec<(usize, ScanLine)>) -> Result<PiImage, SimError> {
        let n = self.lines();
        let mut slots: Vec<Option<ScanLine>> = vec![None; n];
        for (t, l) in records {
            match slots.get_mut(t) {
                Some(s @ None) => *s = Some(l),
                _ => {
                    return Err(SimError::out_of_range(
                        "lines",
                        t,
                        "each line of the image once",
                    ))
                }
            }
        }
        let lines: Vec<ScanLine> = slots
            .into_iter()
            .collect::<Option<_>>()
            .ok_or_else(|| SimError::out_of_range("lines", n, "every line of the image"))?;
        let mut img = PiImage {
            ideal: self.ideal.clone(),
            lines,
            settings: self.settings,
            units: self.units,
            artefacts: [empty_artefacts(); 2],
            warnings: self
                .ideal
                .warnings
                .iter()
                .map(|w| format!("the ideal image beside the scan: {w}"))
                .collect(),
        };
        if let Some(t) = self.recipe.scan.temperature {
            img.warnings
                .extend(crate::request::limits::temperature_warnings(t));
            for m in &self.job.spec.materials {
                let (_, scheme) = crate::integrate::exact::noise::thermal_method(&m.contact_law);
                for w in scheme {
                    if !img.warnings.contains(&w) {
                        img.warnings.push(w);
                    }
                }
            }
        }
        // a lock-in time constant given outside the typical range: a likely unit slip, named
        // (the lever's default τ_c/4 is no slip, whatever its value)
        if let Some(tc) = self.recipe.scan.time_constant {
            let range = ("feedback", "time_constant");
            img.warnings
                .extend(crate::probe::ranges::warn("time_constant", range, tc));
        }
        img.artefacts = [0, 1].map(|d| img.artefacts_of(d));
        for (d, a) in ["trace", "retrace"].iter().zip(img.artefacts) {
            if a.lost_contact_pixels > 0 {
                img.warnings.push(warning!(
                    "scan.lost-contact",
                    "Scan slower or raise the gains.",
                    "{d}: {} pixel(s) lost contact (the tip left the sample and the amplitude \
                     rose toward the free amplitude: parachuting; scan slower or raise the gains)",
                    a.lost_contact_pixels
                ));
            }
            if a.saturated_periods > 0 {
                img.warnings.push(warning!(
                    "scan.saturated",
                    "Scan slower, or lower the gains.",
                    "{d}: the controller's output sat at a limit of its range (the approach \
                     curves' z_c range above the local surface) for {} drive period(s): a step \
                     too steep for the scan rate pressed the tip to the lowest z_c, or the loop \
                     is unstable (scan slower, or lower the gains)",
                    a.saturated_periods
                ));
            }
        }
        Ok(img)
    }
}

fn empty_artefacts() -> Artefacts {
    Artefacts {
        height_rms_error: f64::NAN,
        height_max_error: f64::NAN,
        overshoot: f64::NAN,
        tracking_error_rms: f64::NAN,
        lost_contact_pixels: 0,
        saturated_periods: 0,
        energy_residual_max: f64::NAN,
    }
}
