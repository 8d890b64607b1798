//! Propagate the default model (paper eq. 26, Ω = 2.6, N = 3) over many drive periods with the
//! exact propagator and print the switchings per period and the final tip state.
//!
//! `cargo run --release -p afmdyn --example propagate -- [periods]`

use afmdyn::integrate::{advance_dyn, build, IntegratorOptions};
use afmdyn::{CantileverModel, Params};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let periods: f64 = std::env::args().nth(1).map_or(Ok(2000.0), |s| s.parse())?;
    let p = Params::default();
    let model = CantileverModel::new(&p)?;
    let mut integ = build(&model, IntegratorOptions::default(), 0.0, &model.rest())?;
    let mut switchings = 0usize;
    let start = std::time::Instant::now();
    advance_dyn(integ.as_mut(), periods * p.period(), &mut |_, step, _| {
        switchings += usize::from(step.event.is_some());
        Ok(())
    })?;
    let dt = start.elapsed();
    let z = integ.state();
    println!(
        "{periods} periods, {:.2} switchings/period, W(1,τ) = {:.9}, {:.2} µs/period",
        switchings as f64 / periods,
        model.w_tip(z),
        dt.as_secs_f64() * 1e6 / periods
    );
    Ok(())
}
