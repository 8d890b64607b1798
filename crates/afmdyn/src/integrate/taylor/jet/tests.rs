use super::*;
use crate::contact::ContactLaw;

/// The products of series (a dot product with one factor backwards) are the Cauchy products
/// written out, at every order.
fn reversed(a: &[f64; M]) -> [f64; M] {
    let mut rev = [0.0; M];
    for k in 0..M {
        rev[M - 1 - k] = a[k];
    }
    rev
}

#[test]
fn products_of_series_are_cauchy_products() {
    let mut a = [0.0; M];
    let mut b = [0.0; M];
    for k in 0..M {
        a[k] = (0.7 * k as f64 + 0.3).sin() / (1.0 + k as f64);
        b[k] = (1.3 * k as f64).cos() * 0.9f64.powi(k as i32);
    }
    let brev = reversed(&b);
    for k in 0..M {
        let naive: f64 = (0..=k).map(|j| a[j] * b[k - j]).sum();
        let got = cauchy_rev(&a, &brev, k);
        assert!((got - naive).abs() <= 1e-15 * (1.0 + naive.abs()), "{k}");
    }
}

/// Inside a contact the τ series ([`Jet::contact_interior`]) and the σ series
/// ([`Jet::contact`]) are two different recurrences of one flow: at the same τ, their states
/// and Jacobians agree to the truncation (Hertz, and DMT with a Kelvin–Voigt damper, whose
/// ∂F/∂δ carries δ̇/(2w)); and the τ series' w² is δ at every order.
#[test]
fn interior_tau_series_match_the_sigma_series() {
    for law in [
        ContactLaw::Hertz,
        ContactLaw::Dmt {
            hamaker: 0.02,
            intermolecular_distance: 0.05,
        },
    ] {
        let m = CantileverModel::new(&crate::params::Params {
            contact_law: law,
            alpha6: 0.3,
            ..crate::params::Params::default()
        })
        .unwrap();
        let jet = Jet::new(&m).unwrap();
        let (n, d) = (m.modes(), m.dim());
        let tip = m.tip().as_slice().to_vec();
        let t2: f64 = tip.iter().map(|x| x * x).sum();
        // V_T = −0.1 at τ = 0 (sin Ωτ = 0), entering the sample at dV_T/dτ = −0.3
        let alpha5 = m.params().alpha5;
        let mut z0 = vec![0.0; d];
        for i in 0..n {
            z0[i] = -(alpha5 + 0.1) * tip[i] / t2;
            z0[n + i] = -0.3 * tip[i] / t2 - m.params().base_amplitude() * m.omega() * tip[i] / t2;
        }
        let delta0 = -m.v_t(0.0, &nalgebra::DVector::from_column_slice(&z0));
        assert!((delta0 - 0.1).abs() < 1e-12);
        let p = 22;
        let (mut st, mut ss) = (Series::default(), Series::default());
        let order = Order {
            p,
            variational: true,
        };
        jet.contact_interior(&mut st, 0.0, &z0, delta0.sqrt(), order);
        jet.contact(&mut ss, 0.0, &z0, delta0.sqrt(), order);
        assert!(!st.sigma && ss.sigma && st.region == Region::Contact);
        for k in 0..=p {
            let w2: f64 = (0..=k).map(|j| st.w[j] * st.w[k - j]).sum();
            let size: f64 = (0..=k).map(|j| (st.w[j] * st.w[k - j]).abs()).sum();
            assert!(
                (w2 - st.del[k]).abs() <= 1e-14 * size.max(st.del[k].abs()),
                "{law:?} k {k}"
            );
        }
        // at the shorter of the two steps the step rule takes (each series is its flow to
        // the tolerance within its own step)
        let ht = super::super::rule(&st, m.period(), 1e-12);
        let hs = super::super::rule(&ss, m.period(), 1e-12);
        let h = ht.min(super::super::poly::eval(&ss.theta[..=p], hs));
        let sigma = super::super::Taylor::sigma_at(&ss.theta[..=p], h, hs);
        let (mut a, mut b) = (vec![0.0; d], vec![0.0; d]);
        st.state_at(h, &mut a);
        ss.state_at(sigma, &mut b);
        for i in 0..d {
            assert!(
                (a[i] - b[i]).abs() <= 1e-11 * (1.0 + b[i].abs()),
                "{law:?} z{i}: {} {}",
                a[i],
                b[i]
            );
        }
        let (mut ja, mut jb) = (vec![0.0; d * d], vec![0.0; d * d]);
        st.jacobian_at(h, &mut ja);
        ss.jacobian_at(sigma, &mut jb);
        for i in 0..d * d {
            assert!(
                (ja[i] - jb[i]).abs() <= 1e-10 * (1.0 + jb[i].abs()),
                "{law:?} Φ{i}: {} {}",
                ja[i],
                jb[i]
            );
        }
    }
}

/// The free flight's series of a model without a tip force are those of the linear
/// equations: the coefficients of e^{A s} z₀ + particular part satisfy
/// (k + 1) z_{k+1} = A z_k + b_k, checked against the model's A and b (the defining
/// recurrence, independent of the code's per-block products); Φ's series those of e^{As}.
#[test]
fn free_flight_series_solve_the_linear_equations() {
    let m = CantileverModel::new(&crate::params::Params {
        contact_law: ContactLaw::Hertz,
        alpha5: 5.0,
        ..crate::params::Params::default()
    })
    .unwrap();
    let jet = Jet::new(&m).unwrap();
    let d = m.dim();
    let z0: Vec<f64> = (0..d).map(|i| 0.1 * (i as f64 + 1.0).sin()).collect();
    let (t0, p) = (0.37, 20);
    let mut s = Series::default();
    let order = Order {
        p,
        variational: true,
    };
    jet.free(&mut s, t0, &z0, order);
    let dy = m.dynamics(Region::Free);
    let om = m.omega();
    for k in 0..p {
        let zk = nalgebra::DVector::from_column_slice(&s.z[k * d..(k + 1) * d]);
        // the k-th coefficient of sin/cos Ω(t0 + s)
        let fk = om.powi(k as i32) / (1..=k).map(|i| i as f64).product::<f64>();
        let phase = om * t0 + k as f64 * std::f64::consts::FRAC_PI_2;
        let mut rhs = &dy.a * &zk + &dy.b_sin * (fk * phase.sin()) + &dy.b_cos * (fk * phase.cos());
        if k == 0 {
            rhs += &dy.b_const;
        }
        for i in 0..d {
            let lhs = (k + 1) as f64 * s.z[(k + 1) * d + i];
            assert!(
                (lhs - rhs[i]).abs() <= 1e-13 * (1.0 + rhs[i].abs()),
                "k {k}"
            );
        }
        let phik = nalgebra::DMatrix::from_column_slice(d, d, &s.phi[k * d * d..(k + 1) * d * d]);
        let next =
            nalgebra::DMatrix::from_column_slice(d, d, &s.phi[(k + 1) * d * d..(k + 2) * d * d])
                * (k + 1) as f64;
        let want = &dy.a * &phik;
        let scale = 1.0 + dy.a.amax() * phik.amax();
        assert!((next - want).amax() <= 1e-13 * scale, "Φ order {k}");
    }
}
