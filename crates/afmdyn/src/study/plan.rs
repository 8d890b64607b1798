//! Studies as stages of numbered tasks for an executor outside the library (Dask:
//! `afmdyn.dask`), which ships each task to a worker as text and hands the results back:
//! [`Plan`]. A plan is rebuilt in any process from its recipe ([`Recipe`], JSON text), so it
//! travels to workers as a few hundred bytes; a task's start and result travel as CBOR text
//! (`to_cbor_text`: every float bit for bit), so a study run on a cluster equals the one run
//! here ([`super::execute`]) bit for bit.
//!
//! - a bifurcation sweep: stage 0 the two coarse continuation passes, stage 1 the chain
//!   segments and random starts seeded by them (`SweepPlan`); with a store, the command
//!   line's resumable one ([`Plan::store`], [`PlanStore`]);
//! - a basin map: one stage per pass, whose start is the attractors and coarse grid of the
//!   passes before it (`pass_start`), one task per row;
//! - a PI-scanned image: one stage, one task per line ([`ScanStudy`]), whose start is what a
//!   line needs (`LineJob`): a worker scans lines without building the study (the
//!   materials' approach curves, each several lines' time);
//! - a PeakForce image: stage 0 the materials' engages from far, one task each; stage 1 the
//!   lines, one task each, whose start is the engages ([`PeakForceImageStudy`]);
//! - a fitted force map (`fit-map`): one stage, one task per line of the map ([`MapStudy`]),
//!   its start empty: a worker rebuilds the study from the recipe (the map indexed once per
//!   process) and reads its lines' curves from the map file itself — a path every worker must
//!   read (the same machine or a shared filesystem); with a store, the command line's
//!   resumable one ([`Plan::store`]: `afmdyn fit-map --out DIR`).
//!
//! The ledger — which tasks a store holds, how the results merge into the outcome — is the
//! plan's: the executor only maps tasks and hands results back.

use super::basins::BasinStudy;
use super::fit_map::{every_curve_failed, fit_map_store, CurveFit, MapStudy};
use super::named::{outcome, Outcome};
use super::peakforce_image::{Engage, LinePixel, PeakForceImageStudy};
use super::scan::{LineJob, ScanStudy};
use super::stored::sweep_outcome;
use super::sweep::{sweep_checkpoint, SweepCheckpoint};
use super::task_store::{from_cbor_text, to_cbor_text};
use super::{Opened, StudyError};
use crate::analysis::am_loop::ScanLine;
use crate::analysis::basins::{pass_start, passes, run_pass_row, BasinRow, PassStart};
use crate::analysis::bifurcation::Resume;
use crate::analysis::bifurcation::{Branch, Seeds, SweepPlan, SweepPoint, SweepSpec, SweepTask};
use crate::error::SimError;
use crate::request::analyses::fingerprint;
use crate::request::image::{ImageRequest, SampleMap};
#[cfg(feature = "files")]
use crate::request::image_job::ImageKeywords;
use crate::request::image_scan::ScanRecipe;
use crate::request::sweep::{every_point_failed, order_key, records, SweepRecord};
use crate::request::{BasinsRequest, BifurcationRequest, DirLock, FitMapRequest, Resolved};
use crate::Params;
use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};

/// What rebuilds a plan in any process: the study's name (`"plan"`), its request and model.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "plan", rename_all = "snake_case", deny_unknown_fields)]
pub enum Recipe {
    /// A bifurcation sweep of `request` over `params`.
    Bifurcation {
        /// The request.
        request: BifurcationRequest,
        /// The model.
        params: Params,
    },
    /// A basin map of `request` over `params`; `probe` the probe file's text (the document's
    /// SI block).
    Basins {
        /// The request.
        request: BasinsRequest,
        /// The model.
        params: Params,
        /// The probe file's text.
        probe: Option<String>,
    },
    /// A PI-scanned image.
    Image {
        /// The scan.
        scan: ScanRecipe,
    },
    /// A PeakForce image (ideal peak-force feedback, [`PeakForceImageStudy`]).
    PeakForceImage {
        /// The probe file's table (SI).
        probe: toml::Table,
        /// The sample map.
        map: SampleMap,
        /// The request (its setpoint the peak force in N).
        request: ImageRequest,
    },
    /// A force map's fit (`fit-map`) of `request` (its `data` a path every worker reads)
    /// over `params`; `probe` the probe file's text (SI; required, as `fit-map` requires it:
    /// the request's validation says so).
    FitMap {
        /// The request.
        request: FitMapRequest,
        /// The model.
        params: Params,
        /// The probe file's text.
        probe: Option<String>,
    },
}

impl Recipe {
    /// The recipe of an image's keywords on the probe text `probe`: a PeakForce image
    /// ([`crate::request::image_job::ImageMode::Peakforce`]: the materials' engages, then the
    /// lines) or a PI scan (the lines).
    ///
    /// # Errors
    /// As [`ImageKeywords::inputs`] and [`ImageKeywords::scan`].
    #[cfg(feature = "files")] // (a sample map may name a file)
    pub fn image(keywords: ImageKeywords, probe: &str) -> Result<Recipe, SimError> {
        use crate::request::image_job::ImageMode;
        Ok(if keywords.mode == Some(ImageMode::Peakforce) {
            let (probe, map) = keywords.inputs(probe)?;
            Recipe::PeakForceImage {
                probe,
                map,
                request: keywords.request(),
            }
        } else {
            Recipe::Image {
                scan: keywords.scan(probe)?,
            }
        })
    }
}

/// The tasks of one stage: the start every task of it takes (text), and their numbers.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stage {
    /// The stage's start, sent once to every worker.
    pub start: String,
    /// The stage's tasks.
    pub tasks: Vec<usize>,
}

/// A study cut into stages of tasks ([module docs](self)).
pub trait Plan: Send + Sync {
    /// The recipe (JSON text) that rebuilds the plan ([`rebuild`]).
    fn recipe(&self) -> &str;
    /// The number of stages.
    fn stages(&self) -> usize;
    /// Stage `stage` from the results of the stages before it (any order).
    ///
    /// # Errors
    /// A result that is not one of this plan's; `stage` not below [`Plan::stages`].
    fn stage(&self, stage: usize, results: &[String]) -> Result<Stage, SimError>;
    /// Run task `task` of the stage beginning at `start`: its result (text).
    ///
    /// # Errors
    /// A start that is not one of this plan's, a task not in it, the task's own errors.
    fn run(&self, start: &str, task: usize, cancel: &AtomicBool) -> Result<String, SimError>;
    /// The outcome of every result (of every stage, any order): what the one door returns
    /// for the same request.
    ///
    /// # Errors
    /// A result that is not one of this plan's; the study's (every point failed).
    fn outcome(&self, results: &[String]) -> Result<Outcome, SimError>;
    /// The command line's resumable store of the plan in the locked directory `lock`; `None`
    /// for a plan without one.
    fn store(&self, _lock: DirLock) -> Option<Box<dyn PlanStore>> {
        None
    }
}

/// A plan's store, written by an executor that runs the tasks elsewhere (see [`Plan::store`]).
pub trait PlanStore: Send {
    /// Where the plan stands in the store (a new run begins without `resume`): `None` when it
    /// finished, else the tasks of the last stage still to run (the stages before it run whole).
    ///
    /// # Errors
    /// [`StudyError::Store`]: another request's store, unreadable files.
    fn open(&mut self, resume: bool) -> Result<Option<Vec<usize>>, StudyError>;
    /// Keep the result of a task of the last stage (what it holds that is not stored yet).
    ///
    /// # Errors
    /// [`StudyError`]: a result not of this plan, the store cannot be written.
    fn append(&mut self, result: &str) -> Result<(), StudyError>;
    /// Put the stored results in the one order and mark the plan finished.
    ///
    /// # Errors
    /// [`StudyError::Store`].
    fn finish(&mut self) -> Result<(), StudyError>;
    /// The outcome of the finished store.
    ///
    /// # Errors
    /// [`StudyError`]: the store's, reading it; the study's (every point failed).
    fn outcome(&mut self) -> Result<Outcome, StudyError>;
}

/// The plan of `recipe`.
///
/// # Errors
/// The request's validation errors on its model.
pub fn plan(recipe: Recipe) -> Result<Box<dyn Plan>, SimError> {
    plan_of(recipe, true)
}

/// [`plan`]; a PI image's study built at once when `eager`, else on first use (a worker that
/// runs lines from the stage's start never builds it).
fn plan_of(recipe: Recipe, eager: bool) -> Result<Box<dyn Plan>, SimError> {
    let text = serde_json::to_string(&recipe).map_err(|e| bad("recipe", e))?;
    Ok(match recipe {
        Recipe::Bifurcation { request, params } => Box::new(Sweep {
            spec: request.spec(&params)?,
            request,
            text,
        }),
        Recipe::Basins {
            request,
            params,
            probe,
        } => Box::new(Basins {
            study: BasinStudy::new(&request, &params)?,
            model: Resolved {
                params,
                probe: probe
                    .as_deref()
                    .map(|t| crate::probe::Probe::parse(t, "probe"))
                    .transpose()
                    .map_err(|e| SimError::Probe(format!("probe {e}")))?,
            },
            request,
            text,
        }),
        Recipe::Image { scan } => {
            let study = std::sync::OnceLock::new();
            if eager {
                let _ = study.set(ScanStudy::from_recipe(&scan)?);
            }
            Box::new(Image { study, scan, text })
        }
        Recipe::PeakForceImage {
            probe,
            map,
            request,
        } => Box::new(PfImage {
            study: PeakForceImageStudy::unengaged(&probe, &map, &request)?,
            text,
        }),
        Recipe::FitMap {
            request,
            params,
            probe,
        } => {
            let model = Resolved {
                params,
                probe: probe
                    .as_deref()
                    .map(|t| {
                        let needs = crate::request::Request::probe_needs(&request);
                        crate::probe::Probe::parse_for(t, "probe", needs)
                    })
                    .transpose()
                    .map_err(|e| SimError::Probe(format!("probe {e}")))?,
            };
            crate::request::Request::validate(&request, &model)?;
            Box::new(FitMap {
                study: Arc::new(MapStudy::new(&request, &model)?),
                request,
                model,
                text,
            })
        }
    })
}

/// The plan of a recipe's text ([`Plan::recipe`]), as a worker rebuilds it: a PI image's
/// study is built on first use, which a worker given the stage's start never makes (its lines
/// run from the start, `crate::request::image_scan::LineJob`).
///
/// # Errors
/// Text that is not a recipe; as [`plan`] (a PI image's study's errors when first used).
pub fn rebuild(text: &str) -> Result<Box<dyn Plan>, SimError> {
    plan_of(
        serde_json::from_str(text).map_err(|e| bad("recipe", e))?,
        false,
    )
}

fn bad(what: &'static str, e: impl std::fmt::Display) -> SimError {
    SimError::out_of_range(what, "the text given", format!("not a study's {what}: {e}"))
}

fn decode<T: serde::de::DeserializeOwned>(what: &'static str, text: &str) -> Result<T, SimError> {
    from_cbor_text(text).map_err(|e| bad(what, e))
}

fn encode<T: Serialize>(value: &T) -> Result<String, SimError> {
    to_cbor_text(value).map_err(|e| bad("result", e))
}

fn no_stage(stage: usize, stages: usize) -> SimError {
    SimError::out_of_range("stage", stage, format!("in 0..{stages}"))
}

/// A bifurcation sweep's plan.
struct Sweep {
    spec: SweepSpec,
    request: BifurcationRequest,
    text: String,
}

/// A sweep task's result: a coarse pass's seeds (forward 0, backward 1), or the rows of
/// `bifurcation.csv` of a segment or random start (numbers in shortest round-trip form).
#[derive(Serialize, Deserialize)]
enum SweepResult {
    Coarse(usize, Vec<Vec<f64>>),
    Rows(Vec<String>),
}

fn sweep_rows(results: &[String]) -> Result<Vec<SweepRecord>, SimError> {
    let mut recs = Vec::new();
    for r in results {
        if let SweepResult::Rows(rows) = decode("result", r)? {
            for l in rows {
                recs.push(SweepRecord::parse_csv(&l).map_err(|e| bad("result", e))?);
            }
        }
    }
    Ok(recs)
}

impl Plan for Sweep {
    fn recipe(&self) -> &str {
        &self.text
    }
    fn stages(&self) -> usize {
        2
    }
    fn stage(&self, stage: usize, results: &[String]) -> Result<Stage, SimError> {
        let plan = SweepPlan::new(&self.spec);
        let n = plan.chunks();
        let tasks = (0..plan.tasks(stage).len()).collect();
        match stage {
            0 => Ok(Stage {
                start: String::new(),
                tasks,
            }),
            1 => {
                let zeros = || vec![vec![0.0; self.spec.base.state_dim()]; n];
                let mut seeds = [zeros(), zeros()];
                for r in results {
                    if let SweepResult::Coarse(k, s) = decode("result", r)? {
                        if let Some(slot) = seeds.get_mut(k) {
                            *slot = s;
                        }
                    }
                }
                Ok(Stage {
                    start: encode(&seeds)?,
                    tasks,
                })
            }
            _ => Err(no_stage(stage, 2)),
        }
    }
    fn run(&self, start: &str, task: usize, cancel: &AtomicBool) -> Result<String, SimError> {
        let plan = SweepPlan::new(&self.spec);
        if start.is_empty() {
            let branch = match task {
                0 => Branch::Forward,
                1 => Branch::Backward,
                _ => return Err(SimError::out_of_range("task", task, "0 or 1")),
            };
            let seeds = plan.coarse(branch, cancel);
            let seeds = seeds.iter().map(|z| z.iter().copied().collect()).collect();
            return encode(&SweepResult::Coarse(task, seeds));
        }
        let tasks = plan.tasks(1);
        let t: SweepTask = *tasks.get(task).ok_or_else(|| {
            SimError::out_of_range("task", task, format!("in 0..{}", tasks.len()))
        })?;
        let [forward, backward]: [Vec<Vec<f64>>; 2] = decode("start", start)?;
        let vectors = |v: Vec<Vec<f64>>| v.into_iter().map(DVector::from_vec).collect();
        let seeds = Seeds::new(vectors(forward), vectors(backward));
        let param = self.spec.param;
        let out = Mutex::new(Vec::new());
        plan.run_task(
            t,
            &seeds,
            &Default::default(),
            &|p: SweepPoint| {
                let rows = records(param, &p);
                out.lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .extend(rows.iter().map(SweepRecord::csv_line));
            },
            cancel,
        );
        encode(&SweepResult::Rows(
            out.into_inner().unwrap_or_else(|e| e.into_inner()),
        ))
    }
    fn outcome(&self, results: &[String]) -> Result<Outcome, SimError> {
        let mut recs = sweep_rows(results)?;
        recs.sort_by_key(order_key);
        if let Some(e) = every_point_failed(&recs) {
            return Err(e);
        }
        Ok(sweep_outcome(&self.spec, &recs))
    }
    fn store(&self, lock: DirLock) -> Option<Box<dyn PlanStore>> {
        Some(Box::new(SweepStore {
            lock,
            fingerprint: fingerprint(&self.request, &self.spec),
            spec: self.spec.clone(),
            done: HashSet::new(),
        }))
    }
}

/// The command line's store of a sweep (`afmdyn bifurcation --out DIR`): it stores the points
/// of each finished task that are not stored yet, so a task computed again after an
/// interruption (a chain segment runs whole from its seed, deterministically) adds nothing
/// twice.
struct SweepStore {
    lock: DirLock,
    fingerprint: serde_json::Value,
    spec: SweepSpec,
    done: HashSet<(usize, Branch)>,
}

impl SweepStore {
    /// The checkpoint in the store's directory.
    fn checkpoint(&self) -> SweepCheckpoint<'_> {
        sweep_checkpoint(&self.lock)
    }
}

impl PlanStore for SweepStore {
    fn open(&mut self, resume: bool) -> Result<Option<Vec<usize>>, StudyError> {
        let opened = self
            .checkpoint()
            .open(&self.fingerprint, resume, |_| false)?;
        let Opened::Run(left) = opened else {
            return Ok(None);
        };
        let left: Resume = left;
        let plan = SweepPlan::new(&self.spec);
        let todo = plan
            .tasks(1)
            .iter()
            .enumerate()
            .filter(|(_, t)| match **t {
                SweepTask::Segment(b, k) => plan
                    .chunk_indices(b, k)
                    .iter()
                    .any(|&i| !left.done.contains(&(i, b))),
                SweepTask::Start(i, s) => !left.done.contains(&(i, Branch::Start(s))),
                SweepTask::Coarse(_) => false,
            })
            .map(|(k, _)| k)
            .collect();
        self.done = left.done;
        Ok(Some(todo))
    }
    fn append(&mut self, result: &str) -> Result<(), StudyError> {
        let recs = sweep_rows(&[result.to_string()])?;
        let mut s = self.checkpoint();
        for point in recs.chunk_by(|a, b| (a.index, a.branch) == (b.index, b.branch)) {
            if !self.done.contains(&(point[0].index, point[0].branch)) {
                s.append(point.to_vec())?;
            }
        }
        self.done.extend(recs.iter().map(|r| (r.index, r.branch)));
        Ok(())
    }
    fn finish(&mut self) -> Result<(), StudyError> {
        Ok(self.checkpoint().finish(&self.fingerprint)?)
    }
    fn outcome(&mut self) -> Result<Outcome, StudyError> {
        let recs = crate::study::checkpoint_file::final_rows(self.lock.path())?;
        if let Some(e) = every_point_failed(&recs) {
            return Err(e.into());
        }
        Ok(sweep_outcome(&self.spec, &recs))
    }
}

/// A basin map's plan.
struct Basins {
    study: BasinStudy,
    request: BasinsRequest,
    model: Resolved,
    text: String,
}

fn basin_rows(results: &[String]) -> Result<Vec<BasinRow>, SimError> {
    results.iter().map(|t| decode("result", t)).collect()
}

impl Plan for Basins {
    fn recipe(&self) -> &str {
        &self.text
    }
    fn stages(&self) -> usize {
        passes(&self.study.spec)
    }
    fn stage(&self, stage: usize, results: &[String]) -> Result<Stage, SimError> {
        if stage >= self.stages() {
            return Err(no_stage(stage, self.stages()));
        }
        let start = pass_start(&self.study.spec, &basin_rows(results)?, stage);
        Ok(Stage {
            tasks: start.rows.iter().map(|(iy, _)| *iy).collect(),
            start: encode(&start)?,
        })
    }
    fn run(&self, start: &str, iy: usize, cancel: &AtomicBool) -> Result<String, SimError> {
        let start: PassStart = decode("start", start)?;
        let Some((_, columns)) = start.rows.iter().find(|(i, _)| *i == iy) else {
            let pass = format!("a row of pass {}", start.pass);
            return Err(SimError::out_of_range("iy", iy, pass));
        };
        let s = &self.study;
        encode(&run_pass_row(
            &s.spec, &s.model, &start, iy, columns, cancel,
        )?)
    }
    fn outcome(&self, results: &[String]) -> Result<Outcome, SimError> {
        let map = self.study.map(basin_rows(results)?)?;
        outcome(&self.request, &self.model, &map)
    }
}

/// A PI scan's plan: its one stage's start is the study's [`LineJob`] (what a line needs,
/// without the materials' approach curves), so that a worker scans lines without building
/// the study.
struct Image {
    /// Built on first use ([`rebuild`]) or at once ([`plan`]).
    study: std::sync::OnceLock<ScanStudy>,
    scan: ScanRecipe,
    text: String,
}

impl Image {
    fn study(&self) -> Result<&ScanStudy, SimError> {
        if let Some(s) = self.study.get() {
            return Ok(s);
        }
        let s = ScanStudy::from_recipe(&self.scan)?;
        Ok(self.study.get_or_init(|| s))
    }
}

impl Plan for Image {
    fn recipe(&self) -> &str {
        &self.text
    }
    fn stages(&self) -> usize {
        1
    }
    fn stage(&self, stage: usize, _results: &[String]) -> Result<Stage, SimError> {
        match stage {
            0 => {
                let study = self.study()?;
                Ok(Stage {
                    start: encode(study.line_job())?,
                    tasks: (0..study.lines()).collect(),
                })
            }
            _ => Err(no_stage(stage, 1)),
        }
    }
    fn run(&self, start: &str, t: usize, cancel: &AtomicBool) -> Result<String, SimError> {
        let line = if start.is_empty() {
            self.study()?.line(t, cancel)?
        } else {
            decode::<LineJob>("start", start)?.line(t, cancel)?
        };
        encode(&(t, line))
    }
    fn outcome(&self, results: &[String]) -> Result<Outcome, SimError> {
        let lines = results
            .iter()
            .map(|t| decode::<(usize, ScanLine)>("result", t))
            .collect::<Result<Vec<_>, _>>()?;
        let img = self.study()?.assemble(lines)?;
        Ok(super::image::ImageOutput::Pi(img).outcome(self.scan.request.setpoint))
    }
}

/// A PeakForce image's plan.
struct PfImage {
    study: PeakForceImageStudy,
    text: String,
}

/// A PeakForce image task's result: a material's engage, or a line.
#[derive(Serialize, Deserialize)]
enum PfResult {
    Engage(usize, Engage),
    Line(usize, Vec<LinePixel>),
}

/// A PeakForce image's results: the materials' engages (in their order) and the lines.
type PfResults = (Vec<Engage>, Vec<(usize, Vec<LinePixel>)>);

impl PfImage {
    /// The engages and lines of `results` (any order; every material's engage required).
    fn results(&self, results: &[String]) -> Result<PfResults, SimError> {
        let mut engages = Vec::new();
        let mut lines = Vec::new();
        for r in results {
            match decode::<PfResult>("result", r)? {
                PfResult::Engage(m, e) => engages.push((m, e)),
                PfResult::Line(t, l) => lines.push((t, l)),
            }
        }
        engages.sort_by_key(|e| e.0);
        let n = self.study.materials.len();
        if engages.len() != n || engages.iter().enumerate().any(|(i, e)| e.0 != i) {
            return Err(bad("result", "not every material's engage"));
        }
        Ok((engages.into_iter().map(|e| e.1).collect(), lines))
    }
}

impl Plan for PfImage {
    fn recipe(&self) -> &str {
        &self.text
    }
    fn stages(&self) -> usize {
        2
    }
    fn stage(&self, stage: usize, results: &[String]) -> Result<Stage, SimError> {
        match stage {
            0 => Ok(Stage {
                start: encode(&None::<Vec<Engage>>)?,
                tasks: (0..self.study.materials.len()).collect(),
            }),
            1 => {
                let engages = self.results(results)?.0;
                self.study.reached(&engages)?;
                Ok(Stage {
                    start: encode(&Some(engages))?,
                    tasks: (0..self.study.lines()).collect(),
                })
            }
            _ => Err(no_stage(stage, 2)),
        }
    }
    fn run(&self, start: &str, t: usize, _cancel: &AtomicBool) -> Result<String, SimError> {
        match decode::<Option<Vec<Engage>>>("start", start)? {
            None => encode(&PfResult::Engage(t, self.study.engage(t)?)),
            Some(engages) => {
                let study = self.study.clone().with_engages(engages);
                encode(&PfResult::Line(t, study.line(t)?))
            }
        }
    }
    fn outcome(&self, results: &[String]) -> Result<Outcome, SimError> {
        let (engages, lines) = self.results(results)?;
        let study = self.study.clone().with_engages(engages);
        let img = study.assemble(lines)?;
        Ok(super::image::ImageOutput::PeakForce(img).outcome(self.study.request.setpoint))
    }
}

/// A force map's plan: one stage, a task per line of the map.
struct FitMap {
    study: Arc<MapStudy>,
    request: FitMapRequest,
    model: Resolved,
    text: String,
}

/// A fit-map task's result: its line and the line's curves' fits.
type MapLine = (usize, Vec<CurveFit>);

/// The fitted map's outcome of its lines (any order; every line required), as the one door
/// gives it (no answer when every curve failed).
fn map_outcome(
    study: &MapStudy,
    request: &FitMapRequest,
    model: &Resolved,
    lines: Vec<MapLine>,
) -> Result<Outcome, SimError> {
    let map = study.assemble(lines)?;
    if let Some(e) = every_curve_failed(&map) {
        return Err(e);
    }
    outcome(request, model, &map)
}

impl Plan for FitMap {
    fn recipe(&self) -> &str {
        &self.text
    }
    fn stages(&self) -> usize {
        1
    }
    fn stage(&self, stage: usize, _results: &[String]) -> Result<Stage, SimError> {
        match stage {
            0 => Ok(Stage {
                start: String::new(),
                tasks: (0..self.study.lines()).collect(),
            }),
            _ => Err(no_stage(stage, 1)),
        }
    }
    fn run(&self, _start: &str, t: usize, cancel: &AtomicBool) -> Result<String, SimError> {
        let lines = self.study.lines();
        if t >= lines {
            return Err(SimError::out_of_range("task", t, format!("in 0..{lines}")));
        }
        let fits = self.study.line(t, cancel)?.ok_or(SimError::Cancelled)?;
        encode(&(t, fits))
    }
    fn outcome(&self, results: &[String]) -> Result<Outcome, SimError> {
        let lines = results
            .iter()
            .map(|r| decode::<MapLine>("result", r))
            .collect::<Result<Vec<_>, _>>()?;
        map_outcome(&self.study, &self.request, &self.model, lines)
    }
    fn store(&self, lock: DirLock) -> Option<Box<dyn PlanStore>> {
        Some(Box::new(MapStore {
            lock,
            study: Arc::clone(&self.study),
            request: self.request.clone(),
            model: self.model.clone(),
        }))
    }
}

/// The command line's store of a force map (`afmdyn fit-map --out DIR`, `afmdyn.fit_map(store=)`):
/// a line of fits per finished task, so that a map interrupted anywhere resumes in any of
/// them, computing only the lines not stored.
struct MapStore {
    lock: DirLock,
    study: Arc<MapStudy>,
    request: FitMapRequest,
    model: Resolved,
}

impl PlanStore for MapStore {
    fn open(&mut self, resume: bool) -> Result<Option<Vec<usize>>, StudyError> {
        let lines = self.study.lines();
        let opened = fit_map_store(&self.lock).open(
            self.study.fingerprint(),
            resume,
            |done: &HashSet<usize>| done.len() >= lines,
        )?;
        Ok(match opened {
            Opened::Finished => None,
            Opened::Run(done) => Some((0..lines).filter(|t| !done.contains(t)).collect()),
        })
    }
    fn append(&mut self, result: &str) -> Result<(), StudyError> {
        let line: MapLine = decode("result", result)?;
        Ok(fit_map_store(&self.lock).append(line)?)
    }
    fn finish(&mut self) -> Result<(), StudyError> {
        Ok(fit_map_store(&self.lock).finish(self.study.fingerprint())?)
    }
    fn outcome(&mut self) -> Result<Outcome, StudyError> {
        let lines = fit_map_store(&self.lock).records()?;
        Ok(map_outcome(&self.study, &self.request, &self.model, lines)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sweep_from_its_tasks_is_the_sweep_bit_for_bit() {
        let request = BifurcationRequest {
            steps: 3,
            starts: 1,
            ..BifurcationRequest::default()
        };
        let recipe = Recipe::Bifurcation {
            request,
            params: Params::default(),
        };
        let p = rebuild(&serde_json::to_string(&recipe).unwrap()).expect("plan");
        let cancel = AtomicBool::new(false);
        let mut results = Vec::new();
        for stage in 0..p.stages() {
            let st = p.stage(stage, &results).expect("stage");
            for t in st.tasks {
                results.push(p.run(&st.start, t, &cancel).expect("task"));
            }
        }
        let out = p.outcome(&results).expect("outcome");
        assert_eq!(out.datasets.len(), 1);
        assert!(p.stage(2, &results).is_err());
        assert!(rebuild("{\"plan\": \"nope\"}").is_err());
    }

    /// A 3 × 2 map of Hertz approaches (the probe's R, k and ν) as the long-format CSV, in a
    /// fresh directory: its path.
    fn small_map(name: &str) -> std::path::PathBuf {
        use std::fmt::Write as _;
        let dir = std::env::temp_dir().join(format!("afmdyn-plan-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut text = String::from("x,y,height,force\n");
        for iy in 0..2 {
            for ix in 0..3 {
                let kh = 4.0 / 3.0 * 5e3 * (1.0 + ix as f64) / 0.75 * 5e-6_f64.sqrt();
                for i in 0..200 {
                    let x = 1e-6 - 2.5e-6 * i as f64 / 199.0;
                    let f = kh * (-x).max(0.0).powf(1.5) + 1e-12 * ((i * 7 + ix) % 5) as f64;
                    let (x0, y0) = (ix as f64 * 1e-6, iy as f64 * 1e-6);
                    writeln!(text, "{x0:e},{y0:e},{:e},{f:e}", x - f / 0.05).unwrap();
                }
            }
        }
        let path = dir.join("map.csv");
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn a_map_from_its_lines_is_the_map_bit_for_bit_and_its_store_resumes() {
        let path = small_map("fit-map");
        let probe = include_str!("../../../../examples/probe-fit-hertz.toml");
        let request = FitMapRequest {
            data: Some(path.display().to_string()),
            ..FitMapRequest::default()
        };
        let parsed = crate::probe::Probe::parse(probe, "probe").unwrap();
        let recipe = Recipe::FitMap {
            request: request.clone(),
            params: parsed.params,
            probe: Some(probe.into()),
        };
        let p = rebuild(&serde_json::to_string(&recipe).unwrap()).expect("plan");
        let cancel = AtomicBool::new(false);
        let st = p.stage(0, &[]).expect("stage");
        assert_eq!(st.tasks, vec![0, 1]);
        let results: Vec<String> = st
            .tasks
            .iter()
            .rev()
            .map(|&t| p.run(&st.start, t, &cancel).expect("line"))
            .collect();
        let out = p.outcome(&results).expect("outcome");
        // the one door's run of the same request
        let model = Resolved {
            params: parsed.params,
            probe: Some(parsed),
        };
        let map = crate::request::run::Analysis::execute(&request, &model, &Default::default())
            .expect("map");
        let door = outcome(&request, &model, &map).expect("outcome");
        assert_eq!(out.document, door.document);
        assert_eq!(out.facts, door.facts);
        assert_eq!(
            format!("{:?}", out.datasets),
            format!("{:?}", door.datasets)
        );
        assert!(p.stage(1, &results).is_err() && p.run("", 2, &cancel).is_err());
        // a store: one line appended, then resumed; the other line is all that is left
        let dir = path.with_file_name("store");
        let lock = || DirLock::acquire(&dir).expect("lock");
        let mut s = p.store(lock()).expect("a store");
        assert_eq!(s.open(true).expect("open"), Some(vec![0, 1]));
        s.append(&results[1]).expect("append");
        drop(s);
        let mut s = p.store(lock()).expect("a store");
        assert_eq!(s.open(true).expect("open"), Some(vec![1]));
        s.append(&results[0]).expect("append");
        s.finish().expect("finish");
        assert_eq!(s.outcome().expect("outcome").document, door.document);
        drop(s);
        let mut s = p.store(lock()).expect("a store");
        assert_eq!(
            s.open(true).expect("open"),
            None,
            "finished: nothing to run"
        );
        assert_eq!(
            s.open(false).expect("open"),
            Some(vec![0, 1]),
            "started over"
        );
        drop(s);
        let _ = std::fs::remove_dir_all(path.parent().unwrap());
    }
}
