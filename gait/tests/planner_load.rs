//! Planning under load (SPEC §1.3 I1', issue "Holding against gravity"),
//! checked independently: every sample of every plan holds the object's
//! weight, the acceleration torque and the disturbance with contact forces
//! in the coupled cones and normal forces within `load.max_grip`, by the
//! test's own SOCP (`planning::load`, Clarabel, its own 26 disturbance
//! directions, no friction margin) — not by the planner's test.
//!
//! CI plans `GAIT_LOAD_GOALS` Haar-random goals from the paper start
//! (default 40); the full run is `GAIT_LOAD_GOALS=10000 cargo test
//! --release -p gait --test planner_load -- --nocapture` (two threads;
//! `GAIT_LOAD_CHECK_EVERY=k` checks every k-th goal independently; runs
//! of 1000 goals or more say on standard error every 500 goals a thread
//! has planned — the 10⁴ run takes over two hours on 2 cores).
//! The 0.5 kg figures: `GAIT_HEAVY_GOALS` (default 12).

mod planning;

use gait::HandConfig;
use gait::HandState;
use gait::planner::{PlanError, Planner, StepKind};
use nalgebra::{UnitQuaternion, Vector3};
use planning::load::{Kind, LoadCheck};
use planning::plan_load::{assert_held, plan_load};
use planning::verify::Checker;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn count(var: &str, default: usize) -> usize {
    std::env::var(var)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn pct(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() as f64 * p) as usize).min(v.len() - 1)]
}

struct Outcome {
    planned: bool,
    duration: f64,
    gaits: f64,
    peak: f64,
    bad: Option<(usize, f64)>,
    kinematic: usize,
    /// Whether the plan spins a contact of a three-finger grasp (the
    /// unwind under load): such plans are always checked.
    spun: bool,
}

/// Plans `goal` from the paper start under `cfg`; the independent load
/// check with `checked` (else the load figures are NaN).
fn one(
    cfg: &HandConfig,
    planner: &Planner,
    check: &LoadCheck,
    goal: &UnitQuaternion<f64>,
    checked: bool,
) -> Outcome {
    let start = HandState::paper_start(cfg);
    match planner.plan(&start, goal) {
        Ok(plan) => {
            let kin = Checker::new(cfg).check_plan(&plan, 20).len();
            let end_err = plan.end_state().object.angle_to(goal);
            assert!(end_err < 1e-9, "final error {end_err}");
            // (Gravity off: only the durations and gaits are compared.)
            let spun = planning::spins_in_a_triple(&plan);
            let (peak, bad) = if !checked && !spun {
                (f64::NAN, None)
            } else if cfg.load.object_mass > 0.0 && cfg.load.gravity != [0.0; 3] {
                plan_load(check, &plan)
            } else {
                (0.0, None)
            };
            Outcome {
                planned: true,
                duration: plan.summary.duration,
                gaits: f64::from(plan.summary.gaits),
                peak,
                bad,
                kinematic: kin,
                spun,
            }
        }
        Err(_) => Outcome {
            planned: false,
            duration: f64::NAN,
            gaits: f64::NAN,
            peak: f64::NAN,
            bad: None,
            kinematic: 0,
            spun: false,
        },
    }
}

/// Plans `goals` under `cfg` on two threads; outcomes in goal order.
/// Every `GAIT_LOAD_CHECK_EVERY`-th goal (default 1: all) gets the
/// independent load check (long runs: the SOCPs dominate).
fn run(cfg: HandConfig, goals: &[UnitQuaternion<f64>]) -> Vec<Outcome> {
    let planner = Planner::new(&cfg).unwrap();
    let check = LoadCheck::new(&cfg);
    let every = count("GAIT_LOAD_CHECK_EVERY", 1).max(1);
    let half = goals.len() / 2;
    let gravity = cfg.load.gravity != [0.0; 3];
    // Long runs (10⁴ goals take over an hour) say how far they are.
    let progress = |thread: &str, i: usize, len: usize| {
        if len >= 1000 && (i + 1).is_multiple_of(500) {
            eprintln!(
                "  [gravity {}] thread {thread}: {}/{len} goals planned",
                if gravity { "on" } else { "off" },
                i + 1
            );
        }
    };
    std::thread::scope(|s| {
        let (a, b) = goals.split_at(half);
        let (planner, check, progress) = (&planner, &check, &progress);
        let ha = s.spawn(move || {
            a.iter()
                .enumerate()
                .map(|(i, g)| {
                    let o = one(&cfg, planner, check, g, i.is_multiple_of(every));
                    progress("a", i, a.len());
                    o
                })
                .collect::<Vec<_>>()
        });
        let hb = s.spawn(move || {
            b.iter()
                .enumerate()
                .map(|(i, g)| {
                    let o = one(&cfg, planner, check, g, (half + i).is_multiple_of(every));
                    progress("b", i, b.len());
                    o
                })
                .collect::<Vec<_>>()
        });
        let mut out = ha.join().unwrap();
        out.extend(hb.join().unwrap());
        out
    })
}

fn goals(n: usize, seed: u64) -> Vec<UnitQuaternion<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| planning::haar(&mut rng)).collect()
}

#[test]
fn plans_from_the_paper_start_hold_the_load_at_every_sample() {
    let n = count("GAIT_LOAD_GOALS", 40);
    let gs = goals(n, 15);
    let on = HandConfig::default();
    let mut off = on;
    off.load.gravity = [0.0; 3];
    let with = run(on, &gs);
    let without = run(off, &gs);
    let failed: Vec<usize> = (0..n).filter(|&i| !with[i].planned).collect();
    let unheld: Vec<(usize, (usize, f64))> =
        (0..n).filter_map(|i| with[i].bad.map(|b| (i, b))).collect();
    let kin: usize = with.iter().map(|o| o.kinematic).sum();
    let stats = |v: &[Outcome], f: fn(&Outcome) -> f64| {
        let mut x: Vec<f64> = v
            .iter()
            .filter(|o| o.planned)
            .map(f)
            .filter(|x| !x.is_nan())
            .collect();
        (
            pct(&mut x, 0.5),
            x.iter().sum::<f64>() / x.len() as f64,
            pct(&mut x, 0.95),
            pct(&mut x, 1.0),
        )
    };
    let (d_on, d_on_mean, d_on95, d_onmax) = stats(&with, |o| o.duration);
    let (d_off, d_off_mean, d_off95, d_offmax) = stats(&without, |o| o.duration);
    let (g_on, g_on_mean, _, g_onmax) = stats(&with, |o| o.gaits);
    let (g_off, g_off_mean, _, g_offmax) = stats(&without, |o| o.gaits);
    let (p_med, _, p95, p_max) = stats(&with, |o| o.peak);
    println!(
        "{n} goals from the paper start, 0.1 kg, load.max_grip {} N: planned {} with gravity, {} without",
        on.load.max_grip,
        n - failed.len(),
        without.iter().filter(|o| o.planned).count()
    );
    println!(
        "  largest F* per goal (independent SOCP, {} goals checked): median {p_med:.2} N, p95 {p95:.2} N, max {p_max:.2} N; goals with samples not held: {}",
        with.iter()
            .filter(|o| o.planned && !o.peak.is_nan())
            .count(),
        unheld.len()
    );
    println!(
        "  time to goal gravity on: median {d_on:.2} s mean {d_on_mean:.2} p95 {d_on95:.2} max {d_onmax:.2}; off: median {d_off:.2} s mean {d_off_mean:.2} p95 {d_off95:.2} max {d_offmax:.2}; median ratio {:.2}",
        d_on / d_off
    );
    println!(
        "  plans that spin a contact of a three-finger grasp (each checked): {} with gravity, {} without",
        with.iter().filter(|o| o.spun).count(),
        without.iter().filter(|o| o.spun).count()
    );
    println!(
        "  gaits gravity on: median {g_on:.0} mean {g_on_mean:.2} max {g_onmax:.0}; off: median {g_off:.0} mean {g_off_mean:.2} max {g_offmax:.0}"
    );
    assert!(failed.is_empty(), "goals not planned: {failed:?}");
    assert!(
        unheld.is_empty(),
        "samples that do not hold the load (goal, (step, F*)): {:?}",
        &unheld[..unheld.len().min(5)]
    );
    assert_eq!(kin, 0, "kinematic invariants broken");
    assert!(p_max <= on.load.max_grip * (1.0 + 1e-6));
}

#[test]
fn the_papers_scenario_holds_the_load() {
    // A full turn about z from the paper start, then one about x from
    // where it ends (not the paper start): both planned at the default
    // 20 N limit and held at every sample — a contact spinning on the
    // object counts as frictionless here (the unwind escape of a
    // three-finger grasp), so the planner may not unwind under load.
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let check = LoadCheck::new(&cfg);
    let checker = Checker::new(&cfg);
    let mut at = HandState::paper_start(&cfg);
    for axis in [Vector3::z(), Vector3::x()] {
        let plan = planner
            .plan_rotation(&at, &axis, std::f64::consts::TAU)
            .unwrap_or_else(|e| panic!("full turn about {:?}: {e}", axis.as_slice()));
        let what = format!("paper scenario, turn about {:?}", axis.as_slice());
        let peak = assert_held(&check, &checker, &cfg, &plan, &what);
        println!(
            "{what}: {} gaits, {:.2} s, largest F* {peak:.2} N",
            plan.summary.gaits, plan.summary.duration
        );
        at = plan.end_state();
    }
}

#[test]
fn the_paper_start_rolls_apart_in_three_legs_under_load() {
    // The paper start's pair must open to about 166–170° before it holds
    // the weight in its horizontal plane: past one great-circle roll's
    // reach from the fingertip pole (18° per finger). The Fig. 2 paths of
    // the rolling planner take four rest-to-rest legs there (4.7 s for 24°
    // per finger); zigzag legs take three (3.37 s, the optimum a
    // differential evolution found). Every such plan is held at every
    // sample by the test's own SOCP.
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let check = LoadCheck::new(&cfg);
    let checker = Checker::new(&cfg);
    let start = HandState::paper_start(&cfg);
    // The widest pair one great-circle roll per finger can make (Theory 2:
    // (r/R)·90° each); after a three-finger turn the pair may hold with
    // less than 166°, but not within that reach.
    let widest_at_start = {
        let n: Vec<Vector3<f64>> = start.fingers.iter().map(|f| f.center.normalize()).collect();
        (0..3)
            .map(|a| n[a].angle(&n[(a + 1) % 3]).to_degrees())
            .fold(0.0, f64::max)
    };
    let one_roll =
        widest_at_start + 2.0 * 90.0 * cfg.model.fingertip_radius / cfg.model.object_radius;
    for (i, goal) in goals(12, 15).iter().enumerate() {
        let plan = planner.plan(&start, goal).expect("planned");
        // (After a turn or a tilt with all three fingers, if the plan
        // starts with one.)
        let prefix: Vec<_> = plan
            .steps
            .iter()
            .skip_while(|s| s.kind == StepKind::Rotate && s.start.grasping().1 == 3)
            .take_while(|s| s.kind == StepKind::Roll)
            .collect();
        let time: f64 = prefix.iter().map(|s| s.duration).sum();
        let opened = {
            let end = prefix
                .last()
                .expect("rolls apart first")
                .eval(&prefix.last().unwrap().dofs().length, &[0.0; 3]);
            let n: Vec<Vector3<f64>> = end
                .state
                .fingers
                .iter()
                .map(|f| f.center.normalize())
                .collect();
            (0..3)
                .map(|a| n[a].angle(&n[(a + 1) % 3]).to_degrees())
                .fold(0.0, f64::max)
        };
        assert!(
            prefix.len() <= 3 && time < 4.0,
            "goal {i}: {} roll steps, {time:.2} s to open the pair to {opened:.1}°",
            prefix.len()
        );
        assert!(
            opened > one_roll,
            "goal {i}: the pair opened to {opened:.1}° only, within one great-circle roll's reach ({one_roll:.1}°)"
        );
        assert_held(&check, &checker, &cfg, &plan, &format!("goal {i}"));
    }
}

#[test]
fn random_states_that_need_the_exact_pair_test_plan_and_hold() {
    // Goals from random two-finger states (the planner bench's seed 7
    // sequence) for which the search's sufficient pair test alone finds no
    // plan: the search asks the exact closed form where the sufficient one
    // fails. Each must plan and hold at every sample by the independent
    // SOCP.
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let check = LoadCheck::new(&cfg);
    let checker = Checker::new(&cfg);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let cases: Vec<_> = (0..=82)
        .map(|_| {
            let start = planning::random_two_finger_state(&mut rng, &cfg);
            (start, planning::haar(&mut rng))
        })
        .collect();
    for i in [32, 66, 82] {
        let (start, goal) = &cases[i];
        let plan = planner
            .plan(start, goal)
            .unwrap_or_else(|e| panic!("random state {i}: {e}"));
        let peak = assert_held(&check, &checker, &cfg, &plan, &format!("random state {i}"));
        println!(
            "random state {i}: {} gaits, {:.2} s, largest F* {peak:.2} N",
            plan.summary.gaits, plan.summary.duration
        );
    }
}

#[test]
fn a_heavy_object_is_planned_or_rejected_with_its_reason() {
    // Stretch figures (printed, not graded): 0.5 kg at the default limit,
    // and the limit every goal would need (from a ladder of limits). Most
    // goals have no plan at the low limits, and a search that finds none
    // spends its whole budget: CI runs 6 goals with a tenth of the default
    // budget (GAIT_HEAVY_GOALS and GAIT_HEAVY_BUDGET set others).
    let n = count("GAIT_HEAVY_GOALS", 6);
    let gs = goals(n, 16);
    let mut cfg = HandConfig::default();
    cfg.load.object_mass = 0.5;
    cfg.planner.max_expansions = count("GAIT_HEAVY_BUDGET", 3000) as u32;
    let mut ladder = Vec::new();
    for limit in [20.0, 30.0, 40.0, 60.0, 80.0, 120.0] {
        cfg.load.max_grip = limit;
        let out = run(cfg, &gs);
        let planned = out.iter().filter(|o| o.planned).count();
        let bad: usize = out.iter().filter(|o| o.bad.is_some()).count();
        assert_eq!(
            bad, 0,
            "a heavy plan with samples that do not hold (limit {limit} N)"
        );
        let mut peaks: Vec<f64> = out
            .iter()
            .filter(|o| o.planned && !o.peak.is_nan())
            .map(|o| o.peak)
            .collect();
        let med = if peaks.is_empty() {
            f64::NAN
        } else {
            pct(&mut peaks, 0.5)
        };
        println!(
            "0.5 kg, load.max_grip {limit} N: {planned}/{n} planned (largest F* median {med:.1} N)"
        );
        ladder.push((limit, planned));
        if planned == n {
            break;
        }
    }
    match ladder.iter().find(|(_, p)| *p == n) {
        Some((l, _)) => println!("0.5 kg: every goal planned from load.max_grip = {l} N"),
        None => println!(
            "0.5 kg: not every goal planned up to {} N",
            ladder.last().unwrap().0
        ),
    }
    // Whatever is not planned is rejected with a reason that says no plan
    // was found: none holds the load, or none was found within the budget.
    cfg.load.max_grip = 20.0;
    let planner = Planner::new(&cfg).unwrap();
    for g in &gs {
        match planner.plan(&HandState::paper_start(&cfg), g) {
            Ok(_) => {}
            Err(e) => assert!(
                matches!(e, PlanError::LoadInfeasible { .. } | PlanError::Timeout),
                "{e:?}"
            ),
        }
    }
}

#[test]
fn a_start_that_cannot_hold_the_load_is_rejected() {
    // Two contacts 143° apart in a horizontal plane: force-closure, but
    // the weight's moment about the chord needs far more than 20 N of
    // torsion grip (~160 N).
    let cfg = HandConfig::default();
    let mut s = HandState::paper_start(&cfg);
    let rc = cfg.model.object_radius + cfg.model.fingertip_radius;
    let half = 71.5f64.to_radians();
    let at = |az: f64| Vector3::new(az.cos(), az.sin(), 0.0) * rc;
    s.fingers[0].center = at(60f64.to_radians() - half);
    s.fingers[1].center = at(60f64.to_radians() + half);
    s.fingers[2].mode = gait::FingerMode::Free;
    s.fingers[2].center = at(240f64.to_radians()) * ((rc + 0.03) / rc);
    let check = LoadCheck::new(&cfg);
    let (held, f) = check.holds(
        &[
            s.fingers[0].center.normalize(),
            s.fingers[1].center.normalize(),
        ],
        Kind::Soft,
        None,
    );
    assert!(!held, "the test's own check: {f} N");
    let planner = Planner::new(&cfg).unwrap();
    let goal = UnitQuaternion::from_scaled_axis(Vector3::z() * 0.5);
    assert_eq!(
        planner.plan(&s, &goal).unwrap_err(),
        PlanError::LoadInfeasible { start: true }
    );
}

#[test]
fn planning_under_load_is_deterministic() {
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let other = Planner::new(&cfg).unwrap();
    for g in goals(8, 17) {
        let s = HandState::paper_start(&cfg);
        let a = planner.plan(&s, &g).unwrap();
        let b = other.plan(&s, &g).unwrap();
        assert_eq!(a, b, "same inputs, different plans");
    }
}

/// Every way the fingertips offer to roll a pair apart from a three-finger
/// grasp under load passes the plan's check as built (SPEC §1.3 I1' at
/// every sample: while two roll, the three carry the load as hard
/// contacts): the search is never handed an opening the check refuses.
/// Three-finger grasps made as the search makes them: a random two-finger
/// state, the free finger placed at one of its candidates.
#[test]
fn every_roll_apart_offered_under_load_passes_the_check() {
    use gait::planner::Unbounded;
    use gait::planner::fingertips::Fingertips;
    use gait::planner::hand_model::{Action, HandModel, RegraspFor};
    let cfg = HandConfig::default();
    let hand = Fingertips::new(&cfg).for_pass(true, false);
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let (mut states, mut offers) = (0, 0);
    while states < 150 {
        let two = planning::random_two_finger_state(&mut rng, &cfg);
        let (_, n) = two.grasping();
        assert_eq!(n, 2);
        let free = (0..3)
            .find(|&k| two.fingers[k].mode == gait::FingerMode::Free)
            .expect("a free finger");
        let cands = hand.candidates(free);
        let c = cands[states * 7 % cands.len()];
        let mut three = two;
        let (touch, _) = hand.touch_for(free, &c, &Vector3::z());
        hand.place(&mut three, free, &c, touch);
        states += 1;
        for lift in 0..3 {
            let why = RegraspFor::OpenPair { lift };
            for o in hand.regrasps(&three, why, &mut Unbounded) {
                let actions = [Action::Regrasp {
                    regrasp: o.regrasp,
                    why,
                }];
                let Ok(steps) = hand.build(&three, &actions) else {
                    continue;
                };
                offers += 1;
                if let Err(v) = hand.check(&three, &steps) {
                    panic!(
                        "an opening for finger {lift} fails the check at step {} (F* {:.2} N): {three:?}",
                        v.step, v.peak
                    );
                }
            }
        }
    }
    println!("{states} three-finger grasps: {offers} openings offered, each held");
    assert!(offers >= 20, "too few openings to test anything: {offers}");
}
