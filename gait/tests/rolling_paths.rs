//! Rolling paths (SPEC §2.4): exact evaluation against the integrated
//! contact kinematics, the Fig. 2 path against an independent closed-form
//! composition, repetition beyond one path's reach, and planner sweeps
//! checking the hemisphere and roll invariants.

mod common;

use gait::HandConfig;
use gait::contact::{BodyRates, ContactGeometry, ContactState, RelativeContact, VectorIntegrator};
use gait::rolling::{
    MAX_SEGMENTS, RollGoal, RollLimits, RollPlanError, RollingPath, SegmentKind, Turn, fig2_reach,
    plan_roll,
};
use nalgebra::{UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{FRAC_PI_2, PI};

fn geom() -> ContactGeometry {
    ContactGeometry::from_config(&HandConfig::default())
}

fn limits(allow_spin: bool) -> RollLimits {
    RollLimits::from_config(&HandConfig::default(), allow_spin)
}

/// Random contact with the fingertip contact `m` (object frame view).
fn contact_with(rng: &mut ChaCha8Rng, m: &Vector3<f64>, roll: f64) -> RelativeContact {
    let n = common::unit(rng);
    RelativeContact {
        contact: n,
        fingertip: common::touching(rng, &n, m),
        roll,
    }
}

/// Independent oracle: walk three geodesic arcs with two 90° turns on the
/// unit sphere (X' = X cos φ + t sin φ, t' = −X sin φ + t cos φ; a left
/// turn maps t to X × t).
fn compose(
    start: &Vector3<f64>,
    heading: &Vector3<f64>,
    legs: [f64; 3],
    left: bool,
) -> Vector3<f64> {
    let (mut x, mut t) = (*start, heading.normalize());
    for (i, phi) in legs.iter().enumerate() {
        let (s, c) = phi.sin_cos();
        (x, t) = (x * c + t * s, -x * s + t * c);
        if i < 2 {
            t = if left { x.cross(&t) } else { t.cross(&x) };
        }
    }
    x
}

/// Drives the vector-form integrator (exact constant-rate steps) with the
/// path's own angular velocity and compares it with `eval` along the way.
fn replay_matches_eval(path: &RollingPath, object: UnitQuaternion<f64>) -> f64 {
    let g = *path.geometry();
    let mut vi = VectorIntegrator::new(g, ContactState::from_relative(path.start(), object));
    let mut worst: f64 = 0.0;
    for (i, seg) in path.segments().iter().enumerate() {
        let (s0, s1) = path.segment_range(i).unwrap();
        let n = 17;
        let rates = BodyRates {
            object: Vector3::zeros(),
            fingertip: object * seg.axis,
            slip: Vector3::zeros(),
        };
        for j in 1..=n {
            vi.advance_constant(&rates, (s1 - s0) / n as f64);
            let e = path.eval(s0 + (s1 - s0) * j as f64 / n as f64);
            let st = ContactState::from_relative(
                &RelativeContact {
                    contact: e.contact,
                    fingertip: e.fingertip,
                    roll: e.roll,
                },
                object,
            );
            worst = worst
                .max((st.normal - vi.state.normal).norm())
                .max(st.fingertip.angle_to(&vi.state.fingertip))
                .max((st.roll - vi.state.roll).abs());
        }
    }
    // Arc lengths: equal on both bodies and equal to the path's.
    worst = worst.max((vi.arc_object - vi.arc_fingertip).abs());
    worst.max((vi.arc_object - path.arc_length()).abs())
}

#[test]
fn eval_derivatives_match_finite_differences() {
    let g = geom();
    let mut rng = common::rng(100);
    for _ in 0..300 {
        let m = common::hemisphere_point(&mut rng);
        let tau0 = rng.random_range(-0.5..0.5);
        let start = contact_with(&mut rng, &m, tau0);
        let mut path = RollingPath::new(g, start);
        for _ in 0..4 {
            let n = path.end().contact;
            if rng.random_bool(0.7) {
                let d = common::unit(&mut rng);
                path.push_roll(&(d - n * n.dot(&d)), rng.random_range(0.01..0.3))
                    .unwrap();
            } else {
                path.push_spin(rng.random_range(-1.0..1.0)).unwrap();
            }
        }
        for _ in 0..20 {
            let i = rng.random_range(0..path.len());
            let (a, b) = path.segment_range(i).unwrap();
            let s = rng.random_range(a + 1e-3..b - 1e-3);
            let h = 1e-6;
            let (p, lo, hi) = (path.eval(s), path.eval(s - h), path.eval(s + h));
            assert_eq!(p.segment, i);
            let fd = |x: Vector3<f64>, y: Vector3<f64>| (y - x) / (2.0 * h);
            assert!((fd(lo.contact, hi.contact) - p.d_contact).norm() < 1e-8);
            assert!(
                (fd(lo.fingertip_contact, hi.fingertip_contact) - p.d_fingertip_contact).norm()
                    < 1e-8
            );
            assert!(((hi.roll - lo.roll) / (2.0 * h) - p.d_roll).abs() < 1e-8);
            assert!(((hi.arc - lo.arc) / (2.0 * h) - p.d_arc).abs() < 1e-8);
            let w = (hi.fingertip * lo.fingertip.inverse()).scaled_axis() / (2.0 * h);
            assert!((w - p.omega).norm() < 1e-8);
            assert!((p.delta * path.start().fingertip).angle_to(&p.fingertip) < 1e-14);
            if p.kind == SegmentKind::Spin {
                assert_eq!(p.d_arc, 0.0);
                assert!(p.d_contact.norm() < 1e-15);
            }
        }
    }
}

#[test]
fn fig2_path_returns_to_the_pole_with_the_exact_roll_and_lands_on_the_oracle() {
    let g = geom();
    let (big, small) = (g.object_radius, g.fingertip_radius);
    let mut rng = common::rng(200);
    let usable = limits(false).usable();
    for _ in 0..2000 {
        let tau0 = rng.random_range(-usable..usable);
        let start = contact_with(&mut rng, &Vector3::z(), tau0);
        let turn = if rng.random_bool(0.5) {
            Turn::Left
        } else {
            Turn::Right
        };
        let budget = rng.random_range(0.0..2.0 * usable);
        let n = start.contact;
        let d = common::unit(&mut rng);
        let heading = (d - n * n.dot(&d)).normalize();
        let mut path = RollingPath::new(g, start);
        let change = path.push_fig2(&heading, turn, budget).unwrap();
        let end = path.end();
        // Fingertip contact back at its pole; roll changed by exactly ±budget.
        assert!((end.fingertip_contact() - Vector3::z()).norm() < 1e-12);
        assert!(
            (change - turn.sign() * budget).abs() < 1e-12,
            "{change} {budget}"
        );
        assert!((end.roll - tau0 - turn.sign() * budget).abs() < 1e-12);
        // Object contact: legs (π/2) r/R, base Δτ·r/(R+r), two 90° turns.
        let a = FRAC_PI_2 * small / big;
        let b = budget * small / (big + small);
        let oracle = compose(&n, &heading, [a, b, a], turn == Turn::Left);
        assert!((end.contact - oracle).norm() < 1e-9);
        // Arc lengths: r π/2, Δτ·rR/(R+r), r π/2 on each body.
        let arc = 2.0 * small * FRAC_PI_2 + budget * small * big / (big + small);
        assert!((path.arc_length() - arc).abs() < 1e-12);
        // The hemisphere is kept (the equator leg runs on its boundary).
        assert!(path.margins().min_hemisphere > -1e-12);
        assert!(replay_matches_eval(&path, common::rotation(&mut rng)) < 1e-12);
    }
}

#[test]
fn papers_equator_arc_gamma_r_overshoots_the_roll() {
    // SPEC §2.4: rolling on a sphere, an equator arc of γr changes the roll
    // by γ(R + r)/R = 72° at γ = 60°; γ·rR/(R + r) gives exactly γ.
    let g = geom();
    let (big, small) = (g.object_radius, g.fingertip_radius);
    let gamma = 60f64.to_radians();
    let mut rng = common::rng(210);
    let start = contact_with(&mut rng, &Vector3::z(), 0.0);
    let mut p = RollingPath::new(g, start);
    let n = start.contact;
    let d = common::unit(&mut rng);
    p.push_roll(&(d - n * n.dot(&d)), FRAC_PI_2 * small / big)
        .unwrap();
    // Equator leg: axis along the pole axis (now tangent to the object).
    let after = *p.end();
    let k = after.pole_axis();
    for (arc, want) in [
        (gamma * small, 72.0),
        (gamma * small * big / (big + small), 60.0),
    ] {
        let mut q = p.clone();
        q.push_roll(&k.cross(&after.contact), arc / big).unwrap();
        let roll = (q.end().roll - after.roll).to_degrees();
        assert!((roll - want).abs() < 1e-9, "{roll} vs {want}");
    }
}

#[test]
fn fig2_to_lands_exactly_on_any_target_within_reach() {
    let g = geom();
    let mut rng = common::rng(300);
    let reach_max = fig2_reach(&g, 1e9);
    for _ in 0..3000 {
        let start = contact_with(&mut rng, &Vector3::z(), 0.0);
        let n = start.contact;
        let dist = rng.random_range(0.0..reach_max * 0.999);
        let d = common::unit(&mut rng);
        let axis = n.cross(&d).normalize();
        let target = UnitQuaternion::from_scaled_axis(axis * dist) * n;
        for turn in [Turn::Left, Turn::Right] {
            let mut path = RollingPath::new(g, start);
            let change = path.push_fig2_to(&target, turn).unwrap();
            assert!((path.end().contact - target).norm() < 1e-12);
            assert!((path.end().fingertip_contact() - Vector3::z()).norm() < 1e-12);
            assert_eq!(change.signum(), turn.sign());
            assert!((fig2_reach(&g, change) - dist).abs() < 1e-12);
        }
    }
}

/// Checks a planned path densely and at its waypoints.
fn check_plan(path: &RollingPath, start: &RelativeContact, goal: &RollGoal, lim: &RollLimits) {
    let bound = lim.usable().max(start.roll.abs()) + 1e-12;
    assert!((path.end().contact - goal.target).norm() < 1e-9);
    assert_eq!(path.start(), start);
    let m = path.margins();
    assert!(m.min_hemisphere >= -1e-9, "{m:?}");
    assert!(m.max_abs_roll <= bound, "{m:?}");
    if let Some(r) = goal.final_roll {
        assert!((path.end().roll - r).abs() < 1e-9);
    }
    for (i, seg) in path.segments().iter().enumerate() {
        if seg.kind == SegmentKind::Spin {
            assert!(lim.allow_spin, "spin in a no-spin plan");
        }
        let (a, b) = path.segment_range(i).unwrap();
        for j in 0..=16 {
            let e = path.eval(a + (b - a) * j as f64 / 16.0);
            assert!(e.fingertip_contact.z >= -1e-9);
            assert!(e.roll.abs() <= bound);
            assert!(e.d_contact.dot(&e.contact).abs() < 1e-12);
        }
    }
}

#[test]
fn planner_reaches_random_targets_within_the_limits() {
    let g = geom();
    let mut rng = common::rng(400);
    let mut fig2_paths = 0;
    for trial in 0..3000 {
        let allow_spin = trial % 3 == 0;
        let lim = limits(allow_spin);
        let m = common::hemisphere_point(&mut rng);
        let tau0 = rng.random_range(-lim.usable()..lim.usable());
        let start = contact_with(&mut rng, &m, tau0);
        let target = common::unit(&mut rng);
        let final_roll =
            (allow_spin && trial % 2 == 0).then(|| rng.random_range(-lim.usable()..lim.usable()));
        let goal = RollGoal { target, final_roll };
        let path = plan_roll(&g, &start, &goal, &lim).unwrap();
        check_plan(&path, &start, &goal, &lim);
        fig2_paths += (path.len() >= 4) as usize;
        // Deterministic, bit for bit.
        assert_eq!(plan_roll(&g, &start, &goal, &lim).unwrap(), path);
    }
    assert!(fig2_paths > 1000);
}

#[test]
fn repeated_fig2_paths_reach_beyond_one_paths_reach() {
    // From the pole with τ = 0, reposition-free: a direct roll reaches
    // a = (π/2) r/R, one Fig. 2 path plus the closing roll a + reach(γ−m).
    // Targets beyond that need the repetition of paper Fig. 3.
    let g = geom();
    let lim = limits(false);
    let a = FRAC_PI_2 * g.fingertip_radius / g.object_radius;
    let one = a + fig2_reach(&g, lim.usable());
    let mut rng = common::rng(500);
    for _ in 0..500 {
        let start = contact_with(&mut rng, &Vector3::z(), 0.0);
        let n = start.contact;
        let dist = rng.random_range(one + 1e-3..PI);
        let d = common::unit(&mut rng);
        let target = UnitQuaternion::from_scaled_axis(n.cross(&d).normalize() * dist) * n;
        let goal = RollGoal {
            target,
            final_roll: None,
        };
        let path = plan_roll(&g, &start, &goal, &lim).unwrap();
        check_plan(&path, &start, &goal, &lim);
        // Fig. 2 paths come in threes, plus the closing roll.
        let paths = (path.len() - 1) / 3;
        assert!(paths >= 2, "{} segments for {dist}", path.len());
        assert_eq!(path.len(), 3 * paths + 1);
        assert!(path.segments().iter().all(|s| s.kind == SegmentKind::Roll));
        // Every pole visit is exact, and each path turns against the roll
        // it starts with: the roll is unwound for free, without spin.
        let mut prev = 0.0f64;
        for k in 0..paths {
            let w = &path.waypoints()[3 * (k + 1)];
            assert!((w.contact.fingertip_contact() - Vector3::z()).norm() < 1e-9);
            assert!((w.contact.roll - prev) * prev <= 0.0, "must turn against τ");
            prev = w.contact.roll;
        }
    }
}

#[test]
fn spin_unwinding_repeats_the_papers_fig3() {
    // Paper Fig. 3: Fig. 2 path, spin the roll back, same path again.
    let g = geom();
    let lim = limits(true);
    let mut rng = common::rng(600);
    for _ in 0..300 {
        let start = contact_with(&mut rng, &Vector3::z(), 0.0);
        let n = start.contact;
        let d = common::unit(&mut rng);
        let dir = (d - n * n.dot(&d)).normalize();
        let mut path = RollingPath::new(g, start);
        let axis = n.cross(&dir);
        let step = fig2_reach(&g, lim.usable());
        for k in 1..=3 {
            let target = UnitQuaternion::from_scaled_axis(axis * (step * k as f64)) * n;
            path.push_fig2_to(&target, Turn::Left).unwrap();
            assert!((path.end().roll - lim.usable()).abs() < 1e-9);
            path.push_spin_roll(-path.end().roll).unwrap();
            assert!(path.end().roll.abs() < 1e-12);
        }
        assert!((common::angle(&n, &path.end().contact) - 3.0 * step).abs() < 1e-9);
        assert!(path.margins().max_abs_roll <= lim.usable() + 1e-12);
    }
}

#[test]
fn planner_errors_are_typed() {
    let g = geom();
    let lim = limits(false);
    let mut rng = common::rng(700);
    let start = contact_with(&mut rng, &Vector3::z(), 0.0);
    let goal = RollGoal {
        target: -start.contact,
        final_roll: None,
    };
    let bad_target = RollGoal {
        target: Vector3::new(f64::NAN, 0.0, 1.0),
        final_roll: None,
    };
    assert_eq!(
        plan_roll(&g, &start, &bad_target, &lim),
        Err(RollPlanError::InvalidTarget)
    );
    let mut bad = start;
    bad.roll = 2.0;
    assert_eq!(
        plan_roll(&g, &bad, &goal, &lim),
        Err(RollPlanError::StartRollOutsideLimit)
    );
    let below = contact_with(&mut rng, &Vector3::new(0.0, 0.6, -0.8), 0.0);
    assert_eq!(
        plan_roll(&g, &below, &goal, &lim),
        Err(RollPlanError::StartOutsideHemisphere)
    );
    let mut off = start;
    off.contact *= 1.1;
    assert_eq!(
        plan_roll(&g, &off, &goal, &lim),
        Err(RollPlanError::InvalidStart)
    );
    let wants = RollGoal {
        final_roll: Some(0.3),
        ..goal
    };
    assert_eq!(
        plan_roll(&g, &start, &wants, &lim),
        Err(RollPlanError::SpinNotAllowed)
    );
    let too_far = RollGoal {
        final_roll: Some(1.2),
        ..goal
    };
    assert_eq!(
        plan_roll(&g, &start, &too_far, &limits(true)),
        Err(RollPlanError::FinalRollOutsideLimit)
    );
    // A 2° roll limit leaves too little budget for the path capacity.
    let tiny = RollLimits {
        roll_limit: 2f64.to_radians(),
        roll_margin: 1f64.to_radians(),
        allow_spin: false,
    };
    assert_eq!(
        plan_roll(&g, &start, &goal, &tiny),
        Err(RollPlanError::CapacityExceeded)
    );
    let none = RollLimits {
        roll_margin: 2f64.to_radians(),
        ..tiny
    };
    assert_eq!(
        plan_roll(&g, &start, &goal, &none),
        Err(RollPlanError::InvalidLimits)
    );
    // Path-level errors.
    let mut p = RollingPath::new(g, start);
    for _ in 0..MAX_SEGMENTS {
        p.push_spin(0.1).unwrap();
    }
    assert_eq!(p.push_spin(0.1), Err(gait::rolling::PathError::Full));
    let off_pole = contact_with(&mut rng, &Vector3::new(0.6, 0.0, 0.8), 0.0);
    let mut q = RollingPath::new(g, off_pole);
    assert_eq!(
        q.push_fig2(&Vector3::x(), Turn::Left, 0.5),
        Err(gait::rolling::PathError::NotAtPole)
    );
    assert!(q.is_empty());
}

#[test]
fn planner_sweeps_random_geometries_and_roll_limits() {
    let mut rng = common::rng(800);
    let (mut ok, mut full) = (0, 0);
    for trial in 0..3000 {
        let big = rng.random_range(0.2..1.0);
        let g = ContactGeometry::new(big, rng.random_range(0.02..0.9) * big).unwrap();
        let lim = RollLimits {
            roll_limit: rng.random_range(15f64..150.0).to_radians(),
            roll_margin: 1f64.to_radians(),
            allow_spin: trial % 2 == 0,
        };
        let m = common::hemisphere_point(&mut rng);
        let tau0 = rng.random_range(-lim.roll_limit..lim.roll_limit);
        let start = contact_with(&mut rng, &m, tau0);
        let goal = RollGoal {
            target: common::unit(&mut rng),
            final_roll: (trial % 4 == 0).then(|| rng.random_range(-lim.usable()..lim.usable())),
        };
        match plan_roll(&g, &start, &goal, &lim) {
            Ok(path) => {
                check_plan(&path, &start, &goal, &lim);
                ok += 1;
            }
            Err(e) => {
                assert_eq!(e, RollPlanError::CapacityExceeded);
                full += 1;
            }
        }
    }
    eprintln!("{ok} planned, {full} beyond capacity");
    assert!(ok > 2000);
}
