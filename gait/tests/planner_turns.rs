//! Requested turns (`Planner::plan_rotation`, e.g. a full turn) turn the
//! object that far about the axis, not merely to the orientation they end
//! at: a detour must not shortcut them.

mod planning;

use gait::HandState;
use gait::planner::{Motion, Planner};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Rotation of the object about `axis` summed over the plan's steps [rad].
fn turned_about(plan: &gait::planner::Plan, axis: &Vector3<f64>) -> f64 {
    plan.steps
        .iter()
        .map(|s| match s.motion {
            Motion::Rotate { axis: a, angle, .. } => angle * a.dot(axis),
            _ => 0.0,
        })
        .sum()
}

#[test]
fn requested_turns_turn_that_far() {
    let cfg = planning::weightless();
    let planner = Planner::new(&cfg).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let tau = std::f64::consts::TAU;
    let (mut detoured, mut worst) = (0, 0.0f64);
    for i in 0..200 {
        let start = if i % 2 == 0 {
            HandState::paper_start(&cfg)
        } else {
            planning::random_two_finger_state(&mut rng, &cfg)
        };
        let axis = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize();
        let angle = [0.25, 0.5, 0.75, 1.0, 2.0][i % 5] * tau;
        let plan = planner
            .plan_rotation(&start, &axis, angle)
            .unwrap_or_else(|e| panic!("turn {i} by {angle:.3} rad: {e}"));
        let want = gait::planner::relative_goal(&start.object, &axis, angle);
        let err = plan.end_state().object.angle_to(&want);
        assert!(err < 1e-9, "turn {i}: final error {err}");
        // Turned that far, that way: the plan's turns projected on the axis
        // add up to the angle asked. A plan may first turn about another
        // axis (a detour, or an escape where no gait can follow), which
        // adds its own share; a full turn lost or gained would be 2π off.
        let turned = turned_about(&plan, &axis);
        assert!(
            (turned - angle).abs() < std::f64::consts::FRAC_PI_2,
            "turn {i}: asked {angle:.3} rad about the axis, the plan turns {turned:.3}"
        );
        if plan.summary.escaped {
            detoured += 1;
        } else {
            // Without a detour, exactly about the axis.
            assert!(
                (turned - angle).abs() < 1e-9,
                "turn {i}: asked {angle:.3} rad about the axis, plan turns {turned:.3}"
            );
        }
        worst = worst.max((turned - angle).abs());
    }
    println!(
        "200 turns checked about their axis, {detoured} with a detour first; largest difference {worst:.3} rad"
    );
}

#[test]
fn a_turn_about_x_after_a_goal_is_a_short_plan() {
    // A user's sequence under the default load: `gaitctl plan --axis
    // 1,-1,2 --angle 100`, then from where it ends `--axis 1,0,0 --angle
    // 90 --relative`. Each must plan within the default budget (an
    // expansion count here) in at most 10 gaits and at most twice a
    // typical plan's time (time to goal median ~8 s from these starts:
    // 16 s).
    let cfg = gait::HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let start = HandState::paper_start(&cfg);
    let first = nalgebra::UnitQuaternion::from_scaled_axis(
        Vector3::new(1.0, -1.0, 2.0).normalize() * 100f64.to_radians(),
    );
    let a = planner.plan(&start, &first).expect("100° about (1,-1,2)");
    let b = planner
        .plan_rotation(&a.end_state(), &Vector3::x(), 90f64.to_radians())
        .expect("then 90° about x");
    for (what, p) in [("100° about (1,-1,2)", &a), ("then 90° about x", &b)] {
        println!(
            "{what}: {} gaits, {:.2} s; {}",
            p.summary.gaits, p.summary.duration, p.route
        );
        assert!(p.summary.gaits <= 10, "{what}: {} gaits", p.summary.gaits);
        assert!(
            p.summary.duration <= 16.0,
            "{what}: {:.2} s",
            p.summary.duration
        );
    }
}
