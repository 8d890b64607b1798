//! The impact law (a rigid sample, Newton's coefficient of restitution r) on the hybrid-system
//! core: contacts per period count the impacts, the closed-form N = 1 flight between impacts,
//! the energy lost at an impact (1 − r²), the grazing singularity of the saltation matrix
//! (∝ 1/velocity) and chattering that ends in sticking within a bounded number of impacts.

use afmdyn::analysis::steady::{steady_state, SteadyOptions};
use afmdyn::galerkin::Region;
use afmdyn::integrate::{advance_dyn, build, IntegratorKind, IntegratorOptions, SwitchEvent};
use afmdyn::trajectory::{record, RecordSpec};
use afmdyn::{CantileverModel, ContactLaw, EventKind, HybridSystem, Params};
use nalgebra::DVector;

use super::common;
use common::{events_until, impact_model, opts};

/// An attractor of the impact law touches the sample: its contacts per period count the
/// impacts (no region II is entered), as many as the observables' impacts per period and the
/// orbit's switchings (1 per period for this period-1 orbit).
#[test]
fn impact_contacts_per_period_count_the_impacts() {
    use afmdyn::analysis::observables::{observe_from, ObservableOptions};
    let m = impact_model(0.5, 1, 0.05, 3.0);
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
    let s = steady_state(it.as_mut(), &SteadyOptions::default()).unwrap();
    let n = s.period().expect("a periodic orbit");
    let o = observe_from(
        &m,
        IntegratorOptions::default(),
        0.0,
        s.end_state(),
        &ObservableOptions {
            periods: n,
            harmonics: 2,
        },
    )
    .unwrap();
    assert!(o.impacts_per_period > 0.0);
    assert_eq!(s.stats.contacts_per_period, o.impacts_per_period);
    assert_eq!(
        s.stats.contact_fraction, 0.0,
        "no time is spent in region II"
    );
}

/// N = 1 between impacts is m ẍ + c ẋ + k x = F_s sin Ωτ + F_c cos Ωτ: its closed-form solution
/// from each post-impact state, the next impact by bisection on V_T, and Newton's law applied by
/// hand, against the adaptive integrator for the first impacts.
#[test]
fn impact_n1_matches_closed_form_flights() {
    let r = 0.5;
    let m = impact_model(r, 1, 0.05, 3.0);
    let g = m.galerkin().region(Region::Free);
    let (mm, c, k) = (g.mass[(0, 0)], g.damping[(0, 0)], g.stiffness[(0, 0)]);
    let (fs, fc) = (g.forcing.sin[0], g.forcing.cos[0]);
    let (w, phi, p) = (m.omega(), m.tip()[0], *m.params());
    // particular solution x_p = A sin + B cos: (k − mΩ²)A − cΩB = F_s, cΩA + (k − mΩ²)B = F_c
    let d = k - mm * w * w;
    let det = d * d + (c * w) * (c * w);
    let (pa, pb) = ((d * fs + c * w * fc) / det, (d * fc - c * w * fs) / det);
    let xp = |t: f64| {
        (
            pa * (w * t).sin() + pb * (w * t).cos(),
            w * (pa * (w * t).cos() - pb * (w * t).sin()),
        )
    };
    let (zeta, w0) = (c / (2.0 * mm), (k / mm).sqrt());
    let wd = (w0 * w0 - zeta * zeta).sqrt();
    // free flight from (t0, x0, v0)
    let flight = |t0: f64, x0: f64, v0: f64, t: f64| {
        let (p0, q0) = xp(t0);
        let (h0, hv0) = (x0 - p0, v0 - q0);
        let s = t - t0;
        let (a, b) = (h0, (hv0 + zeta * h0) / wd);
        let e = (-zeta * s).exp();
        let (sn, cs) = (wd * s).sin_cos();
        let (px, pv) = xp(t);
        (
            px + e * (a * cs + b * sn),
            pv + e * (-zeta * (a * cs + b * sn) + wd * (-a * sn + b * cs)),
        )
    };
    let v_t = |t: f64, x: f64| phi * x + p.alpha2 * (w * t).sin() + p.alpha5;
    let (mut t0, mut x0, mut v0) = (0.0, 0.0, 0.0);
    let mut want = Vec::new();
    while want.len() < 6 {
        // march to the first sign change of V_T, then bisect
        let dt = 1e-3;
        let mut t = t0 + dt;
        while v_t(t, flight(t0, x0, v0, t).0) > 0.0 {
            t += dt;
        }
        let (mut lo, mut hi) = (t - dt, t);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if v_t(mid, flight(t0, x0, v0, mid).0) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let ti = 0.5 * (lo + hi);
        let (x, v) = flight(t0, x0, v0, ti);
        let vt_dot = phi * v + p.alpha2 * w * (w * ti).cos();
        want.push((ti, vt_dot));
        // Newton's law through the tip: V̇_T⁺ = −r V̇_T⁻
        let v_plus = v - (1.0 + r) * vt_dot / phi;
        (t0, x0, v0) = (ti, x, v_plus);
    }
    let mut it = build(&m, opts(IntegratorKind::Adaptive, 1e-13), 0.0, &m.rest()).unwrap();
    let ev = events_until(it.as_mut(), want[5].0 + 1e-6);
    assert_eq!(ev.len(), 6);
    for (e, (t, vd)) in ev.iter().zip(&want) {
        assert_eq!(e.kind, EventKind::Impact);
        assert!((e.tau - t).abs() < 1e-9, "impact at {} vs {t}", e.tau);
        assert!(
            (e.v_t_dot - vd).abs() < 1e-9,
            "velocity {} vs {vd}",
            e.v_t_dot
        );
    }
}

/// Every impact obeys V̇_T⁺ = −r V̇_T⁻; the energy balance of a run closes with the impact
/// losses (1 − r²) ½ m_eff (V̇_T⁻)² and the impulse's work on the moving frame; with r = 1 no
/// energy is lost at impacts.
#[test]
fn impact_law_energy_and_restitution() {
    for r in [0.5, 1.0] {
        let m = impact_model(r, 3, 0.02, 2.8);
        let mut it = build(&m, opts(IntegratorKind::Adaptive, 1e-13), 0.0, &m.rest()).unwrap();
        let tr = record(
            it.as_mut(),
            &RecordSpec {
                transient_periods: 0.0,
                record_tau: 6.0 * m.period(),
                samples_per_period: 0,
                energy: true,
                body_contact: false,
            },
        )
        .unwrap();
        let impacts: Vec<_> = tr
            .events
            .iter()
            .filter(|e| e.kind == EventKind::Impact)
            .collect();
        assert!(impacts.len() >= 3, "r = {r}: {} impacts", impacts.len());
        let mut it2 = build(&m, opts(IntegratorKind::Adaptive, 1e-13), 0.0, &m.rest()).unwrap();
        advance_dyn(it2.as_mut(), tr.tau_end, &mut |integ, s, _| {
            if let Some(e) = &s.event {
                if e.kind == EventKind::Impact {
                    let after = integ.system().v_t_dot(e.tau, integ.state());
                    assert!((after + r * e.v_t_dot).abs() < 1e-12 * (1.0 + e.v_t_dot.abs()));
                }
            }
            Ok(())
        })
        .unwrap();
        let loss: f64 = tr.energy.iter().map(|b| b.contact_dissipation).sum();
        // impacts lose (1 − r²) ½ m_eff (V̇_T⁻)², the plastic impact that starts sticking ½ m_eff (V̇_T⁻)²
        let want: f64 = tr
            .events
            .iter()
            .map(|e| match e.kind {
                EventKind::Impact => 0.5 * (1.0 - r * r) * m.effective_mass() * e.v_t_dot.powi(2),
                EventKind::Stick => 0.5 * m.effective_mass() * e.v_t_dot.powi(2),
                _ => 0.0,
            })
            .sum();
        assert!(
            (loss - want).abs() < 1e-12 * (1.0 + want),
            "r = {r}: {loss} vs {want}"
        );
        for b in &tr.energy {
            assert!(
                b.residual().abs() < 1e-8,
                "r = {r}: residual {:e}",
                b.residual()
            );
        }
    }
}

/// A grazing impact: the saltation matrix grows like 1/V̇_T⁻ (Nordmark's square-root map), and
/// the flow map flags the orbit's distance to grazing.
#[test]
fn impact_grazing_saltation_scales_as_inverse_velocity() {
    let m = impact_model(0.8, 2, 0.0, 2.8);
    let n = m.modes();
    let tau = 0.4;
    let mut norms = Vec::new();
    for v in [1e-2, 1e-3, 1e-4, 1e-5] {
        // a state on V_T = 0 approaching at V̇_T⁻ = −v
        let mut z = DVector::from_vec(vec![0.0, 0.01, 0.0, 0.0]);
        z[0] -= m.v_t(tau, &z) / m.tip()[0];
        z[n] -= (m.v_t_dot(tau, &z) + v) / m.tip()[0];
        assert!(m.v_t(tau, &z).abs() < 1e-15 && (m.v_t_dot(tau, &z) + v).abs() < 1e-15);
        norms.push(m.saltation(Region::Free, tau, &z).norm() * v);
    }
    for w in norms.windows(2) {
        assert!((w[1] / w[0] - 1.0).abs() < 0.02, "‖S‖·v: {norms:?}");
    }
}

/// A chattering sequence (the tip pushed onto the sample) ends in sticking after a bounded number
/// of impacts, and the tip is released when the constraint force changes sign.
#[test]
fn chattering_ends_in_sticking_within_bounded_impacts() {
    for (r, gap, omega) in [(0.3, 0.0, 2.6), (0.8, -0.05, 1.0)] {
        let m = CantileverModel::new(&Params {
            alpha2: 0.3,
            alpha5: gap,
            omega,
            contact_law: ContactLaw::Impact { restitution: r },
            ..Params::default()
        })
        .unwrap();
        let mut it = build(&m, opts(IntegratorKind::Adaptive, 1e-12), 0.0, &m.rest()).unwrap();
        let ev = events_until(it.as_mut(), 20.0 * m.period());
        let sticks = ev.iter().filter(|e| e.kind == EventKind::Stick).count();
        let releases = ev.iter().filter(|e| e.kind == EventKind::Release).count();
        assert!(
            sticks >= 3 && releases + 1 >= sticks,
            "r = {r}, α5 = {gap}: {sticks} sticks"
        );
        // a chattering sequence: from the first impact with a compressive λ > 0 (plastic state
        // V̇_T = 0), the bounce heights h = m_eff (r V̇_T⁻)²/(2λ) fall by about r² per impact to
        // h_stick = 1e3 guard tolerances: every bounce of the sequence is above h_stick, the
        // sticking one below, and the sequence has about ln(h_stick/h₀)/(2 ln r) impacts; λ and
        // the flight asymmetry drift over a long sequence, so the bound allows 1.5× that + 6
        let h_stick = 1e3 * m.guard_tolerance(Region::Free, 0.0, m.rest().as_slice());
        let n = m.modes();
        let lambda_plastic = |e: &SwitchEvent| {
            let mut zp = e.state.clone();
            zp.rows_mut(n, n)
                .axpy(-m.effective_mass() * e.v_t_dot, m.tip_mobility(), 1.0);
            m.guard(Region::Contact, e.tau, zp.as_slice()).value
        };
        // (impacts in the sequence, its first bounce height, the last one): a bounce higher than
        // the last starts a new sequence (the drive can lift the tip again before it settles;
        // the geometric decay holds from the highest bounce on)
        let mut chatter: Option<(usize, f64, f64)> = None;
        for e in &ev {
            match e.kind {
                EventKind::Impact => {
                    let lambda = lambda_plastic(e);
                    if lambda > 0.0 {
                        let h = m.effective_mass() * (r * e.v_t_dot).powi(2) / (2.0 * lambda);
                        assert!(h > h_stick, "r = {r}: bounce of {h:e} not stuck");
                        chatter = match chatter {
                            Some((count, h0, last)) if h <= last => Some((count + 1, h0, h)),
                            _ => Some((1, h, h)),
                        };
                    } else {
                        chatter = None;
                    }
                }
                EventKind::Stick => {
                    let h =
                        m.effective_mass() * (r * e.v_t_dot).powi(2) / (2.0 * lambda_plastic(e));
                    assert!(h <= h_stick, "r = {r}: stuck at a bounce of {h:e}");
                    if let Some((count, h0, _)) = chatter {
                        let bound =
                            (1.5 * (h_stick / h0).ln() / (2.0 * r.ln())).max(0.0) as usize + 6;
                        assert!(count <= bound, "r = {r}: {count} impacts, bound {bound}");
                    }
                    chatter = None;
                }
                _ => chatter = None,
            }
        }
        // while stuck the tip stays on the sample
        for e in ev.iter().filter(|e| e.kind == EventKind::Release) {
            assert!(m.v_t(e.tau, &e.state).abs() < 1e-9);
        }
    }
}

// ------------------------------------------------------- every analysis on every law
