//! `reconstruct`: the summary of a reconstructed force, its table `reconstruct.csv`, its
//! document `reconstruct.json` and the force figure.

use super::{lines, numeric_csv, tail, with_document, Destination, Files};
use crate::analysis::reconstruct::Reconstruction;
use crate::layout::figure::{Series, Style};
use crate::report::{Presentation, TextUnits};
use serde_json::Value;

/// Where a reconstruction comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Inversion {
    /// An FM curve by the Sader–Jarvis inversion.
    SaderJarvis,
    /// An AM curve by the matrix method.
    AmMatrix,
    /// An FM curve by the exact inversion (Sader–Jarvis corrected through Giessibl's relation).
    Exact,
}

/// The presentation of reconstruction `r` and its `document`: the summary (the distances, the
/// most attractive force and where), and with `files` the table `reconstruct.csv`, the force
/// figure (all files; with the model's force `law` in the curve's order when known) and the
/// document `reconstruct.json`; when the files go to `dir`, the document records the table's
/// path there (`"csv"`, in the document printed too).
pub(crate) fn reconstruction(
    r: &Reconstruction,
    how: Inversion,
    law: Option<Vec<f64>>,
    document: &mut Value,
    text: TextUnits,
    to: Destination<'_>,
) -> Presentation {
    let mut p = tail();
    let (k, f) = r
        .force
        .iter()
        .enumerate()
        .min_by(|x, y| x.1.total_cmp(y.1))
        .map_or((0, f64::NAN), |(k, f)| (k, *f));
    p.line(format!(
        "{} distances from {} to {}: most attractive force {} at d = {}",
        r.distance.len(),
        text.value(r.distance[0], "m"),
        text.value(r.distance[r.distance.len() - 1], "m"),
        text.value(f, "N"),
        text.value(r.distance.get(k).copied().unwrap_or(f64::NAN), "m"),
    ));
    if let Some(e) = &r.exact {
        p.line(format!(
            "exact inversion: {} correction step(s), forward residual {} of the largest |Δf| \
             (Sader–Jarvis's: {}){}",
            e.iterations,
            crate::error::number(e.forward_residual),
            crate::error::number(e.sader_jarvis_residual),
            if e.converged {
                ""
            } else {
                ", stopped where a step no longer shrank it"
            },
        ));
    }
    if to.files == Files::None {
        return p;
    }
    let rows: Vec<_> = (r.distance.iter().zip(&r.force).zip(&r.potential))
        .map(|((d, force), u)| vec![*d, *force, *u])
        .collect();
    numeric_csv(
        &mut p,
        "reconstruct.csv",
        &["distance", "force", "potential"],
        &rows,
    );
    if to.files == Files::All {
        let points = |ys: &[f64]| r.distance.iter().copied().zip(ys.iter().copied()).collect();
        let reconstructed = Series {
            label: "reconstructed".into(),
            points: points(&r.force),
            style: Style::Line,
            color: 0,
        };
        let law = law.map(|law| Series {
            label: "the model's force law".into(),
            points: points(&law),
            style: Style::Dashed,
            color: 1,
        });
        let title = match how {
            Inversion::AmMatrix => "Tip–sample force from the AM curve (matrix method)",
            Inversion::SaderJarvis => "Tip–sample force by the Sader–Jarvis inversion",
            Inversion::Exact => "Tip–sample force by the exact inversion",
        };
        let labels = (
            "distance of closest approach d (m)".into(),
            "force F (N)".into(),
        );
        let series = std::iter::once(reconstructed).chain(law).collect();
        p.figure("reconstruct-force", lines(title, labels, series));
    }
    with_document(
        &mut p,
        document,
        ("reconstruct.json", "reconstruct.csv"),
        to.dir,
    );
    p
}
