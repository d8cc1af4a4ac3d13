//! A TriFingerPro grasp of the shipped tennis ball against the torque box
//! (SPEC §14.1 "Forces"): the solver's forces hold every load within the
//! friction cones and every motor's limit, checked by the test's own
//! statics (the contact point's Jacobian from the chain's frames, not the
//! solver's J_v + r [n]ₓ J_ω), and the answer agrees with the hand's
//! README: the ball holds with room to spare, ten times its mass does not.
//! And the pairs: which two-finger grasps of the ball hold it at rest, the
//! question finger gaiting on a chain hand stands on.

use gait::grasp::{Contact, FingerStatics, Friction, TorqueBoxSolver};
use kinematics::{
    Chain, ClosedFormIk, FingerGap, HandDescription, Margins, Workspace, gravity_torques, reach,
    sphere_grid,
};
use nalgebra::Vector3;

const URDF: &str = include_str!("../../deploy/hands/trifingerpro/trifingerpro.urdf");
const SECTION: &str = include_str!("../../deploy/hands/trifingerpro/hand.toml");

struct Grasp {
    chains: Vec<Chain<3>>,
    q: Vec<Vector3<f64>>,
    normals: Vec<Vector3<f64>>,
    hand: HandDescription,
}

/// The shipped description and its three chains.
fn shipped() -> (HandDescription, Vec<Chain<3>>) {
    let hand = HandDescription::parse(URDF, SECTION).unwrap();
    let chains = hand
        .fingers
        .iter()
        .map(|f| Chain::from_description(f, hand.joint_limit_margin).unwrap())
        .collect();
    (hand, chains)
}

/// Each finger on the ball's equator at its azimuth (finger 0 at 75°, the
/// others turned with their fingers: the README's grasp).
fn equator_grasp() -> Grasp {
    let (hand, chains) = shipped();
    let margins = Margins {
        patch: 0.0,
        clearance: 0.0,
    };
    let mut q = Vec::new();
    let mut normals = Vec::new();
    for (k, c) in chains.iter().enumerate() {
        let az = (75.0 - 120.0 * k as f64).to_radians();
        let n = Vector3::new(az.cos(), az.sin(), 0.0);
        let ik = ClosedFormIk::new(c).unwrap();
        let r = reach(c, &ik, &hand.object, &hand.gravity, &n, &margins).expect("reached");
        q.push(r.q);
        normals.push(n);
    }
    Grasp {
        chains,
        q,
        normals,
        hand,
    }
}

fn statics(g: &Grasp) -> Vec<FingerStatics> {
    g.chains
        .iter()
        .zip(&g.q)
        .zip(&g.normals)
        .map(|((c, q), n)| finger_statics(c, q, n, &g.hand.gravity))
        .collect()
}

/// The solver's input for finger `c` at `q` touching at `n`.
fn finger_statics(
    c: &Chain<3>,
    q: &Vector3<f64>,
    n: &Vector3<f64>,
    gravity: &Vector3<f64>,
) -> FingerStatics {
    let s = c.forward(q);
    let jv = s.jacobian_v();
    let jw = s.jacobian_w();
    let jp = jv + n.cross_matrix() * jw * c.tip_radius;
    FingerStatics {
        force_to_torque: jp.transpose(),
        moment_to_torque: jw.transpose(),
        bias: gravity_torques(c, &s, gravity),
        limit: c.effort(),
    }
}

fn friction(g: &Grasp) -> Friction {
    Friction {
        mu: g.hand.friction.mu,
        mu_torsion: g.hand.friction.torsion,
        object_radius: g.hand.object.radius,
    }
}

/// The largest |τ_j| / τ_max,j of forces (F, M) per finger, by the test's
/// own statics: the contact point's Jacobian from the chain's frames.
fn utilisation(g: &Grasp, forces: &[(Vector3<f64>, Vector3<f64>)]) -> f64 {
    let mut u: f64 = 0.0;
    for (k, (c, q)) in g.chains.iter().zip(&g.q).enumerate() {
        let s = c.forward(q);
        let p = g.hand.object.centre + g.normals[k] * g.hand.object.radius;
        let jp = s.point_jacobian(&p, 3);
        let (f, m) = forces[k];
        let tau = jp.transpose() * f
            + s.jacobian_w().transpose() * m
            + gravity_torques(c, &s, &g.hand.gravity);
        for j in 0..3 {
            u = u.max(tau[j].abs() / c.limits[j].effort);
        }
    }
    u
}

#[test]
fn the_tennis_ball_holds_within_the_torque_box_and_ten_times_it_does_not() {
    let g = equator_grasp();
    let fr = friction(&g);
    let contacts: Vec<Contact> = g.normals.iter().map(|n| Contact::soft(*n)).collect();
    let solver = TorqueBoxSolver::new(fr);
    let weight = g.hand.gravity * g.hand.object.mass;
    let mut shares = Vec::new();
    for scale in [1.0, 10.0] {
        let load = [(weight * scale, Vector3::zeros())];
        let sol = solver.solve(&contacts, &statics(&g), &load, 0.0).unwrap();
        let f = &sol.forces[0];
        // Balance: the contacts carry the weight, no net torque.
        let sum: Vector3<f64> = f.iter().map(|(f, _)| f).sum();
        let torque: Vector3<f64> = f
            .iter()
            .zip(&g.normals)
            .map(|((f, m), n)| (n * g.hand.object.radius).cross(f) + m)
            .sum();
        assert!((sum + weight * scale).norm() < 1e-6, "forces {sum:?}");
        assert!(torque.norm() < 1e-7, "torque {torque:?}");
        // Friction: each contact inside its soft cone.
        for ((f, m), n) in f.iter().zip(&g.normals) {
            let fn_ = -f.dot(n);
            let ft = (f + n * fn_).norm();
            let spin = m.norm() * fr.mu / fr.mu_torsion;
            assert!(fn_ >= -1e-9, "pulls: {fn_}");
            assert!(
                (ft * ft + spin * spin).sqrt() <= fr.mu * fn_ + 1e-6,
                "outside the cone: {ft} {spin} vs μ {fn_}"
            );
        }
        let own = utilisation(&g, f);
        assert!(
            (own - sol.utilisation).abs() < 1e-5,
            "torque share: the solver's {} and the test's statics' {own}",
            sol.utilisation
        );
        shares.push(sol.utilisation);
    }
    // A hand-built solution (the README's): each tip presses W/(3μ) and
    // carries W/3 upwards. The optimum can only be better.
    let w = weight.norm();
    let hand_built: Vec<_> = g
        .normals
        .iter()
        .map(|n| (-n * (w / (3.0 * fr.mu)) - weight / 3.0, Vector3::zeros()))
        .collect();
    let built = utilisation(&g, &hand_built);
    eprintln!(
        "tennis ball on the equator: torque share u* {:.3} (hand-built forces {built:.3}); ten times the mass: {:.3}",
        shares[0], shares[1]
    );
    assert!(
        shares[0] <= built + 1e-6,
        "u* {} above a feasible {built}",
        shares[0]
    );
    // The README: the motors can push 7.4 times the force the ball needs.
    assert!(shares[0] < 0.5, "the ball needs {} of the box", shares[0]);
    assert!(shares[1] > 1.0, "ten times the ball fits: {}", shares[1]);
}

/// Two fingers of three on the ball: every pair of workspace normals
/// (5° inside the tip patch, 5 mm of link clearance, the fingers 5 mm
/// apart) that is force-closure as a soft pair (Fact 3: more than
/// π − 2·atan μ apart, here with 2° to spare), asked whether it holds the
/// ball's weight within the torque box. Printed: how many do, and the
/// least share; asserted: some pair of every finger pair holds (finger
/// gaiting needs them), and each held verdict's forces pass the test's own
/// statics.
#[test]
fn two_fingers_hold_the_tennis_ball() {
    let (hand, chains) = shipped();
    let margins = Margins {
        patch: 5f64.to_radians(),
        clearance: 0.005,
    };
    let grid = sphere_grid(400);
    let ws: Vec<Workspace> = chains
        .iter()
        .map(|c| {
            let ik = ClosedFormIk::new(c).unwrap();
            Workspace::new(c, &ik, &hand.object, &hand.gravity, &grid, &margins)
        })
        .collect();
    let fr = Friction {
        mu: hand.friction.mu,
        mu_torsion: hand.friction.torsion,
        object_radius: hand.object.radius,
    };
    let apart = std::f64::consts::PI - 2.0 * fr.mu.atan() + 2f64.to_radians();
    let solver = TorqueBoxSolver::new(fr);
    let weight = hand.gravity * hand.object.mass;
    let load = [(weight, Vector3::zeros())];
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let gap = FingerGap::new(&chains[a], &chains[b]);
        let (mut closure, mut held, mut best) = (0, 0, f64::INFINITY);
        for (na, ra) in &ws[a].reached {
            let sa = chains[a].forward(&ra.q);
            for (nb, rb) in &ws[b].reached {
                if na.angle(nb) <= apart {
                    continue;
                }
                let sb = chains[b].forward(&rb.q);
                if gap.gap((&chains[a], &sa), (&chains[b], &sb)) < 0.005 {
                    continue;
                }
                closure += 1;
                let contacts = [Contact::soft(*na), Contact::soft(*nb)];
                let fingers = [
                    finger_statics(&chains[a], &ra.q, na, &hand.gravity),
                    finger_statics(&chains[b], &rb.q, nb, &hand.gravity),
                ];
                let Ok(sol) = solver.solve(&contacts, &fingers, &load, 0.0) else {
                    continue;
                };
                best = best.min(sol.utilisation);
                if sol.utilisation > 1.0 {
                    continue;
                }
                held += 1;
                let g = Grasp {
                    chains: vec![chains[a], chains[b]],
                    q: vec![ra.q, rb.q],
                    normals: vec![*na, *nb],
                    hand: hand.clone(),
                };
                let own = utilisation(&g, &sol.forces[0]);
                assert!(
                    own <= 1.0 + 1e-6,
                    "fingers {a},{b}: held by the solver, {own} of the box by the test's statics"
                );
                let sum: Vector3<f64> = sol.forces[0].iter().map(|(f, _)| f).sum();
                assert!((sum + weight).norm() < 1e-6, "unbalanced: {sum:?}");
            }
        }
        eprintln!(
            "fingers {a} and {b}: {closure} force-closure pairs clear of each other, {held} hold the ball within the torque box (least share {best:.3})"
        );
        assert!(held > 0, "no pair of fingers {a} and {b} holds the ball");
    }
}
