//! `simulate` streamed to files ([`SimulateStream`]): the request, its checks against the
//! files' budget ([`SeriesStore::Files`]) and its cost before any work (its running, recorded
//! in chunks with the plots' data in bounded memory, is the study layer's).

use super::analyses::{initial_state, SeriesStore, SimulateRequest, SimulateSpan};
use super::costs::{state_bytes, MODEL_BYTES};
use super::limits::Cost;
use crate::analysis::spectrum::SPECTRUM_SAMPLES;
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::trajectory::chunked::CHUNK_SAMPLES;
use std::path::PathBuf;

/// Samples kept for the phase portrait (the last ones).
pub(crate) const PHASE_SAMPLES: usize = 50_000;
/// Drive periods `tip.png` shows (the last ones) when more were recorded; `tip-all.png` then
/// shows every recorded period (a 50-period chaotic record drawn whole is unreadable).
pub(crate) const TIP_WINDOW_PERIODS: usize = 10;
/// Pixel columns of the tip plots' grid, on which their lines are decimated as they come.
pub(crate) const TIP_COLUMNS: f64 = 2000.0;

/// `simulate` with its series streamed to the files of `dir` (none: only the summary).
#[derive(Debug, Clone, PartialEq)]
pub struct SimulateStream {
    /// The run.
    pub request: SimulateRequest,
    /// The output directory (locked by the caller); `None`: no files, only the summary.
    pub dir: Option<PathBuf>,
    /// Draw the figures (with `dir`).
    pub figures: bool,
    /// Also write the time series as CSV (`timeseries.csv`; by default only the NPY file).
    pub csv: bool,
    /// Drive periods held in memory at once (testing the streaming; `None`: from the samples).
    pub chunk_periods: Option<usize>,
}

impl SimulateStream {
    /// `all` (data and figures), `data` or `none`: the files written.
    pub fn files(&self) -> &'static str {
        match (&self.dir, self.figures) {
            (None, _) => "none",
            (Some(_), false) => "data",
            (Some(_), true) => "all",
        }
    }

    /// The request validated on `params` for its store: τ, V_T, W, Ẇ, contact, force and the
    /// 2N modal coordinates per sample, 8 bytes each in the NPY file and up to 24 more in the
    /// CSV one.
    pub(crate) fn span(&self, params: &crate::params::Params) -> Result<SimulateSpan, SimError> {
        let (store, bytes_per_value) = match (&self.dir, self.csv) {
            (None, _) => (SeriesStore::Nothing, 0.0),
            (Some(_), true) => (SeriesStore::Files, 8.0 + 24.0),
            (Some(_), false) => (SeriesStore::Files, 8.0),
        };
        self.request
            .validate(params, store, 6 + 2 * params.modes, bytes_per_value)
    }
}

impl_request! {
    SimulateStream, "simulate";
    validate |r, model| {
        r.span(&model.params)?;
        r.request.integrator_options()?;
        r.request.thermal(model.probe.as_ref())?;
        let m = CantileverModel::new(&model.params)?;
        initial_state(&m, r.request.initial.as_deref()).map(|_| ())
    };
    cost |r, model| {
        // every period integrated, transient included; in memory one chunk of samples (its
        // rows and the converted copy, at most CHUNK_SAMPLES of 6 + 2N + m values, or one
        // period of them) and the plots' windows (the last TIP_WINDOW_PERIODS periods, the
        // phase portrait's and the spectrum's samples, the decimated lines)
        let p = &model.params;
        let span = r.span(p)?;
        let spp = r.request.samples_per_period as f64;
        let row = 6.0 * 8.0 + state_bytes(p);
        let chunk = match r.chunk_periods {
            Some(n) => n as f64 * spp,
            None => (CHUNK_SAMPLES as f64).max(spp),
        };
        let plots = (TIP_WINDOW_PERIODS as f64 * spp + 1.0) * 32.0
            + PHASE_SAMPLES as f64 * 24.0
            + 2.0 * 9.0 * TIP_COLUMNS * 16.0;
        let kept = match r.dir {
            Some(_) => 2.0 * chunk * row + SPECTRUM_SAMPLES as f64 * 8.0 + plots,
            None => 0.0,
        };
        Ok(Cost {
            bytes: MODEL_BYTES + kept,
            work: span.total_periods * p.modes as f64,
        })
    }
}
