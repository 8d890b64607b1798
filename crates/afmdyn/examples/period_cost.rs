//! Cost of one forcing period for a law and a mode count: accepted steps and events per period
//! (counted with [`advance_dyn`]) and wall time per period with [`advance`] (no observer), after
//! a transient of 50 periods on the attractor (default parameters, paper eq. 26, Ω = 2.6; `auto`
//! integrator). The last column is the time per period through [`advance_dyn`] with an observer.
//!
//! `cargo run --release -p afmdyn --example period_cost -- <linear|hertz|dmt|impact> <N> [periods]
//! [both|advance|observed|recorded]` (the last argument runs only one of the two timed loops,
//! for instruction counts; `recorded` runs the observed one with the statistics observer of a
//! steady-state recording, [`StatsObserver`] through [`advance_observed`], after every step).
//! With the linear law, `PROPAGATION=dense|modal` in the environment forces the exact
//! propagator's path ([`Propagation`]).
//!
//! `... -- probe <FILE.toml> [periods] [...]`: the same for the model of a probe file. With
//! `INTEGRATOR=<kind>` in the environment (auto, adaptive, split, taylor, ...) the
//! integrator is that kind instead of `auto`.
//!
//! `... -- build <N> [reps]`: time of one exact-propagator build at the default parameters,
//! without and with reuse of earlier builds ([`ExactOptions::reuse`]), and of a build after a
//! change of Ω by 1e-6 (spectral data reused, grid exponential and particular solution redone).
//!
//! `... -- shoot <N> [reps]`: time of one shooting solve of the period-1 orbit at Ω = 3.5 from
//! the attractor perturbed by 1e-3 (as `benches/stability.rs`).
//!
//! `... -- continuation <N> [reps]`: time of the continuation of the default period-1 branch
//! over Ω from 5 down to 1 (as `benches/stability.rs`), best of `reps`, and its number of points.
//!
//! `... -- grid <N>`: the exact propagator's grid sub-steps per forcing period at the default
//! parameters (for `scripts/perf-floor.sh`).

use afmdyn::analysis::continuation::{continue_branch, ContinuationSpec};
use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::analysis::steady::{steady_state, StatsObserver, SteadyOptions};
use afmdyn::integrate::exact::{ExactOptions, ExactPropagator, Propagation};
use afmdyn::integrate::{
    advance, advance_dyn, advance_observed, build, IntegratorOptions, Observed, Observer, Step,
};
use afmdyn::maps::StroboscopicMap;
use afmdyn::{CantileverModel, LawKind, Params, SweepParam};
use nalgebra::DVector;
use std::time::Instant;

/// The statistics observer of a steady-state recording ([`StatsObserver`] through
/// [`advance_observed`], as `analysis::steady` records), counting the steps and events.
#[derive(Default)]
struct Counted {
    stats: StatsObserver,
    steps: usize,
    events: usize,
}

impl Observer for Counted {
    fn start(&mut self, it: &mut Observed<'_>) -> Result<(), afmdyn::SimError> {
        self.stats.start(it)
    }
    fn step(&mut self, it: &mut Observed<'_>, s: &Step) -> Result<(), afmdyn::SimError> {
        self.steps += 1;
        self.events += usize::from(s.event.is_some());
        self.stats.step(it, s)
    }
}

fn best_of(reps: usize, mut f: impl FnMut()) -> f64 {
    (0..reps)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e6
        })
        .fold(f64::INFINITY, f64::min)
}

fn builds(modes: usize, reps: usize) -> Result<(), Box<dyn std::error::Error>> {
    let p = Params {
        modes,
        ..Params::default()
    };
    let m = CantileverModel::new(&p)?;
    let cache = afmdyn::integrate::PropagatorCache::new();
    let opts = |reuse: bool| ExactOptions {
        cache: reuse.then(|| cache.clone()),
        ..ExactOptions::default()
    };
    let cold = best_of(reps, || {
        std::hint::black_box(ExactPropagator::try_with(&m, opts(false)).ok());
    });
    ExactPropagator::try_with(&m, opts(true))?;
    let warm = best_of(reps, || {
        std::hint::black_box(ExactPropagator::try_with(&m, opts(true)).ok());
    });
    let models: Vec<CantileverModel> = (1..=reps)
        .map(|i| {
            CantileverModel::new(&Params {
                omega: p.omega + 1e-6 * i as f64,
                ..p
            })
        })
        .collect::<Result<_, _>>()?;
    let mut next = models.iter();
    let omega_step = best_of(reps, || {
        if let Some(model) = next.next() {
            std::hint::black_box(ExactPropagator::try_with(model, opts(true)).ok());
        }
    });
    println!(
        "build N = {modes}: {cold:.1} µs cold, {warm:.1} µs same parameters, \
         {omega_step:.1} µs after an Ω step"
    );
    Ok(())
}

fn shooting(modes: usize, reps: usize) -> Result<(), Box<dyn std::error::Error>> {
    let p = Params {
        modes,
        omega: 3.5,
        ..Params::default()
    };
    let m = CantileverModel::new(&p)?;
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest())?;
    let z = steady_state(it.as_mut(), &SteadyOptions::default())?
        .end_state()
        .clone();
    let guess = z + DVector::from_element(m.dim(), 1e-3);
    // one build and one solve per repetition, the builds sharing one propagator cache (as the
    // builds of one request do)
    let opts = IntegratorOptions::default();
    let solve = || {
        let mut it = build(&m, opts.clone(), 0.0, &m.rest())?;
        let map = &mut StroboscopicMap::new(it.as_mut(), 1);
        shoot(map, &guess, &ShootingOptions::default())
    };
    let iters = solve()?.residuals.len();
    let us = best_of(reps, || {
        std::hint::black_box(solve().ok());
    });
    println!("shoot N = {modes}: {us:.1} µs ({iters} residual evaluations)");
    Ok(())
}

fn continuation(modes: usize, reps: usize) -> Result<(), Box<dyn std::error::Error>> {
    let base = Params {
        modes,
        ..Params::default()
    };
    let p = Params { omega: 5.0, ..base };
    let m = CantileverModel::new(&p)?;
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest())?;
    let guess = steady_state(it.as_mut(), &SteadyOptions::default())?
        .end_state()
        .clone();
    let spec = ContinuationSpec::new(base, SweepParam::Omega, 5.0, 1.0, 1);
    let mut points = 0;
    let us = best_of(reps, || {
        points = continue_branch(&spec, &guess, &Progress::new()).map_or(0, |b| b.len());
    });
    println!(
        "continuation N = {modes}, Ω 5 → 1: {:.3} s ({points} points)",
        us * 1e-6
    );
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let first = args.next().unwrap_or_else(|| "linear".into());
    let second = args.next();
    let modes: usize = if first == "probe" {
        1
    } else {
        second.as_deref().map_or(Ok(3), str::parse)?
    };
    match first.as_str() {
        "build" => return builds(modes, args.next().map_or(Ok(200), |s| s.parse())?),
        "shoot" => return shooting(modes, args.next().map_or(Ok(200), |s| s.parse())?),
        "continuation" => {
            return continuation(modes, args.next().map_or(Ok(3), |s| s.parse())?);
        }
        "grid" => {
            let m = CantileverModel::new(&Params {
                modes,
                ..Params::default()
            })?;
            println!(
                "{}",
                ExactPropagator::try_with(&m, ExactOptions::default())?.steps_per_period()
            );
            return Ok(());
        }
        _ => {}
    }
    let periods: f64 = args.next().map_or(Ok(200.0), |s| s.parse())?;
    let which = args.next().unwrap_or_else(|| "both".into());
    let p = if first == "probe" {
        // `probe <file>`: the model of a probe file (the mode count argument is the file)
        let path = std::env::args().nth(2).unwrap_or_default();
        afmdyn::probe::Probe::parse(&std::fs::read_to_string(&path)?, &path)?.params
    } else {
        let law: LawKind = first.parse()?;
        Params {
            modes,
            contact_law: law.with_groups(Default::default()),
            ..Params::default()
        }
    };
    let m = CantileverModel::new(&p)?;
    let kind = match std::env::var("INTEGRATOR") {
        Ok(k) => k.parse()?,
        Err(_) => afmdyn::integrate::IntegratorKind::Auto,
    };
    let opts = IntegratorOptions {
        kind,
        ..IntegratorOptions::default()
    };
    let mut it = build(&m, opts, 0.0, &m.rest())?;
    let forced = match std::env::var("PROPAGATION").as_deref() {
        Ok("dense") => Some(Propagation::Dense),
        Ok("modal") => Some(Propagation::Auto),
        _ => None,
    };
    if let Some(propagation) = forced {
        let opts = ExactOptions {
            propagation,
            ..ExactOptions::default()
        };
        it = Box::new(ExactPropagator::try_with(&m, opts)?);
        it.reset(0.0, &m.rest())?;
    }
    advance(it.as_mut(), 50.0 * p.period())?;
    let (tau0, z0) = (it.tau(), it.state().clone());
    let t_end = tau0 + periods * p.period();
    let start = Instant::now();
    if matches!(which.as_str(), "both" | "advance") {
        advance(it.as_mut(), t_end)?;
    }
    let us = start.elapsed().as_secs_f64() * 1e6 / periods;
    it.reset(tau0, &z0)?;
    let (mut steps, mut events) = (0usize, 0usize);
    let start = Instant::now();
    if which == "recorded" {
        // the recording of a steady state (`analysis::steady`): the statistics observer
        let mut rec = Counted::default();
        advance_observed(it.as_mut(), t_end, &mut rec)?;
        (steps, events) = (rec.steps, rec.events);
    } else if which != "advance" {
        advance_dyn(it.as_mut(), t_end, &mut |_, s, _| {
            steps += 1;
            events += usize::from(s.event.is_some());
            Ok(())
        })?;
    }
    let us_observed = start.elapsed().as_secs_f64() * 1e6 / periods;
    println!(
        "{} {modes} {} {:.1} {:.2} {us:.1} {us_observed:.1}",
        p.contact_law.name(),
        it.name(),
        steps as f64 / periods,
        events as f64 / periods
    );
    Ok(())
}
