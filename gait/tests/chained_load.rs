//! Goals one after another, each from wherever the last one ended (as the
//! daemon runs them), under the default load (SPEC §1.3 I1'): after the
//! paper's full turns about z and x, seeded Haar goals. Every plan must
//! hold the load at every sample by the test's own SOCP and stay within
//! `load.max_grip`; a goal the planner refuses must be refused with
//! `LoadInfeasible`, the hand staying where it is. How many are refused
//! is printed: a figure, the planner's coverage from reached states (the
//! MuJoCo closed loop's refusals, gait/LOAD-FIGURES.md §10).

mod planning;

use gait::planner::{PlanError, Planner};
use gait::{HandConfig, HandState};
use nalgebra::Vector3;
use planning::load::LoadCheck;
use planning::plan_load::assert_held;
use planning::verify::Checker;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Where the paper's full turns about z, then x, leave the hand.
fn after_the_paper_turns(cfg: &HandConfig, planner: &Planner) -> HandState {
    let mut at = HandState::paper_start(cfg);
    for axis in [Vector3::z(), Vector3::x()] {
        at = planner
            .plan_rotation(&at, &axis, std::f64::consts::TAU)
            .unwrap_or_else(|e| panic!("paper turn about {:?}: {e}", axis.as_slice()))
            .end_state();
    }
    at
}

#[test]
fn chained_goals_hold_the_load_or_are_refused_with_their_reason() {
    let n: usize = std::env::var("GAIT_CHAIN_GOALS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(30);
    let mut cfg = HandConfig::default();
    if let Some(w) = std::env::var("GAIT_WAYPOINTS")
        .ok()
        .and_then(|v| v.parse().ok())
    {
        cfg.planner.waypoint_axes = w;
    }
    let planner = Planner::new(&cfg).unwrap();
    let check = LoadCheck::new(&cfg);
    let checker = Checker::new(&cfg);
    let mut at = after_the_paper_turns(&cfg, &planner);
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let (mut refused, mut gaits, mut peak) = (Vec::new(), Vec::new(), 0.0f64);
    let (mut durations, mut wall) = (Vec::new(), Vec::new());
    for i in 0..n {
        let goal = planning::haar(&mut rng);
        let t0 = std::time::Instant::now();
        let planned = planner.plan(&at, &goal);
        wall.push(t0.elapsed().as_secs_f64());
        match planned {
            Ok(plan) => {
                let f = assert_held(&check, &checker, &cfg, &plan, &format!("goal {i}"));
                let end = plan.end_state();
                assert!(end.object.angle_to(&goal) < 1e-9, "goal {i}: not reached");
                peak = peak.max(f);
                gaits.push(plan.summary.gaits);
                durations.push(plan.summary.duration);
                at = end;
            }
            Err(e) => {
                assert_eq!(
                    e,
                    PlanError::LoadInfeasible { start: false },
                    "goal {i}: refused for another reason"
                );
                refused.push(i);
            }
        }
    }
    gaits.sort_unstable();
    durations.sort_by(f64::total_cmp);
    wall.sort_by(f64::total_cmp);
    let at_ = |v: &[f64], p: f64| {
        v.get(((v.len() as f64 * p) as usize).min(v.len().max(1) - 1))
            .copied()
            .unwrap_or(f64::NAN)
    };
    println!(
        "{n} chained goals after the paper's scenario, 0.1 kg, {} waypoint axes: {} planned, \
         refused {refused:?}; gaits median {}, max {}; time to goal median {:.2} s, p95 {:.2}, \
         max {:.2}; largest F* {peak:.2} N; planning wall time median {:.3} s, max {:.2} s",
        cfg.planner.waypoint_axes,
        n - refused.len(),
        gaits.get(gaits.len() / 2).copied().unwrap_or(0),
        gaits.last().copied().unwrap_or(0),
        at_(&durations, 0.5),
        at_(&durations, 0.95),
        durations.last().copied().unwrap_or(f64::NAN),
        at_(&wall, 0.5),
        wall.last().copied().unwrap_or(f64::NAN),
    );
}

#[test]
fn a_reached_grasp_the_search_cannot_leave_plans_by_way_of_a_waypoint() {
    // Goal 7 of the chain above: from where goals 0–6 left the hand, the
    // search about the goal's axis runs out of nodes in every tier
    // (refused with waypoint_axes = 0); by way of the start turned 90°
    // about one of 8 directions it plans, held at every sample.
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let mut at = after_the_paper_turns(&cfg, &planner);
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    for i in 0..7 {
        let goal = planning::haar(&mut rng);
        at = planner
            .plan(&at, &goal)
            .unwrap_or_else(|e| panic!("chain goal {i}: {e}"))
            .end_state();
    }
    let goal = planning::haar(&mut rng);
    let mut without = cfg;
    without.planner.waypoint_axes = 0;
    assert_eq!(
        Planner::new(&without).unwrap().plan(&at, &goal),
        Err(PlanError::LoadInfeasible { start: false }),
        "goal 7 plans without waypoints: pick another stuck grasp"
    );
    let plan = planner
        .plan(&at, &goal)
        .expect("planned by way of a waypoint");
    let f = assert_held(
        &LoadCheck::new(&cfg),
        &Checker::new(&cfg),
        &cfg,
        &plan,
        "goal 7",
    );
    assert_eq!(plan.start, at);
    assert!(plan.end_state().object.angle_to(&goal) < 1e-9);
    println!(
        "goal 7 by way of a waypoint: {} gaits, {:.2} s, largest F* {f:.2} N",
        plan.summary.gaits, plan.summary.duration
    );
}
