//! The executor's closed-form grip forces (per tick) against the grasp-force
//! SOCP (SPEC §3.3): the closed form is feasible — it balances the load and
//! stays inside every friction cone — and its largest normal force is
//! compared with the SOCP's optimum (reported; bounded).

mod common;

use gait::executor::grip::GripModel;
use gait::grasp::{Contact, ContactForce, Friction, GraspForceSolver, Load};
use gait::planner::geometry::Geometry;
use gait::{FingerMode, FingerState, HandConfig, HandState};
use nalgebra::{UnitQuaternion, Vector3};
use rand::Rng;

fn state_with(normals: &[Vector3<f64>], r: f64) -> HandState {
    let mut fingers = [FingerState {
        mode: FingerMode::Free,
        center: Vector3::new(0.0, 0.0, 1.0),
        orientation: UnitQuaternion::identity(),
        roll: 0.0,
    }; 3];
    for (k, n) in normals.iter().enumerate() {
        fingers[k].mode = FingerMode::Grasping;
        fingers[k].center = n * r;
    }
    HandState {
        object: UnitQuaternion::identity(),
        fingers,
    }
}

/// Checks equilibrium and cones of a closed-form grip; returns its max normal.
fn feasible(cfg: &HandConfig, normals: &[Vector3<f64>], soft: bool) -> Option<f64> {
    let g = GripModel::new(cfg);
    let s = state_with(
        normals,
        cfg.model.object_radius + cfg.model.fingertip_radius,
    );
    let grip = g.grip(&s, &Vector3::zeros());
    if grip.capped {
        return None;
    }
    let r = cfg.model.object_radius;
    let w = Vector3::from(cfg.load.gravity) * cfg.load.object_mass;
    let mut force = w;
    let mut torque = Vector3::zeros();
    for (k, n) in normals.iter().enumerate() {
        let f = grip.force[k];
        force += f;
        torque += (n * r).cross(&f) - n * grip.torsion[k];
        let fn_ = f.dot(&-n);
        let ft = (f + n * fn_).norm();
        let tors = grip.torsion[k] * cfg.mu() / cfg.mu_torsion();
        let cone = if soft { ft.hypot(tors) } else { ft };
        assert!(
            fn_ >= -1e-12 && cone <= cfg.mu() * fn_ * (1.0 + 1e-9) + 1e-12,
            "cone {k}: {cone} vs {}",
            cfg.mu() * fn_
        );
        assert!((grip.normal[k] - fn_).abs() < 1e-9);
    }
    assert!(force.norm() < 1e-9, "net force {force}");
    assert!(torque.norm() < 1e-9, "net torque {torque}");
    Some(
        normals
            .iter()
            .enumerate()
            .map(|(k, _)| grip.normal[k])
            .fold(0.0, f64::max),
    )
}

#[test]
fn closed_form_grip_is_feasible_and_near_the_socp_optimum() {
    let mut cfg = HandConfig::default();
    // The SOCP comparison uses the weight only (no disturbance scenarios).
    cfg.load.disturbance_force = 0.0;
    cfg.load.min_grip = 0.0;
    let geom = Geometry::new(&cfg);
    let friction = Friction {
        mu: cfg.mu(),
        mu_torsion: cfg.mu_torsion(),
        object_radius: cfg.model.object_radius,
    };
    let load = Load {
        weight: Vector3::from(cfg.load.gravity) * cfg.load.object_mass,
        disturbance_force: 0.0,
        disturbance_torque: 0.0,
    };
    let mut socp = GraspForceSolver::with_tie_break(friction, load, 0.0);
    let mut rng = common::rng(5);
    let mut ratios = Vec::new();
    let mut capped = 0;
    for case in 0..2000 {
        let three = case % 2 == 1;
        let normals: Vec<Vector3<f64>> = loop {
            let a = common::unit(&mut rng);
            if three {
                // Around a random great circle, roughly 120° apart.
                let axis = common::perpendicular(&mut rng, &a);
                let v: Vec<_> = (0..3)
                    .map(|i| {
                        let ang = i as f64 * 2.094 + rng.random_range(-0.3..0.3);
                        let q = UnitQuaternion::from_scaled_axis(axis * ang);
                        let tilt = rng.random_range(0.0..0.2);
                        common::at_angle(&mut rng, &(q * a), tilt)
                    })
                    .collect();
                break v;
            }
            let off = rng.random_range(0.0..(std::f64::consts::PI - geom.fc_min_angle));
            let b = common::at_angle(&mut rng, &(-a), off);
            if geom.is_fc_pair(&a, &b) {
                break vec![a, b];
            }
        };
        let Some(closed) = feasible(&cfg, &normals, !three) else {
            capped += 1;
            continue;
        };
        let contacts: Vec<Contact> = normals
            .iter()
            .map(|n| {
                if three {
                    Contact::hard(*n)
                } else {
                    Contact::soft(*n)
                }
            })
            .collect();
        let mut out = vec![ContactForce::default(); contacts.len()];
        if let Ok(sol) = socp.solve(&contacts, &mut out) {
            let best = sol.max_normal;
            assert!(
                closed >= best * (1.0 - 1e-6),
                "closed form below the optimum: {closed} < {best}"
            );
            ratios.push(closed / best);
        }
    }
    ratios.sort_by(f64::total_cmp);
    let n = ratios.len();
    println!(
        "closed form / SOCP max normal force over {n} grasps: median {:.3}, p95 {:.3}, max {:.3}; {capped} capped",
        ratios[n / 2],
        ratios[n * 95 / 100],
        ratios[n - 1]
    );
    assert!(n > 1500);
    assert!(ratios[n / 2] < 1.5, "closed form is far from optimal");
    assert!(
        ratios[n * 95 / 100] < 2.5,
        "closed form tail is far from optimal"
    );
}
