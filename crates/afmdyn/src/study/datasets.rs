//! The arrays of each analysis' result as [`Layout`]s ([`Datasets`]): what a front end shows
//! beside the document — Python's datasets and result objects, built from them generically.
//! The stepped curves' layouts are laid out from their documents (`fm`'s and `reconstruct`'s
//! where they run).

use super::named::Datasets;
use crate::analysis::steady::SteadyState;
use crate::eigen::RegionSpectrum;
use crate::error::SimError;
use crate::layout::{Layout, Values, Variable};
use crate::model::CantileverModel;
use crate::report;
use crate::request::modes::ModesRequest;
use crate::request::run::{ApproachRequest, Bimodal, Resolved, ResonanceRequest};
use crate::request::BasinArrays;
use crate::request::{
    AttractorsRequest, BasinsRequest, ContinuationRequest, ConvergeRequest,
    GlobalContinuationRequest, LyapunovRequest, ObserveRequest, OrbitRequest,
};
use nalgebra::DVector;
use serde_json::{json, Map, Value};

/// What [`Datasets::datasets`] returns.
type Arrays = Result<super::named::Arrays, SimError>;

/// One named layout, no facts.
fn one(name: &str, layout: Layout) -> Arrays {
    Ok((vec![(name.into(), layout)], Map::new()))
}

/// The facts of a JSON object.
fn facts(v: Value) -> Map<String, Value> {
    v.as_object().cloned().unwrap_or_default()
}

/// Vectors of one length as the rows of a row-major matrix.
fn rows<'a>(v: impl IntoIterator<Item = &'a DVector<f64>>) -> Vec<f64> {
    v.into_iter().flat_map(|z| z.iter().copied()).collect()
}

/// A dimensionless float variable.
fn f64s(name: &str, dims: &[&str], values: Vec<f64>) -> Variable {
    Variable::new(name, dims, "", name, Values::F64(values))
}

/// A region's spectrum: `omega` over `mode`, `eigenvalues` (complex) and `zeta` over
/// `eigenvalue`.
fn spectrum(title: &str, r: &RegionSpectrum) -> Layout {
    let e = &r.eigenvalues;
    Layout::new(
        title,
        &[("mode", r.omega.len()), ("eigenvalue", e.len())],
        vec![
            f64s("omega", &["mode"], r.omega.clone()),
            Variable::new(
                "eigenvalues",
                &["eigenvalue"],
                "",
                "eigenvalues",
                Values::C64(e.iter().map(|x| (x.re, x.im)).collect()),
            ),
            f64s("zeta", &["eigenvalue"], e.iter().map(|x| x.zeta).collect()),
        ],
    )
}

impl Datasets for ModesRequest {
    fn datasets(&self, _: &Resolved, (free, contact): &Self::Output) -> Arrays {
        let layouts = vec![
            ("free".into(), spectrum("free", free)),
            ("contact".into(), spectrum("contact", contact)),
        ];
        Ok((layouts, Map::new()))
    }
}

impl Datasets for OrbitRequest {
    fn datasets(&self, _: &Resolved, o: &Self::Output) -> Arrays {
        let dim = o.state.len();
        let m = &o.multipliers;
        one(
            "orbit",
            Layout::new(
                "orbit",
                &[
                    ("component", dim),
                    ("section_point", o.section.len()),
                    ("row", dim),
                    ("multiplier", m.len()),
                    ("iteration", o.residuals.len()),
                ],
                vec![
                    f64s("state", &["component"], o.state.as_slice().to_vec()),
                    f64s("section", &["section_point", "component"], rows(&o.section)),
                    // nalgebra stores column-major: its transpose's buffer is row-major
                    f64s(
                        "monodromy",
                        &["row", "component"],
                        o.monodromy.transpose().as_slice().to_vec(),
                    ),
                    Variable::new(
                        "multipliers",
                        &["multiplier"],
                        "",
                        "Floquet multipliers",
                        Values::C64(m.iter().map(|x| (x.re, x.im)).collect()),
                    ),
                    f64s("newton_residuals", &["iteration"], o.residuals.clone()),
                ],
            ),
        )
    }
}

impl Datasets for LyapunovRequest {
    fn datasets(&self, _: &Resolved, l: &Self::Output) -> Arrays {
        let n = l.exponents.len();
        one(
            "lyapunov",
            Layout::new(
                "lyapunov",
                &[("exponent", n), ("uncertain", l.uncertainty.len())],
                vec![
                    f64s("exponents", &["exponent"], l.exponents.clone()),
                    f64s("uncertainty", &["uncertain"], l.uncertainty.clone()),
                ],
            ),
        )
    }
}

impl Datasets for ObserveRequest {
    /// The observables' layout from the document (`crate::report::curve_layout::observe_layout`)
    /// and the period.
    fn datasets(&self, model: &Resolved, o: &Self::Output) -> Arrays {
        let doc = crate::request::run::document(self, model, o)?;
        let layout =
            crate::report::curve_layout::observe_layout(&doc, o.state.as_slice(), o.period);
        Ok((
            vec![("observe".into(), layout)],
            facts(json!({ "period": o.period })),
        ))
    }
}

impl Datasets for ConvergeRequest {
    /// `afmdyn.converge`'s dataset: over (`n_modes`, `sample`) the tip deflection, V_T and τ
    /// over the first K samples every run has, per run its period and RMS change, the
    /// coordinates `n_modes` and `tau_from_section`.
    fn datasets(&self, _: &Resolved, runs: &Self::Output) -> Arrays {
        let k = runs.iter().map(|r| r.w_tip.len()).min().unwrap_or(0);
        let r = runs.len();
        let t0 = runs
            .first()
            .and_then(|x| x.tau.first())
            .copied()
            .unwrap_or(0.0);
        let grab = |f: fn(&crate::analysis::converge::ConvergenceRun) -> &Vec<f64>| {
            Values::F64(runs.iter().flat_map(|x| f(x)[..k].to_vec()).collect())
        };
        let (g, tau, time) = ("g0", "τ (eq. 5)", "time τ");
        let both = ["n_modes", "sample"];
        let first = runs.first().map_or(&[][..], |x| &x.tau[..k]);
        let vars = vec![
            Variable::new(
                "w_tip",
                &both,
                g,
                "tip deflection W(1,τ)",
                grab(|x| &x.w_tip),
            ),
            Variable::new("v_t", &both, g, "V_T", grab(|x| &x.v_t)),
            Variable::new("tau", &both, tau, time, grab(|x| &x.tau)),
            Variable::i32(
                "period",
                &["n_modes"],
                "",
                "period of the steady state (−1: nonperiodic)",
                &runs
                    .iter()
                    .map(|x| x.period.map_or(-1, |n| n as i32))
                    .collect::<Vec<_>>(),
            ),
            Variable::f64(
                "rms_change",
                &["n_modes"],
                g,
                "RMS of W_tip(N) − W_tip(N−1)",
                &runs
                    .iter()
                    .map(|x| x.rms_change.unwrap_or(f64::NAN))
                    .collect::<Vec<_>>(),
            ),
            Variable::i32(
                "n_modes",
                &["n_modes"],
                "",
                "number of Galerkin modes N",
                &runs.iter().map(|x| x.modes as i32).collect::<Vec<_>>(),
            ),
            Variable::f64(
                "tau_from_section",
                &["sample"],
                tau,
                "τ − τ0 from a section point",
                &first.iter().map(|t| t - t0).collect::<Vec<_>>(),
            ),
        ];
        one(
            "converge",
            Layout::new("converge", &[("n_modes", r), ("sample", k)], vars),
        )
    }
}

/// A steady state's section points over `section` (τ, V_T, W_tip and the state over
/// `component`) and its statistics as scalars.
fn steady(title: &str, s: &SteadyState, extra: Vec<Variable>) -> Layout {
    let p = &s.poincare;
    let dim = p.first().map_or(0, |q| q.state.len());
    let st = &s.stats;
    let scalar = |name: &str, v: f64| f64s(name, &[], vec![v]);
    let mut vars = vec![
        f64s(
            "section_tau",
            &["section"],
            p.iter().map(|q| q.tau).collect(),
        ),
        f64s(
            "section_v_t",
            &["section"],
            p.iter().map(|q| q.v_t).collect(),
        ),
        f64s(
            "section_w_tip",
            &["section"],
            p.iter().map(|q| q.w_tip).collect(),
        ),
        f64s(
            "section_state",
            &["section", "component"],
            rows(p.iter().map(|q| &q.state)),
        ),
        Variable::i32(
            "transient_periods",
            &[],
            "",
            "",
            &[s.transient_periods as i32],
        ),
        scalar("x_max", st.x_max),
        scalar("x_min", st.x_min),
        scalar("v_t_min", st.v_t_min),
        scalar("contact_fraction", st.contact_fraction),
        scalar("contacts_per_period", st.contacts_per_period),
        Variable::new(
            "body_contact",
            &[],
            "",
            "",
            Values::Bool(vec![st.body_contact]),
        ),
    ];
    vars.extend(extra);
    Layout::new(title, &[("section", p.len()), ("component", dim)], vars)
}

impl Datasets for AttractorsRequest {
    /// One layout per attractor (`attractor-1`, …, most frequent first): its steady state,
    /// count, basin fraction and initial state; the failures' messages as a fact.
    fn datasets(&self, _: &Resolved, r: &Self::Output) -> Arrays {
        let layouts = r
            .attractors
            .iter()
            .enumerate()
            .map(|(i, a)| {
                let extra = vec![
                    Variable::i32("count", &[], "", "", &[a.count as i32]),
                    f64s("basin_fraction", &[], vec![a.basin_fraction]),
                    f64s("initial", &["component"], a.initial.as_slice().to_vec()),
                ];
                let name = format!("attractor-{}", i + 1);
                (name.clone(), steady(&name, &a.steady, extra))
            })
            .collect();
        Ok((layouts, facts(json!({ "failures": r.failures }))))
    }
}

impl Datasets for ContinuationRequest {
    /// The branch points' layout (`report::continuation_layout`) and the parameter's name.
    fn datasets(&self, model: &Resolved, branches: &Self::Output) -> Arrays {
        let p0 = model.params.with(self.param, self.from);
        let m = CantileverModel::new(&p0)?;
        let layout = report::continuation_layout(self.param, &m, branches);
        Ok((
            vec![("continuation".into(), layout)],
            facts(json!({ "param": self.param.name() })),
        ))
    }
}

impl Datasets for BasinsRequest {
    /// The basin map's layout ([`BasinArrays::layout`], the command line's `basins.nc`).
    fn datasets(&self, model: &Resolved, map: &Self::Output) -> Arrays {
        let spec = self.spec(&model.params)?;
        one("basins", BasinArrays::new(map).layout(&spec))
    }
}

impl Datasets for GlobalContinuationRequest {
    /// The continuation's layout (`report::global_continuation_layout`).
    fn datasets(&self, _: &Resolved, steps: &Self::Output) -> Arrays {
        one(
            "global_continuation",
            report::global_continuation_layout(self.param, steps),
        )
    }
}

impl Datasets for ApproachRequest {
    /// The curve's layout from its document (`crate::report::curve_layout::curve_layout`).
    fn datasets(&self, model: &Resolved, curve: &Self::Output) -> Arrays {
        let doc = crate::request::run::document(self, model, curve)?;
        one("curve", crate::report::curve_layout::curve_layout(&doc))
    }
}

impl Datasets for ResonanceRequest {
    /// The curve's layout from its document (`crate::report::curve_layout::curve_layout`).
    fn datasets(&self, model: &Resolved, curve: &Self::Output) -> Arrays {
        let doc = crate::request::run::document(self, model, curve)?;
        one("curve", crate::report::curve_layout::curve_layout(&doc))
    }
}

impl Datasets for Bimodal {
    fn datasets(
        &self,
        model: &Resolved,
        c: &crate::analysis::stepped::SteppedCurve,
    ) -> Result<super::named::Arrays, SimError> {
        self.0.datasets(model, c)
    }
}
