//! Haar-random goals planned and executed tick by tick on the kinematic
//! hand, from the paper's start and from random valid states:
//! every goal succeeds with final error ≤ 1e-6 rad *of the plant's true
//! object* (not the controller's setpoint), and an independent per-tick
//! check (force closure, workspace, hemisphere, roll, collisions, no slip:
//! equal arcs at every grasping contact between ticks) finds nothing, on
//! the plant's true state as on the command; setpoints are continuous.
//!
//! CI runs `GAIT_SWEEP_GOALS` goals from random states (default 300) and
//! half as many from the paper start, on two threads; the full sweep (10⁴ from random
//! states, 5000 from the paper start) is `GAIT_SWEEP_GOALS=10000 cargo
//! test --release -p gait --test executor_sweep -- --nocapture`.

mod planning;

use gait::executor::{ExecutorCommand, GoalStage, GoalTarget};
use gait::{HandConfig, HandState};
use nalgebra::UnitQuaternion;
use planning::run::Rig;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn goals() -> usize {
    std::env::var("GAIT_SWEEP_GOALS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300)
}

fn sweep(seed: u64, random_start: bool) {
    // From the paper start with the default load (gravity on); from random
    // states weightless, the kinematic regime (planning::weightless).
    let cfg = if random_start {
        planning::weightless()
    } else {
        HandConfig::default()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // From the paper start, under load, half as many: its goals plan
    // slowest (tilts, rolls apart and turns with all three fingers).
    let n = if random_start {
        goals()
    } else {
        goals().div_ceil(2)
    };
    // The goals (and starts) in the seeded order, then executed on two
    // threads: from the paper start, planning under load dominates (~280 s
    // on one core in CI's profile, the other idle).
    let cases: Vec<(HandState, UnitQuaternion<f64>)> = (0..n)
        .map(|_| {
            let start = if random_start {
                planning::random_two_finger_state(&mut rng, &cfg)
            } else {
                HandState::paper_start(&cfg)
            };
            (start, planning::haar(&mut rng))
        })
        .collect();
    let outcomes = planning::on_two_threads(n, |i| execute(cfg, i, &cases[i], random_start));
    let (mut ticks, mut worst_err, mut exec_s) = (0u64, 0.0f64, Vec::with_capacity(n));
    let mut failed = Vec::new();
    let mut refused_load = Vec::new();
    for (i, o) in outcomes.into_iter().enumerate() {
        match o.end {
            End::Succeeded => worst_err = worst_err.max(o.err),
            End::Failed(last) => failed.push((i, last)),
            End::Refused => refused_load.push(i),
        }
        ticks += o.ticks;
        exec_s.push(o.ticks as f64 * 1e-3);
    }
    exec_s.sort_by(f64::total_cmp);
    println!("not succeeded: {failed:?}; refused under load (LoadInfeasible): {refused_load:?}");
    let mean = exec_s.iter().sum::<f64>() / n as f64;
    println!(
        "{} goals from {}: {} succeeded; {ticks} ticks checked; worst final error {worst_err:.1e} rad; execution mean {mean:.2} s p95 {:.2} s max {:.2} s",
        n,
        if random_start {
            "random valid states"
        } else {
            "the paper's start"
        },
        n - failed.len() - refused_load.len(),
        exec_s[(n * 95 / 100).min(n - 1)],
        exec_s[n - 1]
    );
    assert!(failed.is_empty(), "goals that did not succeed: {failed:?}");
    // At most 1 % refused (planner_load.rs measured 0.68 % of 10⁴).
    assert!(
        refused_load.len() * 100 <= n,
        "refused under load: {refused_load:?}"
    );
}

/// How a goal ended: succeeded, refused under load with its reason, or
/// not succeeded (the last goal stage seen).
enum End {
    Succeeded,
    Refused,
    Failed(Option<(u64, GoalStage)>),
}

/// One goal's outcome: its end, the plant's final error, ticks run.
struct Outcome {
    end: End,
    err: f64,
    ticks: u64,
}

/// Executes goal `i` from its start tick by tick; every tick checked
/// (panics with the goal's number on a violation).
fn execute(
    cfg: HandConfig,
    i: usize,
    (start, goal): &(HandState, UnitQuaternion<f64>),
    random_start: bool,
) -> Outcome {
    let mut rig = Rig::new(cfg, *start, 1e-3);
    rig.command(ExecutorCommand::Goal {
        id: 1,
        target: GoalTarget::Orientation(*goal),
        limits: None,
    });
    let t = rig.run_until_idle(200_000);
    let s = &rig.stats;
    let err = rig.plant.state().object.angle_to(goal);
    // Every tick is checked whatever the outcome; a goal that did not
    // succeed is listed (and fails the test at the end).
    let end = if s.goals.last() == Some(&(1, GoalStage::Succeeded)) {
        End::Succeeded
    } else if !random_start
        // Under load a goal may be refused with its reason (SPEC §1.3
        // I1'): the planner's answer for it, counted apart.
        && gait::planner::Planner::new(&cfg).unwrap().plan(start, goal)
            == Err(gait::planner::PlanError::LoadInfeasible { start: false })
    {
        End::Refused
    } else {
        End::Failed(s.goals.last().copied())
    };
    assert!(
        !matches!(end, End::Succeeded) || err <= 1e-6,
        "goal {i}: final error {err}"
    );
    assert!(
        s.violations.is_empty(),
        "goal {i}: {:?}",
        &s.violations[..s.violations.len().min(3)]
    );
    assert_eq!(s.slips, 0, "goal {i}: slip");
    assert!(
        s.plant_violations.is_empty(),
        "goal {i}, the plant's state: {:?}",
        &s.plant_violations[..s.plant_violations.len().min(3)]
    );
    assert_eq!(s.plant_slips, 0, "goal {i}: the plant slipped");
    assert!(
        s.discontinuities.is_empty(),
        "goal {i}: {:?}",
        &s.discontinuities[..s.discontinuities.len().min(3)]
    );
    assert_eq!(s.faults, 0, "goal {i}: fault");
    Outcome { end, err, ticks: t }
}

#[test]
fn goals_from_the_paper_start_execute_cleanly() {
    sweep(101, false);
}

#[test]
fn goals_from_random_states_execute_cleanly() {
    sweep(202, true);
}
