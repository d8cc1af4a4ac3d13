//! The gaits recognised in real plans ([`gait::planner::gaiting`]) are what the paper
//! calls them (§2.1), checked against the plans' hand states: a
//! substitution hands the grasp from one finger to another; a rewind
//! relocates one or both fingers of the grasping pair, without object
//! motion, and ends with the same pair grasping.

mod planning;

use gait::HandState;
use gait::planner::gaiting::{FingerGait, GaitTracker};
use gait::planner::{Plan, Planner, StepKind};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn grasp_set(s: &HandState) -> Vec<usize> {
    let (idx, n) = s.grasping();
    idx[..n].to_vec()
}

/// The state after step `i`.
fn after(plan: &Plan, i: usize) -> HandState {
    plan.steps
        .get(i + 1)
        .map_or_else(|| plan.end_state(), |s| s.start)
}

/// Index of the Place/Lift step before `i`, skipping transfers; panics on
/// object motion in between (no gait spans a Rotate or Roll).
fn previous_gait(plan: &Plan, i: usize) -> usize {
    (0..i)
        .rev()
        .find(|&j| plan.steps[j].kind != StepKind::Transfer)
        .filter(|&j| matches!(plan.steps[j].kind, StepKind::Place | StepKind::Lift))
        .unwrap_or_else(|| panic!("step {i}: no gait right before it"))
}

fn check_substitution(plan: &Plan, lift: usize, left: u8, by: u8) {
    let place = previous_gait(plan, lift);
    let (p, l) = (&plan.steps[place], &plan.steps[lift]);
    assert_eq!((p.kind, p.finger()), (StepKind::Place, Some(by as usize)));
    assert_eq!((l.kind, l.finger()), (StepKind::Lift, Some(left as usize)));
    let mut before = grasp_set(&p.start);
    let end = grasp_set(&after(plan, lift));
    before.retain(|&f| f != left as usize);
    before.push(by as usize);
    before.sort_unstable();
    assert_eq!(before, end, "the grasp went from `left` to `by`");
}

fn check_rewind(plan: &Plan, lift: usize, relocated: u8, helper: u8) {
    let h = helper as usize;
    let l = &plan.steps[lift];
    assert_eq!((l.kind, l.finger()), (StepKind::Lift, Some(h)));
    // Back to where the helper was placed, over gaits only.
    let mut first = lift;
    let mut lifted = 0u8;
    loop {
        first = previous_gait(plan, first);
        let s = &plan.steps[first];
        let f = s.finger().unwrap();
        match s.kind {
            StepKind::Place if f == h => break,
            StepKind::Lift => {
                assert_ne!(f, h, "the helper lifted twice");
                lifted |= 1 << f;
            }
            _ => {}
        }
    }
    assert_eq!(relocated, lifted, "the fingers lifted meanwhile");
    let before = plan.steps[first].start;
    let end = after(plan, lift);
    assert_eq!(grasp_set(&before), grasp_set(&end), "the same pair grasps");
    assert!(!grasp_set(&end).contains(&h), "the helper is free again");
    assert!(
        before.object.angle_to(&end.object) < 1e-12,
        "no object motion"
    );
    for f in (0..3).filter(|f| relocated & 1 << f != 0) {
        assert!(grasp_set(&end).contains(&f));
        let moved = (before.object_contact(f) - end.object_contact(f)).norm();
        assert!(moved > 1e-6, "finger {f} relocated ({moved})");
    }
}

#[test]
fn recognised_gaits_match_the_plans_states() {
    let cfg = planning::weightless();
    let planner = Planner::new(&cfg).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut subs, mut rewinds) = (0, 0);
    for i in 0..400 {
        let start = if i % 2 == 0 {
            HandState::paper_start(&cfg)
        } else {
            planning::random_two_finger_state(&mut rng, &cfg)
        };
        let plan = planner
            .plan(&start, &planning::haar(&mut rng))
            .unwrap_or_else(|e| panic!("goal {i}: {e}"));
        let mut t = GaitTracker::new();
        let (mut plan_subs, mut plan_rewinds) = (0, 0);
        for (j, s) in plan.steps.iter().enumerate() {
            t.started(s.kind);
            let done = t.done(s.kind, s.finger().map_or(u8::MAX, |f| f as u8));
            if let Some(FingerGait::Substitution { left, by }) = done.substitution {
                check_substitution(&plan, j, left, by);
                plan_subs += 1;
            }
            if let Some(FingerGait::Rewind { relocated, helper }) = done.rewind {
                check_rewind(&plan, j, relocated, helper);
                plan_rewinds += 1;
            }
        }
        assert_eq!(
            (plan.summary.substitutions, plan.summary.rewinds),
            (plan_subs, plan_rewinds),
            "goal {i}: the plan's summary"
        );
        assert_eq!(plan_subs, lifts_after_a_placement(&plan), "goal {i}");
        subs += plan_subs;
        rewinds += plan_rewinds;
    }
    println!("{subs} substitutions, {rewinds} rewinds");
    assert!(
        subs > 100 && rewinds > 0,
        "{subs} substitutions, {rewinds} rewinds"
    );
}

/// Lifts that come right after another finger's placement, counted
/// without the tracker. (The tracker also counts a Place, object motion,
/// Lift as a substitution; plans never contain that, so here they agree.)
fn lifts_after_a_placement(plan: &Plan) -> u32 {
    let gaits: Vec<_> = plan
        .steps
        .iter()
        .filter(|s| s.kind != StepKind::Transfer)
        .collect();
    gaits
        .windows(2)
        .filter(|w| {
            w[0].kind == StepKind::Place
                && w[1].kind == StepKind::Lift
                && w[0].finger() != w[1].finger()
        })
        .count() as u32
}

#[test]
fn turn_plans_count_their_substitutions() {
    // The paper's scenario (two turns about z) and turns about other axes
    // are planned in pieces; the summary counts over the whole plan.
    let cfg = planning::weightless();
    let planner = Planner::new(&cfg).unwrap();
    let start = HandState::paper_start(&cfg);
    for axis in [
        nalgebra::Vector3::z(),
        nalgebra::Vector3::new(1.0, 1.0, 0.5).normalize(),
    ] {
        let plan = planner
            .plan_rotation(&start, &axis, 2.0 * std::f64::consts::TAU)
            .unwrap();
        let s = plan.summary;
        println!(
            "two turns about {:?}: {} gaits, {} substitutions, {} rewinds",
            axis.as_slice(),
            s.gaits,
            s.substitutions,
            s.rewinds
        );
        assert!(s.substitutions > 0);
        assert_eq!(s.substitutions, lifts_after_a_placement(&plan));
    }
}
