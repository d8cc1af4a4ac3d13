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
use planning::plan_load::plan_load;
use planning::verify::Checker;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

#[test]
fn chained_goals_hold_the_load_or_are_refused_with_their_reason() {
    let n: usize = std::env::var("GAIT_CHAIN_GOALS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(30);
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let check = LoadCheck::new(&cfg);
    let checker = Checker::new(&cfg);
    let mut at = HandState::paper_start(&cfg);
    for axis in [Vector3::z(), Vector3::x()] {
        let plan = planner
            .plan_rotation(&at, &axis, std::f64::consts::TAU)
            .unwrap_or_else(|e| panic!("paper turn about {:?}: {e}", axis.as_slice()));
        at = plan.end_state();
    }
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let (mut refused, mut gaits, mut peak) = (Vec::new(), Vec::new(), 0.0f64);
    for i in 0..n {
        let goal = planning::haar(&mut rng);
        match planner.plan(&at, &goal) {
            Ok(plan) => {
                let (f, bad) = plan_load(&check, &plan);
                assert_eq!(
                    bad, None,
                    "goal {i}: a sample that does not hold (step, F*)"
                );
                assert!(f <= cfg.load.max_grip * (1.0 + 1e-6), "goal {i}: F* {f} N");
                assert!(checker.check_plan(&plan, 20).is_empty(), "goal {i}");
                let end = plan.end_state();
                assert!(end.object.angle_to(&goal) < 1e-9, "goal {i}: not reached");
                peak = peak.max(f);
                gaits.push(plan.summary.gaits);
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
    println!(
        "{n} chained goals after the paper's scenario, 0.1 kg: {} planned, refused {refused:?}; \
         gaits median {}, max {}; largest F* {peak:.2} N",
        n - refused.len(),
        gaits.get(gaits.len() / 2).copied().unwrap_or(0),
        gaits.last().copied().unwrap_or(0),
    );
}
