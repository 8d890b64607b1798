//! The native side of `scripts/perf-wasm.sh`: wall time per forcing period of
//! [`afmdyn_wasm::advance_periods`] (the same call the browser times), best of 3:
//!
//! ```sh
//! cargo run --release -p afmdyn-wasm --example periods -- '<input JSON>' <periods>
//! ```
//!
//! Prints µs per period.

use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let input = args.get(1).map_or("{}", String::as_str);
    let periods: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2000);
    let best = (0..3)
        .map(|_| {
            let t = Instant::now();
            afmdyn_wasm::advance_periods(input, periods).expect("the model integrates");
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min);
    println!("{:.3}", best / periods as f64 * 1e6);
}
