//! The hand model and invariant check (SPEC §1.3) over seeded random
//! sweeps: verdicts agree with independent oracles (the conic test,
//! constructions with known slack), reports are self-consistent, and the
//! conic path is rare on the states a plan goes through.

mod common;

use core::f64::consts::{FRAC_PI_2, PI};

use gait::grasp::{ConicSolver, Contact};
use gait::hand::{Bound, FcMethod, Invariant, InvariantChecker, StateError, Subject, Unit};
use gait::{FingerMode, FingerState, HandConfig, HandState};
use nalgebra::{Rotation3, Unit as NUnit, UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

fn cfg() -> HandConfig {
    HandConfig::default()
}

/// A fingertip touching at normal `n` with its contact at angle `off`
/// from its pole (towards a random side) and a random roll about the pole.
fn touching(rng: &mut ChaCha8Rng, n: Vector3<f64>, off: f64, roll: f64) -> FingerState {
    let c = cfg();
    let q = UnitQuaternion::rotation_between(&Vector3::z(), &(-n))
        .unwrap_or(UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI));
    // Pole axis a = q e_z = −n; tilt it by `off` so that m is `off` from e_z.
    let side = common::perpendicular(rng, &n);
    let tilt = UnitQuaternion::from_axis_angle(&NUnit::new_normalize(n.cross(&side)), off);
    let spin =
        UnitQuaternion::from_axis_angle(&NUnit::new_normalize(-n), rng.random_range(-PI..PI));
    FingerState {
        mode: FingerMode::Grasping,
        center: n * (c.model.object_radius + c.model.fingertip_radius),
        orientation: tilt * spin * q,
        roll,
    }
}

fn free(p: Vector3<f64>) -> FingerState {
    FingerState {
        mode: FingerMode::Free,
        center: p,
        orientation: UnitQuaternion::identity(),
        roll: 0.0,
    }
}

fn in_cone(rng: &mut ChaCha8Rng, k: usize, max: f64) -> Vector3<f64> {
    let d = HandState::paper_start(&cfg()).fingers[k].contact_normal();
    let a = rng.random_range(0.0..max);
    common::at_angle(rng, &d, a)
}

#[test]
fn paper_start_passes_by_fact4_without_the_conic() {
    let mut ch = InvariantChecker::new(&cfg()).unwrap();
    let s = HandState::paper_start(&cfg());
    let r = ch.check(&s).unwrap();
    assert!(r.ok(), "{:?}", r.first_violation());
    assert_eq!(r.force_closure.method, FcMethod::Fact4);
    assert_eq!(ch.conic_solves(), 0);
    // The paper: three-finger FC but no pair can lift.
    for k in 0..3 {
        assert!(ch.model().lift_slack(&s, k).unwrap() < 0.0);
    }
}

/// Oracle for I1 with margin δ: force closure at θ − δ/2 by the conic
/// test, three hard contacts or any soft pair (SPEC §1.3).
struct Oracle {
    hard: ConicSolver,
    soft: ConicSolver,
}

impl Oracle {
    fn new() -> Self {
        let f = gait::hand::FingertipLimits::new(&cfg())
            .unwrap()
            .margin_friction();
        Self {
            hard: ConicSolver::new(f),
            soft: ConicSolver::new(f),
        }
    }
    /// (verdict, distance of the deciding margins from 0).
    fn pair(&mut self, a: Vector3<f64>, b: Vector3<f64>) -> f64 {
        self.soft
            .margin(&[Contact::soft(a), Contact::soft(b)])
            .unwrap()
            .t_star
            .unwrap_or(-1.0)
    }
    fn triple(&mut self, n: [Vector3<f64>; 3]) -> f64 {
        self.hard
            .margin(&n.map(Contact::hard))
            .unwrap()
            .t_star
            .unwrap_or(-1.0)
    }
}

#[test]
fn force_closure_verdict_matches_the_conic_oracle() {
    let mut rng = common::rng(21);
    let mut ch = InvariantChecker::new(&cfg()).unwrap();
    let mut fast = InvariantChecker::new(&cfg()).unwrap();
    fast.set_conic_fallback(false);
    let mut oracle = Oracle::new();
    let (mut checked, mut by_method) = (0, [0usize; 5]);
    while checked < 10_000 {
        let three = rng.random_bool(0.6);
        // Half the states inside the workspace cones, half anywhere.
        let spread = if rng.random_bool(0.5) { 1.2 } else { PI };
        let n: [Vector3<f64>; 3] = core::array::from_fn(|k| in_cone(&mut rng, k, spread));
        let mut s = HandState::paper_start(&cfg());
        for (f, nk) in s.fingers.iter_mut().zip(n) {
            *f = touching(&mut rng, nk, 0.3, 0.0);
        }
        if !three {
            let lifted = rng.random_range(0..3);
            s.fingers[lifted].mode = FingerMode::Free;
        }
        let (idx, count) = s.grasping();
        let pairs: Vec<f64> = match count {
            2 => vec![oracle.pair(n[idx[0]], n[idx[1]])],
            _ => vec![
                oracle.pair(n[0], n[1]),
                oracle.pair(n[0], n[2]),
                oracle.pair(n[1], n[2]),
            ],
        };
        let tri = if count == 3 {
            oracle.triple(n)
        } else {
            f64::NEG_INFINITY
        };
        // Skip cases within solver precision of a boundary.
        if pairs.iter().chain([&tri]).any(|t| t.abs() < 1e-5) {
            continue;
        }
        let expected = pairs.iter().any(|&t| t > 0.0) || tri > 0.0;
        let fc = ch.force_closure(&s);
        assert_eq!(
            fc.check.pass, expected,
            "{fc:?} pairs {pairs:?} triple {tri}"
        );
        // Without the conic fallback the verdict is the same.
        let quick = fast.force_closure(&s);
        assert_eq!(quick.check.pass, expected, "{quick:?}");
        if fc.check.pass {
            assert_eq!(fc, quick);
        }
        by_method[match fc.method {
            FcMethod::Fact3 { .. } => 0,
            FcMethod::Fact4 => 1,
            FcMethod::Planar => 2,
            FcMethod::Conic => {
                // The conic runs only where no certificate exists.
                assert!(!fc.check.pass);
                3
            }
            _ => 4,
        }] += 1;
        checked += 1;
    }
    println!(
        "I1 vs oracle: {checked} states; passed by Fact 3 {}, Fact 4 {}, planar {}; \
         conic (failing states) {}, other {}",
        by_method[0], by_method[1], by_method[2], by_method[3], by_method[4]
    );
    assert_eq!(by_method[4], 0);
    assert_eq!(fast.conic_solves(), 0);
}

#[test]
fn slacks_match_constructions() {
    let mut rng = common::rng(22);
    let c = cfg();
    let mut ch = InvariantChecker::new(&c).unwrap();
    let m = *ch.model();
    let beta = c.model.workspace_half_angle_deg.to_radians();
    let ws_margin = c.model.workspace_margin_deg.to_radians();
    for _ in 0..10_000 {
        let k = rng.random_range(0..3);
        let alpha = rng.random_range(0.0..1.4);
        let off = rng.random_range(0.0..PI);
        let roll = rng.random_range(-2.0..2.0);
        let n = common::at_angle(&mut rng, &m.base_direction(k), alpha);
        let mut s = HandState::paper_start(&c);
        s.fingers[k] = touching(&mut rng, n, off, roll);
        let r = ch.check(&s).unwrap();
        let f = r.fingers[k];
        assert!((f.workspace.slack - (beta - ws_margin - alpha)).abs() < 1e-9);
        assert_eq!(f.workspace.pass, alpha <= beta - ws_margin + 1e-9);
        assert!((f.hemisphere.unwrap().slack - (FRAC_PI_2 - off)).abs() < 1e-9);
        assert!(
            (f.roll.unwrap().slack - (c.model.roll_limit_deg.to_radians() - roll.abs())).abs()
                < 1e-12
        );
        assert!(f.contact.unwrap().pass);
        // Self-consistency: ok() ⇔ no violations; each verdict follows its slack.
        assert_eq!(r.ok(), r.violations().next().is_none());
        for (_, _, chk) in r.checks() {
            assert!(chk.slack.is_finite());
            if chk.pass {
                assert!(chk.slack >= -gait::hand::SLACK_TOLERANCE);
            }
        }
        // A free finger: shell and direction.
        let h = rng.random_range(-0.02..0.07);
        let dir = common::at_angle(&mut rng, &m.base_direction(k), alpha);
        s.fingers[k] = free(dir * (m.contact_radius() + h));
        let r = ch.check(&s).unwrap();
        let shell = r.fingers[k].shell.unwrap();
        assert_eq!(
            shell.pass,
            h > 0.0 && h <= c.model.free_space_height + 1e-12,
            "{h} {shell:?}"
        );
        assert!((r.fingers[k].workspace.slack - (beta - ws_margin - alpha)).abs() < 1e-9);
        assert!(r.fingers[k].contact.is_none() && r.fingers[k].hemisphere.is_none());
    }
}

#[test]
fn collisions_and_contact_drift_are_reported_with_their_subject() {
    let mut rng = common::rng(23);
    let c = cfg();
    let mut ch = InvariantChecker::new(&c).unwrap();
    let m = *ch.model();
    for _ in 0..5_000 {
        let mut s = HandState::paper_start(&c);
        // Finger 1 next to finger 0 at a random centre distance.
        let gap = rng.random_range(0.15..0.3);
        let p0 = s.fingers[0].center;
        let angle = 2.0 * (gap / (2.0 * m.contact_radius())).asin();
        let n1 = Rotation3::from_axis_angle(&Vector3::z_axis(), angle) * p0.normalize();
        s.fingers[1] = touching(&mut rng, n1, 0.0, 0.0);
        let r = ch.check(&s).unwrap();
        let d = (s.fingers[1].center - p0).norm();
        assert!((r.collisions[0].slack - (d - m.min_fingertip_distance())).abs() < 1e-12);
        let expect = d >= m.min_fingertip_distance() - 1e-9;
        assert_eq!(r.collisions[0].pass, expect);
        if !expect {
            assert!(
                r.violations().any(
                    |v| v.invariant == Invariant::Collision && v.subject == Subject::Pair(0, 1)
                )
            );
        }
        // Radial drift of a grasping finger.
        let drift = rng.random_range(-3e-4..3e-4);
        let mut s = HandState::paper_start(&c);
        s.fingers[2].center *= 1.0 + drift / m.contact_radius();
        let r = ch.check(&s).unwrap();
        let chk = r.fingers[2].contact.unwrap();
        assert!((chk.slack - (c.model.contact_tolerance - drift.abs())).abs() < 1e-12);
        assert_eq!(chk.unit, Unit::Metre);
    }
}

#[test]
fn margin_semantics_fact3_equals_reduced_friction_conic() {
    // Fact 3 with margin δ is force closure at θ − δ/2 (the notion I1 uses
    // for every method).
    let mut rng = common::rng(24);
    let m = gait::hand::FingertipLimits::new(&cfg()).unwrap();
    let mut oracle = Oracle::new();
    let mut n = 0;
    while n < 5_000 {
        let a = common::unit(&mut rng);
        let sep = rng.random_range(2.3..PI);
        let b = common::at_angle(&mut rng, &a, sep);
        let slack = m.pair_fc_slack(&a, &b);
        if slack.abs() < 1e-3 {
            continue;
        }
        assert_eq!(slack > 0.0, oracle.pair(a, b) > 0.0);
        n += 1;
    }
}

#[test]
fn planned_states_never_need_the_conic() {
    // The paper's roll prefix (two fingers move apart along the equator,
    // the third stays) and substitution states (a Fact 3 pair plus a third
    // finger anywhere in its cone) are decided by closed forms.
    let c = cfg();
    let mut ch = InvariantChecker::new(&c).unwrap();
    let mut rng = common::rng(25);
    let eq = |deg: f64| {
        let a = deg.to_radians();
        Vector3::new(a.cos(), a.sin(), 0.0)
    };
    for i in 0..=1000 {
        let spread = 120.0 + 24.0 * f64::from(i) / 1000.0;
        let mut s = HandState::paper_start(&c);
        s.fingers[0] = touching(&mut rng, eq(60.0 - spread / 2.0), 0.0, 0.0);
        s.fingers[1] = touching(&mut rng, eq(60.0 + spread / 2.0), 0.0, 0.0);
        let r = ch.check(&s).unwrap();
        assert!(
            r.force_closure.check.pass,
            "{spread}: {:?}",
            r.force_closure
        );
        // Finger 2 may lift exactly when the pair is past 140° + 2°.
        let lift = ch.model().lift_slack(&s, 2).unwrap();
        assert!((lift - (spread - 142.0).to_radians()).abs() < 1e-9);
    }
    for _ in 0..5_000 {
        let mut s = HandState::paper_start(&c);
        let a = in_cone(&mut rng, 0, 0.9);
        let sep = rng.random_range(2.5..PI);
        let b = common::at_angle(&mut rng, &(-a), PI - sep);
        s.fingers[0] = touching(&mut rng, a, 0.0, 0.0);
        s.fingers[1] = touching(&mut rng, b, 0.0, 0.0);
        let third = in_cone(&mut rng, 2, 1.0);
        s.fingers[2] = touching(&mut rng, third, 0.0, 0.0);
        let r = ch.check(&s).unwrap();
        assert!(r.force_closure.check.pass);
    }
    assert_eq!(ch.conic_solves(), 0);
}

#[test]
fn reports_are_deterministic_across_histories() {
    let c = cfg();
    let mut rng = common::rng(26);
    let mut fresh = InvariantChecker::new(&c).unwrap();
    let mut used = InvariantChecker::new(&c).unwrap();
    let states: Vec<HandState> = (0..300)
        .map(|_| {
            let mut s = HandState::paper_start(&c);
            for k in 0..3 {
                let n = in_cone(&mut rng, k, 1.3);
                s.fingers[k] = touching(&mut rng, n, 0.4, 0.1);
            }
            s
        })
        .collect();
    for s in states.iter().rev() {
        used.check(s).unwrap();
    }
    for s in &states {
        let (a, b) = (fresh.check(s).unwrap(), used.check(s).unwrap());
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }
}

#[test]
fn bad_states_are_errors_not_panics() {
    let c = cfg();
    let mut ch = InvariantChecker::new(&c).unwrap();
    let mut s = HandState::paper_start(&c);
    s.fingers[1].roll = f64::NAN;
    assert_eq!(ch.check(&s), Err(StateError::FingerNotFinite { finger: 1 }));
    let mut s = HandState::paper_start(&c);
    s.fingers[2].center = Vector3::zeros();
    assert_eq!(ch.check(&s), Err(StateError::CentreAtOrigin { finger: 2 }));
    let mut s = HandState::paper_start(&c);
    s.object =
        UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(f64::INFINITY, 0.0, 0.0, 0.0));
    assert_eq!(ch.check(&s), Err(StateError::ObjectNotFinite));
    // One grasping finger: I1 fails by the missing contact.
    let mut s = HandState::paper_start(&c);
    s.fingers[0].mode = FingerMode::Free;
    s.fingers[1].mode = FingerMode::Free;
    let r = ch.check(&s).unwrap();
    assert_eq!(r.force_closure.method, FcMethod::TooFewContacts);
    assert_eq!(
        r.first_violation().unwrap().invariant,
        Invariant::ForceClosure
    );
    // Bound::Margin is tighter than Bound::Limit.
    let m = ch.model();
    assert!(m.roll_slack(0.5, Bound::Margin) < m.roll_slack(0.5, Bound::Limit));
}
