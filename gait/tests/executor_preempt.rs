//! Goals, cancels and holds arriving mid-execution (mid-gait, mid-roll):
//! the setpoint stream stays continuous, every tick stays within the
//! invariants, and the last goal is reached.

mod planning;

use gait::executor::{ExecutorCommand, GoalStage, GoalTarget, Mode};
use gait::planner::StepKind;
use gait::{HandConfig, HandState};
use planning::run::Rig;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;

#[test]
fn interruptions_keep_the_stream_continuous_and_valid() {
    // Weightless: interruptions, not the load, are under test here (goals
    // under load, refusals included: executor_load.rs, executor_sweep.rs).
    let cfg = planning::weightless();
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let mut rig = Rig::new(cfg, HandState::paper_start(&cfg), 1e-3);
    let mut interrupted: BTreeMap<&'static str, u32> = BTreeMap::new();
    let mut id = 0u64;
    let mut last_goal = None;
    // Rounds until gaits, turns and transfers have each been interrupted
    // (a transfer is mostly made during a turn, so it comes up least).
    let kinds = ["gait", "rotate", "transfer"];
    for round in 0..300 {
        if round >= 60
            && kinds
                .iter()
                .all(|k| interrupted.get(k).copied().unwrap_or(0) > 0)
        {
            break;
        }
        // Let something run for a random while, then interrupt it.
        let wait = rng.random_range(50..2500);
        for _ in 0..wait {
            rig.tick();
        }
        let r = *rig.exec.report();
        let what = match (r.phase, r.step_kind) {
            (Mode::Moving | Mode::Stopping, Some(StepKind::Roll)) => "roll",
            (Mode::Moving | Mode::Stopping, Some(StepKind::Place | StepKind::Lift)) => "gait",
            (Mode::Moving | Mode::Stopping, Some(StepKind::Transfer)) => "transfer",
            (Mode::Moving | Mode::Stopping, Some(StepKind::Rotate)) => "rotate",
            _ => "rest",
        };
        *interrupted.entry(what).or_default() += 1;
        let choice = if round % 10 == 0 {
            0
        } else {
            rng.random_range(0..10)
        };
        match choice {
            0 => {
                rig.command(ExecutorCommand::Cancel);
            }
            1 => {
                rig.command(ExecutorCommand::Hold);
            }
            _ => {
                id += 1;
                let goal = planning::haar(&mut rng);
                rig.command(ExecutorCommand::Goal {
                    id,
                    target: GoalTarget::Orientation(goal),
                    limits: None,
                });
                last_goal = Some((id, goal));
            }
        }
    }
    // The last word: one more goal, run to the end.
    id += 1;
    let goal = planning::haar(&mut rng);
    rig.command(ExecutorCommand::Goal {
        id,
        target: GoalTarget::Orientation(goal),
        limits: None,
    });
    last_goal = Some((id, goal)).or(last_goal);
    rig.run_until_idle(200_000);
    let (last_id, last_q) = last_goal.unwrap();
    let err = rig.plant.state().object.angle_to(&last_q);
    println!(
        "interrupted while: {interrupted:?}; {} ticks",
        rig.stats.ticks
    );
    let s = &rig.stats;
    assert!(
        s.violations.is_empty(),
        "{:?}",
        &s.violations[..s.violations.len().min(5)]
    );
    assert_eq!(s.slips, 0);
    assert!(
        s.discontinuities.is_empty(),
        "{:?}",
        &s.discontinuities[..s.discontinuities.len().min(5)]
    );
    assert_eq!(s.faults, 0);
    assert!(s.unmoved_steps.is_empty(), "{:?}", s.unmoved_steps);
    assert!(err < 1e-6, "last goal error {err}");
    assert_eq!(s.goals.last(), Some(&(last_id, GoalStage::Succeeded)));
    for kind in kinds {
        assert!(
            interrupted.get(kind).copied().unwrap_or(0) > 0,
            "never interrupted a {kind}"
        );
    }
}

#[test]
fn a_goal_preempts_the_initial_roll() {
    let cfg = HandConfig::default();
    let mut rig = Rig::new(cfg, HandState::paper_start(&cfg), 1e-3);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    rig.command(ExecutorCommand::Goal {
        id: 1,
        target: GoalTarget::Orientation(planning::haar(&mut rng)),
        limits: None,
    });
    // Tick into the roll to a two-finger grasp (after a turn or a tilt
    // with all three fingers, if the plan starts with one).
    let mut ticks = 0;
    while rig.exec.report().step_kind != Some(StepKind::Roll) {
        rig.tick();
        ticks += 1;
        assert!(ticks < 5000, "the plan rolls a pair apart first");
    }
    for _ in 0..300 {
        rig.tick();
    }
    assert_eq!(rig.exec.report().step_kind, Some(StepKind::Roll));
    let goal = planning::haar(&mut rng);
    rig.command(ExecutorCommand::Goal {
        id: 2,
        target: GoalTarget::Orientation(goal),
        limits: None,
    });
    rig.run_until_idle(100_000);
    let s = &rig.stats;
    assert!(
        s.violations.is_empty(),
        "{:?}",
        &s.violations[..s.violations.len().min(5)]
    );
    assert!(
        s.discontinuities.is_empty(),
        "{:?}",
        &s.discontinuities[..s.discontinuities.len().min(5)]
    );
    assert_eq!(
        s.goals,
        vec![(1, GoalStage::Preempted), (2, GoalStage::Succeeded)]
    );
    assert!(rig.plant.state().object.angle_to(&goal) < 1e-6);
}

#[test]
fn a_stop_near_the_end_of_a_step_does_not_announce_the_next_one() {
    // Hold at every tick of the last 60 ms of the first Rotate: the motion
    // comes to rest on the step's path (or, were braking to overshoot the
    // path, at the step's resting end) and the stop ends there. The next
    // step is never begun, so no `Step` event may announce it (the daemon
    // would publish a Lift or Roll that never happens).
    let cfg = HandConfig::default();
    let start = HandState::paper_start(&cfg);
    let goal = ExecutorCommand::Goal {
        id: 1,
        target: GoalTarget::Rotation {
            axis: nalgebra::Vector3::z(),
            angle: 1.0,
        },
        limits: None,
    };
    let mut rig = Rig::new(cfg, start, 1e-3);
    rig.command(goal);
    let mut end = 0;
    let mut in_rotate = false;
    for t in 1..20_000 {
        let kind = rig.tick().step_kind;
        if kind == Some(StepKind::Rotate) {
            in_rotate = true;
        } else if in_rotate {
            end = t;
            break;
        }
    }
    assert!(end > 0, "no Rotate step ended");
    for lead in 1..=60 {
        let mut rig = Rig::new(cfg, start, 1e-3);
        rig.command(goal);
        for _ in 1..end - lead {
            rig.tick();
        }
        assert_eq!(rig.exec.report().step_kind, Some(StepKind::Rotate));
        rig.command(ExecutorCommand::Hold);
        rig.run_until_idle(10_000);
        assert!(
            rig.stats.unmoved_steps.is_empty(),
            "hold {lead} ticks before the end: {:?}",
            rig.stats.unmoved_steps
        );
        assert!(rig.stats.violations.is_empty() && rig.stats.discontinuities.is_empty());
        assert_eq!(
            rig.exec.phase(),
            Mode::Holding,
            "hold {lead} ticks before the end"
        );
    }
}
