//! Feedback that corrects (SPEC §6.3): a hand whose object lags the
//! commanded grasp by a fixed small rotation (soft contacts take up part of
//! every motion) still reaches the goal, because the orientation error
//! feeds the fingertip setpoints — graded on the object the hand really
//! has, not on the command. Without the correction (gain 0) the same hand
//! ends off by the lag.

use gait::HandConfig;
use gait::HandState;
use gait::executor::{Executor, ExecutorCommand, ExecutorEvent, GoalStage, GoalTarget, Mode};
use gait::planner::Planner;
use gait::sim::{MeasuredFinger, Measurement};
use nalgebra::{UnitQuaternion, Vector3};

/// The plant: fingertips exactly where commanded, the object `lag` behind
/// the commanded object (true = lag · commanded). It measures itself
/// exactly.
fn measure(commanded: &HandState, lag: &UnitQuaternion<f64>) -> Measurement {
    Measurement {
        object: lag * commanded.object,
        fingers: commanded.fingers.map(|f| MeasuredFinger {
            center: f.center,
            orientation: f.orientation,
            contact: f.mode == gait::FingerMode::Grasping,
            normal_force: None,
            roll: Some(f.roll),
        }),
        center: None,
        age: 0,
        object_age: 0,
    }
}

/// Runs one goal; returns the true object's final error from the goal
/// \[rad\] and the largest correction commanded \[rad\].
fn run(gain: f64, lag: UnitQuaternion<f64>, goal: UnitQuaternion<f64>) -> (f64, f64) {
    let mut cfg = HandConfig::default();
    cfg.feedback.orientation_gain = gain;
    let start = HandState::paper_start(&cfg);
    let planner = Planner::new(&cfg).unwrap();
    let mut exec = Executor::new(&cfg, 1e-3, start).unwrap();
    exec.command(ExecutorCommand::Goal {
        id: 1,
        target: GoalTarget::Orientation(goal),
        limits: None,
    });
    let mut written = start;
    let mut largest = 0.0f64;
    let mut outcome = None;
    for _ in 0..200_000 {
        let m = measure(&written, &lag);
        let r = *exec.tick(Some(&m));
        written = r.setpoint.state;
        largest = largest.max(written.object.angle_to(&exec.setpoint().state.object));
        if let Some(req) = exec.take_plan_request() {
            drop(exec.deliver_plan(req.goal, req.plan(&planner).map(Box::new)));
        }
        while let Some(e) = exec.pop_event() {
            match e {
                ExecutorEvent::Goal { state, .. } if state.is_terminal() => outcome = Some(state),
                ExecutorEvent::Fault { kind, .. } => panic!("fault {kind:?}"),
                _ => {}
            }
        }
        if outcome.is_some() && exec.phase() == Mode::Holding {
            break;
        }
    }
    assert_eq!(outcome, Some(GoalStage::Succeeded));
    // Hold on a while: the correction settles.
    for _ in 0..2000 {
        let m = measure(&written, &lag);
        written = exec.tick(Some(&m)).setpoint.state;
    }
    let truth = lag * written.object;
    (truth.angle_to(&goal), largest)
}

#[test]
fn a_lagging_hand_still_reaches_the_goal() {
    let lag = UnitQuaternion::from_scaled_axis(Vector3::new(0.3, -1.0, 0.5).normalize() * 0.0008);
    let goal = UnitQuaternion::from_scaled_axis(Vector3::new(1.0, 1.0, 0.2).normalize() * 1.3);
    let (with, c) = run(HandConfig::default().feedback.orientation_gain, lag, goal);
    let (without, c0) = run(0.0, lag, goal);
    println!(
        "lag {:.2e} rad: final error {with:.1e} rad with the correction (largest {c:.1e} rad), \
         {without:.1e} rad without",
        lag.angle()
    );
    assert!(with <= 1e-6, "with the correction: {with:e} rad off");
    assert!(
        (without - lag.angle()).abs() < 1e-6,
        "without: off by the lag ({without:e})"
    );
    assert!(
        (c - lag.angle()).abs() < 1e-4,
        "the correction took up the lag: {c:e}"
    );
    assert!(c0 < 1e-12, "no correction at gain 0: {c0:e}");
}
