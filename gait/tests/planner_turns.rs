//! Requested turns (`Planner::plan_rotation`, e.g. a full turn) turn the
//! object that far about the axis, not merely to the orientation they end
//! at: the quicker detours of orientation goals must not shortcut them.

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
    let (mut checked, mut escaped) = (0, 0);
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
        // An escape (rare, from random states) turns about another axis
        // first; then the end orientation and the full turns are promised.
        if plan.summary.escaped {
            let spun: f64 = plan
                .steps
                .iter()
                .map(|s| match s.motion {
                    Motion::Rotate { angle, .. } => angle.abs(),
                    _ => 0.0,
                })
                .sum();
            let turns = (angle / tau + 1e-9).floor();
            assert!(
                turns < 1.0 || spun >= tau * turns - std::f64::consts::PI,
                "turn {i}: {turns} full turns asked, the escaped plan rotates {spun:.3} rad"
            );
            escaped += 1;
            continue;
        }
        let turned = turned_about(&plan, &axis);
        assert!(
            (turned - angle).abs() < 1e-9,
            "turn {i}: asked {angle:.3} rad about the axis, plan turns {turned:.3}"
        );
        checked += 1;
    }
    // Not vacuous: most turns need no escape (each piece of a long turn
    // escapes only from a grasp no gait can leave).
    assert!(checked >= 100, "only {checked} turns without an escape");
    println!("{checked} turns checked about their axis, {escaped} after an escape");
}
