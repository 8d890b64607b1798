//! A long run recorded in chunks of whole drive periods, each handed to the caller as it is
//! finished, so that memory does not grow with the length of the run (`afmdyn simulate`
//! streams its files this way; any front end can). The chunks are [`record_rows`] calls
//! continued
//! from one another; samples and section points a chunk shares with the previous one are
//! passed once.

use super::{record_rows, EnergyBalance, RecordSpec, SampleRows, Trajectory};
use crate::error::SimError;
use crate::integrate::{Integrator, SwitchEvent};
use nalgebra::DVector;

/// Samples held in memory at once by default (a chunk of the run).
pub(crate) const CHUNK_SAMPLES: usize = 65_536;
/// Drive periods of a chunk when no samples are kept.
pub(crate) const CHUNK_PERIODS_WITHOUT_SAMPLES: usize = 4096;

/// What to record, in chunks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ChunkedSpec {
    /// Drive periods run and discarded first.
    pub transient_periods: f64,
    /// Length of the recorded part, in τ.
    pub record_tau: f64,
    /// Samples per drive period (0: none kept).
    pub samples_per_period: usize,
    /// Audit the energy balance of every period ([`RecordSpec::energy`]).
    pub energy: bool,
    /// Drive periods per chunk; `None`: [`CHUNK_SAMPLES`] samples, or
    /// [`CHUNK_PERIODS_WITHOUT_SAMPLES`] periods without samples.
    pub chunk_periods: Option<usize>,
}

/// One finished chunk: the new samples, switchings, section points and energy balances.
#[derive(Debug)]
pub(crate) struct Chunk<'a> {
    /// Whether this is the first chunk (its first sample is the start of the recording).
    pub first: bool,
    /// The new samples (those of the previous chunk's end left out), rows of
    /// [`Chunk::width`] values as [`SampleRows`] has them.
    pub rows: &'a [f64],
    /// Values per row of [`Chunk::rows`], 6 + 2N ([`SampleRows::width`]).
    pub width: usize,
    /// The new stroboscopic section points (τ, z), z of shape `[2N]`.
    pub sections: Vec<&'a (f64, DVector<f64>)>,
    /// The chunk's recording, whole (switchings, energy, final state).
    pub trajectory: &'a Trajectory,
}

impl Chunk<'_> {
    /// The new samples, row by row ([`SampleRows`]' layout).
    pub(crate) fn samples(&self) -> std::slice::ChunksExact<'_, f64> {
        self.rows.chunks_exact(self.width.max(1))
    }

    /// The switchings of the chunk.
    pub(crate) fn events(&self) -> &[SwitchEvent] {
        &self.trajectory.events
    }

    /// The energy balances of the chunk's complete periods.
    pub(crate) fn energy(&self) -> &[EnergyBalance] {
        &self.trajectory.energy
    }
}

/// The totals of a chunked run.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct ChunkedSummary {
    /// Switchings in all.
    pub switchings: usize,
    /// Stroboscopic section points in all.
    pub sections: usize,
    /// Whether any beam point other than the tip reached the substrate.
    pub body_contact: bool,
    /// Largest per-period energy residual, absolute.
    pub residual: f64,
    /// Largest per-period energy residual relative to the period's largest term (NaN when a
    /// residual was NaN).
    pub relative: f64,
    /// The final τ.
    pub tau_end: f64,
    /// The final state, `[2N]`; `None` when nothing was recorded.
    pub final_state: Option<DVector<f64>>,
}

impl ChunkedSummary {
    fn add(&mut self, tr: &Trajectory) {
        self.switchings += tr.events.len();
        self.body_contact |= tr.body_contact;
        let (abs, rel) = super::energy_residual(&tr.energy);
        self.residual = self.residual.max(abs);
        self.relative = if rel.is_nan() {
            rel
        } else {
            self.relative.max(rel)
        };
    }
}

/// Record `spec` from `integ`'s current state in chunks, calling `each` on every chunk as it
/// is finished (the body-contact check on, the energy balance as `spec` asks), and `progress` with the drive periods done
/// (transient included).
///
/// Chunks end on stroboscopic sections τ = 2πk/Ω (so that no energy period is split) when the
/// sample grid passes through them — when transient × samples_per_period is an integer, or
/// when no samples are kept; otherwise on the sample grid (an energy period may then be split
/// between two chunks).
///
/// # Errors
/// The integrator's [`SimError`], or the first error `each` returns.
pub(crate) fn record_chunked<E: From<SimError>>(
    integ: &mut dyn Integrator,
    spec: &ChunkedSpec,
    mut each: impl FnMut(&Chunk<'_>) -> Result<(), E>,
    mut progress: impl FnMut(f64),
) -> Result<ChunkedSummary, E> {
    let period = integ.system().period();
    let spp = spec.samples_per_period;
    let start = integ.tau() + spec.transient_periods * period;
    let end = start + spec.record_tau;
    let chunk = spec
        .chunk_periods
        .unwrap_or(
            CHUNK_SAMPLES
                .checked_div(spp)
                .map_or(CHUNK_PERIODS_WITHOUT_SAMPLES, |n| n.max(1)),
        )
        .max(1) as f64;
    let on_sections = spp == 0 || {
        let x = spec.transient_periods * spp as f64;
        (x - x.round()).abs() <= 1e-9 * (1.0 + x)
    };
    let first_section = (start / period - 1e-9).ceil();
    let mut summary = ChunkedSummary::default();
    let mut last_sample = f64::NEG_INFINITY;
    let mut last_section = f64::NEG_INFINITY;
    let mut k = 0.0;
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (1.0 + a.abs());
    let mut rows = SampleRows::default();
    loop {
        k += 1.0;
        let target = if on_sections {
            (first_section + k * chunk) * period
        } else {
            start + k * chunk * period
        }
        .min(end);
        let first = k == 1.0;
        let now = integ.tau();
        let tr = record_rows(
            integ,
            &RecordSpec {
                transient_periods: if first { spec.transient_periods } else { 0.0 },
                record_tau: if first {
                    target - start
                } else {
                    (target - now).max(0.0)
                },
                samples_per_period: spp,
                energy: spec.energy,
                body_contact: true,
            },
            &mut rows,
        )?;
        summary.add(&tr);
        let width = rows.width();
        let skip = (0..rows.len())
            .take_while(|&i| close(rows.row(i)[0], last_sample))
            .count();
        let new_rows = &rows.as_slice()[skip * width..];
        if let Some(last) = new_rows.chunks_exact(width).last() {
            last_sample = last[0];
        }
        let sections: Vec<_> = tr
            .poincare
            .iter()
            .filter(|(t, _)| !close(*t, last_section))
            .collect();
        if let Some((t, _)) = sections.last() {
            last_section = *t;
        }
        summary.sections += sections.len();
        each(&Chunk {
            first,
            rows: new_rows,
            width,
            sections,
            trajectory: &tr,
        })?;
        progress(spec.transient_periods + (integ.tau() - start) / period);
        summary.tau_end = tr.tau_end;
        summary.final_state = Some(tr.final_state);
        if integ.tau() >= end {
            break;
        }
    }
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{build, IntegratorOptions};
    use crate::model::CantileverModel;
    use crate::params::Params;
    use crate::trajectory::record;

    /// The chunks, put together, are the run recorded at once: the same samples and section
    /// points, each once, whatever the chunk length (the defining property of the streaming),
    /// equal to round-off (a chunk restarts the grid stint at its start: 1e-15 here); the
    /// totals count each switching and section point once.
    #[test]
    fn chunks_put_together_are_the_whole_run() {
        let model = CantileverModel::new(&Params::default()).unwrap();
        let period = model.period();
        let opts = IntegratorOptions {
            steps_per_period: 40,
            ..IntegratorOptions::default()
        };
        let whole = {
            let mut integ = build(&model, opts.clone(), 0.0, &model.rest()).unwrap();
            record(
                integ.as_mut(),
                &RecordSpec {
                    transient_periods: 2.0,
                    record_tau: 10.0 * period,
                    samples_per_period: 40,
                    energy: true,
                    body_contact: true,
                },
            )
            .unwrap()
        };
        for chunk_periods in [1, 3, 7, 50] {
            let mut integ = build(&model, opts.clone(), 0.0, &model.rest()).unwrap();
            let (mut taus, mut sections, mut chunks) = (vec![], vec![], 0);
            let summary = record_chunked::<SimError>(
                integ.as_mut(),
                &ChunkedSpec {
                    transient_periods: 2.0,
                    record_tau: 10.0 * period,
                    samples_per_period: 40,
                    energy: true,
                    chunk_periods: Some(chunk_periods),
                },
                |c| {
                    chunks += 1;
                    taus.extend(c.samples().map(|s| (s[0], s[2])));
                    sections.extend(c.sections.iter().map(|(t, z)| (*t, z[0])));
                    Ok(())
                },
                |_| {},
            )
            .unwrap();
            let same = |got: &[(f64, f64)], expected: Vec<(f64, f64)>| {
                assert_eq!(
                    got.len(),
                    expected.len(),
                    "chunks of {chunk_periods} periods"
                );
                for (g, e) in got.iter().zip(&expected) {
                    assert!((g.0 - e.0).abs() <= 1e-13 * (1.0 + e.0), "{g:?} vs {e:?}");
                    assert!((g.1 - e.1).abs() <= 1e-12, "{g:?} vs {e:?}");
                }
            };
            same(
                &taus,
                whole.samples.iter().map(|s| (s.tau, s.w_tip)).collect(),
            );
            same(
                &sections,
                whole.poincare.iter().map(|(t, z)| (*t, z[0])).collect(),
            );
            assert_eq!(summary.sections, whole.poincare.len());
            assert_eq!(summary.switchings, whole.events.len());
            assert_eq!(chunks, 10usize.div_ceil(chunk_periods));
        }
    }
}
