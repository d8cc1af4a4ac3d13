//! Shared helpers of the integration tests.
#![allow(dead_code)]

pub mod load;
pub mod plan_load;
pub mod verify;

use gait::planner::geometry::{Geometry, rotation, swing};
use gait::{FingerMode, FingerState, HandConfig, HandState};
use nalgebra::Vector3;
use rand::Rng;

// Each test binary uses some of these only.
#[allow(unused_imports)]
pub use test_support::random::{haar, unit};

/// A random unit vector within `angle` of `axis`.
pub fn in_cap(rng: &mut impl Rng, axis: &Vector3<f64>, angle: f64) -> Vector3<f64> {
    loop {
        let u = unit(rng);
        if u.dot(axis) >= angle.cos() {
            return u;
        }
    }
}

/// A random valid two-finger state (SPEC §1.3): a force-closure pair with
/// margin holding the configured load at rest (I1'), contacts anywhere in
/// the cones, fingertip contacts anywhere in a cap around the pole (as
/// rolling leaves them), rolls anywhere within the limit, the free finger
/// anywhere in its free-space shell; random object orientation.
pub fn random_two_finger_state(rng: &mut impl Rng, cfg: &HandConfig) -> HandState {
    let g = Geometry::new(cfg);
    let m = &cfg.model;
    loop {
        let pair_first: usize = rng.random_range(0..3);
        let pair = [pair_first, (pair_first + 1 + rng.random_range(0..2)) % 3];
        let free = (0..3).find(|k| !pair.contains(k)).unwrap();
        let mut fingers = [FingerState {
            mode: FingerMode::Free,
            center: Vector3::zeros(),
            orientation: nalgebra::UnitQuaternion::identity(),
            roll: 0.0,
        }; 3];
        for &k in &pair {
            let n = in_cap(rng, &g.base[k], g.cone_half_angle);
            let mc = in_cap(rng, &Vector3::z(), 70f64.to_radians());
            let q0 = swing(&mc, &(-n));
            fingers[k] = FingerState {
                mode: FingerMode::Grasping,
                center: n * g.contact_radius,
                orientation: rotation(&n, rng.random_range(0.0..std::f64::consts::TAU)) * q0,
                roll: rng.random_range(-g.roll_limit..g.roll_limit),
            };
        }
        let u = in_cap(rng, &g.base[free], g.cone_half_angle);
        let rho = g.contact_radius + rng.random_range(0.05..1.0) * m.free_space_height;
        fingers[free] = FingerState {
            mode: FingerMode::Free,
            center: u * rho,
            orientation: haar(rng),
            roll: rng.random_range(-g.roll_limit..g.roll_limit),
        };
        let s = HandState {
            object: haar(rng),
            fingers,
        };
        let (a, b) = (
            s.fingers[pair[0]].contact_normal(),
            s.fingers[pair[1]].contact_normal(),
        );
        if !g.is_fc_pair(&a, &b) {
            continue;
        }
        let clear = (0..3).all(|i| {
            (i + 1..3).all(|j| {
                (s.fingers[i].center - s.fingers[j].center).norm() >= g.min_center_distance + 1e-6
            })
        });
        // Valid includes holding the load (SPEC §1.3 I1') at rest.
        if clear
            && gait::grasp::grip::GripModel::new(cfg)
                .grip(&s, &Vector3::zeros())
                .feasible
        {
            return s;
        }
    }
}
pub mod run;

/// The default configuration with a weightless object and no
/// disturbance: no load to hold, so the planner only has the kinematic
/// invariants (SPEC §1.3 I1–I5) — the regime the kinematic sweeps and the
/// lifecycle tests check. Holding against gravity (I1') is checked by
/// `planner_load.rs` and `executor_load.rs`.
pub fn weightless() -> gait::HandConfig {
    let mut cfg = gait::HandConfig::default();
    cfg.load.object_mass = 0.0;
    cfg.load.disturbance_force = 0.0;
    cfg
}

/// Whether a step of `plan` spins a fingertip while all three fingers
/// grasp (the unwind under load, SPEC §1.3 I1').
pub fn spins_in_a_triple(plan: &gait::planner::Plan) -> bool {
    plan.steps.iter().any(|st| {
        matches!(st.motion, gait::planner::Motion::RollSegment { segment, .. }
            if segment.kind == gait::rolling::SegmentKind::Spin)
            && st
                .start
                .fingers
                .iter()
                .all(|f| f.mode == gait::FingerMode::Grasping)
    })
}

/// `f(i)` for every `i` in `0..n`, on two threads (interleaved, so both get
/// a share of the slow cases); results in index order. A panic in `f`
/// fails the caller.
pub fn on_two_threads<R: Send>(n: usize, f: impl Fn(usize) -> R + Sync) -> Vec<R> {
    std::thread::scope(|sc| {
        let f = &f;
        let part =
            |k: usize| sc.spawn(move || (k..n).step_by(2).map(|i| (i, f(i))).collect::<Vec<_>>());
        let (a, b) = (part(0), part(1));
        let mut all = a.join().unwrap();
        all.extend(b.join().unwrap());
        all.sort_by_key(|(i, _)| *i);
        all.into_iter().map(|(_, r)| r).collect()
    })
}

/// A hand state with the three tips of `chains` where the joints `q` put
/// them, grasping (relative to the ball's centre, as the planner's states
/// are).
pub fn chain_state(
    chains: &[kinematics::Chain<3>; 3],
    q: &[Vector3<f64>; 3],
    o: &kinematics::Object,
) -> HandState {
    let mut s = HandState::paper_start(&HandConfig::default());
    for k in 0..3 {
        s.fingers[k].mode = FingerMode::Grasping;
        s.fingers[k].center = chains[k].forward(&q[k]).tip_centre() - o.centre;
    }
    s
}
