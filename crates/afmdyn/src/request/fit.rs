//! `fit`: a measured quasi-static force curve fitted with a contact law of the registry
//! ([`crate::analysis::fit::force_curve`]) — the request the command line (`afmdyn fit`) and,
//! by its name, Python share: its data (read here), its options, their checks and its declared
//! cost. Everything is SI (m, N, Pa, J/m²); a probe file is needed (the lever's spring
//! constant, the start values and the held parameters).

use super::costs::OPERATION_WORK;
use super::fit_dynamic::fit_evaluations;
use super::fit_result::MIN_FIT_ROWS;
use super::limits::Cost;
use super::run::Resolved;
use crate::analysis::fit::force_curve::{self, Segment, CONTACT_POINT, YOUNGS_MODULUS};
use crate::analysis::fit::profile::MAX_GRID_REFITS;
use crate::analysis::fit::sls_curve;
use crate::contact::indenter::bottom_effect::BottomEffect;
use crate::contact::indenter::Indenter;
use crate::contact::LawKind;
use crate::error::SimError;
use crate::probe::SampleInputs;
use serde::{Deserialize, Serialize};

/// The most rows a force curve may have (a 1 MHz record of one second).
pub(crate) const MAX_FIT_ROWS: usize = 1_000_000;

/// The segment of the curve fitted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "snake_case")]
pub enum FitSegment {
    /// The approach, up to the lowest piezo height.
    #[default]
    Approach,
    /// The retract, after it.
    Retract,
    /// Every row: approach, dwell and retract (the default of the `sls` law, whose dwell
    /// shows its relaxation or creep).
    Whole,
}

request! {
    /// `fit`: the force curve (a CSV file `data`, or the columns `height`, `force` and optionally
    /// `sigma` and `time`), the parameters fitted (`fit`, probe keys), the segment and the range of tip
    /// positions fitted.
    pub struct FitRequest {
        /// A CSV file, read through the bounded reader (instead of the columns `height` and
        /// `force`). A force
        /// curve: the columns `height` (m, the piezo height, decreasing into the sample), `force`
        /// (N, repulsion positive) and optionally `sigma` (N, each force's standard deviation) and
        /// `time` (s, strictly increasing; needed by the `sls` law). A
        /// dynamic curve: `z` (m, the piezo position, in the order stepped) with `amplitude` (m)
        /// and/or `phase` (deg) (AM), or `frequency_shift` (Hz) (FM, at the probe's free
        /// amplitude), or `amplitude_2` (m) and/or `phase_2` (deg) (bimodal, a probe with a second
        /// drive component), each with an optional `sigma_<column>`.
        pub data: Option<String>,
        /// The piezo heights (m), when no `data` file is given.
        pub height: Vec<f64>,
        /// The forces (N), as many as `height`.
        pub force: Vec<f64>,
        /// The forces' standard deviations (N, > 0), as many as `force`; without them the noise is
        /// estimated from the residuals.
        pub sigma: Option<Vec<f64>>,
        /// The rows' times (s, strictly increasing), as many as `force`, when no `data` file is
        /// given; needed by the `sls` law (its relaxation and creep), ignored by the others.
        pub time: Vec<f64>,
        /// The parameters fitted, by their probe keys: `sample.youngs_modulus`, `tip.radius`,
        /// `contact_point`, `baseline`, and `sample.hamaker` (DMT) or `sample.adhesion_energy`
        /// (JKR); of the `sls` law `sample.stiffness`, `sample.maxwell_stiffness`,
        /// `sample.relaxation_time` (N/m, N/m, s), `contact_point` and `baseline`. The others are
        /// held at the probe's values (contact point and baseline at 0, after the preprocessing).
        /// Default `sample.youngs_modulus`, `contact_point` (for `sls`: its three, `contact_point`
        /// and `baseline`). Of an AM, FM or bimodal curve: `sample.youngs_modulus`,
        /// `sample.hamaker` (DMT), `sample.viscosity` (DMT and JKR; Kelvin–Voigt η, Pa s),
        /// `sample.damping` (Hertz's damper, N s/m), `sample.adhesion_energy` (JKR, J/m²),
        /// `tip.radius`, `drive.free_amplitude` (m),
        /// `cantilever.quality_factor` (AM and bimodal curves without `[medium]`;
        /// at resonance Q trades against the sample's E: fit it with E held) and `z_offset` (always
        /// fitted); default `sample.youngs_modulus`, `sample.hamaker` (DMT) or
        /// `sample.adhesion_energy` (JKR) and `z_offset`.
        pub fit: Vec<String> = vec![YOUNGS_MODULUS.into(), CONTACT_POINT.into()],
        /// The segment fitted: `approach`, `retract` or `whole`; default the approach, the whole
        /// curve for the `sls` law.
        pub segment: Option<FitSegment>,
        /// The range of tip positions fitted [lo, hi] (m, after the preprocessing's offset, as
        /// nanite's `range_x`; on a dynamic curve, of its piezo positions z); default the whole
        /// segment.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
        pub range: Option<[f64; 2]>,
        /// The number of rows of the approach (the rest is the retract), as an instrument records
        /// its segments (afmformats' `segment` column, which Python reads from an instrument
        /// file); default up to the lowest piezo height, inclusive. 1 to the number of rows.
        pub approach_rows: Option<usize>,
        /// Profile-likelihood intervals (Δχ² ≤ 3.84) for the fitted parameters, up to 4 of them,
        /// the probe keys (sample, tip) before the contact point, baseline and z_offset (beyond,
        /// and when off, the Wald intervals ±1.96 SE). Default on for a force curve; off
        /// for an AM curve, where every profile point is a refit of stepped approaches (on, each
        /// side is walked by secants on √Δχ² in units of the standard error, at most 6 refits, each
        /// started from its neighbour; a side that has not risen by then is reported flat).
        pub profiles: Option<bool>,
        /// The sample's thickness h (m, > 0) above a rigid substrate: the Hertz law's force is
        /// corrected for the bottom effect (Dimitriadis et al., *Biophys. J.* 82 (2002) 2798 for
        /// the paraboloid and the sphere; Garcia & Garcia, *Biophys. J.* 114 (2018) 2923 for the
        /// cone, the pyramids and the flat punch, an incompressible sample, ν 0.45–0.5). Default
        /// none: a sample infinitely thick.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
        pub thickness: Option<f64>,
        /// Whether the sample is bonded to the substrate (glued; the default, true) or free to
        /// slide on it (false: Dimitriadis et al.'s non-bonded series, of the paraboloid and the
        /// sphere only). Used with `thickness`.
        pub bonded: Option<bool>,
        /// The temperature T (K, > 0 and ≤ 1500) of a force curve's thermal σ: when the data carry
        /// no `sigma`, each force's standard deviation is the lever's thermal force noise
        /// σ_F = k √(⟨z*²⟩_B + n_d² B), ⟨z*²⟩_B the optical lever's mean-square deflection below
        /// the `bandwidth` B from the probe's thermal spectrum (`afmdyn thermal`, each mode as its
        /// oscillator) and n_d the `detector_noise`: the free lever's (in contact with a sample of
        /// stiffness k_s the scatter about the fit grows to √(1 + k_s/k) times it, the lever and
        /// the sample in parallel seen through the tip position computed from the deflection).
        /// Default none: σ from the residuals.
        pub temperature: Option<f64>,
        /// The detection bandwidth B (Hz, > 0) of the thermal σ; default the Nyquist frequency of
        /// the `time` column, 1/(2Δt).
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "frequency")))]
        pub bandwidth: Option<f64>,
        /// The detector's deflection noise floor n_d (m/√Hz, ≥ 0) of the thermal σ; default 0.
        pub detector_noise: Option<f64>,
    }
}

/// A force curve's columns: heights, forces, their σ and the rows' times.
type Columns = (Vec<f64>, Vec<f64>, Option<Vec<f64>>, Option<Vec<f64>>);

/// A refusal naming `name`.
pub(crate) fn bad(
    name: &'static str,
    value: impl std::fmt::Display,
    allowed: impl Into<std::borrow::Cow<'static, str>>,
) -> SimError {
    SimError::out_of_range(name, value, allowed)
}

/// The columns `height`, `force` and optionally `sigma` and `time` of the CSV file `path`, read through
/// the bounded reader ([`crate::io::curve_file::read_curve_file`], a curve CSV's cap).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `data` and the file: refused by the reader, unreadable, a
/// missing column or a field that is not a number.
#[cfg(feature = "files")]
pub(crate) fn read_force_curve(path: &std::path::Path) -> Result<Columns, SimError> {
    use crate::io::curve_file::{read_curve_file, CurveFile};
    let file = |m: String| bad("data", path.display(), m);
    match read_curve_file(path).map_err(|e| file(e.to_string()))? {
        CurveFile::Document(_) => Err(file(
            "a JSON document; fit reads a CSV with the columns height (m) and force (N)".into(),
        )),
        CurveFile::Columns(names, cols) => {
            let col = |n: &str| names.iter().position(|c| c == n).map(|i| cols[i].clone());
            let missing = |c: &str| file(format!("no column {c} among {}", names.join(", ")));
            let height = col("height").ok_or_else(|| missing("height (m)"))?;
            let force = col("force").ok_or_else(|| missing("force (N)"))?;
            Ok((height, force, col("sigma"), col("time")))
        }
    }
}

impl FitRequest {
    /// The data's columns: the file's or the request's.
    ///
    /// # Errors
    /// As `read_force_curve`; [`SimError::OutOfRange`] naming `data` where both or neither
    /// are given, or a file without the `files` feature.
    pub fn columns(&self) -> Result<Columns, SimError> {
        match (&self.data, self.height.is_empty() && self.force.is_empty()) {
            (Some(_), false) => Err(bad(
                "data",
                "given with height/force",
                "give either a data file or the columns height and force, not both",
            )),
            #[cfg(feature = "files")]
            (Some(path), true) => read_force_curve(std::path::Path::new(path)),
            #[cfg(not(feature = "files"))]
            (Some(_), true) => Err(bad(
                "data",
                "a file",
                "this build reads no files: give the columns height and force",
            )),
            (None, true) => Err(bad(
                "data",
                "missing",
                "a force curve is needed: a CSV file (columns height, force, optional sigma) \
                 or the columns height and force",
            )),
            (None, false) => Ok((
                self.height.clone(),
                self.force.clone(),
                self.sigma.clone(),
                (!self.time.is_empty()).then(|| self.time.clone()),
            )),
        }
    }

    /// The law of the probe and every model parameter's name.
    fn law(model: &Resolved) -> Result<LawKind, SimError> {
        let p = model.probe.as_ref().ok_or_else(|| {
            bad(
                "probe",
                "missing",
                "fit needs a probe file (the lever's spring constant, the start values and the \
                 held parameters in SI)",
            )
        })?;
        let name = p.params.contact_law.name();
        name.parse::<LawKind>()
            .ok()
            .filter(|&k| force_curve::parameter_names(k).is_some())
            .ok_or_else(|| {
                bad(
                    "law",
                    name,
                    "the force-curve fit takes the probe's [sample].law = hertz, dmt, jkr or sls",
                )
            })
    }

    /// The parameters fitted: `fit`, or the `sls` law's default when `fit` is the request's.
    pub(crate) fn fitted(&self, law: LawKind) -> Vec<String> {
        if law == LawKind::Sls && self.fit == FitRequest::default().fit {
            return sls_curve::DEFAULT_FIT
                .iter()
                .map(|s| s.to_string())
                .collect();
        }
        self.fit.clone()
    }

    /// The segment fitted: `segment`, or the law's default (the whole curve for `sls`).
    pub(crate) fn segment_of(&self, law: LawKind) -> Segment {
        match self.segment {
            Some(FitSegment::Approach) => Segment::Approach,
            Some(FitSegment::Retract) => Segment::Retract,
            Some(FitSegment::Whole) => Segment::Whole,
            None if law == LawKind::Sls => Segment::Whole,
            None => Segment::Approach,
        }
    }

    /// The tip's shape of the probe's `[tip]` and the bottom-effect correction of `thickness`
    /// (and `bonded`) for the sample `s` ([`crate::contact::indenter`]).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `thickness`, `bonded` or `sample.poisson_ratio`
    /// ([`BottomEffect::new`]), or `bonded` given without `thickness`.
    pub(crate) fn indenter(&self, s: &SampleInputs) -> Result<Indenter, SimError> {
        let shape = s.tip_shape;
        let bottom = match (self.thickness, self.bonded) {
            (None, Some(b)) => {
                return Err(bad(
                    "bonded",
                    b,
                    "bonded is the bottom-effect correction's: give the sample's thickness (m)",
                ))
            }
            (None, None) => None,
            (Some(h), bonded) => {
                let nu = s.poisson_ratio.unwrap_or(f64::NAN);
                Some(BottomEffect::new(shape, h, bonded.unwrap_or(true), nu)?)
            }
        };
        Ok(Indenter { shape, bottom })
    }

    /// Check the options against the probe's law (the data are checked when read).
    pub(crate) fn check(&self, model: &Resolved) -> Result<LawKind, SimError> {
        let law = Self::law(model)?;
        let inputs = model
            .probe
            .as_ref()
            .map(|p| p.sample_inputs)
            .unwrap_or_default();
        inputs.tip_shape.check_law(law)?;
        if self.thickness.is_some() && law != LawKind::Hertz {
            return Err(bad(
                "thickness",
                crate::error::number(self.thickness.unwrap_or(f64::NAN)),
                format!(
                    "the bottom-effect correction is the hertz law's elastic force's; the {} \
                     law takes none",
                    law.name()
                ),
            ));
        }
        if law == LawKind::Hertz {
            self.indenter(&inputs)?;
        }
        self.check_noise(model)?;
        let names = force_curve::parameter_names_of(law, &inputs.tip_shape).unwrap_or_default();
        if law == LawKind::Jkr && self.segment == Some(FitSegment::Whole) {
            return Err(bad(
                "segment",
                "whole",
                "the jkr law's contact differs on the approach and the retract: fit one of them",
            ));
        }
        let fit = self.fitted(law);
        if fit.is_empty() {
            return Err(bad(
                "fit",
                "none",
                format!("name one or more of {}", names.join(", ")),
            ));
        }
        for (i, f) in fit.iter().enumerate() {
            if !names.contains(&f.as_str()) {
                return Err(bad(
                    "fit",
                    f,
                    format!(
                        "the {} law's parameters are {}",
                        law.name(),
                        names.join(", ")
                    ),
                ));
            }
            if fit[..i].contains(f) {
                return Err(bad("fit", f, "named twice"));
            }
        }
        self.check_range()?;
        if self.data.is_none() {
            // (the times matter, and are checked, for the sls law only)
            let time =
                (law == LawKind::Sls && !self.time.is_empty()).then_some(self.time.as_slice());
            check_columns(&self.height, &self.force, self.sigma.as_deref(), time)?;
        }
        Ok(law)
    }

    /// `range`, when given, is two finite positions lo < hi.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `range`.
    fn check_range(&self) -> Result<(), SimError> {
        match self.range {
            Some([lo, hi]) if !(lo.is_finite() && hi.is_finite() && lo < hi) => Err(bad(
                "range",
                format!("[{lo}, {hi}]"),
                "must be two finite positions lo < hi (m)",
            )),
            _ => Ok(()),
        }
    }

    /// The thermal σ's options: T in (0, 1500] K, B > 0, n_d ≥ 0, neither of the latter
    /// without T, and a probe that gives the lever's resonance and Q (not a quasi-static
    /// read's stand-ins).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the option.
    fn check_noise(&self, model: &Resolved) -> Result<(), SimError> {
        let needs = [
            ("bandwidth", self.bandwidth),
            ("detector_noise", self.detector_noise),
        ];
        super::limits::needs_temperature(self.temperature, &needs)?;
        let Some(t) = self.temperature else {
            return Ok(());
        };
        super::limits::check_temperature(t)?;
        let number = crate::error::number;
        let positive = |b| super::limits::positive("bandwidth", b, "finite and > 0 (Hz)");
        self.bandwidth.map(positive).transpose()?;
        if let Some(n) = self.detector_noise {
            let why = "finite and ≥ 0 (m/√Hz)";
            crate::error::within("detector_noise", n, 0.0..f64::INFINITY, why)?;
        }
        match model.probe.as_ref().map(|p| &p.assumed) {
            Some(a) if a.iter().any(|k| k.starts_with("[cantilever]")) => Err(bad(
                "temperature",
                number(t),
                "the thermal σ needs the lever's modes: give [cantilever] resonance_frequency \
                 and quality_factor in the probe",
            )),
            _ => Ok(()),
        }
    }
}

/// The columns' lengths, sizes and values.
pub(crate) fn check_columns(
    height: &[f64],
    force: &[f64],
    sigma: Option<&[f64]>,
    time: Option<&[f64]>,
) -> Result<(), SimError> {
    let rows = force.len();
    if height.len() != rows
        || sigma.is_some_and(|s| s.len() != rows)
        || time.is_some_and(|t| t.len() != rows)
    {
        return Err(bad(
            "force",
            force.len(),
            format!(
                "height, force (and sigma, time) must have one value per row ({} heights)",
                height.len()
            ),
        ));
    }
    if !(MIN_FIT_ROWS..=MAX_FIT_ROWS).contains(&force.len()) {
        return Err(bad(
            "data",
            format!("{} rows", force.len()),
            format!("a force curve has {MIN_FIT_ROWS}..={MAX_FIT_ROWS} rows"),
        ));
    }
    for (name, column) in [("height", height), ("force", force)] {
        if let Some(i) = column.iter().position(|x| !x.is_finite()) {
            return Err(bad(
                name,
                format!("row {}: {}", i + 1, column[i]),
                "every value must be finite",
            ));
        }
    }
    if let Some(i) = sigma.and_then(|s| s.iter().position(|x| !(x.is_finite() && *x > 0.0))) {
        return Err(bad(
            "sigma",
            format!("row {}", i + 1),
            "must be finite and > 0 (N)",
        ));
    }
    if let Some(i) = time
        .and_then(|t| (0..t.len()).position(|i| !(t[i].is_finite() && (i == 0 || t[i] > t[i - 1]))))
    {
        return Err(bad(
            "time",
            format!("row {}", i + 1),
            "must be finite and strictly increasing (s)",
        ));
    }
    Ok(())
}

impl_request! {
    // a force curve uses the probe's spring constant, tip and sample only; an AM, FM or
    // bimodal curve refuses the values a quasi-static read stood in for
    // (`super::fit_dynamic::am_probe`)
    FitRequest, "fit",
    advice = "give fewer rows (an AM curve: fit fewer rows or parameters, or without profiles)",
    needs = Static;
    validate |r, model| {
        if super::fit_dynamic::read_am_data(r.data.as_deref())?.is_some() {
            // an AM curve: its names and columns are checked when it runs; a probe read
            // for a force curve (its stand-ins) is refused now
            if let Some(p) = model.probe.as_ref().filter(|p| !p.assumed.is_empty()) {
                super::fit_dynamic::am_probe(p)?;
            }
            if let Some((name, value)) = r
                .thickness
                .map(|h| ("thickness", crate::error::number(h)))
                .or(r.bonded.map(|b| ("bonded", b.to_string())))
                .or(r
                    .temperature
                    .map(|t| ("temperature", crate::error::number(t))))
            {
                return Err(bad(
                    name,
                    value,
                    "the bottom-effect correction is the force-curve fit's; a dynamic curve's \
                     sample is a half space",
                ));
            }
            return r.check_range();
        }
        r.check(model).map(|_| ())
    };
    cost |r, model| {
        // an AM curve: its stepped approaches, the profiles' refits included
        if let Some(d) = super::fit_dynamic::read_am_data(r.data.as_deref())? {
            let law = model
                .probe
                .as_ref()
                .map_or("", |p| p.params.contact_law.name());
            let default_fit = r.fit == FitRequest::default().fit;
            let n = super::fit_dynamic::fitted_names(&r.fit, default_fit, law).len();
            let profiles = r.profiles.unwrap_or(false);
            return super::fit_dynamic::cost(d.z.len(), n, profiles, &model.params);
        }
        // no integration; a row of the columns, the preprocessed curve, the Jacobian (≤ 5
        // columns), the residuals, the document's numbers, the outcome's arrays and the front
        // end's table and figures: 900 bytes (the library's run 343 at 1 000 to 10⁶ rows,
        // `tests/door.rs`; the command line's heap 783 and its resident set 818 at 10⁶ rows)
        let (n, walk) = (r.fit.len().max(5), r.profiles.unwrap_or(true));
        let rows = if r.data.is_some() {
            MAX_FIT_ROWS
        } else {
            r.force.len()
        } as f64;
        Ok(Cost {
            bytes: super::costs::MODEL_BYTES + rows * 900.0,
            // each evaluation a row's model and Jacobian (of at most five parameters: SLS's
            // three, the contact point and the baseline), the profiles walked on a grid
            work: rows * OPERATION_WORK * fit_evaluations(n, walk.then_some(MAX_GRID_REFITS)),
        })
    }
}
