//! The table of the door's limits in docs/outputs.md (between its `limits-table` markers) is
//! generated here, each allowed range written from the library's constants (the ones
//! `Params::validate`, the requests' checks, the readers and the cost budget test against),
//! and must equal the committed text, so that the book cannot drift from the code.
//! `AFMDYN_WRITE_SCHEMA=1 cargo test -p afmdyn --lib integration::limits_table::` rewrites it.
#![cfg(feature = "files")]

use afmdyn::analysis::attractors::MAX_ATTRACTOR_SAMPLES;
use afmdyn::analysis::bifurcation::MAX_SWEEP_POINTS;
use afmdyn::analysis::global_continuation::{MAX_CONTINUATION_RUNS, MAX_CONTINUATION_VALUES};
use afmdyn::analysis::period::MAX_PERIOD;
use afmdyn::analysis::steady::{MAX_STEADY_PERIODS, MAX_TOL, MIN_TOL};
use afmdyn::analysis::traces::{MAX_TRACE_PERIODS, MAX_TRACE_SAMPLES};
use afmdyn::contact::DAMPING_MAX;
use afmdyn::io::caps::{MAX_CSV_BYTES, MAX_NPY_BYTES, MAX_NPY_HEADER_BYTES, MAX_PIXELS};
use afmdyn::io::input::{
    MAX_CSV_LINE_BYTES, MAX_INPUT_CSV_BYTES, MAX_INPUT_DOCUMENT_BYTES, MAX_INPUT_TEXT_BYTES,
    MAX_LEDGER_BYTES, MAX_STORE_BYTES, MAX_STORE_LINE_BYTES,
};
use afmdyn::params::{
    ADAPTIVE_STEPS_BUDGET, ALPHA1_MAX, ALPHA4_MAX, DISPLACEMENT_MAX, GRID_BUDGET_BYTES, MAX_MODES,
    OMEGA_MAX, OMEGA_MIN, STATE_NORM_MAX,
};
use afmdyn::probe::MAX_QUALITY_FACTOR;
use afmdyn::request::chart::{
    MAX_CHART_CELLS, MAX_CHART_LYAPUNOV_PERIODS, MAX_CHART_RUNS, MAX_CHART_SLOTS, MAX_CHART_STARTS,
    MAX_CHART_TILE,
};
use afmdyn::request::costs::{OPERATION_WORK, TRACE_GROWTH};
use afmdyn::request::limits::{
    MAX_CONVERGE_PERIODS, MAX_CONVERGE_SAMPLES, MAX_INITIAL_ENTRY, MAX_REQUEST_BYTES,
    MAX_REQUEST_WORK, MAX_RUN_PERIODS, MAX_SAMPLES_PER_PERIOD, MAX_SERIES_BYTES,
    MAX_SERIES_MEMORY_BYTES, MAX_THREADS, MAX_TRACE_BYTES, TOLERANCE_RANGE,
};

const BEGIN: &str = "<!-- limits-table: generated from the library's constants by \
                     crates/afmdyn/tests/limits_table.rs; do not edit -->";
const END: &str = "<!-- end of limits-table -->";

/// A number as the book writes it: beyond 1e3 a multiple of a power of ten as `meN` (`1e4`,
/// `2e6`), below 1e-2 a power of ten as `1eN`, an integer as itself, else its shortest form.
fn num(x: f64) -> String {
    let k = x.abs().log10().floor();
    let m = x / 10f64.powf(k);
    let short = (m - m.round()).abs() < 1e-9 && (x.abs() >= 1e4 || (x.abs() < 1e-2 && m == 1.0));
    if x != 0.0 && short {
        format!("{}e{}", m.round() as i64, k as i32)
    } else if x.fract() == 0.0 {
        format!("{}", x as i64)
    } else {
        format!("{x}")
    }
}

/// A size in bytes in KiB, MiB or GiB (at most 3 significant digits).
fn bytes(b: f64) -> String {
    let (v, unit) = [(1u64 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")]
        .into_iter()
        .map(|(s, u)| (b / s as f64, u))
        .find(|(v, _)| *v >= 1.0)
        .unwrap_or((b, "bytes"));
    // three significant digits
    let scale = 10f64.powf(2.0 - v.log10().floor());
    let v = (v * scale).round() / scale;
    format!("{} {unit}", num(v))
}

/// The rows: (input, allowed, why).
fn rows() -> Vec<[String; 3]> {
    let r = |a: &str, b: String, c: &str| [a.to_string(), b, c.to_string()];
    vec![
        r(
            "`--modes` N",
            format!("1..={MAX_MODES}"),
            &format!("mode shapes accurate to ~1e-13 up to i = {MAX_MODES}"),
        ),
        r(
            "α1 tip-mass ratio",
            format!("0..={}", num(ALPHA1_MAX)),
            "the mass matrix I + α1φφᵀ has condition ≈ 4Nα1",
        ),
        r(
            "α2 drive amplitude, \\|α5\\| gap",
            format!("≤ {}", num(DISPLACEMENT_MAX)),
            &format!(
                "displacements scale with them; states of norm {} count as diverged",
                num(STATE_NORM_MAX)
            ),
        ),
        r(
            "α3 beam damping, α6 contact damping",
            format!("0..={}", num(DAMPING_MAX)),
            "heavy damping makes the system stiff (grid steps ∝ α·T)",
        ),
        r(
            "α4 contact stiffness",
            format!("0..={}", num(ALPHA4_MAX)),
            "contact frequencies grow as √(4Nα4): stiff and ill-conditioned",
        ),
        r(
            "Ω drive frequency",
            format!("{}..={}", num(OMEGA_MIN), num(OMEGA_MAX)),
            "below: too many steps per period; above: the drive α2Ω² swamps the response in \
           round-off (the energy balance fails) and Ω is far above the highest mode",
        ),
        r(
            "`--initial-modal` entries",
            format!("\\|x\\| < {}", num(MAX_INITIAL_ENTRY)),
            &format!(
                "the integrators treat ‖z‖ ≥ {} as diverged",
                num(STATE_NORM_MAX)
            ),
        ),
        r(
            "exact integrator grid",
            format!(
                "(2N + 2)(m + 1) × 8 bytes ≤ {} for m steps per period",
                bytes(GRID_BUDGET_BYTES)
            ),
            "refused before allocating: Ω small with stiff or damped contact, or too many \
           `--samples-per-period`",
        ),
        r(
            "adaptive integrator",
            format!(
                "T‖A‖_F ≤ {} estimated steps per period",
                num(ADAPTIVE_STEPS_BUDGET)
            ),
            "same reason",
        ),
        r(
            "`simulate`",
            format!(
                "≤ {} periods; `--samples-per-period` 1..={}; time series ≤ {} in files \
                   (Python, which holds it in memory: ≤ {})",
                num(MAX_RUN_PERIODS),
                num(MAX_SAMPLES_PER_PERIOD as f64),
                bytes(MAX_SERIES_BYTES),
                bytes(MAX_SERIES_MEMORY_BYTES)
            ),
            "see above",
        ),
        r(
            "`bifurcation --steps`",
            format!(
                "1..={}; values × (2 + starts) ≤ {} points",
                num(MAX_SWEEP_POINTS as f64),
                num(MAX_SWEEP_POINTS as f64)
            ),
            "every point is a steady-state computation; the resume set and output index grow \
           with it",
        ),
        r(
            "`chart --x-steps`, `--y-steps`",
            format!(
                "1..={} each, ≤ {} cells; `--starts` 1..={}, cells × starts ≤ {}; `--tile` \
                   1..={}; `--max-attractors` 1..={}; `--lyapunov-periods` 0 or 10..={}",
                num(MAX_CHART_CELLS as f64),
                num(MAX_CHART_CELLS as f64),
                MAX_CHART_STARTS,
                num(MAX_CHART_RUNS as f64),
                num(MAX_CHART_TILE as f64),
                MAX_CHART_SLOTS,
                num(MAX_CHART_LYAPUNOV_PERIODS as f64)
            ),
            "every cell is K steady states; the arrays hold cells × slots",
        ),
        r("`--threads`", format!("1..={MAX_THREADS}"), ""),
        r(
            "`--max-periods`",
            format!(
                "1..={} (default: derived from Q, see \"The steady-state search\")",
                num(MAX_STEADY_PERIODS as f64)
            ),
            "",
        ),
        r(
            "`--tol` (returns)",
            format!("{}..={}", num(MIN_TOL), num(MAX_TOL)),
            "below: round-off; above: a slow transient or chaos passes for an orbit",
        ),
        r(
            "`attractors --samples`",
            format!("1..={}", num(MAX_ATTRACTOR_SAMPLES as f64)),
            "",
        ),
        r(
            "`attractors --sweep --steps`",
            format!(
                "1..={} values, values × (samples + 1) ≤ {}; `--match-tol` finite, ≥ 0",
                num(MAX_CONTINUATION_VALUES as f64),
                num(MAX_CONTINUATION_RUNS as f64)
            ),
            "a census per value",
        ),
        r(
            "`--period` (orbit, continue), `--max-period`",
            format!("1..={MAX_PERIOD}"),
            &format!("the period search compares up to {MAX_PERIOD} returns"),
        ),
        r(
            "`converge --periods`",
            format!(
                "1..={}, × samples ≤ {}",
                num(MAX_CONVERGE_PERIODS as f64),
                num(MAX_CONVERGE_SAMPLES as f64)
            ),
            "",
        ),
        r(
            "`lyapunov`",
            format!("transient + periods ≤ {}", num(MAX_RUN_PERIODS)),
            "",
        ),
        r(
            "`--tolerance` (every integrator, every law)",
            format!(
                "{}..={} (`approach`/`resonance`: below {})",
                num(TOLERANCE_RANGE.0),
                num(TOLERANCE_RANGE.1),
                num(TOLERANCE_RANGE.1)
            ),
            "below a double's resolution the steps shrink without end; above, it is no \
           accuracy. Checked for the exact propagator and RK4 too, which ignore it",
        ),
        r(
            "`approach`/`resonance --traces`",
            format!(
                "2..={} samples per period; points × samples × {} periods × 24 bytes ≤ {}, \
                   and within the request's memory budget below at {} × that (the traces' \
                   measured peak, 2.27 × while their vectors grow, 2.95 × with the outcome's \
                   arrays: `request::costs::TRACE_GROWTH`), so about {} of samples in practice",
                num(MAX_TRACE_SAMPLES as f64),
                MAX_TRACE_PERIODS,
                bytes(MAX_TRACE_BYTES),
                num(TRACE_GROWTH),
                bytes(MAX_REQUEST_BYTES / TRACE_GROWTH)
            ),
            &format!(
                "checked before the run for the longest trace ({MAX_TRACE_PERIODS} periods); \
           the files and NumPy arrays copy them"
            ),
        ),
        r(
            "input files: `--probe`, `--config`, `image --sample`, Python `probe=`, `sample=`",
            format!(
                "≤ {} (`MAX_INPUT_TEXT_BYTES`) of UTF-8 text",
                bytes(MAX_INPUT_TEXT_BYTES as f64)
            ),
            "every file is read by one reader, `afmdyn::io::input`, with a cap per kind \
           (`InputKind`): a regular file larger than its cap is refused from its length before \
           it is read; anything else (`/dev/zero`, a pipe) is read with `Read::take` and \
           refused past the cap; the message names the option, the file, the cap and the kind",
        ),
        r(
            "`continue --overlay` CSV, `reconstruct --fm` CSV",
            format!(
                "≤ {} (`MAX_INPUT_CSV_BYTES`) of UTF-8, lines ≤ {} (`MAX_CSV_LINE_BYTES`)",
                bytes(MAX_INPUT_CSV_BYTES as f64),
                bytes(MAX_CSV_LINE_BYTES as f64)
            ),
            "about a million rows of a sweep; a CSV parser holds a line whole, so a file without \
           line ends (`/dev/zero`) is refused after its line cap",
        ),
        r(
            "`reconstruct --fm`, `--am` JSON document",
            format!(
                "≤ {} (`MAX_INPUT_DOCUMENT_BYTES`)",
                bytes(MAX_INPUT_DOCUMENT_BYTES as f64)
            ),
            "parsed as it is read, never held as text",
        ),
        r(
            "a sample map's `height_map` file",
            format!(
                "CSV ≤ {} (lines ≤ {}), NPY ≤ {} + header (≤ {})",
                bytes(MAX_CSV_BYTES as f64),
                bytes(MAX_CSV_LINE_BYTES as f64),
                bytes((MAX_NPY_BYTES - MAX_NPY_HEADER_BYTES as u64 - 12) as f64),
                bytes(MAX_NPY_HEADER_BYTES as f64)
            ),
            &format!("{MAX_PIXELS} × {MAX_PIXELS} heights"),
        ),
        r(
            "store files a `--resume` (Python `resume=True`) reads",
            format!(
                "ledger (`.*.run.json`) ≤ {} (`MAX_LEDGER_BYTES`), parsed as it is read; a \
                   sweep's CSV and a study's records (`.*.jsonl`) ≤ {} (`MAX_STORE_BYTES`), \
                   lines ≤ {} (CSV) and ≤ {} (`MAX_STORE_LINE_BYTES`, records); no NUL byte",
                bytes(MAX_LEDGER_BYTES as f64),
                bytes(MAX_STORE_BYTES as f64),
                bytes(MAX_CSV_LINE_BYTES as f64),
                bytes(MAX_STORE_LINE_BYTES as f64)
            ),
            &format!(
                "the largest stores a request makes (a PI scan's ledger holds its {MAX_PIXELS} × \
           {MAX_PIXELS} height map; 10⁶ sweep points of 64 rows; a chart tile of 10⁴ cells × 64 \
           attractors). A store afmdyn wrote is text: a NUL byte (`/dev/zero`, a sparse file) \
           refuses the file at once. A refusal names the file and the cap, exit code 2, and the \
           store is left as it was"
            ),
        ),
        r(
            "every request's cost (`afmdyn::request::Analysis::cost`)",
            format!(
                "peak memory ≤ {} (`MAX_REQUEST_BYTES`); work ≤ {} mode-periods \
                   (`MAX_REQUEST_WORK`: drive periods integrated × modes; a request that \
                   integrates nothing counts its elementary operations at {} mode-period each \
                   (`OPERATION_WORK`): `fit`'s model evaluations × rows, the minimiser's and the \
                   profiles' refits at their caps, `reconstruct`'s FFT butterflies or \
                   direct-sum pairs, the exact inversion's at each of its 50 steps)",
                bytes(MAX_REQUEST_BYTES),
                num(MAX_REQUEST_WORK),
                num(OPERATION_WORK)
            ),
            "estimated before the run for the worst case the options allow (every steady-state \
           search to its transient cap, every Newton solve to its iteration limit) and refused \
           naming the request, its cost, about how much of the size asked fits, the budget and \
           the fields that drive the cost (`approach: a peak memory of 1.25 GiB (about 88 % of \
           this size fits) exceeds the budget of 1.1 GiB (ask for fewer points or trace samples \
           (traces), or branches = false)`): products such as starts × transient cap or cells \
           × transient cap are bounded, not only each factor. 1e11 mode-periods is about four \
           days on one core at N = 20 (`request::costs`). The declared memory is an upper \
           bound, tested for every request of the registry at two sizes against a counting \
           allocator's peak (`crates/afmdyn/tests/door.rs`); a cancel (Ctrl-C on every front \
           end) ends every request within a second, tested the same way: every loop that \
           integrates checks the run's cancel flag at each step",
        ),
        r(
            "model values (every command, `chart` included)",
            "finite numbers".to_string(),
            "a `NaN` or `inf` is refused naming the flag",
        ),
        r(
            "probe `quality_factor`, `quality_factors`",
            format!("(0, {}]", num(MAX_QUALITY_FACTOR)),
            "beyond any cantilever or quartz sensor in vacuum; Q = 1e308 left α2 NaN",
        ),
    ]
}

/// The generated table (Markdown).
fn table() -> String {
    let mut t = String::from("| input | allowed | why |\n|---|---|---|\n");
    for [a, b, c] in rows() {
        let why = if c.is_empty() { c } else { format!("{c} ") };
        t.push_str(&format!("| {a} | {b} | {why}|\n"));
    }
    t
}

#[test]
fn the_docs_table_of_limits_is_the_librarys() {
    super::common::generated_section("docs/outputs.md", BEGIN, END, &table(), "limits_table");
}
