//! Reasons and limits that reach the client (separate processes: gaitd
//! and the client library):
//! - motion-limit overrides are accepted only inside the range LAYOUT.md
//!   documents ("Command validation": at least 1 % of the configured
//!   limit, at most the configured limit), each side with its own reason,
//!   and a goal under an override is planned with it: the ETA the daemon
//!   reports when it starts executing is when it really ends;
//! - a goal the planner cannot plan ends Aborted with the planner's own
//!   reason, in the outcome, the status and the goal-transition event
//!   (here: its search budget; `daemon/tests/plan_reasons.rs` checks every
//!   reason the planner can give).
//!
//! Times are compared in daemon ticks (1 ms of controller time each), never
//! in wall-clock time.

use gaitd_client::{Command, EventKind, GoalFrame, GoalState, LimitKind, LimitOrder, ReasonCode};
use gaitd_tests::TestDaemon;
use std::time::Duration;

const T: Duration = Duration::from_secs(5);
const LONG: Duration = Duration::from_secs(60);

// The configured defaults (SPEC §5, deploy/gaitd.toml) the overrides are
// measured against.
const OBJECT_VELOCITY: f64 = 1.0;
const FINGERTIP_JERK: f64 = 40.0;
/// LAYOUT.md: an override must be at least this fraction of the configured
/// limit.
const MIN_FRACTION: f64 = 0.01;

#[test]
fn overrides_outside_the_documented_range_are_rejected_with_their_reason() {
    let d = TestDaemon::start("limits");
    let mut c = d.client();
    let me = c.client_id();
    // The object is already at the identity: an accepted goal has nothing
    // to do and succeeds at once.
    let here = |id: u64| Command::goal(me, id, GoalFrame::Absolute, [1.0, 0.0, 0.0, 0.0]);
    let cases = [
        // Tiny: once a Trajectory fault reported as NonFiniteState.
        (
            here(1).with_limit(LimitKind::Object, LimitOrder::Velocity, 1e-6),
            Some(ReasonCode::LimitBelowMinimum),
        ),
        (
            here(2).with_limit(
                LimitKind::Fingertip,
                LimitOrder::Jerk,
                FINGERTIP_JERK * MIN_FRACTION * 0.99,
            ),
            Some(ReasonCode::LimitBelowMinimum),
        ),
        // Huge.
        (
            here(3).with_limit(LimitKind::Rolling, LimitOrder::Acceleration, 1e300),
            Some(ReasonCode::LimitAboveConfigured),
        ),
        (
            here(4).with_limit(
                LimitKind::Object,
                LimitOrder::Velocity,
                OBJECT_VELOCITY * 1.01,
            ),
            Some(ReasonCode::LimitAboveConfigured),
        ),
        // Both ends of the range are inside it.
        (
            here(5).with_limit(
                LimitKind::Object,
                LimitOrder::Velocity,
                OBJECT_VELOCITY * MIN_FRACTION,
            ),
            None,
        ),
        (
            here(6).with_limit(LimitKind::Fingertip, LimitOrder::Jerk, FINGERTIP_JERK),
            None,
        ),
    ];
    for (cmd, want) in cases {
        let a = c.command(cmd, T).unwrap();
        match want {
            Some(reason) => {
                assert_eq!(
                    a.verdict(),
                    Ok(gaitd_client::Verdict::Rejected(reason)),
                    "{cmd:?}"
                );
            }
            None => {
                assert_eq!(a.verdict(), Ok(gaitd_client::Verdict::Accepted), "{cmd:?}");
                let o = c.wait_outcome(cmd.goal_id, LONG).unwrap();
                assert_eq!(
                    (o.state, o.reason),
                    (GoalState::Succeeded, ReasonCode::Reached)
                );
            }
        }
    }
    let s = c.wait_status(T).unwrap();
    assert_eq!(s.fault, shm_schema::FaultCode::None.code());
    assert_eq!((s.commands, s.rejected), (6, 4));
}

/// A goal at half the configured limits is planned at half the limits: the
/// ETA reported at its start is when it ends (in ticks), which a plan timed
/// at the configured limits would miss by seconds.
#[test]
fn a_goal_under_an_override_ends_when_its_eta_said() {
    let d = TestDaemon::start("eta");
    let mut c = d.client();
    let me = c.client_id();
    let mut cmd = Command::goal(me, 1, GoalFrame::AxisAngle, [1.2, 0.2, -0.1, 1.0]);
    // Half of every configured limit (SPEC §5 defaults: object 1 rad/s,
    // 4 rad/s², 40 rad/s³; fingertip 0.5 m/s, 4, 40; rolling 2 rad/s, 8, 80).
    for (kind, configured) in [
        (LimitKind::Object, [1.0, 4.0, 40.0]),
        (LimitKind::Fingertip, [0.5, 4.0, 40.0]),
        (LimitKind::Rolling, [2.0, 8.0, 80.0]),
    ] {
        let orders = [
            LimitOrder::Velocity,
            LimitOrder::Acceleration,
            LimitOrder::Jerk,
        ];
        for (order, v) in orders.into_iter().zip(configured) {
            cmd = cmd.with_limit(kind, order, v * 0.5);
        }
    }
    let a = c.command(cmd, T).unwrap();
    assert_eq!(a.verdict(), Ok(gaitd_client::Verdict::Accepted));
    // The first status of the executing goal with its ETA.
    let (start_tick, eta) = loop {
        let s = c.wait_status(T).unwrap();
        if s.goal.goal_id == 1 && s.goal_state() == Ok(GoalState::Executing) && s.goal.eta >= 0.0 {
            break (s.tick, s.goal.eta);
        }
    };
    let o = c.wait_outcome(1, LONG).unwrap();
    assert_eq!(
        (o.state, o.reason),
        (GoalState::Succeeded, ReasonCode::Reached)
    );
    let end_tick = c
        .events()
        .unwrap()
        .filter(|e| {
            e.kind() == Ok(EventKind::GoalTransition)
                && e.goal_id == 1
                && e.state == GoalState::Succeeded.code()
        })
        .map(|e| e.tick)
        .last()
        .expect("the success event");
    let predicted = start_tick as f64 + eta * 1000.0;
    let off = end_tick as f64 - predicted;
    println!("ETA {eta:.3} s at tick {start_tick}: ended at {end_tick}, {off:+.0} ticks off");
    assert!(eta > 1.0, "a real plan: {eta}");
    // Steps end on ticks; a status sample may lag its tick by a few.
    assert!(off.abs() <= 5.0, "ended {off} ticks off its ETA");
}

/// A planner that runs out of its search budget (one expansion): the goal
/// is aborted with the planner's own reason, `PlanTimeout`, seen the same
/// in the outcome, the status and the event.
#[test]
fn a_goal_without_a_plan_carries_the_planners_reason() {
    // Weightless, no disturbance: the search budget, not the load, ends it
    // (under load the refusal is LoadInfeasible: plan_reasons.rs).
    let mut d = TestDaemon::new(
        "noplan",
        "[planner]\nmax_expansions = 1\n[load]\nobject_mass = 0.0\ngravity = [0.0, 0.0, 0.0]\ndisturbance_force = 0.0\n",
    );
    d.spawn();
    let mut c = d.client();
    let me = c.client_id();
    // Half a turn about a tilted axis: several segments and gaits.
    let cmd = Command::goal(me, 1, GoalFrame::AxisAngle, [3.0, 1.0, 1.0, 0.2]);
    let a = c.command(cmd, T).unwrap();
    assert_eq!(a.verdict(), Ok(gaitd_client::Verdict::Accepted));
    let o = c.wait_outcome(1, LONG).unwrap();
    assert_eq!(
        (o.state, o.reason),
        (GoalState::Aborted, ReasonCode::PlanTimeout)
    );
    let s = c.wait_status(T).unwrap();
    assert_eq!(
        (s.goal_state(), s.goal_reason()),
        (Ok(GoalState::Aborted), Ok(ReasonCode::PlanTimeout))
    );
    let e = c
        .events()
        .unwrap()
        .filter(|e| e.kind() == Ok(EventKind::GoalTransition) && e.goal_id == 1)
        .last()
        .expect("a transition");
    assert_eq!(
        (e.state, e.reason),
        (GoalState::Aborted.code(), ReasonCode::PlanTimeout.code())
    );
}
