//! The one place where wire types (`shm_schema`) and maths types (`gait`,
//! nalgebra) meet: the daemon is the only crate that sees both, and only
//! here.

use crate::control::controller::{ClientTarget, ControlCommand, ControlOutput, Goal};
use gait::config::{LimitsConfig, MotionLimit};
use gait::{FingerMode, HandState};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use shm_schema::{
    FingerStatus, GoalFrame, GoalRequest, LimitKind, LimitOrder, MIN_LIMIT_OVERRIDE_FRACTION,
    NO_FINGER, ReasonCode, Status, ValidCommand, measured,
};

fn quat_to_wire(q: &UnitQuaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

fn vec_to_wire(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn override_limit(
    configured: MotionLimit,
    req: &GoalRequest,
    kind: LimitKind,
) -> Result<MotionLimit, ReasonCode> {
    // The documented range (LAYOUT.md): [MIN_LIMIT_OVERRIDE_FRACTION ×
    // configured, configured]. The product is computed as the reader of
    // the documentation would, so the boundary itself is accepted.
    let pick = |order, cfg: f64| match req.limits.get(kind, order) {
        None => Ok(cfg),
        Some(v) if v > cfg => Err(ReasonCode::LimitAboveConfigured),
        Some(v) if v < cfg * MIN_LIMIT_OVERRIDE_FRACTION => Err(ReasonCode::LimitBelowMinimum),
        Some(v) => Ok(v),
    };
    Ok(MotionLimit {
        velocity: pick(LimitOrder::Velocity, configured.velocity)?,
        acceleration: pick(LimitOrder::Acceleration, configured.acceleration)?,
        jerk: pick(LimitOrder::Jerk, configured.jerk)?,
    })
}

/// A validated wire command → the controller's command: renormalises the
/// target and applies limit overrides, which may only lower the
/// configured limits (the configured ones are the hardware's), and by at
/// most a factor 100 ([`MIN_LIMIT_OVERRIDE_FRACTION`]).
pub fn control_command(
    cmd: &ValidCommand,
    limits: &LimitsConfig,
) -> Result<ControlCommand, ReasonCode> {
    Ok(match *cmd {
        ValidCommand::Goal(ref g) => {
            let [w, x, y, z] = g.target;
            let q = || UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
            let target = match g.frame {
                GoalFrame::Absolute => ClientTarget::Absolute(q()),
                GoalFrame::Relative => ClientTarget::Relative(q()),
                GoalFrame::AxisAngle => ClientTarget::Rotation {
                    axis: Vector3::new(x, y, z).normalize(),
                    angle: w,
                },
            };
            ControlCommand::Goal(Goal {
                client_id: g.client_id,
                goal_id: g.goal_id,
                target,
                limits: LimitsConfig {
                    object: override_limit(limits.object, g, LimitKind::Object)?,
                    fingertip: override_limit(limits.fingertip, g, LimitKind::Fingertip)?,
                    rolling: override_limit(limits.rolling, g, LimitKind::Rolling)?,
                },
            })
        }
        ValidCommand::Cancel { client_id, goal_id } => {
            ControlCommand::Cancel { client_id, goal_id }
        }
        ValidCommand::Hold { client_id } => ControlCommand::Hold { client_id },
        ValidCommand::Reset { client_id } => ControlCommand::Reset { client_id },
    })
}

/// Writes the controller's report into the status (every field but the
/// daemon's own: tick, times, instance, daemon state, timing, counters).
pub fn fill_status(out: &ControlOutput, object_radius: f64, status: &mut Status) {
    status.phase = out.phase.code();
    status.fault = out.fault.code();
    status.grasp = out.grasp.code();
    status.grasp_margin = out.grasp_margin;
    status.load_grip = out.load_grip;
    status.load_margin = out.load_margin;
    status.commanded_object_q = quat_to_wire(&out.hand.object);
    status.commanded_object_omega = vec_to_wire(&out.object_omega);
    let g = &out.goal;
    status.goal.goal_id = g.goal_id;
    status.goal.client_id = g.client_id;
    status.goal.state = g.state.code();
    status.goal.reason = g.reason.code();
    status.goal.remaining_angle = g.remaining_angle;
    status.goal.eta = g.eta.unwrap_or(-1.0);
    status.goal.gaits_done = g.gaits_done;
    status.goal.gaits_planned = g.gaits_planned;
    status.goal.active_finger = g.active_finger.map_or(NO_FINGER, |f| f as u32);
    status.goal.reserved = 0;
    for (k, fs) in status.fingers.iter_mut().enumerate() {
        *fs = finger_status(&out.hand, k, object_radius);
        fs.state = out.fingers[k].phase.code();
        fs.workspace_margin = out.fingers[k].workspace_margin;
        fs.commanded_normal_force = out.fingers[k].normal_force;
        let f = &out.fingers[k];
        fs.commanded_joints = f.joints.map_or([0.0; 3], |q| vec_to_wire(&q));
        fs.tip_margin = f.tip_margin;
        fs.link_clearance = f.link_clearance.unwrap_or(0.0);
    }
    status.hand = if out.chains {
        shm_schema::status::hand::CHAINS
    } else {
        shm_schema::status::hand::FINGERTIPS
    };
    fill_measured(out, status);
}

/// The measurement beside the command: orientation, fingertip poses,
/// contacts and forces as the plant reported them (a chain hand's joints,
/// where its plant measures them), and the tracking errors.
fn fill_measured(out: &ControlOutput, status: &mut Status) {
    let Some(report) = &out.measured else {
        status.measured_tick = 0;
        status.measured_age = 0;
        status.measured_mask = 0;
        status.measured_object_q = [0.0; 4];
        status.object_error = 0.0;
        return;
    };
    let m = &report.measurement;
    // Against the setpoint the measurement answers (the plant has not
    // seen this tick's yet): while moving, this tick's differs from it by
    // the distance moved in a period, which is no tracking error.
    let answered = &report.answers;
    status.measured_tick = report.tick;
    status.measured_age = m.age;
    status.measured_object_q = quat_to_wire(&m.object);
    status.object_error = m.object.angle_to(&answered.object);
    let forces = m.fingers.iter().all(|f| f.normal_force.is_some());
    status.measured_mask = measured::OBJECT
        | measured::TIPS
        | measured::CONTACTS
        | if forces { measured::FORCES } else { 0 }
        | if report.joints.is_some() {
            measured::JOINTS
        } else {
            0
        };
    for (k, fs) in status.fingers.iter_mut().enumerate() {
        let f = &m.fingers[k];
        fs.measured_joints = report.joints.map_or([0.0; 3], |q| vec_to_wire(&q[k]));
        fs.measured_tip_position = vec_to_wire(&f.center);
        fs.measured_tip_orientation = quat_to_wire(&f.orientation);
        fs.measured_contact = u32::from(f.contact);
        fs.measured_normal_force = f.normal_force.unwrap_or(0.0);
        fs.tip_error = (f.center - answered.fingers[k].center).norm();
    }
}

/// Geometry of finger `k`: contact points (SPEC §2.3: on the object
/// R·n in the hand frame, R·Q_oᵀ n in the object frame; on the fingertip
/// m = Q_fᵀ(−n)) while it touches; pose and roll always.
fn finger_status(hand: &HandState, k: usize, object_radius: f64) -> FingerStatus {
    let f = &hand.fingers[k];
    let mut s = FingerStatus {
        commanded_tip_position: vec_to_wire(&f.center),
        commanded_tip_orientation: quat_to_wire(&f.orientation),
        roll: f.roll,
        ..FingerStatus::default()
    };
    if f.mode == FingerMode::Grasping {
        s.contact_hand = vec_to_wire(&(f.contact_normal() * object_radius));
        s.contact_object = vec_to_wire(&(hand.object_contact(k) * object_radius));
        s.tip_contact = vec_to_wire(&f.fingertip_contact());
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::controller::Controller;
    use crate::control::tick_events::TickEvents;
    use crate::hold::HoldController;
    use gait::HandConfig;
    use shm_schema::{Command, DaemonState};

    #[test]
    fn overrides_may_only_lower_limits() {
        let cfg = LimitsConfig::default();
        let goal = |v| {
            Command::goal(1, 1, GoalFrame::Absolute, [0.0, 1.0, 0.0, 0.0])
                .with_limit(LimitKind::Object, LimitOrder::Velocity, v)
                .validate()
                .unwrap()
        };
        match control_command(&goal(0.5), &cfg).unwrap() {
            ControlCommand::Goal(g) => {
                assert_eq!(g.limits.object.velocity, 0.5);
                assert_eq!(g.limits.object.jerk, cfg.object.jerk);
                assert_eq!(g.limits.rolling, cfg.rolling);
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(
            control_command(&goal(1.5), &cfg),
            Err(ReasonCode::LimitAboveConfigured)
        );
    }

    #[test]
    fn relative_goal_keeps_its_frame_and_is_renormalised() {
        let c = Command::goal(1, 1, GoalFrame::Relative, [1.0005, 0.0, 0.0, 0.0]);
        match control_command(&c.validate().unwrap(), &LimitsConfig::default()).unwrap() {
            ControlCommand::Goal(Goal {
                target: ClientTarget::Relative(q),
                ..
            }) => assert!((q.quaternion().norm() - 1.0).abs() < 1e-15),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn status_of_the_paper_start_passes_its_own_checks() {
        let cfg = HandConfig::default();
        let mut ctl = HoldController::new(&cfg);
        let mut events = TickEvents::new();
        let mut ctx = crate::control::controller::TickContext {
            now: 0,
            tick: 0,
            events: &mut events,
        };
        let mut out = ControlOutput {
            hand: HandState::paper_start(&cfg),
            object_omega: Vector3::zeros(),
            measured: None,
            phase: shm_schema::Phase::Hold,
            fault: shm_schema::FaultCode::None,
            goal: Default::default(),
            fingers: [crate::control::controller::FingerOutput::bare(shm_schema::FingerPhase::Free);
                3],
            chains: false,
            grasp: shm_schema::GraspState::Unknown,
            grasp_margin: 0.0,
            load_grip: 0.0,
            load_margin: 0.0,
            plant_command: None,
        };
        ctl.tick(&mut ctx, &mut out);
        let mut s = Status {
            daemon_state: DaemonState::Running.code(),
            ..Status::default()
        };
        fill_status(&out, cfg.model.object_radius, &mut s);
        s.check().unwrap();
        for f in &s.fingers {
            let r: f64 = f.contact_hand.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((r - 0.5).abs() < 1e-12);
            assert!(
                (f.tip_contact[2] - 1.0).abs() < 1e-12,
                "pole contact m = e_z"
            );
            assert_eq!(f.contact_hand, f.contact_object, "object at identity");
        }
        assert_eq!(s.commanded_object_q, [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(s.goal.eta, -1.0);
        assert_eq!(s.goal.active_finger, NO_FINGER);
    }
}
