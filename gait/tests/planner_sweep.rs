//! Seeded sweeps of Haar-random goals: every plan is checked state by state
//! by an independent checker and must end exactly at the goal.

mod planning;

use gait::planner::Planner;
use gait::{HandConfig, HandState};
use nalgebra::UnitQuaternion;
use planning::verify::Checker;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Plans goal `i` and checks the plan state by state: its duration, gaits
/// and whether it escaped, or `None` when refused under load (with its
/// reason; any other error fails).
fn plan_one(
    planner: &Planner,
    checker: &Checker,
    i: usize,
    (start, goal): &(HandState, UnitQuaternion<f64>),
    load: bool,
) -> Option<(f64, f64, bool)> {
    match planner.plan(start, goal) {
        Ok(plan) => {
            let v = checker.check_plan(&plan, 50);
            assert!(v.is_empty(), "goal {i}: {:?}", &v[..v.len().min(5)]);
            let err = plan.end_state().object.angle_to(goal);
            assert!(err < 1e-9, "goal {i}: final error {err}");
            Some((
                plan.summary.duration,
                f64::from(plan.summary.gaits),
                plan.summary.escaped,
            ))
        }
        Err(e) => {
            // Under load a goal may be refused, with its reason.
            assert!(
                load && e == gait::planner::PlanError::LoadInfeasible { start: false },
                "goal {i}: {e:?}"
            );
            eprintln!("goal {i}: {e}");
            None
        }
    }
}

fn sweep(n: usize, seed: u64, random_start: bool, load: bool) {
    // With the default load (gravity on: every plan also holds it,
    // planner_load.rs checks that), or weightless, the kinematic regime
    // (planning::weightless).
    let cfg = if load {
        HandConfig::default()
    } else {
        planning::weightless()
    };
    let planner = Planner::new(&cfg).unwrap();
    let checker = Checker::new(&cfg);
    let start = HandState::paper_start(&cfg);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // The goals (and starts) in the seeded order, planned on two threads
    // (measured in CI's profile: this binary 153 → 101 s).
    let cases: Vec<(HandState, UnitQuaternion<f64>)> = (0..n)
        .map(|_| {
            let start = if random_start {
                planning::random_two_finger_state(&mut rng, &cfg)
            } else {
                start
            };
            (start, planning::haar(&mut rng))
        })
        .collect();
    let outcomes =
        planning::on_two_threads(n, |i| plan_one(&planner, &checker, i, &cases[i], load));
    let (mut durations, mut gaits, mut fails, mut escapes) = (Vec::new(), Vec::new(), 0, 0);
    for o in outcomes {
        match o {
            Some((d, g, e)) => {
                durations.push(d);
                gaits.push(g);
                escapes += e as usize;
            }
            None => fails += 1,
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let mut d = durations.clone();
    d.sort_by(f64::total_cmp);
    println!(
        "n={n} fails={fails} escapes={escapes} duration mean {:.2} p95 {:.2} max {:.2} s; gaits mean {:.2} max {}",
        mean(&durations),
        d[(d.len() * 95 / 100).min(d.len() - 1)],
        d[d.len() - 1],
        mean(&gaits),
        gaits.iter().cloned().fold(0.0, f64::max)
    );
    // Under load: at most 0.5 % refused (measured 3 in 10³: the unwind
    // escape may not spin a contact under load, SPEC §1.3 I1').
    assert!(
        fails as f64 <= if load { 0.005 * n as f64 } else { 0.0 },
        "{fails} of {n} goals not planned"
    );
}

#[test]
fn paper_start_random_goals() {
    sweep(10000, 1, false, false);
}

#[test]
fn paper_start_random_goals_under_load() {
    // Fewer: planning under load takes far longer (the load tests, the
    // paper start's rolls apart); the count of 2000 and 10⁴ goals is
    // planner_load.rs's release run.
    sweep(200, 3, false, true);
}

#[test]
fn random_states_random_goals() {
    sweep(10000, 2, true, false);
}
