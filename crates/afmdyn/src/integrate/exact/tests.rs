//! Tests of the exact propagator's parts: the modal step's tip, the tip series against the
//! closed form, and the forcing cache.

use super::modal::{ModalExp, Modes};
use super::search::TipPoly;
use super::series::{Expansion, SeriesStart};
use super::tip::base_amp;
use super::{ExactOptions, ExactPropagator, PropagatorCache};
use crate::model::CantileverModel;
use crate::params::Params;
use crate::system::Region;
use nalgebra::DVector;

/// The homogeneous tip deflection and rate a modal grid step returns are those
/// `ModalExp::tip_of` reads from its result, bit for bit (`tip_values` takes the first after
/// a step of `step_impl`, the second after a run or the batch), and both are c̃ᵀy and c̃ᵀÃy
/// of the state y = V q formed in energy coordinates, to round-off; an odd (N = 1, 3) and
/// an even (N = 8) number of representatives, both regions.
#[test]
fn modal_step_tip_is_the_tip_of_its_result() {
    for modes in [1usize, 3, 8] {
        let model = CantileverModel::new(&Params {
            modes,
            ..Params::default()
        })
        .unwrap();
        let prop = ExactPropagator::try_new(&model, 1).unwrap();
        let dim = 2 * modes;
        for ri in 0..2 {
            let (sp, fr) = (&prop.spec[ri], &prop.forced[ri]);
            let me = sp.modal.as_ref().expect("well conditioned");
            let y0 = DVector::from_fn(dim, |j, _| (0.7 * j as f64 + 0.3).sin());
            let (mut q, mut out) = (Modes::ZERO, Modes::ZERO);
            me.project(y0.as_slice(), &mut q);
            for _ in 0..5 {
                let stepped = me.advance_into(&q, &fr.grid_fac, &mut out);
                let read = me.tip_of(&out);
                assert_eq!(stepped.0.to_bits(), read.0.to_bits(), "N = {modes}");
                assert_eq!(stepped.1.to_bits(), read.1.to_bits(), "N = {modes}");
                let mut y = vec![0.0; dim];
                ModalExp::expand(&me.v, &out, &mut y, false);
                let row = |n: usize| (0..dim).map(|j| sp.rows[(n, j)] * y[j]).sum::<f64>();
                let scale = sp.ct_norm * y0.norm() * (1.0 + sp.rho);
                assert!((read.0 - row(0)).abs() <= 1e-13 * scale, "N = {modes}");
                assert!((read.1 - row(1)).abs() <= 1e-13 * scale, "N = {modes}");
                q = out;
            }
        }
    }
}

/// The tip series of a step — expanded at its start, and centred at its middle from the
/// energy coordinates there or from the modal ones (the moments of
/// [`ModalExp::moments`]) — equal the gap g = σ V_T + dead and its rate from the closed-form
/// homogeneous solution c̃ᵀ e^{Ãt} y0 (nalgebra's matrix exponential, independent of the
/// eigendecomposition) plus the harmonic part of eq. 8, to round-off over the whole step,
/// in both regions, at N = 1, 3 and 8; and so does the dense tip deflection [W, W', W''].
#[test]
fn tip_series_equal_the_closed_form() {
    for modes in [1usize, 3, 8] {
        let p = Params {
            modes,
            ..Params::default()
        };
        let model = CantileverModel::new(&p).unwrap();
        let prop = ExactPropagator::try_new(&model, 1).unwrap();
        let (h, dim) = (prop.grid.h, 2 * modes);
        for (ri, r) in [Region::Free, Region::Contact].into_iter().enumerate() {
            let (sp, fr) = (&prop.spec[ri], &prop.forced[ri]);
            let me = sp.modal.as_ref().expect("well conditioned");
            let y0 = DVector::from_fn(dim, |j, _| (0.7 * j as f64 + 0.3).sin());
            let tau0 = 1.234;
            let y_at = |t: f64| (&sp.at * t).exp() * &y0;
            let row = |n: usize, y: &DVector<f64>| -> f64 {
                (0..dim).map(|j| sp.rows[(n, j)] * y[j]).sum()
            };
            let (amp, om) = (fr.wp[1] + base_amp(&p), p.omega);
            let exact = |t: f64| -> (f64, f64) {
                let y = y_at(t);
                let (s, c) = (om * (tau0 + t)).sin_cos();
                let v = row(0, &y) + fr.wp[0] + p.alpha5 + amp * s + fr.wp[2] * c;
                let dv = row(1, &y) + om * (amp * c - fr.wp[2] * s);
                let sigma = r.guard_sign();
                (sigma * v + prop.dead, sigma * dv)
            };
            // W_hom = c̃ᵀy and its derivatives c̃ᵀÃy, c̃ᵀÃ²y, plus W_p = wp·(1, sin, cos)
            let tip_exact = |t: f64| -> [f64; 3] {
                let y = y_at(t);
                let (s, c) = (om * (tau0 + t)).sin_cos();
                let (w0, ws, wc) = (fr.wp[0], fr.wp[1], fr.wp[2]);
                [
                    row(0, &y) + w0 + ws * s + wc * c,
                    row(1, &y) + om * (ws * c - wc * s),
                    row(2, &y) - om * om * (ws * s + wc * c),
                ]
            };
            let y_mid = y_at(0.5 * h);
            let mut q_mid = Modes::ZERO;
            me.project(y_mid.as_slice(), &mut q_mid);
            let scale = sp.ct_norm * y0.norm() * (1.0 + sp.rho)
                + fr.wp.iter().map(|w| w.abs()).sum::<f64>()
                + amp.abs() * (1.0 + om);
            let starts = [
                (0.0, SeriesStart::Energy(y0.as_slice())),
                (0.5 * h, SeriesStart::Energy(y_mid.as_slice())),
                (0.5 * h, SeriesStart::Modal(me, &q_mid)),
            ];
            for (case, (center, start)) in starts.into_iter().enumerate() {
                let mut poly = TipPoly::empty();
                let at = Expansion {
                    tau0,
                    center,
                    trig: (om * (tau0 + center)).sin_cos(),
                    len: h,
                    start,
                };
                ExactPropagator::build_poly(sp, fr, &p, prop.dead, r, &at, &mut poly);
                assert_eq!(poly.center, center);
                for k in 0..=40 {
                    let t = h * k as f64 / 40.0;
                    let (g, dg) = poly.g(t);
                    let (ge, dge) = exact(t);
                    let at = format!("N = {modes}, {r:?}, start {case}, t = {t}");
                    assert!((g - ge).abs() <= 1e-13 * scale, "{at}: g {g} vs {ge}");
                    assert!((dg - dge).abs() <= 1e-12 * scale, "{at}: g' {dg} vs {dge}");
                    // the dense tip deflection [W, W', W''] (eq. 9 at ξ = 1, with the
                    // particular part W_p), W'' against c̃ᵀÃ²y
                    let w = poly.w(t);
                    let we = tip_exact(t);
                    for (d, tol) in [(0, 1e-13), (1, 1e-12), (2, 1e-11 * (1.0 + sp.rho))] {
                        let (a, b) = (w[d], we[d]);
                        assert!((a - b).abs() <= tol * scale, "{at}: W^({d}) {a} vs {b}");
                    }
                }
            }
        }
    }
}

/// The cached forcing data (particular solution, grid tables) belong to the parameters that
/// made them: a build that differs only in the gap α5 — with no contact stiffness or damping,
/// so that no region's forcing vector sees α5 — gets V_T on the grid of its own α5, as a
/// build without reuse does.
#[test]
fn forcing_cache_tells_gaps_apart() {
    let p = Params {
        alpha4: 0.0,
        alpha6: 0.0,
        alpha5: 0.3,
        ..Params::default()
    };
    let q = Params { alpha5: 0.7, ..p };
    let (mp, mq) = (
        CantileverModel::new(&p).unwrap(),
        CantileverModel::new(&q).unwrap(),
    );
    let cached = ExactOptions {
        cache: Some(PropagatorCache::new()),
        ..ExactOptions::default()
    };
    let _first = ExactPropagator::try_with(&mp, cached.clone()).unwrap();
    let reused = ExactPropagator::try_with(&mq, cached).unwrap();
    // α5 is in the forcing key only: the spectral data and the grid exponential are reused
    assert_eq!(reused.reused(), (true, true, false));
    let fresh = ExactPropagator::try_with(&mq, ExactOptions::default()).unwrap();
    for ri in 0..2 {
        assert_eq!(
            reused.forced[ri].vp_grid, fresh.forced[ri].vp_grid,
            "region {ri}"
        );
    }
}

/// The closed-form integrals of the energy-balance rates over the steps of the exact
/// propagator (`energy.rs`: the tables of whole grid steps, the modal closed form of the other
/// steps) equal 24-point Gauss–Legendre quadrature of [`CantileverModel::power`] on the step's
/// dense output, to 1e-12 of the step's scale h (1 + |z|²) (the rates are quadratic in z with
/// coefficients of order 1; the closed form sums larger terms that cancel): both regions,
/// modal and dense propagation, N = 1, 3 and 8, beam and point mass, whole grid steps and the
/// partial steps around switchings.
#[test]
fn closed_form_rate_integrals_equal_quadrature_of_the_dense_output() {
    use super::build::Propagation;
    use crate::integrate::Integrator;
    use crate::params::Structure;
    use gauss_quad::legendre::GaussLegendre;
    use std::num::NonZeroUsize;
    let gl = GaussLegendre::new(NonZeroUsize::new(24).unwrap());
    for (modes, structure) in [
        (1, Structure::Beam),
        (3, Structure::Beam),
        (8, Structure::Beam),
        (1, Structure::PointMass),
    ] {
        let p = Params {
            modes,
            structure,
            alpha1: if structure == Structure::Beam {
                0.1
            } else {
                0.0
            },
            ..Params::default()
        };
        let model = CantileverModel::new(&p).unwrap();
        for propagation in [Propagation::Auto, Propagation::Dense] {
            let opts = ExactOptions {
                propagation,
                ..ExactOptions::default()
            };
            let mut prop = ExactPropagator::try_with(&model, opts).unwrap();
            prop.reset(0.0, &model.rest()).unwrap();
            let (mut whole, mut partial, mut regions) = (0, 0, [false; 2]);
            let mut target = 3.7;
            while prop.tau() < 20.0 * p.period() {
                // a requested end off the grid now and then: partial steps without a switching
                if prop.tau() >= target {
                    target += 3.7;
                }
                let step = prop.step(target).unwrap();
                if step.tau1 <= step.tau0 {
                    continue;
                }
                let got = prop
                    .last_step_rate_integrals()
                    .expect("every step of a modal region has them");
                let h = prop.grid.h;
                if prop.last.full
                    && step.event.is_none()
                    && (step.tau1 - step.tau0 - h).abs() < 1e-12
                {
                    whole += 1;
                } else {
                    partial += 1;
                }
                regions[step.region.index()] = true;
                let half = 0.5 * (step.tau1 - step.tau0);
                let mut want = [0.0; 3];
                for (x, w) in gl.iter() {
                    let tau = step.tau0 + half * (x + 1.0);
                    let pw = model.power(step.region, tau, &prop.dense_state(tau));
                    for (o, v) in
                        want.iter_mut()
                            .zip([pw.base, pw.beam_dissipation, pw.contact_dissipation])
                    {
                        *o += half * w * v;
                    }
                }
                let z2 = prop
                    .state()
                    .norm_squared()
                    .max(prop.dense_state(step.tau0).norm_squared());
                let scale = 2.0 * half * (1.0 + z2);
                for (g, w) in got.iter().zip(want) {
                    assert!(
                        (g - w).abs() <= 1e-12 * scale,
                        "N = {modes} {structure:?} {propagation:?} {:?} over {}: {got:?} vs {want:?}",
                        step.region,
                        2.0 * half
                    );
                }
            }
            assert!(
                whole > 100 && partial > 40,
                "{whole} whole, {partial} partial steps"
            );
            if structure == Structure::Beam {
                assert_eq!(regions, [true, true], "both regions");
            }
        }
    }
}

/// A cache is shared by the clones of its handle only: a build through a clone reuses what an
/// earlier one stored (bit-identical propagation), a build through another cache or none
/// computes afresh; each table holds at most `CAPACITY` entries, the least recently used
/// dropped first.
#[test]
fn a_cache_is_shared_by_its_clones_only() {
    use super::cache::CAPACITY;
    use crate::integrate::Integrator;
    let m = CantileverModel::new(&Params::default()).unwrap();
    let with = |cache: Option<PropagatorCache>| {
        let opts = ExactOptions {
            cache,
            ..ExactOptions::default()
        };
        ExactPropagator::try_with(&m, opts).unwrap()
    };
    let cache = PropagatorCache::new();
    assert!(cache.is_empty());
    assert_eq!(with(Some(cache.clone())).reused(), (false, false, false));
    assert_eq!(cache.len(), (1, 1, 1));
    let mut again = with(Some(cache.clone()));
    assert_eq!(again.reused(), (true, true, true));
    assert_eq!(
        with(Some(PropagatorCache::new())).reused(),
        (false, false, false)
    );
    assert_eq!(with(None).reused(), (false, false, false));
    assert_ne!(cache, PropagatorCache::new());
    assert_eq!(cache, cache.clone());
    // the reused build propagates as a fresh one, bit for bit
    let mut fresh = with(None);
    for it in [&mut again, &mut fresh] {
        it.reset(0.0, &m.rest()).unwrap();
        crate::integrate::advance(it, 20.0).unwrap();
    }
    assert_eq!(again.state(), fresh.state());
    // bounded: CAPACITY + 2 values of Ω keep the spectral data once and CAPACITY grids
    for k in 0..CAPACITY + 2 {
        let p = Params {
            omega: 2.0 + 0.01 * k as f64,
            ..Params::default()
        };
        let mk = CantileverModel::new(&p).unwrap();
        let opts = ExactOptions {
            cache: Some(cache.clone()),
            ..ExactOptions::default()
        };
        ExactPropagator::try_with(&mk, opts).unwrap();
    }
    let (s, g, f) = cache.len();
    assert_eq!(s, 1);
    assert!(g <= CAPACITY && f <= CAPACITY, "{g} {f}");
}
