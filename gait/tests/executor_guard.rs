//! An invariant near its limit (SPEC §6.3, `gait::executor::guard`): a
//! measured contact that stays within half the workspace margin of its
//! cone's edge for a few ticks stops the motion smoothly; the goal is
//! replanned and reached. With the guard off, a measurement error away
//! from the edge, within the guard, or for a single tick, the motion goes
//! on.

mod planning;

use gait::executor::guard::GUARD_TICKS;
use gait::executor::{ExecutorCommand, FaultKind, GoalStage, GoalTarget, Mode, TickReport};
use gait::{FingerMode, HandConfig, HandState};
use nalgebra::{UnitQuaternion, Vector3};
use planning::run::Rig;

/// A hand whose tracking is looser than the embedded one's (so that the
/// sensor error below is within tracking and drift tolerance).
fn loose(limit_guard: f64) -> HandConfig {
    let mut cfg = HandConfig::default();
    cfg.feedback.finger_tolerance = 0.02;
    cfg.feedback.contact_tolerance = 0.02;
    cfg.feedback.limit_guard = limit_guard;
    cfg
}

/// Ticks a full turn about z until a grasping contact is within `slack`
/// [rad] of its cone's margin boundary while the object turns (a pair
/// turns as far as its cones allow); returns that finger.
fn run_to_the_edge(rig: &mut Rig, slack: f64) -> usize {
    rig.command(ExecutorCommand::Goal {
        id: 1,
        target: GoalTarget::Rotation {
            axis: Vector3::z(),
            angle: std::f64::consts::TAU,
        },
        limits: None,
    });
    for _ in 0..60_000 {
        let r = rig.tick();
        if r.phase != Mode::Moving {
            continue;
        }
        let s = r.setpoint.state;
        if let Some(k) = (0..3)
            .find(|&k| s.fingers[k].mode == FingerMode::Grasping && r.workspace_slack[k] < slack)
        {
            return k;
        }
    }
    panic!("no contact came near its cone's edge");
}

/// A sensor error of `angle` [rad] moving finger `k`'s measured centre
/// away from its cone axis (negative: towards it) for `ticks` ticks.
fn mismeasure(rig: &mut Rig, k: usize, angle: f64, ticks: u8) -> TickReport {
    let az = rig.cfg.model.finger_azimuth_deg[k].to_radians();
    let d = Vector3::new(az.cos(), az.sin(), 0.0);
    let mut r = *rig.exec.report();
    for _ in 0..ticks {
        r = rig.tick_measured(|m| {
            let c = m.fingers[k].center;
            let axis = d.cross(&c).normalize();
            m.fingers[k].center = UnitQuaternion::from_scaled_axis(axis * angle) * c;
        });
    }
    r
}

fn assert_reached(rig: &mut Rig, what: &str) {
    rig.run_until_idle(100_000);
    let s = &rig.stats;
    assert_eq!(s.goals, vec![(1, GoalStage::Succeeded)], "{what}");
    assert!(s.violations.is_empty(), "{what}: {:?}", &s.violations[..1]);
    assert!(s.discontinuities.is_empty(), "{what}");
    assert_eq!(s.faults, 0, "{what}");
}

#[test]
fn a_measured_contact_near_its_workspace_limit_stops_and_replans() {
    let cfg = loose(0.5);
    let start = HandState::paper_start(&cfg);
    let mut rig = Rig::new(cfg, start, 1e-3);
    let k = run_to_the_edge(&mut rig, 0.2f64.to_radians());
    // 0.8° further out: 0.6° or more of the 1° margin used, 0.4° or less
    // left to the edge (the guard keeps half).
    let r = mismeasure(&mut rig, k, 0.8f64.to_radians(), GUARD_TICKS);
    assert_eq!(rig.stats.near_limits, vec![(FaultKind::Workspace, k as u8)]);
    assert_eq!(r.phase, Mode::Stopping, "the motion brakes");
    assert_reached(&mut rig, "after the stop");
    // (A full turn about z ends where it started.)
    let err = rig.plant.state().object.angle_to(&start.object);
    assert!(err < 1e-6, "true object {err:e} rad from the goal");
}

#[test]
fn no_stop_with_the_guard_off_or_an_error_away_from_the_edge() {
    for (guard, angle, ticks, what) in [
        (0.0, 0.8f64, GUARD_TICKS, "guard off"),
        (0.5, -0.8, GUARD_TICKS, "error towards the cone axis"),
        (0.5, 0.2, GUARD_TICKS, "error within the guard"),
        (0.5, 0.8, GUARD_TICKS - 1, "too short"),
    ] {
        let mut rig = Rig::new(loose(guard), HandState::paper_start(&loose(guard)), 1e-3);
        let k = run_to_the_edge(&mut rig, 0.2f64.to_radians());
        let r = mismeasure(&mut rig, k, angle.to_radians(), ticks);
        assert_eq!(r.phase, Mode::Moving, "{what}");
        assert!(rig.stats.near_limits.is_empty(), "{what}");
        assert_reached(&mut rig, what);
    }
}

#[test]
fn the_guard_keeps_its_fraction_of_the_margin() {
    // Keep a quarter: from within 0.05° of the margin boundary, 0.7° more
    // leaves 0.3–0.35° of the 1° margin (more than a quarter: goes on),
    // 0.9° leaves at most 0.15° (stops).
    for (angle, stops) in [(0.7f64, false), (0.9, true)] {
        let cfg = loose(0.25);
        let mut rig = Rig::new(cfg, HandState::paper_start(&cfg), 1e-3);
        let k = run_to_the_edge(&mut rig, 0.05f64.to_radians());
        let r = mismeasure(&mut rig, k, angle.to_radians(), GUARD_TICKS);
        assert_eq!(rig.stats.near_limits.len(), usize::from(stops), "{angle}°");
        assert_eq!(r.phase == Mode::Stopping, stops, "{angle}°");
        assert_reached(&mut rig, "keep a quarter");
    }
}

#[test]
fn a_persistent_error_ends_in_safe_hold_once_the_replans_are_spent() {
    // The sensor keeps reporting finger k past the guard (a calibration
    // error): every replan runs into it again; after `max_replans` it is a
    // fault, as for drift.
    let mut cfg = loose(0.5);
    cfg.feedback.max_replans = 1;
    let mut rig = Rig::new(cfg, HandState::paper_start(&cfg), 1e-3);
    let k = run_to_the_edge(&mut rig, 0.2f64.to_radians());
    for _ in 0..50_000 {
        let r = mismeasure(&mut rig, k, 0.8f64.to_radians(), 1);
        if r.phase == Mode::SafeHold {
            break;
        }
    }
    assert_eq!(rig.exec.phase(), Mode::SafeHold);
    assert_eq!(rig.stats.near_limits.len(), 1, "one replan, then the fault");
    assert_eq!(
        rig.exec.report().fault.map(|f| f.0),
        Some(FaultKind::Workspace)
    );
}
