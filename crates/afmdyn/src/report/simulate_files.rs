//! The data files of a long run, streamed chunk by chunk ([`crate::trajectory::chunked`]) so
//! that memory does not grow with the run (`afmdyn simulate --out DIR`; `docs/outputs.md`):
//!
//! - `timeseries.npy` (and `timeseries.csv` when asked for): the samples, columns
//!   [`SeriesUnits::columns`] (time, V_T, W(1,τ), ∂W/∂τ, contact, force, a_1…a_N,
//!   ȧ_1…ȧ_N), with `timeseries.npy.json` describing them;
//! - `events.csv`: time, from, to, dV_T/dτ of every switching;
//! - `poincare.csv`: time, V_T, W(1,τ), ∂W/∂τ at the stroboscopic section τ = 2πk/Ω;
//! - `energy.csv` (when asked for): the energy balance of every complete drive period (start, stored energy at
//!   its start and end, base work, beam and contact dissipation, residual, end).
//!
//! Values are in the units of a [`SeriesUnits`]: the model's, or SI with a probe. Every file is
//! written to a temporary name and renamed into place by [`SeriesFiles::finish`]; dropped
//! unfinished (an error, an interrupt), the partial files are removed.

use crate::layout::files::{csv_finish, csv_line, csv_lines, csv_stream};
use crate::layout::files::{Column, CsvStream, Field, FileError, NpyStream};
use crate::model::CantileverModel;
use crate::report::SeriesUnits;
use crate::system::Region;
use crate::trajectory::chunked::Chunk;
use std::path::Path;

/// The names of the files [`SeriesFiles`] writes (a run removes their stale temporary
/// siblings first).
pub(crate) const SERIES_FILES: [&str; 6] = [
    "timeseries.npy",
    "timeseries.npy.json",
    "timeseries.csv",
    "events.csv",
    "poincare.csv",
    "energy.csv",
];

/// The open data files of a run (see the module doc).
pub(crate) struct SeriesFiles {
    su: SeriesUnits,
    npy: NpyStream,
    csv: Option<CsvStream>,
    events: CsvStream,
    poincare: CsvStream,
    energy: Option<CsvStream>,
    /// The samples converted to `su`'s units, and CSV lines: reused from chunk to chunk.
    converted: Vec<f64>,
    lines: Vec<u8>,
}

/// The columns of `timeseries.npy` (and `.csv`) of an N-mode run in `su`'s units.
pub(crate) fn series_columns(n: usize, su: &SeriesUnits) -> Vec<Column> {
    su.columns(n)
        .into_iter()
        .map(|c| Column::new(c.name, c.unit, c.long_name))
        .collect()
}

/// The rows of samples of an `n`-mode run ([`crate::trajectory::SampleRows`]' layout, rows of
/// `width` = 6 + 2N + m) as [`series_columns`] has them, in `su`'s units, written over `out`:
/// the modal state (a, ȧ) of each row; a law's m internal states (an SLS sample's u, the row's
/// last entries) are not written.
fn convert_rows(rows: &[f64], width: usize, n: usize, su: &SeriesUnits, out: &mut Vec<f64>) {
    out.clear();
    out.reserve(rows.len());
    for r in rows.chunks_exact(width) {
        out.extend([
            su.t(r[0]),
            su.x(r[1]),
            su.x(r[2]),
            su.v(r[3]),
            r[4],
            su.force(r[5]),
        ]);
        out.extend(r[6..6 + n].iter().map(|&a| su.x(a)));
        out.extend(r[6 + n..6 + 2 * n].iter().map(|&a| su.v(a)));
    }
}

/// The name of a region in `events.csv`.
fn region(r: Region) -> &'static str {
    match r {
        Region::Free => "free",
        Region::Contact => "contact",
    }
}

impl SeriesFiles {
    /// Open the files of an `n`-mode run in `dir` (`timeseries.csv` only with `csv`,
    /// `energy.csv` only with `energy`).
    ///
    /// # Errors
    /// [`FileError`] naming a file that cannot be created.
    pub(crate) fn create(
        dir: &Path,
        n: usize,
        su: SeriesUnits,
        csv: bool,
        energy: bool,
    ) -> Result<Self, FileError> {
        let columns = series_columns(n, &su);
        let names = su.names();
        let time = [
            if su.u.si { "t0" } else { "tau0" },
            if su.u.si { "t1" } else { "tau1" },
        ];
        Ok(SeriesFiles {
            npy: NpyStream::create(&dir.join("timeseries.npy"), columns.clone())?,
            csv: match csv {
                true => {
                    let hdr: Vec<&str> = columns.iter().map(|c| c.name.as_str()).collect();
                    Some(csv_stream(&dir.join("timeseries.csv"), &hdr)?)
                }
                false => None,
            },
            events: csv_stream(
                &dir.join("events.csv"),
                &[names.time, "from", "to", "v_t_dot"],
            )?,
            poincare: csv_stream(
                &dir.join("poincare.csv"),
                &[names.time, "v_t", "w_tip", "w_tip_dot"],
            )?,
            energy: match energy {
                true => Some(csv_stream(
                    &dir.join("energy.csv"),
                    &[
                        time[0],
                        "e_start",
                        "e_end",
                        "base_work",
                        "beam_dissipation",
                        "contact_dissipation",
                        "residual",
                        time[1],
                    ],
                )?),
                false => None,
            },
            su,
            converted: Vec::new(),
            lines: Vec::new(),
        })
    }

    /// Append a chunk of `model`'s run: its new samples, switchings, section points and the
    /// energy balances of its complete periods.
    ///
    /// # Errors
    /// [`FileError`] naming a file that cannot be written.
    pub(crate) fn push(&mut self, model: &CantileverModel, c: &Chunk<'_>) -> Result<(), FileError> {
        let su = &self.su;
        // dimensionless units and no internal state: the rows as they are (the conversion
        // would multiply by 1)
        let n = model.modes();
        let width = 6 + 2 * n;
        let rows = if [su.u.time, su.u.length, su.u.force] == [1.0; 3] && c.width == width {
            c.rows
        } else {
            convert_rows(c.rows, c.width, n, su, &mut self.converted);
            &self.converted
        };
        self.npy.push_rows(rows)?;
        let lines = &mut self.lines;
        if let Some(csv) = self.csv.as_mut() {
            lines.clear();
            for row in rows.chunks_exact(width) {
                csv_line(lines, row.iter().map(|&v| Field::Num(v)));
            }
            csv_lines(csv, lines)?;
        }
        lines.clear();
        for e in c.events() {
            csv_line(
                lines,
                [
                    Field::Num(su.t(e.tau)),
                    Field::Word(region(e.from)),
                    Field::Word(region(e.to)),
                    Field::Num(su.v(e.v_t_dot)),
                ],
            );
        }
        csv_lines(&mut self.events, lines)?;
        lines.clear();
        for (t, z) in &c.sections {
            csv_line(
                lines,
                [
                    su.t(*t),
                    su.x(model.v_t(*t, z)),
                    su.x(model.w_tip(z)),
                    su.v(model.w_tip_dot(z)),
                ]
                .map(Field::Num),
            );
        }
        csv_lines(&mut self.poincare, lines)?;
        let Some(energy) = self.energy.as_mut() else {
            return Ok(());
        };
        lines.clear();
        let period = model.period();
        for e in c.energy() {
            // each interval ends at the first stroboscopic section after its start
            let tau1 = ((e.tau0 / period + 1e-9).floor() + 1.0) * period;
            csv_line(
                lines,
                [
                    su.t(e.tau0),
                    su.energy(e.e_start),
                    su.energy(e.e_end),
                    su.energy(e.base_work),
                    su.energy(e.beam_dissipation),
                    su.energy(e.contact_dissipation),
                    su.energy(e.residual()),
                    su.t(tau1),
                ]
                .map(Field::Num),
            );
        }
        csv_lines(energy, lines)
    }

    /// Finish every file (renamed into place, `timeseries.npy.json` written).
    ///
    /// # Errors
    /// [`FileError`] naming a file that cannot be finished.
    pub(crate) fn finish(self) -> Result<(), FileError> {
        self.npy.finish()?;
        if let Some(c) = self.csv {
            csv_finish(c)?;
        }
        csv_finish(self.events)?;
        csv_finish(self.poincare)?;
        self.energy.map_or(Ok(()), csv_finish)
    }
}
