//! The chain hand's load test along the three fingers' turns, remembered
//! per start and axis (`CarryLoads`): asked about turns of one grasp about
//! one axis, in any order, it answers as a fresh scan of each turn at the
//! same spacing does — for a test that fails beyond a known angle, and for
//! one that fails only at the start — and asks the test fewer times.

#[path = "../../kinematics/tests/common/mod.rs"]
mod common;
mod planning;

use common::{LIMITS, top_grasp};
use gait::HandState;
use gait::planner::chains::ChainHand;
use gait::planner::chains::carry_load::CarryLoads;
use gait::planner::chains::steps::along_carry;
use nalgebra::Vector3;
use planning::chain_state;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The memo's spacing, as the chain hand's: 3°.
const STEP: f64 = 3.0 * std::f64::consts::PI / 180.0;

fn setup() -> (ChainHand, HandState) {
    let chains = common::chains();
    let o = common::hand().object;
    let hand = ChainHand::new(&common::hand(), LIMITS).expect("TriFingerPro is a chain hand");
    let start = chain_state(&chains, &top_grasp(&chains, &o), &o);
    (hand, start)
}

/// How far the object of `s` is turned from `start`'s \[rad\].
fn turned(s: &HandState, start: &HandState) -> f64 {
    s.object.angle_to(&start.object)
}

/// Asks `angles` in order, of the memo and of a fresh scan each, with the
/// test `passes`: the verdicts must agree; returns the test's calls (memo,
/// fresh).
fn ask(
    hand: &ChainHand,
    start: &HandState,
    axis: &Vector3<f64>,
    angles: &[f64],
    passes: &dyn Fn(&HandState) -> bool,
) -> (usize, usize) {
    let memo = CarryLoads::default();
    let (mut by_memo, mut fresh) = (0, 0);
    for &a in angles {
        let m = memo.holds_along(hand, start, axis, a, STEP, &mut |s| {
            by_memo += 1;
            passes(s)
        });
        let n = (a / STEP).ceil().max(1.0) as usize;
        let f = along_carry(hand, start, axis, a, n, &mut |s| {
            fresh += 1;
            passes(s)
        });
        assert_eq!(
            m,
            f,
            "a {:.2}° turn: the memo says {m}, a fresh scan {f} (asked {:?})",
            a.to_degrees(),
            angles.iter().map(|a| a.to_degrees()).collect::<Vec<_>>()
        );
    }
    (by_memo, fresh)
}

#[test]
fn remembered_load_tests_answer_as_fresh_scans_with_fewer_asks() {
    let (hand, start) = setup();
    let axis = Vector3::new(0.3, -0.2, 1.0).normalize();
    // Fails beyond 37° (no sample of these turns lands within 0.1° of it).
    let limit = 37f64.to_radians();
    let beyond = |s: &HandState| turned(s, &start) <= limit;
    let quarters: Vec<f64> = [0.25, 0.5, 0.75, 1.0]
        .iter()
        .map(|f| f * 60f64.to_radians())
        .collect();
    let (memo, fresh) = ask(&hand, &start, &axis, &quarters, &beyond);
    println!("quarters of 60°: {memo} asks against {fresh} fresh");
    assert!(
        memo < fresh,
        "the memo asked {memo} times, fresh scans {fresh}"
    );
    // Longest first, then shorter ones on both sides of the failure.
    let down = [50.0, 20.0, 36.0, 38.0, 45.0, 10.0].map(f64::to_radians);
    ask(&hand, &start, &axis, &down, &beyond);
    // Random orders.
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    for _ in 0..20 {
        let angles: Vec<f64> = (0..5)
            .map(|_| {
                loop {
                    let a: f64 = rng.random_range(1.0..70.0);
                    if (a - 37.0).abs() > 0.5 {
                        break a.to_radians();
                    }
                }
            })
            .collect();
        ask(&hand, &start, &axis, &angles, &beyond);
    }
    // A test that fails only where the carry starts.
    let at_start = |s: &HandState| turned(s, &start) > 1e-9;
    ask(&hand, &start, &axis, &quarters, &at_start);
}
