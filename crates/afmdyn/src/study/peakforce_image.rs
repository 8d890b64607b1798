//! PeakForce images (issue 61 §3): `afmdyn image --mode peakforce --setpoint 2nN` — the maps
//! an ideal peak-force feedback records over a sample map ([`crate::request::image::SampleMap`]) with an
//! off-resonance probe ([`crate::analysis::peakforce`]).
//!
//! **Ideal feedback.** At every pixel the feedback holds the steady tap's peak force at the
//! setpoint: the pixel's operating point is the periodic tap orbit of its material at the mean
//! rest separation z_c where F_peak(z_c) = F_set (to [`SETPOINT_TOL`] relative), and the z
//! piezo records the true height plus that z_c: the apparent height is h + z_c − z_c,ref,
//! z_c,ref the background's (as AM images do, [`crate::request::image`]).
//!
//! **History.** Each line is engaged from far on its first pixel's material: the feedback's own
//! search from rest ([`peak_force_setpoint`]), computed once per material before the lines
//! ([`PeakForceImageStudy::new`]). Along the line:
//! - a pixel of the same material (the same model) as the previous one has its operating
//!   point: the previous orbit at the previous z_c is the fixed point the continuation starts
//!   from (the feedback has nothing to correct), so it is taken, not computed again;
//! - at a change of material z_c is found by the secant method on F_peak(z_c) − F_set
//!   started from the new material's engaged z_c and orbit — its operating point at the
//!   setpoint. z_c is the rest separation from the local surface, so the topography does not
//!   shift it (the height enters the apparent height only), and the first tap, from the
//!   orbit's own fixed point, is at the setpoint to the feedback's tolerance: a change of
//!   material costs one tap. Were it off, the secant's first step is from the lever's static
//!   compliance c (the quasi-static slope |dF_peak/dα5| ≤ 1/c: the first step falls short of
//!   the root, never across a fold), at most `CONTINUE_ITERATIONS` taps. (Continuing from
//!   the previous material's orbit and z_c instead cost 6.4 taps per change, issue 61.)
//! - where the continuation does not converge (a tap that does not settle, a fold of the
//!   steady taps) the pixel is re-engaged from far on its material (counted and reported);
//! - a material whose engage from far does not reach the setpoint leaves its pixels empty
//!   (NaN, reported) and the next pixel engages again.
//!
//! **Thermal noise** (a request's temperature): each material's engage also gives its tap's
//! σ of the peak force and the deformation from cycle to cycle
//! ([`crate::analysis::peakforce::tap_noise`], in SI), and every pixel of the material takes
//! it — a pixel kept, continued into or re-engaged is the material's operating point at the
//! setpoint, to the feedback's tolerance — so the noise maps cost one walk over a tap per
//! material.
//!
//! A uniform domain thus costs no tap per pixel and a change of material one tap, so the
//! image costs the materials' engages plus its material changes. **A line is a task**
//! ([`PeakForceImageStudy::line`]): it depends only on the request and its number, so the image
//! does not depend on the thread count or the executor.
//!
//! Here: the study (`PeakForceImageStudy::tasks`: one task per line) and its local run
//! (`peakforce_image`); the request's checks and cost are
//! [`crate::request::image_peakforce`]'s.

use super::peakforce::{modulus_scale, setpoint_in_newtons};
use super::Tasks;
use crate::analysis::peakforce::{
    peak_force_setpoint, static_compliance, steady_tap_from, tap_noise, PeakForceOptions,
    SetpointOptions, SteadyTap, TapNoise, SETPOINT_TOL,
};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use crate::report::CurveUnits;
use crate::request::image::{material_models, pixel_grid, ImageRequest, SampleMap};
use crate::request::image_peakforce::peakforce_probe;
use crate::request::limits::thermal_force;
use crate::request::run::Resolved;
use nalgebra::DVector;
use serde_json::Value;

impl PeakForceImageStudy {
    /// The image as a `Tasks` study: one task per line (its pixels).
    pub(crate) fn tasks(&self) -> Tasks<'_, Vec<LinePixel>> {
        Tasks::new(&self.fingerprint, self.lines(), |t, _| {
            self.line(t).map(Some)
        })
    }
}

/// The PeakForce image of `map` under `probe_table` at the peak force `req.setpoint` (N)
/// ([`crate::request::image_peakforce`]), its lines on `threads` worker threads (`None`: all
/// cores) with progress and cancellation in `observer`.
///
/// # Errors
/// As [`PeakForceImageStudy::new`] and the lines; [`SimError::Cancelled`].
pub(crate) fn peakforce_image(
    probe_table: &toml::Table,
    map: &SampleMap,
    req: &ImageRequest,
    threads: Option<usize>,
    observer: &dyn super::Observer,
) -> Result<PeakForceImage, SimError> {
    let study = PeakForceImageStudy::new(probe_table, map, req)?;
    let records = super::execute_in_memory(&study.tasks(), threads, observer)?;
    study.assemble(records)
}

pub use crate::report::image::{LinePixel, PeakForceImage, PeakForceTap, PfMaterialReport};

/// Most taps of the secant continuation at a change of material before the pixel is
/// re-engaged from far.
pub(crate) const CONTINUE_ITERATIONS: usize = 30;

/// A material of a PeakForce image and its engage.
#[derive(Debug, Clone)]
pub struct PfMaterial {
    /// `background` or the domain's name.
    pub name: String,
    /// Its model (the probe's lever and drive, its sample).
    pub params: Params,
    /// The sample's true reduced modulus E* (Pa; NaN without a tip radius).
    pub true_modulus: f64,
    /// The factor from the Hertz group (model units) to E* (Pa); `None` without a tip radius.
    pub modulus_scale: Option<f64>,
    /// The engage from far: α5, the orbit's state at τ = 0 and the operating point; or why
    /// the setpoint is not reached.
    pub engaged: Result<(f64, DVector<f64>, PeakForceTap), String>,
    /// Steady taps of the engage's search.
    pub evaluations: usize,
}

/// A PeakForce image as a study of lines ([module docs](self)).
#[derive(Debug, Clone)]
pub struct PeakForceImageStudy {
    /// The sample map.
    pub map: SampleMap,
    /// The request (its setpoint the peak force in N).
    pub request: ImageRequest,
    /// The materials: 0 the background, then one per domain with its own sample.
    pub materials: Vec<PfMaterial>,
    /// The material of each domain.
    pub of_domain: Vec<usize>,
    /// SI units of the model.
    pub units: CurveUnits,
    /// The setpoint in model units F̃.
    pub setpoint: f64,
    /// The materials' own probe warnings (a sample in JKR's regime under the DMT law, a value
    /// outside its typical range), which the image's warnings begin with.
    pub probe_warnings: Vec<String>,
    /// The steady taps' options.
    pub options: PeakForceOptions,
    /// What a resumed run must match.
    pub fingerprint: Value,
    /// k_B T of the noise maps (model units; with a temperature).
    pub kt: Option<f64>,
}

/// A material's engage from far, as a task computes it: the steady taps of the feedback's
/// search, and α5, the orbit's state at τ = 0 and the operating point, or why the setpoint is
/// not reached.
pub(crate) type Engage = (usize, Result<(f64, Vec<f64>, PeakForceTap), String>);

impl PeakForceImageStudy {
    /// The study of `map` under the probe `probe_table` at the peak force `req.setpoint` (N):
    /// the materials' models and their engages from far (module docs).
    ///
    /// # Errors
    /// As `PeakForceImageStudy::unengaged`; [`SimError::Cancelled`];
    /// [`SimError::EveryRunFailed`] when no material reaches the setpoint
    /// (`PeakForceImageStudy::reached`).
    pub fn new(
        probe_table: &toml::Table,
        map: &SampleMap,
        req: &ImageRequest,
    ) -> Result<PeakForceImageStudy, SimError> {
        let study = Self::unengaged(probe_table, map, req)?;
        let engages = (0..study.materials.len())
            .map(|m| study.engage(m))
            .collect::<Result<Vec<_>, SimError>>()?;
        study.reached(&engages)?;
        Ok(study.with_engages(engages))
    }

    /// That some material reaches the setpoint from far: an image none of whose materials
    /// does would have no finite pixel in any map (issue 77 §3: it was written as a result).
    ///
    /// # Errors
    /// [`SimError::EveryRunFailed`] naming the first material and why, before any line.
    pub(crate) fn reached(&self, engages: &[Engage]) -> Result<(), SimError> {
        if engages.iter().any(|(_, e)| e.is_ok()) {
            return Ok(());
        }
        let first = (self.materials.iter().zip(engages))
            .find_map(|(m, (_, e))| e.as_ref().err().map(|e| format!("{}: {e}", m.name)))
            .unwrap_or_default();
        Err(SimError::EveryRunFailed {
            what: "materials' engages at the setpoint (no pixel of the image reaches it, so no \
                   map would have a value)",
            runs: engages.len(),
            first,
        })
    }

    /// The study before its materials' engages ([`PeakForceImageStudy::engage`], then
    /// [`PeakForceImageStudy::with_engages`]): an executor elsewhere (Dask) runs the engages
    /// as tasks of their own.
    ///
    /// # Errors
    /// As [`ImageRequest::validate_grid`] and [`peakforce_probe`]; [`SimError::Probe`] for a
    /// domain's sample the probe format refuses.
    pub(crate) fn unengaged(
        probe_table: &toml::Table,
        map: &SampleMap,
        req: &ImageRequest,
    ) -> Result<PeakForceImageStudy, SimError> {
        req.validate_grid(map)?;
        let background = peakforce_probe(probe_table, req.setpoint)?;
        let units = CurveUnits::from_scales(&background.scales, true);
        let (models, of_domain, probe_warnings) = material_models(probe_table, map, &background)?;
        // k_B T of the noise maps (the materials' laws are admitted with the request's cost,
        // and by the noise's walk)
        let kt = (req
            .temperature
            .map(|t| thermal_force(t, 0, Some(&background))))
        .transpose()?
        .map(|f| f.kt);
        let resolved = |p: Params| Resolved {
            params: p,
            probe: Some(background.clone()),
        };
        let materials = models
            .into_iter()
            .map(|(name, params)| {
                let scale = modulus_scale(&resolved(params), &params);
                PfMaterial {
                    name,
                    true_modulus: scale.map_or(f64::NAN, |s| s * params.alpha4),
                    modulus_scale: scale,
                    params,
                    engaged: Err("not engaged".into()),
                    evaluations: 0,
                }
            })
            .collect();
        let fingerprint = serde_json::json!({
            "afmdyn": env!("CARGO_PKG_VERSION"),
            "image": "peakforce",
            "probe": probe_table,
            "map": map,
            "request": req,
        });
        Ok(PeakForceImageStudy {
            map: map.clone(),
            request: *req,
            materials,
            of_domain,
            setpoint: req.setpoint / units.force,
            probe_warnings: probe_warnings.concat(),
            units,
            options: PeakForceOptions::default(),
            fingerprint,
            kt,
        })
    }

    /// The engage of material `m` from far: the feedback's search from rest
    /// ([`peak_force_setpoint`]).
    ///
    /// # Errors
    /// [`SimError::Cancelled`]; a setpoint the material does not reach is the engage's
    /// message, not an error.
    pub(crate) fn engage(&self, m: usize) -> Result<Engage, SimError> {
        let params = self.materials[m].params;
        let opts = SetpointOptions {
            tap: self.options.clone(),
            ..SetpointOptions::default()
        };
        Ok(match peak_force_setpoint(&params, self.setpoint, &opts) {
            Ok(s) => {
                let mut tap = si_tap(&params, &self.units, self.scale(m), s.alpha5, &s.tap);
                tap.noise = self.noise(&params.with(SweepParam::Alpha5, s.alpha5), &s.tap)?;
                (
                    s.evaluations,
                    Ok((s.alpha5, s.tap.state.iter().copied().collect(), tap)),
                )
            }
            Err(SimError::Cancelled) => return Err(SimError::Cancelled),
            Err(e) => {
                let newtons = self.setpoint * self.units.force;
                (0, Err(setpoint_in_newtons(e, newtons).to_string()))
            }
        })
    }

    /// The thermal noise of the tap `tap` of `params` in SI (`None` without a temperature):
    /// a pixel's, every pixel of a material taking its engage's (its operating point at the
    /// setpoint, to the feedback's tolerance).
    ///
    /// # Errors
    /// As [`tap_noise`].
    fn noise(&self, params: &Params, tap: &SteadyTap) -> Result<Option<TapNoise>, SimError> {
        let Some(kt) = self.kt else { return Ok(None) };
        let (model, integrator) = (
            CantileverModel::new(params)?,
            self.options.integrator.clone(),
        );
        let n = tap_noise(&model, &tap.state, tap.period, kt, integrator)?;
        Ok(Some(TapNoise {
            peak_force: n.peak_force * self.units.force,
            deformation: n.deformation * self.units.length,
            ..n
        }))
    }

    /// The study with the materials' engages (in the order of the materials).
    pub(crate) fn with_engages(mut self, engages: Vec<Engage>) -> PeakForceImageStudy {
        for (m, (evaluations, e)) in self.materials.iter_mut().zip(engages) {
            m.evaluations = evaluations;
            m.engaged = e.map(|(a5, z, tap)| (a5, DVector::from_vec(z), tap));
        }
        self
    }

    /// The number of lines.
    pub fn lines(&self) -> usize {
        self.request.lines(&self.map)
    }

    /// The material of the pixel at (x, y).
    pub(crate) fn material_at(&self, x: f64, y: f64) -> usize {
        self.map.domain_at(x, y).map_or(0, |k| self.of_domain[k])
    }

    /// Line `t` (module docs): each pixel engaged, kept or continued from the previous.
    ///
    /// # Errors
    /// [`SimError`] from a model the map's material refuses (checked when the study was
    /// built); a tap that does not converge re-engages the pixel instead.
    pub fn line(&self, t: usize) -> Result<Vec<LinePixel>, SimError> {
        let (x, y) = pixel_grid(&self.map, &self.request);
        let yj = y[t];
        let mut out = Vec::with_capacity(x.len());
        // the previous pixel: its material, α5, orbit state and operating point
        let mut prev: Option<(usize, f64, DVector<f64>, PeakForceTap)> = None;
        for &xi in &x {
            let m = self.material_at(xi, yj);
            let mat = &self.materials[m];
            let engage = |reengaged: bool| match &mat.engaged {
                Ok((a5, z, tap)) => (
                    Some((m, *a5, z.clone(), *tap)),
                    LinePixel {
                        tap: Some(*tap),
                        evaluations: 0,
                        reengaged,
                    },
                ),
                Err(_) => (
                    None,
                    LinePixel {
                        tap: None,
                        evaluations: 0,
                        reengaged,
                    },
                ),
            };
            let (next, pixel) = match prev.take() {
                // a material that does not reach the setpoint from far: its pixels are empty
                // and the next pixel engages again
                None => engage(false),
                Some(_) if mat.engaged.is_err() => engage(false),
                Some((pm, a5, z, tap)) if self.materials[pm].params == mat.params => {
                    let pixel = LinePixel {
                        tap: Some(tap),
                        evaluations: 0,
                        reengaged: false,
                    };
                    (Some((m, a5, z, tap)), pixel)
                }
                // a change of material: the secant starts from the material's engaged z_c
                // and orbit (its operating point at the setpoint, module docs)
                Some(_) => match self.continue_to(&mat.params, &mat.engaged)? {
                    (Some((b5, tap)), evaluations) => {
                        let mut si = si_tap(&mat.params, &self.units, self.scale(m), b5, &tap);
                        si.noise = mat.engaged.as_ref().ok().and_then(|e| e.2.noise);
                        let pixel = LinePixel {
                            tap: Some(si),
                            evaluations,
                            reengaged: false,
                        };
                        (Some((m, b5, tap.state, si)), pixel)
                    }
                    (None, evaluations) => {
                        let (n, mut pixel) = engage(true);
                        pixel.evaluations = evaluations;
                        (n, pixel)
                    }
                },
            };
            prev = next;
            out.push(pixel);
        }
        Ok(out)
    }

    /// The factor from the Hertz group to E* (Pa) of material `m`.
    fn scale(&self, m: usize) -> Option<f64> {
        self.materials[m].modulus_scale
    }

    /// The tap of `params` at the setpoint by the secant method from its engage `engaged`:
    /// α5 `a0` and the orbit state `z0` (module docs): (α5 and the tap, or `None` where it
    /// does not converge or there is no engage; the taps computed).
    ///
    /// # Errors
    /// [`SimError`] other than a tap's non-convergence (a model that cannot be built).
    fn continue_to(
        &self,
        params: &Params,
        engaged: &Result<(f64, DVector<f64>, PeakForceTap), String>,
    ) -> Result<Continued, SimError> {
        let Ok((a0, z0, _)) = engaged else {
            return Ok((None, 0));
        };
        let a0 = *a0;
        let f_set = self.setpoint;
        let tol = SETPOINT_TOL * f_set;
        let mut start = z0.clone();
        let mut evaluations = 0;
        let mut eval =
            |a5: f64, start: &mut DVector<f64>| -> Result<Option<(f64, SteadyTap)>, SimError> {
                let model = CantileverModel::new(&params.with(SweepParam::Alpha5, a5))?;
                evaluations += 1;
                match steady_tap_from(&model, &self.options, start) {
                    Ok(tap) => {
                        start.copy_from(&tap.state);
                        Ok(Some((tap.channels.peak_force - f_set, tap)))
                    }
                    Err(SimError::NoConvergence { .. }) => Ok(None),
                    Err(e) => Err(e),
                }
            };
        let Some((mut g0, tap)) = eval(a0, &mut start)? else {
            return Ok((None, evaluations));
        };
        let mut x0 = a0;
        if g0.abs() <= tol {
            return Ok((Some((a0, tap)), evaluations));
        }
        // the first step from the quasi-static slope bound 1/c: short of the root
        let c = static_compliance(&CantileverModel::new(params)?);
        let mut x1 = a0 + g0 * c;
        for _ in 1..CONTINUE_ITERATIONS {
            let Some((g1, tap)) = eval(x1, &mut start)? else {
                return Ok((None, evaluations));
            };
            if g1.abs() <= tol {
                return Ok((Some((x1, tap)), evaluations));
            }
            // the peak force falls as α5 grows: a slope ≥ 0 is a fold (or round-off)
            let slope = (g1 - g0) / (x1 - x0);
            if !(slope < 0.0 && slope.is_finite()) {
                return Ok((None, evaluations));
            }
            (x0, g0) = (x1, g1);
            x1 -= g1 / slope;
        }
        Ok((None, evaluations))
    }
}

/// A continuation's outcome: α5 and the tap at the setpoint (`None`: it did not converge), and
/// the steady taps it computed.
type Continued = (Option<(f64, SteadyTap)>, usize);

/// The SI operating point of the tap `tap` of `p` at α5 `a5` (`scale`: the Hertz group to E*).
fn si_tap(
    p: &Params,
    u: &CurveUnits,
    scale: Option<f64>,
    a5: f64,
    tap: &SteadyTap,
) -> PeakForceTap {
    let c = &tap.channels;
    let q = p.with(SweepParam::Alpha5, a5);
    PeakForceTap {
        z_c: q.rest_distance() * u.length,
        peak_force: c.peak_force * u.force,
        adhesion: c.adhesion * u.force,
        deformation: c.deformation * u.length,
        dissipation: c.dissipation * u.energy,
        modulus_dmt: match (tap.fit, scale) {
            (Some(f), Some(s)) => f.hertz_group * s,
            _ => f64::NAN,
        },
        taps_per_cycle: c.taps_per_cycle,
        period: tap.period,
        stable: tap.stable,
        noise: None,
    }
}

impl PeakForceImageStudy {
    /// Where the DMT fit of a material's single-tap pixels reads more than
    /// [`super::peakforce::MAX_MODULUS_BIAS`] off its own E* (which a simulation knows), as a
    /// single tap's document says it (issue 77): one warning per such material, with the range
    /// of the ratio and how many of its pixels.
    fn modulus_bias(
        &self,
        materials: &[PfMaterialReport],
        pixels: &[Vec<LinePixel>],
        x: &[f64],
        y: &[f64],
    ) -> Vec<String> {
        let bound = super::peakforce::MAX_MODULUS_BIAS;
        let mut ratios = vec![Vec::new(); materials.len()];
        for (row, &yj) in pixels.iter().zip(y) {
            for (pixel, &xi) in row.iter().zip(x) {
                let Some(t) = pixel.tap.filter(|t| t.taps_per_cycle <= 1.0 + 1e-9) else {
                    continue;
                };
                let m = self.material_at(xi, yj);
                let ratio = t.modulus_dmt / materials[m].true_modulus;
                if ratio.is_finite() {
                    ratios[m].push(ratio);
                }
            }
        }
        let biased = |r: &&f64| (**r - 1.0).abs() > bound;
        let cause = super::peakforce::BIAS_CAUSE;
        materials
            .iter()
            .zip(&ratios)
            .filter_map(|(m, r)| {
                let off: Vec<f64> = r.iter().filter(biased).copied().collect();
                if off.is_empty() {
                    return None;
                }
                let lo = off.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = off.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let reads = if hi - lo > 5e-4 * hi {
                    format!("{lo:.3}–{hi:.3}")
                } else {
                    format!("{hi:.3}")
                };
                Some(warning!(
                    "peakforce-image.modulus-bias",
                    "Calibrate the reading against a material of known modulus; do not \
                     read it as the material's modulus.",
                    "{}: modulus_dmt reads {reads} × the material's own E* on {} of its {} \
                     single-tap pixels (more than {:.0} % off): the DMT fit is biased there \
                     ({cause}): compare it against a calibration sample, not as the material's \
                     modulus",
                    m.name,
                    off.len(),
                    r.len(),
                    bound * 100.0
                ))
            })
            .collect()
    }

    /// The image of the lines' records (any order).
    ///
    /// # Errors
    /// [`SimError::Cancelled`] when a line is missing (a run cut short).
    pub fn assemble(
        &self,
        mut records: Vec<(usize, Vec<LinePixel>)>,
    ) -> Result<PeakForceImage, SimError> {
        records.sort_by_key(|r| r.0);
        let n = self.lines();
        if records.len() != n || records.iter().enumerate().any(|(i, r)| r.0 != i) {
            return Err(SimError::Cancelled);
        }
        let (x, y) = pixel_grid(&self.map, &self.request);
        let grid = |f: &dyn Fn(f64, f64) -> f64| -> Vec<Vec<f64>> {
            y.iter()
                .map(|&yj| x.iter().map(|&xi| f(xi, yj)).collect())
                .collect()
        };
        let materials: Vec<PfMaterialReport> = self
            .materials
            .iter()
            .map(|m| PfMaterialReport {
                name: m.name.clone(),
                true_modulus: m.true_modulus,
                engaged: m.engaged.as_ref().ok().map(|e| e.2),
                message: m.engaged.as_ref().err().cloned(),
                evaluations: m.evaluations,
            })
            .collect();
        let mut warnings = self.probe_warnings.clone();
        warnings.extend(materials.iter().filter_map(|m| {
            m.message.as_ref().map(|e| {
                format!(
                    "{}: the setpoint is not reached ({e}): its pixels are empty (NaN)",
                    m.name
                )
            })
        }));
        let pixels: Vec<Vec<LinePixel>> = records.into_iter().map(|r| r.1).collect();
        let all = || pixels.iter().flatten();
        let reengaged = all().filter(|p| p.reengaged).count();
        if reengaged > 0 {
            warnings.push(warning!(
                "peakforce-image.reengaged",
                "Look at those pixels: the steady taps fold there, or a tap does not \
                 settle; another setpoint may avoid it.",
                "{reengaged} pixel(s) re-engaged from far: the feedback's continuation from the \
                 previous pixel did not converge there (a fold of the steady taps, or a tap that \
                 does not settle)"
            ));
        }
        let taps = || all().filter_map(|p| p.tap);
        if taps().any(|t| t.taps_per_cycle > 1.0 + 1e-9) {
            warnings.push(warning!(
                "peakforce-image.double-tap",
                "Find them by taps_per_cycle; their modulus_dmt is not meaningful.",
                "double taps on some pixels (more than one contact per modulation period): \
                 modulus_dmt is not meaningful there (taps_per_cycle)"
            ));
        }
        if taps().any(|t| t.period > 1) {
            warnings.push(warning!(
                "peakforce-image.period",
                "Find them by period; their cycle shows the first of its modulation \
                 periods.",
                "period-2 (or longer) tapping on some pixels (period)"
            ));
        }
        warnings.extend(self.modulus_bias(&materials, &pixels, &x, &y));
        if let Some(t) = self.request.temperature {
            // the linear response's limits at each material's tap (every pixel's, module docs)
            warnings.extend(crate::request::limits::temperature_warnings(t));
            let engaged = materials.iter().filter_map(|m| m.engaged);
            let taps: Vec<_> =
                (engaged.filter_map(|e| Some((e.noise?, e.peak_force, e.deformation)))).collect();
            warnings.extend(super::peakforce::linear_warnings(&taps, true));
        }
        if taps().any(|t| !t.stable) {
            warnings.push(warning!(
                "peakforce-image.unstable",
                "Find them by stable; their values are those of an orbit the lever does \
                 not stay on.",
                "unstable steady taps on some pixels (stable = false)"
            ));
        }
        Ok(PeakForceImage {
            setpoint: self.request.setpoint,
            temperature: self.request.temperature,
            reference: materials[0].engaged.map_or(f64::NAN, |t| t.z_c),
            material: y
                .iter()
                .map(|&yj| x.iter().map(|&xi| self.material_at(xi, yj)).collect())
                .collect(),
            domain: y
                .iter()
                .map(|&yj| x.iter().map(|&xi| self.map.domain_at(xi, yj)).collect())
                .collect(),
            true_height: grid(&|xi, yj| self.map.height_at(xi, yj)),
            materials,
            pixels,
            domain_names: self.map.domains.iter().map(|d| d.name.clone()).collect(),
            warnings,
            x,
            y,
        })
    }
}
