//! The executor against a plant that is not the embedded kinematic hand:
//! it waits for the plant and starts from its measured state (refusing one
//! that breaks an invariant), compares a late measurement with the setpoint
//! it really answers, and faults when a grasping contact is lost.

use gait::HandConfig;
use gait::HandState;
use gait::executor::{Executor, ExecutorCommand, ExecutorEvent, FaultKind, GoalTarget, Mode};
use gait::planner::Planner;
use gait::sim::{MeasuredFinger, Measurement};
use nalgebra::{UnitQuaternion, Vector3};

fn measure(s: &HandState, age: u32) -> Measurement {
    Measurement {
        object: s.object,
        fingers: s.fingers.map(|f| MeasuredFinger {
            center: f.center,
            orientation: f.orientation,
            contact: f.mode == gait::FingerMode::Grasping,
            normal_force: None,
            roll: Some(f.roll),
        }),
        center: None,
        age,
        object_age: 0,
    }
}

fn faults(exec: &mut Executor) -> Vec<FaultKind> {
    let mut out = Vec::new();
    while let Some(e) = exec.pop_event() {
        if let ExecutorEvent::Fault { kind, .. } = e {
            out.push(kind);
        }
    }
    out
}

#[test]
fn it_starts_from_the_measured_state_or_refuses_it() {
    let cfg = HandConfig::default();
    let paper = HandState::paper_start(&cfg);
    let mut exec = Executor::new(&cfg, 1e-3, paper).unwrap();
    exec.await_plant();
    assert!(exec.awaiting_plant());
    assert_eq!(exec.phase(), Mode::SafeHold);
    assert_eq!(faults(&mut exec), [FaultKind::PlantWaiting]);
    // The plant is elsewhere: the object turned 0.3 rad about z with the
    // grasp (every contact kept).
    let turn = UnitQuaternion::from_scaled_axis(Vector3::z() * 0.3);
    let mut there = paper;
    there.object = turn * there.object;
    for f in &mut there.fingers {
        f.center = turn * f.center;
        f.orientation = turn * f.orientation;
    }
    assert!(exec.start_from(&measure(&there, 0)));
    assert_eq!(exec.phase(), Mode::Holding);
    assert!(exec.setpoint().state.object.angle_to(&there.object) < 1e-15);
    assert!(faults(&mut exec).is_empty());
    // A plant whose first state has only two contacts 120° apart: not
    // force-closure (Fact 3). Refused with that reason; nothing moves.
    let mut exec = Executor::new(&cfg, 1e-3, paper).unwrap();
    exec.await_plant();
    faults(&mut exec);
    let mut bad = paper;
    bad.fingers[0].mode = gait::FingerMode::Free;
    bad.fingers[0].center *= 0.65 / 0.6;
    assert!(!exec.start_from(&measure(&bad, 0)));
    assert_eq!(faults(&mut exec), [FaultKind::ForceClosure]);
    assert_eq!(exec.phase(), Mode::SafeHold);
    let r = *exec.tick(Some(&measure(&bad, 0)));
    assert_eq!(r.fault.map(|f| f.0), Some(FaultKind::ForceClosure));
    assert_eq!(r.setpoint.state, paper, "nothing moved");
}

/// A plant whose measurement lags three setpoints behind while the hand
/// moves fast: compared with the setpoint it answers, not the last one,
/// it is no tracking error; compared with the last one it would be.
#[test]
fn a_late_measurement_is_compared_with_the_setpoint_it_answers() {
    let cfg = HandConfig::default();
    let start = HandState::paper_start(&cfg);
    let planner = Planner::new(&cfg).unwrap();
    let mut exec = Executor::new(&cfg, 1e-3, start).unwrap();
    exec.command(ExecutorCommand::Goal {
        id: 1,
        target: GoalTarget::Rotation {
            axis: Vector3::z(),
            angle: 2.0,
        },
        limits: None,
    });
    let lag = 3usize;
    let mut history = vec![start; lag + 1];
    let (mut moving_ticks, mut worst) = (0, 0.0f64);
    for _ in 0..20_000 {
        let old = history[history.len() - 1 - lag];
        let r = *exec.tick(Some(&measure(&old, lag as u32)));
        let last = r.setpoint.state;
        if r.phase == Mode::Moving {
            moving_ticks += 1;
            for k in 0..3 {
                worst = worst.max((old.fingers[k].center - last.fingers[k].center).norm());
            }
        }
        history.push(last);
        if let Some(req) = exec.take_plan_request() {
            drop(exec.deliver_plan(req.goal, req.plan(&planner).map(Box::new)));
        }
        assert!(faults(&mut exec).is_empty(), "a fault");
        if r.phase == Mode::Holding && moving_ticks > 0 {
            break;
        }
    }
    let tol = cfg.feedback.finger_tolerance;
    println!(
        "{lag} ticks late: the fingertips were up to {worst:.1e} m from the last setpoint (tolerance {tol:e})"
    );
    assert!(moving_ticks > 100);
    assert!(worst > tol, "the lag matters: {worst} vs {tol}");
}

#[test]
fn a_grasping_contact_lost_is_a_fault_after_the_grace() {
    let cfg = HandConfig::default();
    let start = HandState::paper_start(&cfg);
    let mut exec = Executor::new(&cfg, 1e-3, start).unwrap();
    let grace = cfg.feedback.contact_grace_ticks;
    let mut m = measure(&start, 0);
    m.fingers[1].contact = false;
    for t in 0..grace {
        exec.tick(Some(&m));
        let f = faults(&mut exec);
        if t + 1 < grace {
            assert!(f.is_empty(), "tick {t}: {f:?}");
        } else {
            assert_eq!(f, [FaultKind::ContactLost], "after {grace} ticks");
        }
    }
    assert_eq!(exec.phase(), Mode::SafeHold);
    // A measured force below the floor is no contact either.
    let mut exec = Executor::new(&cfg, 1e-3, start).unwrap();
    let mut m = measure(&start, 0);
    for f in &mut m.fingers {
        f.normal_force = Some(1.0);
    }
    m.fingers[2].normal_force = Some(cfg.feedback.min_contact_force / 2.0);
    for _ in 0..grace {
        exec.tick(Some(&m));
    }
    assert_eq!(faults(&mut exec), [FaultKind::ContactLost]);
}
