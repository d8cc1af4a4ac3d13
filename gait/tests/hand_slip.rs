//! I5 no-slip between consecutive states over seeded random steps: exact
//! rolling steps (SPEC §2.3) and rigid motions pass; added slip or, in a
//! two-finger grasp, spin fail by the amount added.

mod common;

use core::f64::consts::PI;

use gait::hand::{Invariant, InvariantChecker};
use gait::{FingerMode, FingerState, HandConfig, HandState};
use nalgebra::{Unit, UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

fn random_state(rng: &mut ChaCha8Rng, c: &HandConfig, grasping: usize) -> HandState {
    let rc = c.model.object_radius + c.model.fingertip_radius;
    let mut s = HandState::paper_start(c);
    s.object = UnitQuaternion::from_scaled_axis(common::unit(rng) * rng.random_range(0.0..PI));
    for (k, f) in s.fingers.iter_mut().enumerate() {
        let off = rng.random_range(0.0..1.0);
        let n = common::at_angle(rng, &f.contact_normal(), off);
        *f = FingerState {
            mode: if k < grasping {
                FingerMode::Grasping
            } else {
                FingerMode::Free
            },
            center: n * if k < grasping { rc } else { rc + 0.02 },
            orientation: UnitQuaternion::from_scaled_axis(
                common::unit(rng) * rng.random_range(0.0..PI),
            ),
            roll: 0.0,
        };
    }
    s
}

/// Rotates the whole hand-object configuration about O (no relative motion).
fn rigid(s: &HandState, rot: &UnitQuaternion<f64>) -> HandState {
    let mut t = *s;
    t.object = rot * s.object;
    for f in &mut t.fingers {
        f.center = rot * f.center;
        f.orientation = rot * f.orientation;
    }
    t
}

/// Finger k rolls on the still object: fingertip turns by `b` about an
/// axis ⊥ n, the contact normal by r b / (R + r) about the same axis.
fn roll(s: &mut HandState, c: &HandConfig, k: usize, axis: Unit<Vector3<f64>>, b: f64) {
    let (big, small) = (c.model.object_radius, c.model.fingertip_radius);
    let a = small * b / (big + small);
    let f = &mut s.fingers[k];
    f.center = UnitQuaternion::from_axis_angle(&axis, a) * f.center;
    f.orientation = UnitQuaternion::from_axis_angle(&axis, b) * f.orientation;
}

#[test]
fn rolling_and_rigid_steps_do_not_slip() {
    let c = HandConfig::default();
    let ch = InvariantChecker::new(&c).unwrap();
    let mut rng = common::rng(31);
    for i in 0..10_000 {
        let grasping = 2 + i % 2;
        let s = random_state(&mut rng, &c, grasping);
        let rot =
            UnitQuaternion::from_scaled_axis(common::unit(&mut rng) * rng.random_range(0.0..0.01));
        let mut t = rigid(&s, &rot);
        let k = rng.random_range(0..grasping);
        let n = t.fingers[k].contact_normal();
        let axis = Unit::new_normalize(common::perpendicular(&mut rng, &n));
        roll(&mut t, &c, k, axis, rng.random_range(-0.02..0.02));
        let r = ch.check_slip(&s, &t).unwrap();
        assert!(r.ok(), "{:?}", r.violations().next());
        for (j, f) in r.fingers.iter().enumerate() {
            assert_eq!(f.is_some(), j < grasping);
            if let Some(f) = f {
                assert_eq!(f.spin.is_some(), grasping == 2);
                assert!((f.arc.slack - c.model.slip_tolerance).abs() < 1e-9, "{f:?}");
            }
        }
    }
}

#[test]
fn added_slip_fails_by_the_amount_added() {
    let c = HandConfig::default();
    let ch = InvariantChecker::new(&c).unwrap();
    let mut rng = common::rng(32);
    let rc = c.model.object_radius + c.model.fingertip_radius;
    let tol = c.model.slip_tolerance;
    for i in 0..10_000 {
        let grasping = 2 + i % 2;
        let s = random_state(&mut rng, &c, grasping);
        let mut t = s;
        let k = rng.random_range(0..grasping);
        let n = t.fingers[k].contact_normal();
        let axis = Unit::new_normalize(common::perpendicular(&mut rng, &n));
        let b = rng.random_range(0.005..0.02);
        roll(&mut t, &c, k, axis, b);
        // Slide the contact further by e without turning the fingertip.
        let e = rng.random_range(0.0..4.0 * tol / rc);
        t.fingers[k].center = UnitQuaternion::from_axis_angle(&axis, e) * t.fingers[k].center;
        let r = ch.check_slip(&s, &t).unwrap();
        let arc = r.fingers[k].unwrap().arc;
        assert!(
            (arc.slack - (tol - e * rc)).abs() < 1e-9,
            "{} vs {}",
            arc.slack,
            tol - e * rc
        );
        assert_eq!(arc.pass, e * rc <= tol + 1e-9);
        if !arc.pass {
            assert!(r.violations().any(|v| v.invariant == Invariant::Slip));
        }
    }
}

#[test]
fn spin_is_forbidden_only_in_two_finger_grasps() {
    let c = HandConfig::default();
    let ch = InvariantChecker::new(&c).unwrap();
    let mut rng = common::rng(33);
    let limit = c.model.slip_tolerance / c.model.fingertip_radius;
    for i in 0..10_000 {
        let grasping = 2 + i % 2;
        let s = random_state(&mut rng, &c, grasping);
        let mut t = s;
        let k = rng.random_range(0..grasping);
        let n = Unit::new_normalize(t.fingers[k].contact_normal());
        let sigma = rng.random_range(-3.0 * limit..3.0 * limit);
        t.fingers[k].orientation =
            UnitQuaternion::from_axis_angle(&n, sigma) * t.fingers[k].orientation;
        let r = ch.check_slip(&s, &t).unwrap();
        let f = r.fingers[k].unwrap();
        assert!(f.arc.pass);
        match f.spin {
            Some(spin) => {
                assert_eq!(grasping, 2);
                assert!((spin.slack - (limit - sigma.abs())).abs() < 1e-9);
                assert_eq!(r.ok(), sigma.abs() <= limit + 1e-9);
            }
            None => assert!(grasping == 3 && r.ok()),
        }
    }
}
