//! `run("simulate", input)`: one trajectory, its summary and its time series, for the page's
//! time-series plot and phase portrait of a clicked orbit.
//!
//! The request takes the keys of [`afmdyn::request::SimulateRequest`] (`periods` or
//! `tau_end`, `transient`, `initial` (2N values a₁…a_N, ȧ₁…ȧ_N at τ = 0), `samples_per_period`,
//! `integrator`, …). The run is recorded whole in memory, as Python's `afmdyn.simulate`
//! records it ([`afmdyn::request::SimulateRequest::record_whole`]), and returned as
//!
//! ```json
//! {"summary": {…}, "series": {"tau": {"dims": ["tau"], "shape": [S], "units": "τ (eq. 5)",
//!   "long_name": "…", "values": […]}, "v_t": {…}, …}}
//! ```
//!
//! * `summary`: the document `afmdyn simulate --files none --json` prints (final state,
//!   switchings, sections, energy residual, warnings; the `"si"` block with a probe;
//!   `"files": "none"`, nothing being written).
//! * `series`: the variables of the library's layout of the run
//!   ([`afmdyn::report::simulate_layout`], Python's `xarray.Dataset`), each
//!   `{"dims", "shape", "units", "long_name", "values"}` with its values flat, row-major
//!   ([`crate::series`]), NaN as `null`. With a probe the values are SI and the time is `t`
//!   (s); without, the model's units and the time is `tau`. Over the time (S = ⌊periods ×
//!   samples_per_period⌋ + 1 samples, the first at the end of the transient):
//!   - `tau` or `t`: the time (τ; s);
//!   - `v_t`: the tip–sample distance V_T (g₀; m), ≤ 0 in contact;
//!   - `v_t_dot`: dV_T/dτ (g₀ per τ; m/s);
//!   - `w_tip`: the tip deflection W(1,τ) (g₀; m);
//!   - `w_tip_dot`: ∂W(1,τ)/∂τ;
//!   - `in_contact`: booleans;
//!   - `contact_force`: the tip–sample force (the model's unit; N), with `attrs.sign_convention`;
//!   - `a`, `a_dot`: the modal coordinates and velocities, dims `[time, "mode"]` (S × N).
//!
//!   Besides: `event_tau`, `event_to_contact`, `event_v_t_dot` (the switchings), `section_tau`,
//!   `section_v_t`, `section_w_tip`, `section_w_tip_dot`, `section_state` (the stroboscopic
//!   section τ = 2πk/Ω), with `energy_balance` the energy balance per period (`energy_tau0`, `energy_start`,
//!   `energy_end`, `base_work`, `beam_dissipation`, `contact_dissipation`,
//!   `energy_residual`), `spectrum` over `frequency` (the amplitude spectrum of W(1,τ)), and
//!   the coordinates `mode` and `component`.
//!
//! The budget: the library's for a series in memory, and at most [`max_samples`] in wasm: 2
//! million samples ([`MAX_SAMPLES`], wasm32's memory), fewer for N > 1 so that the JSON text
//! fits in a JavaScript string ([`MAX_VALUES`]: 1,538,461 samples for N = 3).

use crate::series::LayoutJson;
use afmdyn::request::{self, Progress, SimulateRequest};
use serde::Serialize;
use serde_json::{json, Value};

/// Most samples of a series in wasm (wasm32 has at most 4 GiB of memory, and the samples, the
/// layout and their JSON text are held at once).
pub const MAX_SAMPLES: usize = 2_000_000;

/// Most values of the series over time in wasm, 7 + 2N per sample (`tau`, `v_t`, `v_t_dot`,
/// `w_tip`, `w_tip_dot`, `in_contact`, `contact_force`, `a`, `a_dot`): a JavaScript string
/// holds at most 2²⁹ − 24 characters (V8), and a value takes up to 24 (measured: 20–23 on
/// average, 264 characters a sample for N = 3).
pub const MAX_VALUES: usize = 20_000_000;

/// The most samples of an N-mode series in wasm: [`MAX_SAMPLES`], fewer where they would hold
/// more than [`MAX_VALUES`] values.
pub fn max_samples(modes: usize) -> usize {
    MAX_SAMPLES.min(MAX_VALUES / (7 + 2 * modes))
}

/// What `run("simulate", …)` returns (module docs).
#[derive(Serialize)]
struct Output<'a> {
    summary: &'a Value,
    series: LayoutJson<'a>,
}

/// The trajectory of `input` (module docs) as JSON text.
///
/// # Errors
/// As [`crate::run_json`]'s model; the request's validation (naming the key and its range);
/// more than [`MAX_SAMPLES`] samples; the initial state's and the integrator's.
pub fn simulate(input: &str) -> Result<String, String> {
    let (model, r) = crate::resolve(input, "simulate")?;
    let r = r.unwrap_or_else(|| Value::Object(Default::default()));
    let request: SimulateRequest = crate::request(Some(r.clone()))?;
    let p = &model.params;
    let span = request.validate_in_memory(p).map_err(|e| e.to_string())?;
    let limit = max_samples(p.modes);
    if span.rows > limit as f64 {
        return Err(format!(
            "periods = {}, samples_per_period = {}: {:.0} samples; must be at most {limit} in the \
             browser for N = {} ({MAX_SAMPLES} samples and {MAX_VALUES} series values at most: \
             wasm32 memory, JavaScript's longest string); lower periods or samples_per_period",
            span.record_tau / p.period(),
            request.samples_per_period,
            span.rows,
            p.modes
        ));
    }
    // the one door, as Python's `afmdyn.simulate`: the run recorded whole, its layout
    let named = request::named::parse("simulate", r)
        .map_err(|e| format!("request: {e}"))?
        .ok_or("analysis = simulate: not a named analysis")?;
    let mut outcome = named
        .run(&model, &Progress::new())
        .map_err(|e| e.to_string())?;
    outcome.document["files"] = json!("none");
    let (_, layout) = outcome.datasets.first().ok_or("simulate: no series")?;
    serde_json::to_string(&Output {
        summary: &outcome.document,
        series: LayoutJson(layout),
    })
    .map_err(|e| format!("simulate: {e}"))
}
