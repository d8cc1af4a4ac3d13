//! Jacobians and the torque box against independent numerics: central
//! finite differences of forward kinematics and of the links' potential
//! energy, on 10^4 random configurations inside the limits (split over the
//! three TriFingerPro fingers).

mod common;

use kinematics::{gravity_torques, joint_torques, max_force_scale};
use nalgebra::Vector3;
use rand::Rng;

const CASES: usize = 10_000;
const H: f64 = 1e-6;

#[test]
fn jacobians_match_central_differences() {
    let chains = common::chains();
    let mut rng = common::rng(1);
    let (mut worst_v, mut worst_w) = (0.0f64, 0.0f64);
    for n in 0..CASES {
        let c = &chains[n % 3];
        let q = common::random_q(c, &mut rng);
        let s = c.forward(&q);
        let (jv, jw) = (s.jacobian_v(), s.jacobian_w());
        for i in 0..3 {
            let mut dq = Vector3::zeros();
            dq[i] = H;
            let (sp, sm) = (c.forward(&(q + dq)), c.forward(&(q - dq)));
            let v = (sp.tip_centre() - sm.tip_centre()) / (2.0 * H);
            // Spatial angular velocity: R(q+h) R(q−h)ᵀ = exp(2h[ω]ₓ) + O(h³);
            // its skew part is sin(2h|ω|)[ω̂]ₓ (accurate where an acos is not).
            let m = sp.tip.rotation * sm.tip.rotation.transpose();
            let w = Vector3::new(
                m[(2, 1)] - m[(1, 2)],
                m[(0, 2)] - m[(2, 0)],
                m[(1, 0)] - m[(0, 1)],
            ) / (4.0 * H);
            worst_v = worst_v.max((jv.column(i) - v).norm());
            worst_w = worst_w.max((jw.column(i) - w).norm());
        }
    }
    // Truncation ~h²|c'''| (1e-13) plus rounding ~ε|c|/h (1e-10).
    assert!(worst_v < 1e-8, "J_v off by {worst_v:e} m/rad");
    assert!(worst_w < 1e-8, "J_ω off by {worst_w:e} rad/rad");
}

#[test]
fn gravity_torques_are_the_potential_gradient() {
    // g(q) = ∂V/∂q with V = −Σ m_j 𝐠·c_j(q): the torque that holds the links.
    let chains = common::chains();
    let h = common::hand();
    let mut rng = common::rng(2);
    let mut worst = 0.0f64;
    for n in 0..CASES {
        let c = &chains[n % 3];
        let q = common::random_q(c, &mut rng);
        let potential = |q: &Vector3<f64>| {
            let s = c.forward(q);
            (0..3)
                .map(|j| -c.bodies[j].mass * h.gravity.dot(&s.joints[j].point(&c.bodies[j].com)))
                .sum::<f64>()
        };
        let g = gravity_torques(c, &c.forward(&q), &h.gravity);
        for i in 0..3 {
            let mut dq = Vector3::zeros();
            dq[i] = H;
            let fd = (potential(&(q + dq)) - potential(&(q - dq))) / (2.0 * H);
            worst = worst.max((g[i] - fd).abs());
        }
    }
    assert!(worst < 1e-8, "g(q) off by {worst:e} N·m");
    // Plausible size: TriFingerPro's links are ~0.6 kg at ≤ 0.3 m.
    let s = chains[0].forward(&Vector3::new(0.0, 0.9, -1.7));
    let g = gravity_torques(&chains[0], &s, &h.gravity);
    assert!(g.iter().all(|t| t.abs() < 0.396), "{g}");
}

#[test]
fn torque_box_is_tight() {
    let chains = common::chains();
    let h = common::hand();
    let mut rng = common::rng(3);
    for n in 0..CASES {
        let c = &chains[n % 3];
        let s = c.forward(&common::random_q(c, &mut rng));
        let d = common::unit(&mut rng);
        let g = gravity_torques(c, &s, &h.gravity);
        let tau_max = c.effort();
        let Some(k) = max_force_scale(&s, &d, &g, &tau_max) else {
            panic!("the links' weight alone exceeds the motors at {n}");
        };
        assert!(k.is_finite() && k > 0.0);
        let usage = |k: f64| {
            let t = joint_torques(&s, &(d * k), &g);
            (0..3).map(|i| t[i].abs() / tau_max[i]).fold(0.0, f64::max)
        };
        assert!(
            (usage(k) - 1.0).abs() < 1e-9,
            "at the largest scale one joint is at its limit"
        );
        assert!(
            usage(k * (1.0 + 1e-6)) > 1.0,
            "and beyond it a joint exceeds"
        );
        // Power balance: τ·q̇ = f·ċ for the tip force part.
        let qd = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let f = d * 2.0;
        let tau = joint_torques(&s, &f, &Vector3::zeros());
        assert!((tau.dot(&qd) - f.dot(&(s.jacobian_v() * qd))).abs() < 1e-12);
    }
    // Gravity ten times Earth's exceeds the motors in a stretched pose: no force.
    let c = &chains[0];
    let s = c.forward(&Vector3::new(0.9, 1.5, -0.1));
    let g = gravity_torques(c, &s, &(h.gravity * 10.0));
    assert_eq!(max_force_scale(&s, &Vector3::z(), &g, &c.effort()), None);
}
