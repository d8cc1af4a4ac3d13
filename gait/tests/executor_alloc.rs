//! Zero heap allocations per executor tick over ≥ 10⁵ ticks that include
//! rolling, gaits, preemption, cancels, faults and replans after contact
//! drift (SPEC §6.1, §6.3, §11). A
//! counting global allocator counts only inside `Executor::tick` and
//! `Executor::command` (planning, which allocates, runs outside them, as it
//! does on the daemon's planner thread).

mod chain_hand;
#[path = "../../kinematics/tests/common/mod.rs"]
mod common;
mod planning;

use std::cell::Cell;

use gait::executor::{Executor, ExecutorCommand, ExecutorEvent, GoalTarget};
use gait::planner::{GoalPlanner, Planner, StepKind};
use gait::sim::{InjectedFault, KinematicHand, Plant};
use gait::{HandConfig, HandState};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use test_support::counting;

#[global_allocator]
static GLOBAL: counting::Counting = counting::Counting;

thread_local! {
    /// This thread's heap traffic in `counted` sections so far.
    static HEAP: Cell<counting::Counts> = const { Cell::new(counting::Counts::ZERO) };
}

fn counted<T>(f: impl FnOnce() -> T) -> T {
    let (r, c) = counting::count(f);
    HEAP.with(|h| {
        let mut sum = h.get();
        sum += c;
        h.set(sum);
    });
    r
}

/// Runs a random mix of goals, cancels, holds, slips, faults and resets for
/// `ticks` ticks from `start`; returns the step kinds seen, goals sent and
/// drifts recovered from.
fn run_mix(cfg: &HandConfig, start: HandState, ticks: u64, seed: u64) -> ([bool; 5], u64, u64) {
    let planner = Planner::new(cfg).unwrap();
    let exec = Executor::new(cfg, 1e-3, start).unwrap();
    run_mix_with(&planner, exec, start, ticks, seed)
}

/// [`run_mix`] with `exec` of any hand, planned by `planner`.
fn run_mix_with(
    planner: &impl GoalPlanner,
    mut exec: Executor,
    start: HandState,
    ticks: u64,
    seed: u64,
) -> ([bool; 5], u64, u64) {
    let mut plant = KinematicHand::new(start, 1e-3);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut old_plans = Vec::new();
    let mut seen = [false; 5];
    let mut id = 0;
    let mut next_event = 300;
    let mut clear_fault_at = None;
    let mut drifts = 0;
    for t in 0..ticks {
        let m = plant.read();
        let rep = *counted(|| exec.tick(m.as_ref()));
        plant.write(&rep.setpoint);
        if let Some(k) = rep.step_kind {
            seen[k as usize] = true;
        }
        drifts += counted(|| {
            let mut n = 0;
            while let Some(e) = exec.pop_event() {
                n += matches!(e, ExecutorEvent::Drift { .. }) as u64;
            }
            n
        });
        if let Some(req) = exec.take_plan_request() {
            let plan = req.plan(planner).map(Box::new);
            let old = counted(|| exec.deliver_plan(req.goal, plan));
            old_plans.extend(old); // freed here, off the "loop"
        }
        if t == next_event {
            next_event += rng.random_range(200..2000);
            let cmd = match rng.random_range(0..16) {
                0 => ExecutorCommand::Cancel,
                1 => ExecutorCommand::Hold,
                2 => {
                    plant.inject(Some(InjectedFault::Missing));
                    clear_fault_at = Some(t + 20);
                    ExecutorCommand::Hold
                }
                3 | 4 => {
                    // A slip of one tick: stop, re-base, replan.
                    plant.inject(Some(InjectedFault::Slip {
                        axis: planning::unit(&mut rng),
                        rate: 2.0,
                    }));
                    clear_fault_at = Some(t + 1);
                    continue;
                }
                5 => {
                    // Sensor noise for 50 ticks: the measured state differs
                    // from the command, so the limit guard evaluates it.
                    plant.inject(Some(InjectedFault::Noise {
                        position: 1e-5,
                        angle: 1e-5,
                    }));
                    clear_fault_at = Some(t + 50);
                    continue;
                }
                _ => {
                    id += 1;
                    ExecutorCommand::Goal {
                        id,
                        target: GoalTarget::Orientation(planning::haar(&mut rng)),
                        limits: None,
                    }
                }
            };
            counted(|| exec.command(cmd));
        }
        if clear_fault_at == Some(t) {
            plant.inject(None);
            clear_fault_at = None;
        }
        if exec.phase() == gait::executor::Mode::SafeHold && plant.fault().is_none() {
            counted(|| exec.command(ExecutorCommand::Reset));
        }
    }
    (seen, id, drifts)
}

#[test]
fn executor_ticks_do_not_allocate() {
    let cfg = HandConfig::default();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    // From the paper's start (rolling) and from a random two-finger state
    // whose free finger hovers low (transfers).
    let (a, goals_a, drifts_a) = run_mix(&cfg, HandState::paper_start(&cfg), 70_000, 99);
    let mut random = planning::random_two_finger_state(&mut rng, &cfg);
    let free = (0..3)
        .find(|&k| random.fingers[k].mode == gait::FingerMode::Free)
        .unwrap();
    let dir = random.fingers[free].center.normalize();
    random.fingers[free].center = dir * 0.61;
    let (b, goals_b, drifts_b) = run_mix(&cfg, random, 50_000, 98);
    let seen: [bool; 5] = std::array::from_fn(|i| a[i] || b[i]);
    let id = goals_a + goals_b;
    let ticks = 120_000;
    let kinds = [
        StepKind::Roll,
        StepKind::Rotate,
        StepKind::Transfer,
        StepKind::Place,
        StepKind::Lift,
    ];
    for k in kinds {
        assert!(seen[k as usize], "no {k:?} step ran ({seen:?}, {id} goals)");
    }
    let drifts = drifts_a + drifts_b;
    println!("{id} goals, {drifts} drifts, step kinds seen {seen:?}");
    assert!(id > 20, "{id} goals");
    assert!(drifts > 5, "{drifts} drifts");
    assert!(counting::is_installed());
    let heap = HEAP.with(Cell::get);
    assert!(heap.is_zero(), "{heap} in {ticks} ticks");
}

/// The same mix on TriFingerPro's chains: the per-tick check of the
/// chain's limits (inverse and forward kinematics, capsules) allocates
/// nothing either.
#[test]
fn chain_hand_ticks_do_not_allocate() {
    let planner = chain_hand::planner();
    let start = chain_hand::start(planner.model());
    let cfg = *planner.model().config();
    let exec = Executor::for_chains(&cfg, planner.model().hand().clone(), 1e-3, start).unwrap();
    let (seen, goals, drifts) = run_mix_with(&planner, exec, start, 40_000, 97);
    println!("{goals} goals, {drifts} drifts, step kinds seen {seen:?}");
    for k in [
        StepKind::Rotate,
        StepKind::Lift,
        StepKind::Transfer,
        StepKind::Place,
    ] {
        assert!(
            seen[k as usize],
            "no {k:?} step ran ({seen:?}, {goals} goals)"
        );
    }
    assert!(goals > 5, "{goals} goals");
    assert!(counting::is_installed());
    let heap = HEAP.with(Cell::get);
    assert!(heap.is_zero(), "{heap} in 40000 ticks");
}
