//! Goals from where a cancel leaves the hand, under the default load (SPEC
//! §1.3 I1', §6.4): the executor brakes a roll, rotation or transfer
//! mid-path and finishes a gait, so the hand rests in a grasp no plan
//! ends in (a finger in the air, a pair far from any goal's choice). A
//! user's next goal from there — a turn (`gaitctl reorient --relative`, a
//! `GoalTarget::Rotation`), then an orientation — must plan, hold the load
//! at every sample by the test's own SOCP, and be reached by the plant; or
//! be refused with a reason that says no plan was found, the hand left
//! where it rests. How many are refused is printed: the planner's coverage
//! from where cancels leave the hand.
//!
//! CI runs `GAIT_CANCEL_ROUNDS` canceled goals (default 8), each followed
//! by a turn and an orientation; the long run (gait/PLANNER-FIGURES.md) is
//! `GAIT_CANCEL_ROUNDS=60 cargo test --release -p gait --test cancel_load
//! -- --nocapture`.

mod planning;

use gait::executor::{ExecutorCommand, GoalStage, GoalTarget, Mode};
use gait::planner::PlanError;
use gait::{HandConfig, HandState};
use nalgebra::Vector3;
use planning::load::LoadCheck;
use planning::plan_load::assert_held;
use planning::run::Rig;
use planning::verify::Checker;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Ticks of 1 ms.
const DT: f64 = 1e-3;

/// Sends goal `id` to turn by `deg` about `axis`.
fn turn(rig: &mut Rig, id: u64, axis: Vector3<f64>, deg: f64) {
    rig.command(ExecutorCommand::Goal {
        id,
        target: turn_by(axis, deg),
        limits: None,
    });
}

/// Goal `id` ended `stage` with no fault or broken invariant on the way.
fn assert_ended(rig: &Rig, id: u64, stage: GoalStage, what: &str) {
    assert_eq!(rig.stats.goals.last(), Some(&(id, stage)), "{what}");
    assert_eq!(rig.stats.faults, 0, "{what}: fault");
    assert!(
        rig.stats.plant_violations.is_empty(),
        "{what}, the plant's state: {:?}",
        &rig.stats.plant_violations[..1]
    );
}

/// Plans `target` from where `rig`'s plant rests, checks every sample's
/// load by the test's own SOCP, then sends it as goal `id` and runs it:
/// the plant's object ends where the target says. Returns (duration, F*).
fn goal_from_rest(rig: &mut Rig, id: u64, target: GoalTarget, what: &str) -> (f64, f64) {
    try_goal_from_rest(rig, id, target, what)
        .unwrap_or_else(|e| panic!("{what}: {target:?} refused: {e}"))
}

/// As [`goal_from_rest`], or the planner's refusal — which must say that
/// no plan was found (the search's budget ran out, or nothing it tried
/// held the load) — after which the hand must not have moved.
fn try_goal_from_rest(
    rig: &mut Rig,
    id: u64,
    target: GoalTarget,
    what: &str,
) -> Result<(f64, f64), PlanError> {
    let cfg = rig.cfg;
    let at = *rig.plant.state();
    let goal = target.resolve(&at.object);
    let plan = match target.plan(&rig.planner, &at) {
        Ok(plan) => plan,
        Err(e) => {
            assert!(
                matches!(
                    e,
                    PlanError::Timeout | PlanError::LoadInfeasible { start: false }
                ),
                "{what}: refused for another reason: {e:?}"
            );
            rig.command(ExecutorCommand::Goal {
                id,
                target,
                limits: None,
            });
            rig.run_until_idle(400_000);
            assert_ended(rig, id, GoalStage::Aborted, what);
            let moved = rig.plant.state().object.angle_to(&at.object);
            assert!(
                moved < 1e-9,
                "{what}: refused, yet the object turned {moved:.2e} rad"
            );
            return Err(e);
        }
    };
    let f = assert_held(
        &LoadCheck::new(&cfg),
        &Checker::new(&cfg),
        &cfg,
        &plan,
        what,
    );
    rig.command(ExecutorCommand::Goal {
        id,
        target,
        limits: None,
    });
    rig.run_until_idle(400_000);
    assert_ended(rig, id, GoalStage::Succeeded, what);
    let err = rig.plant.state().object.angle_to(&goal);
    assert!(
        err < 1e-6,
        "{what}: the plant's object is {err:.2e} rad off"
    );
    Ok((plan.summary.duration, f))
}

/// A turn by `deg` about `axis` (as `gaitctl reorient --relative` sends).
fn turn_by(axis: Vector3<f64>, deg: f64) -> GoalTarget {
    GoalTarget::Rotation {
        axis,
        angle: deg.to_radians(),
    }
}

#[test]
fn a_turn_after_the_canceled_turn_of_the_walkthrough_plans_and_holds() {
    // A user's walkthrough (deploy/gaitd.toml, 0.1 kg): 90° about z, then
    // 120° about x canceled after 1.2 s, then 28.65° about z, from a
    // two-finger grasp no plan ends in: it must plan, hold and be reached.
    let cfg = HandConfig::default();
    let mut rig = Rig::new(cfg, HandState::paper_start(&cfg), DT);
    turn(&mut rig, 1, Vector3::z(), 90.0);
    rig.run_until_idle(200_000);
    assert_ended(&rig, 1, GoalStage::Succeeded, "90° about z");
    turn(&mut rig, 2, Vector3::x(), 120.0);
    for _ in 0..1200 {
        rig.tick();
    }
    assert_eq!(rig.exec.phase(), Mode::Moving, "canceled before it ended");
    rig.command(ExecutorCommand::Cancel);
    rig.run_until_idle(100_000);
    assert_ended(&rig, 2, GoalStage::Canceled, "the canceled turn");
    let (t, f) = goal_from_rest(&mut rig, 3, turn_by(Vector3::z(), 28.65), "28.65° about z");
    println!("28.65° about z after the cancel: {t:.2} s, largest F* {f:.2} N");
}

#[test]
fn turns_from_where_cancels_leave_the_hand_plan_and_hold() {
    let rounds: usize = std::env::var("GAIT_CANCEL_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(8);
    let cfg = HandConfig::default();
    let mut rig = Rig::new(cfg, HandState::paper_start(&cfg), DT);
    let mut rng = ChaCha8Rng::seed_from_u64(0xCA2CE1);
    let (mut id, mut durations, mut peak) = (0u64, Vec::new(), 0.0f64);
    let mut refused = Vec::new();
    let mut canceled_in = std::collections::BTreeMap::<String, u32>::new();
    for round in 0..rounds {
        // A goal canceled a random while after it was sent: mid-roll,
        // mid-rotation, mid-transfer or mid-gait (a gait finishes first).
        id += 1;
        rig.command(ExecutorCommand::Goal {
            id,
            target: GoalTarget::Orientation(planning::haar(&mut rng)),
            limits: None,
        });
        for _ in 0..rng.random_range(300..4000) {
            rig.tick();
        }
        let r = *rig.exec.report();
        if r.phase != Mode::Moving {
            // It ended (or was refused) first: go on from there.
            rig.run_until_idle(400_000);
            continue;
        }
        *canceled_in
            .entry(format!("{:?}", r.step_kind.expect("moving")))
            .or_default() += 1;
        rig.command(ExecutorCommand::Cancel);
        rig.run_until_idle(100_000);
        assert_ended(&rig, id, GoalStage::Canceled, &format!("round {round}"));
        // From there a turn about a random axis by up to 170°, then a
        // Haar orientation.
        let axis = planning::unit(&mut rng);
        let deg = rng.random_range(5.0..170.0);
        let goals = [
            ("turn", turn_by(axis, deg)),
            (
                "orientation",
                GoalTarget::Orientation(planning::haar(&mut rng)),
            ),
        ];
        for (kind, target) in goals {
            id += 1;
            let what = format!("round {round}, {kind}");
            match try_goal_from_rest(&mut rig, id, target, &what) {
                Ok((t, f)) => {
                    durations.push(t);
                    peak = peak.max(f);
                }
                Err(e) => refused.push(format!("{what}: {e:?}")),
            }
        }
    }
    durations.sort_by(f64::total_cmp);
    println!(
        "{rounds} goals, canceled while {canceled_in:?}; {} goals after them (a turn, then an \
         orientation) planned, held and reached, {} refused {refused:?}: time median {:.2} s, \
         max {:.2} s; largest F* {peak:.2} N",
        durations.len(),
        refused.len(),
        durations
            .get(durations.len() / 2)
            .copied()
            .unwrap_or(f64::NAN),
        durations.last().copied().unwrap_or(f64::NAN),
    );
    assert!(
        canceled_in.values().sum::<u32>() * 2 >= rounds as u32,
        "too few goals were canceled while moving: {canceled_in:?}"
    );
}
