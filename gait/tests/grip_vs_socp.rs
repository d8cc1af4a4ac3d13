//! The closed-form grip forces (`gait::grasp::hold`, used every tick and
//! while planning) against the SOCP of `gait::grasp::forces::LoadSolver`
//! (SPEC §3.3, §1.3 I1'):
//! - the commanded forces balance the weight and the acceleration torque,
//!   lie inside the (reduced) coupled cones and press at least `min_grip`;
//! - the closed form's largest normal force is an upper bound of the exact
//!   F* over the same load scenarios, and close to it (ratios printed and
//!   bounded);
//! - it also bounds F* for disturbances drawn anywhere on the ball of the
//!   configured size (the icosahedron of scenarios contains the ball).

mod common;

use gait::HandConfig;
use gait::grasp::grip::GripModel;
use gait::grasp::{Accel, Contact, Friction, HoldModel, LoadSolver};
use gait::planner::geometry::Geometry;
use gait::{FingerMode, FingerState, HandState};
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

/// The friction the closed form works with: θ reduced by half the
/// force-closure margin, μ_t scaled alike.
fn friction(cfg: &HandConfig) -> Friction {
    Friction::from_config(cfg).reduced(0.5 * cfg.model.fc_margin_deg.to_radians())
}

/// Equilibrium, cones and floor of the commanded (weight-only) grip.
fn check_commanded(cfg: &HandConfig, normals: &[Vector3<f64>], soft: bool, torque: &Vector3<f64>) {
    let g = GripModel::new(cfg);
    let s = state_with(
        normals,
        cfg.model.object_radius + cfg.model.fingertip_radius,
    );
    let grip = g.grip(&s, torque);
    if !grip.feasible {
        return;
    }
    let fr = friction(cfg);
    let r = cfg.model.object_radius;
    let w = Vector3::from(cfg.load.gravity) * cfg.load.object_mass;
    let mut force = w;
    let mut tq = Vector3::zeros();
    for (k, n) in normals.iter().enumerate() {
        let f = grip.force[k];
        force += f;
        tq += (n * r).cross(&f) - n * grip.torsion[k];
        let fn_ = f.dot(&-n);
        let ft = (f + n * fn_).norm();
        let tors = grip.torsion[k] * fr.mu / fr.mu_torsion;
        let cone = if soft { ft.hypot(tors) } else { ft };
        assert!(
            cone <= fr.mu * fn_ * (1.0 + 1e-9) + 1e-12,
            "cone {k}: {cone} vs {}",
            fr.mu * fn_
        );
        assert!(fn_ >= cfg.load.min_grip - 1e-9, "floor {k}: {fn_}");
        assert!((grip.normal[k] - fn_).abs() < 1e-9);
        assert!(fn_ <= grip.peak + 1e-9);
    }
    assert!(force.norm() < 1e-9, "net force {force}");
    assert!((tq - torque).norm() < 1e-9, "net torque {tq} vs {torque}");
}

fn random_pair(rng: &mut rand_chacha::ChaCha8Rng, geom: &Geometry) -> Vec<Vector3<f64>> {
    loop {
        let a = common::unit(rng);
        let off = rng.random_range(0.0..(std::f64::consts::PI - geom.fc_min_angle));
        let b = common::at_angle(rng, &(-a), off);
        if geom.is_fc_pair(&a, &b) {
            return vec![a, b];
        }
    }
}

fn random_triple(rng: &mut rand_chacha::ChaCha8Rng) -> Vec<Vector3<f64>> {
    let a = common::unit(rng);
    let axis = common::perpendicular(rng, &a);
    (0..3)
        .map(|i| {
            let ang = i as f64 * 2.094 + rng.random_range(-0.3..0.3);
            let q = UnitQuaternion::from_scaled_axis(axis * ang);
            let tilt = rng.random_range(0.0..0.2);
            common::at_angle(rng, &(q * a), tilt)
        })
        .collect()
}

fn pct(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() as f64 * p) as usize).min(v.len() - 1)]
}

#[test]
fn closed_form_holds_the_load_and_bounds_the_socp_optimum() {
    let cfg = HandConfig::default();
    let geom = Geometry::new(&cfg);
    let hold = HoldModel::new(&cfg);
    let solver = LoadSolver::new(friction(&cfg));
    let mut rng = common::rng(5);
    let (mut pair_ratio, mut triple_ratio) = (Vec::new(), Vec::new());
    let mut ball_checked = 0;
    for case in 0..1200 {
        let three = case % 3 == 2;
        let normals = if three {
            random_triple(&mut rng)
        } else {
            random_pair(&mut rng, &geom)
        };
        // Rest, or rotating about a random axis at the acceleration limit.
        let accel = if case % 2 == 0 {
            Accel::None
        } else {
            Accel::About {
                axis: common::unit(&mut rng),
                max: cfg.limits.object.acceleration,
            }
        };
        let loads = hold.loads(accel);
        let h = if three {
            hold.triple(&[normals[0], normals[1], normals[2]], &loads)
        } else {
            hold.pair(&[normals[0], normals[1]], &loads)
        };
        let torque = match accel {
            Accel::About { axis, max } => axis * (hold.inertia() * max),
            _ => Vector3::zeros(),
        };
        check_commanded(&cfg, &normals, !three, &torque);
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
        let scenarios: Vec<_> = (0..loads.count()).map(|s| loads.scenario(s)).collect();
        let exact = solver.solve(&contacts, &scenarios, cfg.load.min_grip);
        match exact {
            Ok(sol) if h.max_peak.is_finite() => {
                let f = sol.peak_normal;
                assert!(
                    h.max_peak >= f * (1.0 - 1e-6) - 1e-6,
                    "case {case}: closed form {} below the optimum {f}",
                    h.max_peak
                );
                if three {
                    triple_ratio.push(h.max_peak / f);
                } else {
                    pair_ratio.push(h.max_peak / f);
                }
                // Disturbances anywhere on the ball are bounded too.
                if case % 10 < 2 {
                    let w = hold.weight();
                    let d = cfg.load.disturbance_force;
                    let mut ball: Vec<_> = (0..40)
                        .map(|_| (w + common::unit(&mut rng) * d, torque))
                        .collect();
                    ball.push((w, torque));
                    let f_ball = solver
                        .solve(&contacts, &ball, cfg.load.min_grip)
                        .unwrap()
                        .peak_normal;
                    assert!(
                        f_ball <= h.max_peak * (1.0 + 1e-6) + 1e-6,
                        "case {case}: ball needs {f_ball} > closed form {}",
                        h.max_peak
                    );
                    ball_checked += 1;
                }
            }
            // The closed form claims nothing it cannot construct.
            Ok(_) => {}
            Err(e) => assert!(
                !h.feasible,
                "case {case}: closed form feasible ({}), SOCP {e}",
                h.max_peak
            ),
        }
    }
    let (np, nt) = (pair_ratio.len(), triple_ratio.len());
    let (pm, p95, pmax) = (
        pct(&mut pair_ratio, 0.5),
        pct(&mut pair_ratio, 0.95),
        pct(&mut pair_ratio, 1.0),
    );
    let (tm, t95, tmax) = (
        pct(&mut triple_ratio, 0.5),
        pct(&mut triple_ratio, 0.95),
        pct(&mut triple_ratio, 1.0),
    );
    println!(
        "closed form / SOCP F*: soft pairs (n={np}) median {pm:.4} p95 {p95:.4} max {pmax:.4}; \
         hard triples (n={nt}) median {tm:.3} p95 {t95:.3} max {tmax:.3}; \
         {ball_checked} grasps checked on 40 random disturbances of the ball"
    );
    assert!(np > 600 && nt > 200, "{np} pairs, {nt} triples");
    assert!(pm < 1.10, "pair closed form far from optimal: median {pm}");
    assert!(p95 < 1.5, "pair closed form tail: p95 {p95}");
    assert!(tm < 1.6, "triple closed form far from optimal: median {tm}");
    assert!(t95 < 3.0, "triple closed form tail: p95 {t95}");
}

/// No commanded normal force exceeds `load.max_grip`, not even by the
/// rounding of the cap: a plant refuses a grip above its limit. A heavy
/// object and a low limit make the cap act on most grasps.
#[test]
fn commanded_normals_never_exceed_the_force_limit() {
    let mut cfg = HandConfig::default();
    cfg.load.object_mass = 0.5;
    cfg.load.max_grip = 7.0;
    let geom = Geometry::new(&cfg);
    let g = GripModel::new(&cfg);
    let r = cfg.model.object_radius + cfg.model.fingertip_radius;
    let mut rng = common::rng(0x9_71b);
    let (mut capped, mut at_limit) = (0u32, 0u32);
    for i in 0..4000 {
        let normals = if i % 2 == 0 {
            random_pair(&mut rng, &geom)
        } else {
            random_triple(&mut rng)
        };
        let torque = common::unit(&mut rng) * rng.random_range(0.0..0.02);
        let grip = g.grip(&state_with(&normals, r), &torque);
        capped += u32::from(grip.capped);
        for n in grip.normal {
            assert!(
                n <= cfg.load.max_grip,
                "grip {n:e} N above {} N",
                cfg.load.max_grip
            );
            at_limit += u32::from(n == cfg.load.max_grip);
        }
    }
    eprintln!("4000 grasps: {capped} capped, {at_limit} normals at the limit");
    assert!(capped > 400, "the cap acted on only {capped} grasps");
}
