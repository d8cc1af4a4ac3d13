//! Grasp force optimisation (SPEC §3.3) over seeded random grasps: the
//! returned forces balance the weight inside the friction cones, and under
//! the stated response model (Δf = −G⁺ δw) they stay inside the cones for
//! sampled disturbances of the configured size. G⁺ is recomputed here
//! independently (SVD pseudo-inverse of the dense grasp map).

mod common;

use gait::HandConfig;
use gait::grasp::contact::grasp_columns;
use gait::grasp::facts::{fact3_force_closure, fact4_force_closure};
use gait::grasp::{
    Contact, ContactForce, ContactFrame, ContactKind, Friction, GraspError, GraspForceSolver, Load,
    closure_margin,
};
use nalgebra::{DMatrix, DVector, Vector3};
use rand::Rng;

/// Dense normalised grasp map (6 × Σ dims) and the commanded force vector
/// in the same variable order (f_n, f_1, f_2 [, s]).
fn dense(
    contacts: &[Contact],
    out: &[ContactForce],
    fr: &Friction,
) -> (DMatrix<f64>, DVector<f64>) {
    let d: usize = contacts.iter().map(|c| c.kind.dim()).sum();
    let mut g = DMatrix::zeros(6, d);
    let mut f = DVector::zeros(d);
    let mut col = 0;
    for (c, o) in contacts.iter().zip(out) {
        let cols = grasp_columns(c, fr);
        let frame = ContactFrame::new(&c.normal);
        let comps = [
            o.normal,
            o.force.dot(&frame.t1),
            o.force.dot(&frame.t2),
            o.torsion * fr.mu / fr.mu_torsion,
        ];
        for j in 0..c.kind.dim() {
            g.set_column(col, &cols[j]);
            f[col] = comps[j];
            col += 1;
        }
    }
    (g, f)
}

/// Smallest cone slack μ f_n − ‖tangential‖ over the contacts, and the
/// largest normal force, of a force vector in variable order.
fn cone_slack(contacts: &[Contact], f: &DVector<f64>, mu: f64) -> (f64, f64) {
    let (mut slack, mut peak) = (f64::INFINITY, 0.0f64);
    let mut off = 0;
    for c in contacts {
        let d = c.kind.dim();
        let t: f64 = (1..d).map(|j| f[off + j] * f[off + j]).sum::<f64>().sqrt();
        slack = slack.min(mu * f[off] - t);
        peak = peak.max(f[off]);
        off += d;
    }
    (slack, peak)
}

fn check_nominal(contacts: &[Contact], out: &[ContactForce], fr: &Friction, load: &Load) {
    let mut f = load.weight;
    let mut t = Vector3::zeros();
    for (c, o) in contacts.iter().zip(out) {
        let n = c.normal.normalize();
        f += o.force;
        t += (n * fr.object_radius).cross(&o.force) - n * o.torsion;
        let normal = -o.force.dot(&n);
        assert!((normal - o.normal).abs() < 1e-9);
        let tangential = (o.force + n * normal).norm();
        let scaled_torsion = o.torsion * fr.mu / fr.mu_torsion;
        let cone = (tangential.powi(2) + scaled_torsion.powi(2)).sqrt();
        assert!(
            cone <= fr.mu * o.normal + 1e-6,
            "cone: {cone} > {}",
            fr.mu * o.normal
        );
        if c.kind == ContactKind::Hard {
            assert_eq!(o.torsion, 0.0);
        }
    }
    assert!(
        f.norm() < 1e-6 && t.norm() < 1e-6,
        "not in equilibrium: {f} {t}"
    );
}

/// A random disturbance inside the configured ball (half on its surface).
fn disturbance(rng: &mut rand_chacha::ChaCha8Rng, size: f64) -> Vector3<f64> {
    let r = if rng.random_bool(0.5) {
        1.0
    } else {
        rng.random_range(0.0f64..1.0).cbrt()
    };
    common::unit(rng) * size * r
}

fn random_grasp(rng: &mut rand_chacha::ChaCha8Rng, soft: bool, theta: f64) -> Vec<Contact> {
    loop {
        if soft {
            let a = common::unit(rng);
            let sep = rng.random_range(2.6..std::f64::consts::PI);
            let b = common::at_angle(rng, &a, sep);
            if fact3_force_closure(&a, &b, theta, 0.05) {
                return vec![Contact::soft(a), Contact::soft(b)];
            }
        } else {
            let p = [common::unit(rng), common::unit(rng), common::unit(rng)];
            if fact4_force_closure(&p[0], &p[1], &p[2], theta)
                || (rng.random_bool(0.5)
                    && closure_margin(
                        &p.map(Contact::hard),
                        &Friction::from_config(&HandConfig::default()),
                    )
                    .unwrap()
                    .t_star
                    .is_some_and(|t| t > 0.02))
            {
                return p.map(Contact::hard).to_vec();
            }
        }
    }
}

fn sweep(seed: u64, soft: bool, torque: f64, grasps: usize) {
    let mut cfg = HandConfig::default();
    cfg.load.disturbance_torque = torque;
    let fr = Friction::from_config(&cfg);
    let load = Load::from_config(&cfg);
    let theta = cfg.model.friction_angle_deg.to_radians();
    let mut rng = common::rng(seed);
    let mut solver = GraspForceSolver::new(fr, load);
    let mut pure = GraspForceSolver::with_tie_break(fr, load, 0.0);
    let (mut worst_hold, mut max_iter, mut max_f) = (f64::INFINITY, 0, 0.0f64);
    for _ in 0..grasps {
        let contacts = random_grasp(&mut rng, soft, theta);
        let mut out = vec![ContactForce::default(); contacts.len()];
        let sol = solver.solve(&contacts, &mut out).unwrap();
        max_iter = max_iter.max(sol.iterations);
        max_f = max_f.max(sol.peak_normal);
        check_nominal(&contacts, &out, &fr, &load);
        // Tie-break costs at most (1 + ε k) on the peak normal force.
        let mut out0 = out.clone();
        let f0 = pure.solve(&contacts, &mut out0).unwrap().peak_normal;
        let k = contacts.len() as f64;
        let eps = gait::grasp::forces::TIE_BREAK;
        assert!(sol.peak_normal <= f0 * (1.0 + eps * k) * (1.0 + 1e-6) + 1e-6);
        assert!(
            f0 <= sol.peak_normal * (1.0 + 1e-6) + 1e-6,
            "pure {f0} vs {}",
            sol.peak_normal
        );
        // Robust under the response model: sampled disturbances of full size.
        let (g, f) = dense(&contacts, &out, &fr);
        let pinv = g.clone().pseudo_inverse(1e-12).unwrap();
        for _ in 0..16 {
            let df = disturbance(&mut rng, load.disturbance_force);
            let dt = disturbance(&mut rng, load.disturbance_torque) / fr.object_radius;
            let dw = DVector::from_column_slice(&[df.x, df.y, df.z, dt.x, dt.y, dt.z]);
            let fd = &f - &pinv * &dw;
            let w = DVector::from_column_slice(&[
                load.weight.x,
                load.weight.y,
                load.weight.z,
                0.0,
                0.0,
                0.0,
            ]);
            assert!(
                (&g * &fd + &w + &dw).norm() < 1e-6,
                "disturbed forces not in equilibrium"
            );
            let (slack, peak) = cone_slack(&contacts, &fd, fr.mu);
            worst_hold = worst_hold.min(slack);
            assert!(
                slack > -1e-6,
                "disturbance ({df}, {dt}) breaks a cone by {slack}"
            );
            assert!(peak <= sol.peak_normal + 1e-6);
        }
    }
    println!(
        "grasp forces ({} contacts, soft={soft}, T_d={torque}): {grasps} grasps, peak normal {max_f:.3} N, \
         worst cone slack {worst_hold:.2e}, max {max_iter} iterations",
        if soft { 2 } else { 3 }
    );
}

#[test]
fn three_hard_contacts_hold_weight_and_disturbance() {
    sweep(11, false, 0.0, 300);
}

#[test]
fn two_soft_contacts_hold_weight_and_disturbance() {
    sweep(12, true, 0.0, 300);
}

#[test]
fn disturbance_torque_is_held_too() {
    sweep(13, false, 0.02, 60);
    sweep(14, true, 0.002, 60);
}

#[test]
fn non_force_closure_grasp_cannot_hold_a_disturbance() {
    let cfg = HandConfig::default();
    let mut solver = GraspForceSolver::new(Friction::from_config(&cfg), Load::from_config(&cfg));
    // Two soft contacts 90° apart are not force-closure.
    let c = [Contact::soft(Vector3::x()), Contact::soft(Vector3::y())];
    let mut out = [ContactForce::default(); 2];
    assert_eq!(solver.solve(&c, &mut out), Err(GraspError::Infeasible));
    let mut short = [ContactForce::default(); 1];
    assert_eq!(solver.solve(&c, &mut short), Err(GraspError::OutputLength));
}
