//! `fit-map`: every curve of a force-volume or QI map fitted as `fit` fits one
//! ([`super::FitRequest`]'s options, [`crate::analysis::fit::force_curve`]'s model), the
//! results laid on the map's grid — the request the command line (`afmdyn fit-map`) and
//! Python (`afmdyn.fit_map`) share: its map file, its options, their checks and its declared
//! cost. Everything is SI (m, N, Pa).

use super::costs::OPERATION_WORK;
use super::fit::{bad, FitRequest, FitSegment};
use super::fit_dynamic::fit_evaluations;
use super::limits::Cost;
use crate::analysis::fit::force_curve::{BASELINE, CONTACT_POINT, YOUNGS_MODULUS};
use crate::error::SimError;

request! {
    /// `fit-map`: the map (`data`, a file), the parameters fitted at every curve (`fit`, probe
    /// keys), the segment and the range of tip positions fitted, and the worker threads.
    pub struct FitMapRequest {
        /// The map, read through the bounded reader and streamed (one curve at a time): a
        /// long-format CSV with the columns `x`, `y` (m, the curve's position), `height` (m, the
        /// piezo height, decreasing into the sample), `force` (N, repulsion positive) and
        /// optionally `segment` (0 approach, 1 retract) and `time` (s), a curve's rows
        /// consecutive; or the NetCDF file `afmdyn.export_map` writes (from any map afmformats
        /// reads, with each curve's grid index and spring constant).
        pub data: Option<String>,
        /// The parameters fitted at every curve, by their probe keys (as `fit`'s:
        /// `sample.youngs_modulus`, `tip.radius`, `contact_point`, `baseline`, `sample.hamaker`
        /// (DMT), `sample.adhesion_energy` (JKR)); the others held at the probe's values. Default
        /// `sample.youngs_modulus`, `contact_point` and `baseline`, as nanite fits a map.
        pub fit: Vec<String> = vec![YOUNGS_MODULUS.into(), CONTACT_POINT.into(), BASELINE.into()],
        /// The segment fitted: `approach` (the default), `retract` or `whole`.
        pub segment: Option<FitSegment>,
        /// The range of tip positions fitted [lo, hi] (m, relative to each curve's contact point
        /// found by the deviation from the baseline, as nanite's `range_x`); default the whole
        /// segment.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
        pub range: Option<[f64; 2]>,
        /// The sample's thickness h (m, > 0) above a rigid substrate, one value for every curve:
        /// the Hertz law's force corrected for the bottom effect as `fit`'s `thickness`
        /// (Dimitriadis et al. 2002; Garcia & Garcia 2018). Default none: a sample infinitely
        /// thick. Not with `substrate_height`.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
        pub thickness: Option<f64>,
        /// The substrate's piezo height (m, the `height` column's frame), read, for instance, on
        /// a bare-glass pixel of the map's topography: each curve's thickness is its fitted
        /// contact point's height above it (the curve refitted until its thickness moves by less
        /// than 1e-4 of itself, from the contact point the deviation from the baseline finds). A
        /// curve whose contact is not above it fails, naming it. Not with `thickness`.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
        pub substrate_height: Option<f64>,
        /// Whether the sample is bonded to the substrate (the default, true) or free to slide on
        /// it (false: the paraboloid's and the sphere's non-bonded series only), with
        /// `thickness` or `substrate_height`.
        pub bonded: Option<bool>,
        /// Worker threads (default: all cores); the results do not depend on it.
        pub threads: Option<usize>,
    }
}

/// The bytes the index keeps of a curve, and a curve's record (its estimates, flag and reason).
const CURVE_BYTES: f64 = 1024.0;

/// The bytes of one row of a curve under way (its columns, the preprocessed curve, the
/// Jacobian and the residuals: `fit`'s 900).
const ROW_BYTES: f64 = 900.0;

impl FitMapRequest {
    /// The map file's path.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `data` when it is missing.
    pub fn path(&self) -> Result<&str, SimError> {
        self.data.as_deref().ok_or_else(|| {
            bad(
                "data",
                "missing",
                "a map is needed: a long-format CSV (x, y, height, force) or the NetCDF file \
                 afmdyn.export_map writes",
            )
        })
    }

    /// The request each curve is fitted with: `fit`'s options, its profiles off (each
    /// estimate's interval is Wald's, ±1.96 standard errors), the sample's `thickness` (with
    /// `substrate_height`, each curve's is set when it is fitted; here 1 m, so that the
    /// shape, `bonded` and the law are checked as with a thickness).
    pub(crate) fn curve_request(&self) -> FitRequest {
        FitRequest {
            data: self.data.clone(),
            fit: self.fit.clone(),
            segment: self.segment,
            range: self.range,
            profiles: Some(false),
            thickness: self.thickness.or(self.substrate_height.map(|_| 1.0)),
            bonded: self.bonded,
            ..FitRequest::default()
        }
    }

    /// Check `thickness` against `substrate_height`.
    fn check_layer(&self) -> Result<(), SimError> {
        match (self.thickness, self.substrate_height) {
            (Some(_), Some(z)) => Err(bad(
                "substrate_height",
                crate::error::number(z),
                "give the sample's thickness or the substrate's height, not both",
            )),
            (_, Some(z)) if !z.is_finite() => Err(bad(
                "substrate_height",
                crate::error::number(z),
                "the substrate's piezo height must be finite (m)",
            )),
            _ => Ok(()),
        }
    }

    /// The map indexed (one streamed pass through its file).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `data` and the file's problem.
    pub(crate) fn index(&self) -> Result<crate::io::force_map::ForceMap, SimError> {
        let path = self.path()?;
        crate::io::force_map::ForceMap::index(std::path::Path::new(path))
            .map_err(|e| bad("data", path, e.to_string()))
    }
}

impl_request! {
    // a map's curves use the probe's spring constant (where the map has none), tip and
    // sample only
    FitMapRequest, "fit_map", advice = "fit a part of the map, or curves of fewer rows",
    needs = Static;
    validate |r, model| {
        r.path()?;
        super::limits::check_threads(r.threads)?;
        r.check_layer()?;
        r.curve_request().check(model).map(|_| ())
    };
    // Measured on the map's index: each curve's record and index entry, one curve under way
    // per worker thread, and each row's evaluations.
    cost |r, _| {
        let (curves, rows, longest) = {
            let map = r.index()?;
            let rows: usize = map.curves.iter().map(|c| c.rows).sum();
            (map.curves.len() as f64, rows as f64, map.max_rows() as f64)
        };
        let cores = || std::thread::available_parallelism().map_or(1, |n| n.get());
        let threads = r.threads.unwrap_or_else(cores) as f64;
        let n = r.fit.len().max(1);
        Ok(Cost {
            bytes: super::costs::MODEL_BYTES + curves * CURVE_BYTES + threads * longest * ROW_BYTES,
            work: rows * OPERATION_WORK * fit_evaluations(n, None),
        })
    }
}
