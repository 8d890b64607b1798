//! PeakForce images (issue 61 §3): `afmdyn image --mode peakforce --setpoint 2nN` — the maps
//! an ideal peak-force feedback records over a sample map ([`super::image::SampleMap`]) with an
//! off-resonance probe ([`crate::analysis::peakforce`]). This module holds the request's side:
//! the background probe checked to be off resonance with its setpoint (`peakforce_probe`) and
//! the image's declared cost (`peakforce_cost`: the materials' engages and one tap per change
//! of material along the lines); the image runs as a study of lines in the study layer.

use super::costs::{newton_work, steady_periods, MODEL_BYTES};
use super::image::{background_probe, material_models, pixel_grid, ImageRequest, SampleMap};
use super::limits::{thermal_force, Cost};
use crate::analysis::peakforce::{PeakForceOptions, BRACKET_STEPS, SETPOINT_ITERATIONS};
use crate::error::SimError;
use crate::probe::Probe;

/// Taps a change of material is expected to cost (the request's cost estimate): one, from the
/// material's engaged orbit (its operating point at the setpoint, where the continuation
/// starts).
pub(crate) const TAPS_PER_CHANGE: f64 = 1.0;

/// The background probe of a PeakForce image, checked to be off resonance.
///
/// # Errors
/// As the background probe of an AM image (a probe the format refuses, a multifrequency
/// drive); [`SimError::OutOfRange`] naming `excitation` or `omega` for a probe without an
/// off-resonance drive ([`super::peakforce::check_off_resonance`]), `setpoint` for a setpoint
/// that is not a finite force > 0.
pub(crate) fn peakforce_probe(probe_table: &toml::Table, setpoint: f64) -> Result<Probe, SimError> {
    let background = background_probe(probe_table)?;
    super::peakforce::check_off_resonance(&background.params, background.off_resonance)?;
    super::limits::positive(
        "setpoint",
        setpoint,
        "must be the peak force (N) the feedback holds, finite and > 0 (2 nN is 2e-9, or 2nN \
         on the command line)",
    )?;
    Ok(background)
}

/// What a PeakForce image of `map` costs: the materials' engages (the feedback's bracket and
/// iterations each), [`TAPS_PER_CHANGE`] taps at every change of material along the lines,
/// each material's thermal noise with a temperature, and the pixels' memory.
///
/// # Errors
/// As [`peakforce_probe`], the probe's models and the taps' transient estimate; as
/// [`thermal_force`] for the temperature; [`SimError::Unsupported`] under one for a material of
/// the impact law.
pub(crate) fn peakforce_cost(
    probe_table: &toml::Table,
    map: &SampleMap,
    req: &ImageRequest,
) -> Result<Cost, SimError> {
    let background = peakforce_probe(probe_table, req.setpoint)?;
    let (models, of_domain, _) = material_models(probe_table, map, &background)?;
    let opts = PeakForceOptions::default();
    let p = background.params;
    let lever_periods = (1.0 / p.omega).max(1.0);
    let tap = (steady_periods(&opts.steady, &p)? * p.modes as f64
        + newton_work(&p, 1, &opts.shooting))
        * lever_periods;
    let (x, y) = pixel_grid(map, req);
    let material = |xi: f64, yj: f64| map.domain_at(xi, yj).map_or(0, |k| of_domain[k]);
    let changes: usize = y
        .iter()
        .map(|&yj| {
            x.windows(2)
                .filter(|w| material(w[0], yj) != material(w[1], yj))
                .count()
        })
        .sum();
    let engages = models.len() as f64 * (2 * BRACKET_STEPS + SETPOINT_ITERATIONS) as f64;
    // with a temperature, each material's noise at its engage, its law admitted
    let mut noise = 0.0;
    if let Some(t) = req.temperature {
        thermal_force(t, 0, Some(&background))?;
        for (_, q) in &models {
            crate::analysis::peakforce::noise::admits(&q.contact_law)?;
            noise += super::peakforce::noise_work(q);
        }
    }
    Ok(Cost {
        bytes: MODEL_BYTES + req.pixel_bytes(map),
        work: (engages + changes as f64 * TAPS_PER_CHANGE) * tap + noise,
    })
}
