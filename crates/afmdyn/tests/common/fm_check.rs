//! The FM model's Jacobian check (`fit_fm.rs`, `fit_jkr.rs`, `fit_viscosity.rs`): its exact
//! sensitivities of Δf against fourth-order central differences of the library's FM curve.

use afmdyn::analysis::fit::am_curve::AmParam;
use afmdyn::analysis::fit::fm_curve::FmCurveModel;
use afmdyn::analysis::fit::CurveModel;

/// The FM model's Jacobian at `p` against the fourth-order central differences of its values
/// (`steps`: relative steps of named parameters, over the table below), to `agree` relative
/// (each value the library's FM curve), row by row where the Jacobian is not flagged.
pub fn check_fm_jacobian(
    model: &FmCurveModel,
    p: &[f64],
    what: &str,
    agree: f64,
    steps: &[(AmParam, f64)],
) {
    let (m, n) = (model.points(), p.len());
    let mut v = vec![0.0; m];
    let mut jac = vec![0.0; m * n];
    model.evaluate(p, &mut v, Some(&mut jac));
    let warnings = model.warnings();
    assert!(warnings.is_empty(), "{what}: {warnings:?}");
    assert!(v.iter().all(|x| x.is_finite()), "{what}: {v:?}");
    eprintln!("{what}: Δf = {v:?} Hz");
    for j in 0..n {
        // a hundredth of E, R, H (Δf is smooth in them: the truncation O(h⁴) ~1e-9); z_offset
        // 5e-4 A₀, under half a percent of the closest distance (the attraction's steep power
        // law leaves 2e-5 at 1e-2 A₀, 1e-6 at 2e-3 A₀), the loop to 1e-12 so that its error
        // over h (~1e-9 Hz over 5 pm) stays below 1e-7 of the derivative
        let table = match model.params[j] {
            // A₀ moves the closest distance z_c − A as z_offset does
            AmParam::ZOffset | AmParam::FreeAmplitude => 5e-4 * model.probe.length_m,
            // the damper moves Δf weakly (the amplitude loop takes up the dissipation: 0.05 Hz
            // over 1e-2 c), so the loop's error over h reaches 1e-6 there; 2e-2 c halves it
            AmParam::Damping => 2e-2 * p[j].abs(),
            _ => 1e-2 * p[j].abs(),
        };
        // a step given for this parameter, relative to its value, over the table's
        let h = steps
            .iter()
            .find(|(q, _)| *q == model.params[j])
            .map_or(table, |(_, r)| r * p[j].abs());
        let at = |k: f64| {
            let mut q = p.to_vec();
            q[j] += k * h;
            let mut out = vec![0.0; m];
            model.evaluate(&q, &mut out, None);
            out
        };
        let (p1, m1, p2, m2) = (at(1.0), at(-1.0), at(2.0), at(-2.0));
        // relative to the entry, or to 1e-3 of the column's largest where the entry is
        // smaller (a row out of contact feels E and R not at all: exactly 0 against the
        // loop's round-off)
        let largest = (0..m).map(|i| jac[i * n + j].abs()).fold(0.0, f64::max);
        for i in 0..m {
            let fd = (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * h);
            let e = jac[i * n + j];
            let scale = e.abs().max(fd.abs()).max(1e-3 * largest);
            let rel = if scale == 0.0 {
                0.0
            } else {
                (e - fd).abs() / scale
            };
            eprintln!(
                "{what} {:?} row {i}: dΔf/dp {e:.9e} (fd {fd:.9e}, rel {rel:.1e})",
                model.params[j]
            );
            assert!(rel <= agree, "{what} {:?} row {i}", model.params[j]);
        }
    }
}
