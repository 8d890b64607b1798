//! Cost of one forcing period for a law and a mode count: accepted steps and events per period
//! and wall time per period, after a transient of 50 periods on the attractor (default
//! parameters, paper eq. 26, Ω = 2.6; `auto` integrator).
//!
//! `cargo run --release -p afmdyn --example period_cost -- <linear|hertz|dmt|impact> <N> [periods]`

use afmdyn::integrate::{advance_dyn, build, IntegratorOptions};
use afmdyn::{CantileverModel, LawKind, Params};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let law: LawKind = args.next().unwrap_or_else(|| "linear".into()).parse()?;
    let modes: usize = args.next().map_or(Ok(3), |s| s.parse())?;
    let periods: f64 = args.next().map_or(Ok(200.0), |s| s.parse())?;
    let p = Params {
        modes,
        contact_law: law.with_groups(None, None, None),
        ..Params::default()
    };
    let m = CantileverModel::new(&p)?;
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest())?;
    advance_dyn(it.as_mut(), 50.0 * p.period(), &mut |_, _, _| Ok(()))?;
    let (mut steps, mut events) = (0usize, 0usize);
    let t_end = it.tau() + periods * p.period();
    let start = std::time::Instant::now();
    advance_dyn(it.as_mut(), t_end, &mut |_, s, _| {
        steps += 1;
        events += usize::from(s.event.is_some());
        Ok(())
    })?;
    let us = start.elapsed().as_secs_f64() * 1e6 / periods;
    println!(
        "{} {modes} {} {:.1} {:.2} {us:.1}",
        p.contact_law.name(),
        it.name(),
        steps as f64 / periods,
        events as f64 / periods
    );
    Ok(())
}
