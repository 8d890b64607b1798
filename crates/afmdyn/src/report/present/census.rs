//! `attractors` and `attractors --sweep`: their summaries, tables, datasets and figures.

use crate::analysis::attractors::{Attractor, AttractorReport};
use crate::analysis::attractors::{AttractorSpec, ATTRACTOR_SAMPLES_PER_PERIOD};
use crate::analysis::global_continuation::ContinuationStep;
use crate::error::SimError;
use crate::integrate::build;
use crate::layout::figure::{Figure, IdSeries, Plot, Series, StackedFractions, Style};
use crate::layout::files::f;
use crate::model::CantileverModel;
use crate::params::Params;
use crate::params::SweepParam;
use crate::report::{self, OutputFile, Presentation, TextUnits};
use crate::system::Region;
use crate::trajectory::{record, RecordSpec, Trajectory};
use serde_json::Value;

/// A period as the summaries name it: `period-n` or `nonperiodic`.
fn period_name(period: Option<usize>) -> String {
    period.map_or("nonperiodic".into(), |n| format!("period-{n}"))
}

/// A period as the sweep's labels name it: `Pn` or `nonperiodic`.
fn period_short(period: Option<usize>) -> String {
    period.map_or("nonperiodic".into(), |n| format!("P{n}"))
}

/// `attractors`: every attractor recorded over its cycle (at least two periods, eight for a
/// nonperiodic one) from its end state — `attractor-k.csv`, its time series and phase plane
/// with the Poincaré points —, `attractors.json` (`document`) and the summary in `u`.
///
/// # Errors
/// [`SimError`] when the model or the census's integrator cannot be built, or a recording
/// fails.
pub(crate) fn attractors(
    spec: &AttractorSpec,
    report: &AttractorReport,
    document: &Value,
    u: TextUnits,
) -> Result<Presentation, SimError> {
    let p = &spec.params;
    let model = CantileverModel::new(p)?;
    let mut s = Presentation::default();
    for (k, att) in report.attractors.iter().enumerate() {
        let periods = att.steady.period().unwrap_or(8).max(2);
        let z0 = att.steady.end_state().clone();
        let tau0 = att.steady.poincare.last().map_or(0.0, |q| q.tau);
        let mut integ = build(&model, spec.integrator.clone(), tau0, &z0)?;
        let tr = record(
            integ.as_mut(),
            &RecordSpec {
                transient_periods: 0.0,
                record_tau: periods as f64 * p.period(),
                samples_per_period: ATTRACTOR_SAMPLES_PER_PERIOD,
                energy: false,
                body_contact: false,
            },
        )?;
        attractor_files(&mut s, &model, k, att, &tr);
    }
    s.files.push(OutputFile::Json {
        name: "attractors.json".into(),
        value: document.clone(),
    });
    summary(&mut s, spec.samples, p, report, u);
    Ok(s)
}

/// The files of attractor `k` (`att`, recorded over its cycle as `tr` under `model`) into `s`:
/// `attractor-k.csv`, its time series and its phase plane with the Poincaré points.
fn attractor_files(
    s: &mut Presentation,
    model: &CantileverModel,
    k: usize,
    att: &Attractor,
    tr: &Trajectory,
) {
    let stem = format!("attractor-{}", k + 1);
    s.csv(
        &format!("{stem}.csv"),
        &["tau", "v_t", "w_tip", "w_tip_dot", "in_contact"],
        (tr.samples.iter())
            .map(|s| {
                vec![
                    f(s.tau),
                    f(s.v_t),
                    f(s.w_tip),
                    f(s.w_tip_dot),
                    u8::from(s.region == Region::Contact).to_string(),
                ]
            })
            .collect(),
    );
    let label = period_name(att.steady.period());
    let line = |points| Series {
        label: String::new(),
        points,
        style: Style::Line,
        color: k,
    };
    s.figure(
        &format!("{stem}-time"),
        Plot::Lines(Figure {
            y_min_span: 0.0,
            title: format!(
                "Attractor {} ({label}, basin {:.1} %), Ω = {}",
                k + 1,
                100.0 * att.basin_fraction,
                model.omega()
            ),
            x_label: "τ".into(),
            y_label: "W(1,τ)".into(),
            series: vec![line(tr.samples.iter().map(|s| (s.tau, s.w_tip)).collect())],
            shade: vec![],
        }),
    );
    let sections = Series {
        label: "Poincaré points".into(),
        points: (att.steady.poincare.iter())
            .map(|q| (q.w_tip, model.w_tip_dot(&q.state)))
            .collect(),
        style: Style::Points,
        color: if k % 10 == 3 { 4 } else { 3 },
    };
    let phase = tr.samples.iter().map(|s| (s.w_tip, s.w_tip_dot)).collect();
    s.figure(
        &format!("{stem}-phase"),
        Plot::Lines(Figure {
            y_min_span: 0.0,
            title: format!("Attractor {} ({label}): phase plane", k + 1),
            x_label: "W(1,τ)".into(),
            y_label: "∂W(1,τ)/∂τ".into(),
            series: vec![line(phase), sections],
            shade: vec![],
        }),
    );
}

/// The census's summary into `s`: the attractors found from `samples` starts at `p`,
/// each with its period, basin, largest excursion, closest approach and contact fraction, and
/// the starts still unsettled; lengths in `u` (g₀, or m with a probe).
fn summary(
    s: &mut Presentation,
    samples: usize,
    p: &Params,
    report: &AttractorReport,
    u: TextUnits,
) {
    s.line(format!(
        "{} attractors from {} starts ({} failed) at {}{}:",
        report.attractors.len(),
        samples,
        report.failures.len(),
        u.drive(p.omega),
        if u.si() {
            format!(", z_c = {}", u.length(p.rest_distance()))
        } else {
            String::new()
        }
    ));
    // lengths in g0, or in m with a probe (13.4747 nm)
    let length = |v: f64| {
        if u.si() {
            u.length(v)
        } else {
            format!("{v:.4}")
        }
    };
    for (k, x) in report.attractors.iter().enumerate() {
        s.line(format!(
            "  {}: {:<12} basin {:>5.1} %  X_max = {}  min V_T = {}  contact fraction {:.3}{}",
            k + 1,
            period_name(x.steady.period()),
            100.0 * x.basin_fraction,
            length(x.steady.stats.x_max),
            length(x.steady.stats.v_t_min),
            x.steady.stats.contact_fraction,
            if x.steady.stats.body_contact {
                "  (beam body touches the substrate: Fig. 2f)"
            } else {
                ""
            }
        ));
    }
    for x in &report.unsettled {
        s.line(format!(
            "  unsettled: {} start(s) still converging after {} periods (λ₁ = {:.3e})",
            x.count,
            report.transient_cap,
            x.lyapunov.map_or(f64::NAN, |l| l.0)
        ));
    }
}

/// The warning of failed random starts of a census of `samples`, if any.
pub(crate) fn failed_starts(report: &AttractorReport, samples: usize) -> Option<String> {
    report.failures.first().map(|first| {
        format!(
            "{} of {samples} random starts failed; the first: {first}",
            report.failures.len(),
        )
    })
}

/// `attractors --sweep`: `attractors-sweep.csv` (one row per value and attractor), the
/// dataset `attractors-sweep.nc`, the stacked basin fractions, `attractors-sweep.json`
/// (`document`) and the summary (per value, each id with its period and basin).
pub(crate) fn global_continuation(
    (param, samples): (SweepParam, usize),
    steps: &[ContinuationStep],
    document: &Value,
) -> Presentation {
    let mut s = Presentation::default();
    let name = param.name();
    let mut rows = Vec::new();
    for st in steps {
        for (id, x) in &st.attractors {
            rows.push(vec![
                f(st.value),
                id.to_string(),
                x.steady
                    .period()
                    .map_or("nonperiodic".into(), |n| n.to_string()),
                f(x.basin_fraction),
                f(x.steady.stats.x_max),
                f(x.steady.stats.v_t_min),
                f(x.steady.stats.contact_fraction),
                x.orbit
                    .as_ref()
                    .map_or(String::new(), |o| u8::from(o.stable).to_string()),
            ]);
        }
    }
    s.csv(
        "attractors-sweep.csv",
        &[
            name,
            "id",
            "period",
            "basin_fraction",
            "x_max",
            "v_t_min",
            "contact_fraction",
            "stable",
        ],
        rows,
    );
    s.dataset(
        "attractors-sweep.nc",
        report::global_continuation_layout(param, steps),
    );
    let ids = document["ids"].as_u64().unwrap_or(0) as usize;
    let per_id: Vec<IdSeries> = (0..ids)
        .map(|id| {
            let points: Vec<Option<(f64, f64)>> = steps
                .iter()
                .map(|st| {
                    (st.attractors.iter())
                        .find(|(i, _)| *i == id)
                        .map(|(_, x)| (x.basin_fraction, x.steady.stats.x_max))
                })
                .collect();
            let periods: std::collections::BTreeSet<String> = steps
                .iter()
                .flat_map(|st| st.attractors.iter().filter(|(i, _)| *i == id))
                .map(|(_, x)| period_short(x.steady.period()))
                .collect();
            let kinds: Vec<String> = periods.into_iter().collect();
            (format!("attractor {id}: {}", kinds.join(", ")), points)
        })
        .collect();
    s.figure(
        "attractors-sweep",
        Plot::Stacked(StackedFractions {
            title: format!(
                "Attractors over {} ({} random starts per value)",
                param.symbol(),
                samples
            ),
            x_label: param.symbol().into(),
            values: steps.iter().map(|st| st.value).collect(),
            ids: per_id,
        }),
    );
    s.files.push(OutputFile::Json {
        name: "attractors-sweep.json".into(),
        value: document.clone(),
    });
    s.line(format!(
        "{ids} attractors over {} values of {name} ({} random starts each):",
        steps.len(),
        samples
    ));
    for st in steps {
        let line: Vec<String> = (st.attractors.iter())
            .map(|(id, x)| {
                format!(
                    "#{id} {} {:.1} %",
                    period_short(x.steady.period()),
                    100.0 * x.basin_fraction
                )
            })
            .collect();
        // 10 significant digits: a linspace value such as 1.7999999999999998 reads 1.8
        let value: f64 = format!("{:.9e}", st.value).parse().unwrap_or(st.value);
        s.line(format!("  {name} = {value:<10} {}", line.join("  ")));
    }
    s
}
