//! The executor runs plans on the kinematic hand: goals reached exactly,
//! every tick within the invariants, no slip, continuous setpoints.

mod planning;

use gait::executor::{ExecutorCommand, GoalStage, GoalTarget};
use gait::{HandConfig, HandState};
use nalgebra::Vector3;
use planning::run::Rig;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn assert_clean(rig: &Rig, what: &str) {
    let s = &rig.stats;
    assert!(
        s.violations.is_empty(),
        "{what}: {:?}",
        &s.violations[..s.violations.len().min(5)]
    );
    assert_eq!(s.slips, 0, "{what}: slip");
    assert!(
        s.discontinuities.is_empty(),
        "{what}: {:?}",
        &s.discontinuities[..s.discontinuities.len().min(5)]
    );
    assert_eq!(s.faults, 0, "{what}: faults");
}

#[test]
fn paper_scenario_full_turns_about_z_and_x() {
    // The lifecycle, not the load: a weightless object (planning::weightless).
    let cfg = planning::weightless();
    let start = HandState::paper_start(&cfg);
    let mut rig = Rig::new(cfg, start, 1e-3);
    let turns = [(1, Vector3::z()), (2, Vector3::x())];
    for (id, axis) in turns {
        let before = rig.plant.state().object;
        let target = GoalTarget::Rotation {
            axis,
            angle: std::f64::consts::TAU,
        };
        assert_eq!(
            rig.command(ExecutorCommand::Goal {
                id,
                target,
                limits: None
            }),
            gait::executor::ExecutorAnswer::Accepted
        );
        let ticks = rig.run_until_idle(200_000);
        let after = rig.plant.state().object;
        let err = before.angle_to(&after);
        println!("turn {id}: {ticks} ticks, final error {err:.2e} rad");
        assert!(err < 1e-6, "full turn ends where it started: {err}");
        assert_eq!(rig.stats.goals.last(), Some(&(id, GoalStage::Succeeded)));
    }
    assert_clean(&rig, "paper scenario");
}

#[test]
fn random_goals_from_the_paper_start() {
    // The lifecycle, not the load: a weightless object (planning::weightless).
    let cfg = planning::weightless();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut rig = Rig::new(cfg, HandState::paper_start(&cfg), 1e-3);
    for id in 1..=30u64 {
        let goal = planning::haar(&mut rng);
        rig.command(ExecutorCommand::Goal {
            id,
            target: GoalTarget::Orientation(goal),
            limits: None,
        });
        rig.run_until_idle(100_000);
        let err = rig.plant.state().object.angle_to(&goal);
        assert!(err < 1e-6, "goal {id}: error {err}");
        assert_eq!(rig.stats.goals.last(), Some(&(id, GoalStage::Succeeded)));
    }
    println!("{} ticks", rig.stats.ticks);
    assert_clean(&rig, "random goals");
}

/// The planner's step durations are the trajectory generator's (plus the
/// handover wait): each step of executed plans takes its planned
/// duration, to the tick.
#[test]
fn planned_step_durations_match_execution() {
    use gait::executor::runner::StepRunner;
    let cfg = HandConfig::default();
    let planner = gait::planner::Planner::new(&cfg).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut runner = StepRunner::new(1e-3).unwrap();
    let mut steps = 0;
    for _ in 0..20 {
        let plan = planner
            .plan(&HandState::paper_start(&cfg), &planning::haar(&mut rng))
            .unwrap();
        for step in &plan.steps {
            runner.start(step, &cfg.limits, None);
            let mut ticks = 0u32;
            while runner.advance().unwrap() != otg::Progress::Finished {
                ticks += 1;
            }
            // The handover after the motion is a fixed wait.
            let executed = f64::from(ticks) * 1e-3 + step.handover.map_or(0.0, |h| h.duration);
            assert!(
                (executed - step.duration).abs() <= 1.5e-3,
                "{:?}: planned {} s, executed {executed} s",
                step.kind,
                step.duration
            );
            steps += 1;
        }
    }
    assert!(steps >= 100, "{steps} steps");
}

/// Each step's trajectory comes with its plan, calculated off the loop
/// (`PlanRequest::plan`): the executor adopts it and calculates none on
/// its own thread, and its setpoints are, tick for tick, those it produces
/// when the plan brings none and it calculates each step at its start.
#[test]
fn step_trajectories_come_with_the_plan() {
    use gait::executor::{Executor, Mode};
    use gait::sim::Measurement;
    let cfg = HandConfig::default();
    let planner = gait::planner::Planner::new(&cfg).unwrap();
    let start = HandState::paper_start(&cfg);
    let run = |strip: bool| {
        let mut exec = Executor::new(&cfg, 1e-3, start).unwrap();
        exec.command(ExecutorCommand::Goal {
            id: 1,
            target: GoalTarget::Rotation {
                axis: Vector3::new(1.0, -1.0, 2.0),
                angle: 2.0,
            },
            limits: None,
        });
        let (mut setpoints, mut steps) = (Vec::new(), None);
        // An exact plant: it measures the last setpoint.
        let mut at = start;
        for _ in 0..200_000 {
            let r = *exec.tick(Some(&Measurement::of(&at)));
            at = r.setpoint.state;
            setpoints.push(r.setpoint.state);
            if let Some(req) = exec.take_plan_request() {
                let mut plan = req.plan(&planner).expect("planned");
                assert_eq!(plan.profiles.len(), plan.steps.len());
                assert!(plan.profiles.iter().all(Option::is_some));
                steps = Some(plan.steps.len() as u64);
                if strip {
                    plan.profiles.clear();
                }
                drop(exec.deliver_plan(req.goal, Ok(Box::new(plan))));
            } else if steps.is_some() && r.phase == Mode::Holding {
                break;
            }
        }
        let steps = steps.expect("a plan");
        (setpoints, exec.trajectory_calculations(), steps)
    };
    let (adopted, on_loop, steps) = run(false);
    let (calculated, on_loop_without, _) = run(true);
    assert!(steps >= 5, "a plan with gaits: {steps} steps");
    assert_eq!(on_loop, 0, "trajectories calculated on the loop");
    assert_eq!(on_loop_without, steps, "without profiles, one per step");
    assert_eq!(adopted.len(), calculated.len());
    assert!(adopted == calculated, "the setpoints differ");
}

/// A plan's preview (`planner::preview`) is where the executor takes the
/// hand: undisturbed, its setpoint k ticks after the plan arrives is the
/// preview's point at k periods, every tick to the end.
#[test]
fn a_plans_preview_is_where_the_executor_takes_the_hand() {
    use gait::executor::{Executor, Mode};
    use gait::planner::preview;
    use gait::sim::Measurement;
    let cfg = HandConfig::default();
    let dt = 1e-3;
    let planner = gait::planner::Planner::new(&cfg).unwrap();
    let start = HandState::paper_start(&cfg);
    let mut exec = Executor::new(&cfg, dt, start).unwrap();
    exec.command(ExecutorCommand::Goal {
        id: 1,
        target: GoalTarget::Rotation {
            axis: Vector3::new(1.0, -1.0, 2.0),
            angle: 2.0,
        },
        limits: None,
    });
    let mut at = start;
    let mut plan = None;
    let (mut k, mut compared, mut worst) = (0u32, 0, 0.0f64);
    for _ in 0..200_000 {
        let r = *exec.tick(Some(&Measurement::of(&at)));
        at = r.setpoint.state;
        if let Some(p) = &plan {
            k += 1;
            let ahead = preview::point_at(p, dt, f64::from(k) * dt);
            let mut err = ahead.object.angle_to(&at.object);
            for (f, tip) in at.fingers.iter().zip(ahead.tips) {
                err = err.max((f.center - tip).norm());
            }
            worst = worst.max(err);
            compared += 1;
            if r.phase == Mode::Holding {
                let end = preview::duration(p, dt);
                assert!(
                    (f64::from(k) * dt - end).abs() < 0.5 * dt,
                    "the goal ended at tick {k}, the preview at {end} s"
                );
                break;
            }
        }
        if let Some(req) = exec.take_plan_request() {
            let p = req.plan(&planner).expect("planned");
            plan = Some(p.clone());
            drop(exec.deliver_plan(req.goal, Ok(Box::new(p))));
        }
    }
    let steps = plan.as_ref().map_or(0, |p| p.steps.len());
    assert!(steps >= 5, "a plan with gaits: {steps} steps");
    assert!(compared > 1000, "{compared} ticks compared");
    assert!(worst < 1e-9, "the preview is {worst} off the setpoints");
}
