//! A goal's motion-limit overrides (SPEC §7.3): the plan is timed with the
//! limits it is executed with, so its duration, the ETA reported when it
//! starts and the real execution time agree, and even the slowest override
//! allowed (1 % of every configured limit, LAYOUT.md) keeps every step
//! inside the trajectory generator's duration bound — no Trajectory fault.
//!
//! Graded on the plant's true object and on the ticks really executed.

mod planning;

use gait::config::{LimitsConfig, MotionLimit};
use gait::executor::{ExecutorCommand, ExecutorEvent, GoalStage, GoalTarget, Mode, Reason};
use gait::{HandConfig, HandState};
use nalgebra::{UnitQuaternion, Vector3};
use planning::run::Rig;

/// Every configured limit times `f`.
fn scaled(l: &LimitsConfig, f: f64) -> LimitsConfig {
    let s = |m: MotionLimit| MotionLimit {
        velocity: m.velocity * f,
        acceleration: m.acceleration * f,
        jerk: m.jerk * f,
    };
    LimitsConfig {
        object: s(l.object),
        fingertip: s(l.fingertip),
        rolling: s(l.rolling),
    }
}

/// Runs a 40° turn about a tilted axis from the paper's start (a roll to
/// a two-finger grasp, then gaits and rotations) under `limits`; returns
/// (planned duration, ETA at the first executing tick, executed seconds).
fn run(limits: Option<LimitsConfig>) -> (f64, f64, f64) {
    let cfg = HandConfig::default();
    let mut rig = Rig::new(cfg, HandState::paper_start(&cfg), 1e-3);
    let goal = UnitQuaternion::from_scaled_axis(Vector3::new(0.3, -0.2, 1.0).normalize() * 0.7);
    rig.command(ExecutorCommand::Goal {
        id: 1,
        target: GoalTarget::Orientation(goal),
        limits,
    });
    let (mut eta, mut moving_ticks, mut planned) = (None, 0u64, 0.0);
    for _ in 0..5_000_000u64 {
        let r = rig.tick();
        if r.phase == Mode::Moving {
            moving_ticks += 1;
            eta.get_or_insert(r.eta);
        }
        if planned == 0.0
            && let Some(p) = rig.exec.plan()
        {
            planned = p.summary.duration;
        }
        if rig.stats.goals.last().is_some() {
            break;
        }
    }
    assert_eq!(rig.stats.goals.last(), Some(&(1, GoalStage::Succeeded)));
    assert_eq!(
        rig.stats.faults, 0,
        "no fault (a Trajectory fault was the bug)"
    );
    assert!(rig.stats.violations.is_empty() && rig.stats.plant_violations.is_empty());
    let err = rig.plant.state().object.angle_to(&goal);
    assert!(
        err <= 1e-6,
        "the hand's object reached the goal: {err:e} rad off"
    );
    (planned, eta.expect("it moved"), moving_ticks as f64 * 1e-3)
}

#[test]
fn plans_are_timed_with_the_goals_limits() {
    let cfg = HandConfig::default();
    let (t_full, eta_full, ran_full) = run(None);
    let (t_half, eta_half, ran_half) = run(Some(scaled(&cfg.limits, 0.5)));
    let (t_min, eta_min, ran_min) = run(Some(scaled(&cfg.limits, 0.01)));
    println!(
        "planned / ETA / executed [s]: configured {t_full:.2} / {eta_full:.2} / {ran_full:.2}, \
         half {t_half:.2} / {eta_half:.2} / {ran_half:.2}, 1 % {t_min:.1} / {eta_min:.1} / {ran_min:.1}"
    );
    for (planned, eta, ran) in [
        (t_full, eta_full, ran_full),
        (t_half, eta_half, ran_half),
        (t_min, eta_min, ran_min),
    ] {
        // Rest-to-rest steps, executed tick by tick: within a tick a step.
        assert!(
            (planned - ran).abs() <= 0.002 * 40.0,
            "{planned} planned, {ran} ran"
        );
        // The ETA counts whole ticks per step (motion and handover): it
        // is when the goal ends, not the plan's continuous sum.
        assert!((eta - ran).abs() <= 0.002, "ETA {eta} vs {ran} ran");
    }
    // With v, a and j all scaled by f, a velocity-limited phase takes 1/f
    // as long, an acceleration-limited one 1/√f, a jerk-limited one
    // 1/∛f: the whole plan between f^(-1/3) and f^(-1) times as long.
    for (f, ran) in [(0.5f64, ran_half), (0.01, ran_min)] {
        let ratio = ran / ran_full;
        assert!(
            ratio >= f.powf(-1.0 / 3.0) * 0.999 && ratio <= f.recip() * 1.001,
            "{ratio} times as long at {f}"
        );
    }
}

/// Limits that are not finite and positive never reach the planner.
#[test]
fn non_positive_limits_are_refused_with_their_own_reason() {
    let cfg = HandConfig::default();
    let mut rig = Rig::new(cfg, HandState::paper_start(&cfg), 1e-3);
    let mut bad = cfg.limits;
    bad.rolling.jerk = 0.0;
    let answer = rig.command(ExecutorCommand::Goal {
        id: 1,
        target: GoalTarget::Orientation(UnitQuaternion::identity()),
        limits: Some(bad),
    });
    assert_eq!(
        answer,
        gait::executor::ExecutorAnswer::Rejected(Reason::InvalidLimits)
    );
    assert!(rig.exec.take_plan_request().is_none());
    while let Some(e) = rig.exec.pop_event() {
        assert!(!matches!(e, ExecutorEvent::Goal { .. }), "{e:?}");
    }
}
